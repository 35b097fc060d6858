//! Linear strain bases `Ψ = Φ q` (gvs-spec §4.1–4.4): Legendre polynomials and FEM-like local
//! (linear/quadratic) bases per division, multi-division rods with a basis per division, and a
//! pointwise basis given as values at the sites (POD modes use it).
//!
//! Per division j, `Φ_j(X) = S_j Φ̄(X̄)` with `S_j = diag(1/ℓ_j, 1/ℓ_j, 1/ℓ_j, 1, 1, 1)`: angular
//! coordinates are angles, linear coordinates dimensionless strains (spec §4.1). Legendre columns are
//! ordered mode by mode (torsion, bend-y, bend-z, elongation, shear-y, shear-z), by increasing degree
//! inside a mode (spec §4.1). FEM-like columns are ordered **node by node**, the active modes in that
//! order inside a node (column `k·m + a` is node `k` of the `a`-th of the `m` active modes; with one
//! active mode this is spec §4.1's order), so that the support of a site — the nodes of its element,
//! every mode — is one contiguous range of `(p + 1)·m` columns ([`StrainParam::columns`]).
//! Divisions follow each other in `q`.
//!
//! `Φ` is stored per site on its support only (6 × Σ_s |cols_s|), not as 6 × n per site.

use super::{SiteJacobian, StrainEval, StrainParam};
use crate::discretize::Discretization;
use crate::error::ModelError;
use crate::lie::V6;
use nalgebra::{DMatrix, DVector, Matrix6xX};
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Names the order of the generalized coordinates `q` (module docs): files that store `q` record it,
/// so that coordinates written under another order are never mixed with these. Before it, FEM-like
/// bases with several modes were ordered mode by mode (`"fem-mode-major"`).
pub const COORDINATE_ORDER: &str = "fem-node-major";

/// Polynomial degree of a FEM-like local basis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FemDegree {
    Linear,
    Quadratic,
}

/// The basis of one division. `modes[i]` says whether strain component i is active.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum DivisionBasis {
    /// Unnormalized Legendre polynomials `P_0..P_k` of `x = 2X̄ − 1`, order `k = orders[i]` per mode.
    Legendre {
        modes: [bool; 6],
        orders: [usize; 6],
    },
    /// Local (nodal) basis on `elements` equal elements: `elements·p + 1` columns per active mode.
    Fem {
        modes: [bool; 6],
        elements: usize,
        degree: FemDegree,
    },
}

impl DivisionBasis {
    /// Number of coordinates of the division.
    pub fn dofs(&self) -> usize {
        (0..6).map(|i| self.mode_dofs(i)).sum()
    }

    fn mode_dofs(&self, i: usize) -> usize {
        match self {
            DivisionBasis::Legendre { modes, orders } => {
                if modes[i] {
                    orders[i] + 1
                } else {
                    0
                }
            }
            DivisionBasis::Fem {
                modes,
                elements,
                degree,
            } => {
                if modes[i] {
                    elements * degree_of(*degree) + 1
                } else {
                    0
                }
            }
        }
    }

    pub fn validate(&self, field: &str) -> Result<(), ModelError> {
        if self.dofs() == 0 {
            return Err(ModelError::invalid(
                field,
                "the basis is empty: activate at least one strain mode",
            ));
        }
        if let DivisionBasis::Fem { elements, .. } = self {
            if *elements == 0 {
                return Err(ModelError::value(
                    format!("{field}.elements"),
                    0.0,
                    "an integer >= 1",
                ));
            }
        }
        Ok(())
    }

    /// Writes `Φ̄(X̄)` scaled by `S_j` (6 × dofs) into `out` (which must be zeroed).
    pub fn fill(&self, x_bar: f64, length: f64, out: &mut nalgebra::DMatrixViewMut<'_, f64>) {
        let scale = |i: usize| if i < 3 { 1.0 / length } else { 1.0 };
        match self {
            DivisionBasis::Legendre { .. } => {
                let x = 2.0 * x_bar - 1.0;
                let mut col = 0;
                for i in 0..6 {
                    let nd = self.mode_dofs(i);
                    let (mut p0, mut p1) = (1.0, x);
                    for m in 0..nd {
                        let v = match m {
                            0 => 1.0,
                            1 => x,
                            _ => {
                                let k = (m - 1) as f64;
                                let p2 = ((2.0 * k + 1.0) * x * p1 - k * p0) / (k + 1.0);
                                p0 = p1;
                                p1 = p2;
                                p2
                            }
                        };
                        out[(i, col + m)] = v * scale(i);
                    }
                    col += nd;
                }
            }
            DivisionBasis::Fem {
                modes,
                elements,
                degree,
            } => {
                let m = modes.iter().filter(|&&a| a).count();
                let (first, values) = fem_shape(x_bar, *elements, *degree);
                let active = (0..6).filter(|&i| modes[i]);
                for (slot, i) in active.enumerate() {
                    for (k, v) in values.iter().enumerate().take(degree_of(*degree) + 1) {
                        out[(i, (first + k) * m + slot)] += v * scale(i);
                    }
                }
            }
        }
    }

    /// The columns (relative to the division's first) on which `Φ̄(X̄)` may be non-zero: all of them
    /// for Legendre; the nodes of the element holding `X̄`, every active mode, for FEM-like bases.
    pub fn support(&self, x_bar: f64) -> Range<usize> {
        match self {
            DivisionBasis::Legendre { .. } => 0..self.dofs(),
            DivisionBasis::Fem {
                modes,
                elements,
                degree,
            } => {
                let m = modes.iter().filter(|&&a| a).count();
                let (first, _) = fem_shape(x_bar, *elements, *degree);
                first * m..(first + degree_of(*degree) + 1) * m
            }
        }
    }
}

/// The FEM-like shape functions at `X̄` (spec §4.3): the first node of the element holding `X̄` and
/// the values of its `p + 1` nodal functions (element `e = ⌊n_e X̄⌋`, `χ = n_e X̄ − e`; linear
/// `1 − χ, χ`; quadratic `2(χ − ½)(χ − 1), −4χ(χ − 1), 2χ(χ − ½)`).
fn fem_shape(x_bar: f64, ne: usize, degree: FemDegree) -> (usize, [f64; 3]) {
    let e = ((x_bar * ne as f64 + 1e-12).floor() as usize).min(ne - 1);
    let chi = x_bar * ne as f64 - e as f64;
    match degree {
        FemDegree::Linear => (e, [1.0 - chi, chi, 0.0]),
        FemDegree::Quadratic => (
            2 * e,
            [
                2.0 * (chi - 0.5) * (chi - 1.0),
                -4.0 * chi * (chi - 1.0),
                2.0 * chi * (chi - 0.5),
            ],
        ),
    }
}

fn degree_of(d: FemDegree) -> usize {
    match d {
        FemDegree::Linear => 1,
        FemDegree::Quadratic => 2,
    }
}

/// A mutable 6 × k block of `Φ`.
type SiteBlockMut<'a> = nalgebra::Matrix<
    f64,
    nalgebra::U6,
    nalgebra::Dyn,
    nalgebra::ViewStorageMut<'a, f64, nalgebra::U6, nalgebra::Dyn, nalgebra::U1, nalgebra::U6>,
>;

/// A linear strain basis tabulated at the sites of one discretization: `Ψ_s = Φ_s q`.
#[derive(Debug, Clone)]
pub struct LinearBasis {
    n: usize,
    /// `Φ_s` of all sites on their columns `cols[s]`, side by side (6 × Σ_s |cols_s|); site `s`
    /// starts at `offsets[s]`.
    phi: Matrix6xX<f64>,
    offsets: Vec<usize>,
    cols: Vec<Range<usize>>,
}

impl LinearBasis {
    /// A basis from `Φ_s` restricted to `cols[s]`, written per site by `block(s, cols[s], out)`.
    fn from_blocks(
        n: usize,
        cols: Vec<Range<usize>>,
        mut block: impl FnMut(usize, &Range<usize>, &mut SiteBlockMut<'_>),
    ) -> Self {
        let mut offsets = Vec::with_capacity(cols.len());
        let mut total = 0;
        for c in &cols {
            offsets.push(total);
            total += c.len();
        }
        let mut phi = Matrix6xX::zeros(total);
        for (s, c) in cols.iter().enumerate() {
            block(s, c, &mut phi.columns_mut(offsets[s], c.len()));
        }
        LinearBasis {
            n,
            phi,
            offsets,
            cols,
        }
    }

    /// `Φ_s` on its columns, as a view.
    fn block(&self, s: usize) -> SiteJacobian<'_> {
        self.phi.columns(self.offsets[s], self.cols[s].len())
    }

    /// One basis per division (spec §4.4); coordinates of the divisions are concatenated. A site's
    /// columns are its division's support at the site ([`DivisionBasis::support`]); the two Magnus
    /// sub-points of a step get the union of theirs.
    pub fn per_division(
        disc: &Discretization,
        bases: &[DivisionBasis],
    ) -> Result<Self, ModelError> {
        if bases.len() != disc.div_length.len() {
            return Err(ModelError::invalid(
                "basis",
                format!(
                    "{} division bases for {} divisions",
                    bases.len(),
                    disc.div_length.len()
                ),
            ));
        }
        let mut offsets = Vec::with_capacity(bases.len());
        let mut n = 0;
        for (j, b) in bases.iter().enumerate() {
            b.validate(&format!("divisions[{j}].basis"))?;
            offsets.push(n);
            n += b.dofs();
        }
        let mut cols: Vec<Range<usize>> = disc
            .sites
            .iter()
            .map(|site| {
                let r = bases[site.div].support(site.x_bar);
                let o = offsets[site.div];
                o + r.start..o + r.end
            })
            .collect();
        for st in disc.steps.iter().flatten() {
            let [s1, s2] = st.sites;
            let hull = cols[s1].start.min(cols[s2].start)..cols[s1].end.max(cols[s2].end);
            cols[s1] = hull.clone();
            cols[s2] = hull;
        }
        // Φ of a division at a site, all its columns (reused scratch), then the site's columns.
        let mut full = DMatrix::zeros(6, bases.iter().map(|b| b.dofs()).max().unwrap_or(0));
        Ok(Self::from_blocks(n, cols, |s, c, out| {
            let site = disc.sites[s];
            let (o, nd) = (offsets[site.div], bases[site.div].dofs());
            full.fill(0.0);
            let mut v = full.view_mut((0, 0), (6, nd));
            bases[site.div].fill(site.x_bar, disc.div_length[site.div], &mut v);
            out.copy_from(&full.columns(c.start - o, c.len()));
        }))
    }

    /// A basis given by its values at every site: `values` is 6·n_sites × n, point-major (site s
    /// occupies rows 6s..6s+6). Every coordinate may act everywhere (as for POD modes).
    pub fn from_site_values(
        disc: &Discretization,
        values: &DMatrix<f64>,
    ) -> Result<Self, ModelError> {
        let ns = disc.n_sites();
        if values.nrows() != 6 * ns || values.ncols() == 0 {
            return Err(ModelError::invalid(
                "basis.values",
                format!(
                    "expected a {}×n matrix (6 rows per site, n >= 1), got {}×{}",
                    6 * ns,
                    values.nrows(),
                    values.ncols()
                ),
            ));
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::invalid(
                "basis.values",
                "contains NaN or infinite entries",
            ));
        }
        let n = values.ncols();
        Ok(Self::from_blocks(n, vec![0..n; ns], |s, _, out| {
            out.copy_from(&values.rows(6 * s, 6))
        }))
    }

    /// A pointwise basis given at the computational points only (`6·n_points × n`, point-major), as a
    /// POD basis learned from strain snapshots is. Values at the Magnus sub-points are interpolated
    /// linearly in X between the two neighbouring points of the same division (2nd-order accurate;
    /// see gvs-spec §12.1).
    pub fn from_point_values(
        disc: &Discretization,
        values: &DMatrix<f64>,
    ) -> Result<Self, ModelError> {
        let np = disc.n_points();
        if values.nrows() != 6 * np || values.ncols() == 0 {
            return Err(ModelError::invalid(
                "basis.values",
                format!(
                    "expected a {}×n matrix (6 rows per point, n >= 1), got {}×{}",
                    6 * np,
                    values.nrows(),
                    values.ncols()
                ),
            ));
        }
        let n = values.ncols();
        let ns = disc.n_sites();
        let mut full = DMatrix::zeros(6 * ns, n);
        full.rows_mut(0, 6 * np).copy_from(values);
        for st in disc.steps.iter().flatten() {
            let (a, b) = (disc.points[st.from], disc.points[st.from + 1]);
            for &site in &st.sites {
                let t = (disc.sites[site].x - a.x) / (b.x - a.x);
                let v =
                    values.rows(6 * st.from, 6) * (1.0 - t) + values.rows(6 * (st.from + 1), 6) * t;
                full.rows_mut(6 * site, 6).copy_from(&v);
            }
        }
        Self::from_site_values(disc, &full)
    }

    /// `Φ_s B` at every site: the basis whose coordinates are mapped onto this one's by the constant
    /// `n × k` matrix `B` (`q = B q_r`). A POD basis expressed on the high-order model's own basis
    /// is one (`B` = the POD modes' coefficients); every coordinate then acts everywhere.
    pub fn compose(&self, b: &DMatrix<f64>) -> Result<LinearBasis, ModelError> {
        if b.nrows() != self.n || b.ncols() == 0 {
            return Err(ModelError::invalid(
                "basis.coefficients",
                format!(
                    "expected a {}×k matrix (k >= 1), got {}×{}",
                    self.n,
                    b.nrows(),
                    b.ncols()
                ),
            ));
        }
        if b.iter().any(|v| !v.is_finite()) {
            return Err(ModelError::invalid(
                "basis.coefficients",
                "contains NaN or infinite entries",
            ));
        }
        let k = b.ncols();
        let ns = self.cols.len();
        Ok(Self::from_blocks(k, vec![0..k; ns], |s, _, out| {
            let r = &self.cols[s];
            out.gemm(1.0, &self.block(s), &b.rows(r.start, r.len()), 0.0);
        }))
    }

    /// `Φ_s` restricted to its columns.
    pub fn phi_at(&self, site: usize) -> nalgebra::DMatrix<f64> {
        let r = &self.cols[site];
        DMatrix::from_iterator(6, r.len(), self.block(site).iter().cloned())
    }
}

impl StrainParam for LinearBasis {
    fn n_dof(&self) -> usize {
        self.n
    }
    fn n_sites(&self) -> usize {
        self.cols.len()
    }
    fn is_linear(&self) -> bool {
        true
    }
    fn columns(&self, site: usize) -> Range<usize> {
        self.cols[site].clone()
    }
    fn new_eval(&self) -> StrainEval {
        let mut ev = StrainEval::with_columns(self.n, &self.cols);
        ev.psi_q.copy_from(&self.phi);
        ev
    }
    fn eval(&self, q: &DVector<f64>, ev: &mut StrainEval) {
        for (s, r) in self.cols.iter().enumerate() {
            ev.psi[s] = self.block(s) * q.rows(r.start, r.len());
        }
    }
    fn eval_rate(&self, _q: &DVector<f64>, _qd: &DVector<f64>, _ev: &mut StrainEval) {}
    fn add_weighted_hessian(
        &self,
        _q: &DVector<f64>,
        _w: &[V6],
        _ev: &mut StrainEval,
        _out: &mut DMatrix<f64>,
    ) {
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discretize::{MagnusOrder, Quadrature};
    use crate::rod::{DivisionGeometry, Material, Rod};

    fn disc(lengths: &[f64], q: Quadrature) -> Discretization {
        let rod = Rod {
            material: Material {
                youngs_modulus: 1e6,
                poisson_ratio: 0.5,
                density: 1000.0,
                damping: 0.0,
            },
            divisions: lengths
                .iter()
                .map(|&l| DivisionGeometry {
                    length: l,
                    radius_start: 0.01,
                    radius_end: 0.01,
                })
                .collect(),
        };
        Discretization::new(&rod, &vec![q; lengths.len()], MagnusOrder::Z4, &[]).unwrap()
    }

    #[test]
    fn paper_dof_counts() {
        let a = DivisionBasis::Legendre {
            modes: [false, true, false, true, false, true],
            orders: [0, 10, 0, 10, 0, 10],
        };
        assert_eq!(a.dofs(), 33);
        let c = DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [1, 2, 2, 1, 1, 1],
        };
        assert_eq!(2 * c.dofs(), 28);
        let b = DivisionBasis::Fem {
            modes: [false, true, false, false, false, false],
            elements: 49,
            degree: FemDegree::Linear,
        };
        assert_eq!(b.dofs(), 50);
        let qd = DivisionBasis::Fem {
            modes: [true, false, false, false, false, false],
            elements: 4,
            degree: FemDegree::Quadratic,
        };
        assert_eq!(qd.dofs(), 9);
    }

    #[test]
    fn legendre_values_and_angular_scaling() {
        let d = disc(&[0.5], Quadrature::Gauss { n: 5 });
        let b = DivisionBasis::Legendre {
            modes: [false, true, false, true, false, false],
            orders: [0, 3, 0, 2, 0, 0],
        };
        let lb = LinearBasis::per_division(&d, &[b]).unwrap();
        for (s, site) in d.sites.iter().enumerate() {
            let x = 2.0 * site.x_bar - 1.0;
            let p = [
                1.0,
                x,
                0.5 * (3.0 * x * x - 1.0),
                0.5 * (5.0 * x * x * x - 3.0 * x),
            ];
            let phi = lb.phi_at(s);
            for m in 0..4 {
                assert!((phi[(1, m)] - p[m] / 0.5).abs() < 1e-14);
            }
            for m in 0..3 {
                assert!((phi[(3, 4 + m)] - p[m]).abs() < 1e-14);
            }
            assert_eq!(phi.row(0).amax(), 0.0);
        }
    }

    #[test]
    fn fem_hat_functions_partition_unity_and_interpolate_nodes() {
        let d = disc(
            &[0.8],
            Quadrature::Elements {
                elements: 7,
                gauss_per_element: 2,
            },
        );
        for deg in [FemDegree::Linear, FemDegree::Quadratic] {
            let b = DivisionBasis::Fem {
                modes: [false, false, false, true, false, false],
                elements: 7,
                degree: deg,
            };
            let lb = LinearBasis::per_division(&d, &[b]).unwrap();
            for s in 0..d.n_sites() {
                let sum: f64 = lb.phi_at(s).row(3).sum();
                assert!((sum - 1.0).abs() < 1e-13);
            }
            // at element ends (weight-0 points) exactly one node is 1
            for (i, p) in d.points.iter().enumerate() {
                if p.weight == 0.0 {
                    let phi = lb.phi_at(i);
                    assert!(
                        (phi.row(3).amax() - 1.0).abs() < 1e-12,
                        "node value at X̄ = {}",
                        p.x_bar
                    );
                }
            }
        }
    }

    #[test]
    fn multi_division_columns_are_disjoint() {
        let d = disc(&[0.3, 0.3], Quadrature::Gauss { n: 5 });
        let c = DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [1, 2, 2, 1, 1, 1],
        };
        let lb = LinearBasis::per_division(&d, &[c.clone(), c]).unwrap();
        assert_eq!(lb.n_dof(), 28);
        assert_eq!(lb.columns(0), 0..14);
        assert_eq!(lb.columns(d.n_points() - 1), 14..28);
    }

    #[test]
    fn empty_basis_is_an_error() {
        let d = disc(&[0.3], Quadrature::Gauss { n: 5 });
        let c = DivisionBasis::Legendre {
            modes: [false; 6],
            orders: [1; 6],
        };
        let e = LinearBasis::per_division(&d, &[c]).unwrap_err().to_string();
        assert!(
            e.contains("divisions[0].basis") && e.contains("empty"),
            "{e}"
        );
    }

    #[test]
    fn a_composed_basis_is_the_product_at_every_site() {
        let d = disc(&[0.3, 0.3], Quadrature::Gauss { n: 4 });
        let c = DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [1, 2, 2, 1, 1, 1],
        };
        let lb = LinearBasis::per_division(&d, &[c.clone(), c]).unwrap();
        let b = DMatrix::from_fn(28, 3, |i, j| ((i * 5 + j * 3) % 7) as f64 - 3.0);
        let pb = lb.compose(&b).unwrap();
        assert_eq!(pb.n_dof(), 3);
        let q_r = DVector::from_vec(vec![0.3, -1.2, 0.7]);
        let (mut e1, mut e2) = (lb.new_eval(), pb.new_eval());
        lb.eval(&(&b * &q_r), &mut e1);
        pb.eval(&q_r, &mut e2);
        for s in 0..d.n_sites() {
            assert!((e1.psi[s] - e2.psi[s]).amax() < 1e-13);
        }
        assert!(lb.compose(&DMatrix::zeros(27, 3)).is_err());
    }

    #[test]
    fn point_values_are_interpolated_to_sub_points() {
        let d = disc(&[0.4], Quadrature::Gauss { n: 6 });
        // a basis linear in X is reproduced exactly at the sub-points
        let np = d.n_points();
        let mut v = DMatrix::zeros(6 * np, 1);
        for (i, p) in d.points.iter().enumerate() {
            v[(6 * i + 1, 0)] = 1.0 + 2.0 * p.x;
        }
        let lb = LinearBasis::from_point_values(&d, &v).unwrap();
        for (s, site) in d.sites.iter().enumerate() {
            assert!((lb.phi_at(s)[(1, 0)] - (1.0 + 2.0 * site.x)).abs() < 1e-13);
        }
    }
}
