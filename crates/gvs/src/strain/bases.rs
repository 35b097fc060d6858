//! Linear strain bases `Ψ = Φ q` (gvs-spec §4.1–4.4) tabulated at the sites of one discretization
//! ([`LinearBasis`]): multi-division rods with a basis per division ([`DivisionBasis`]: Legendre
//! polynomials, FEM-like local bases), a pointwise basis given as values at the sites (POD modes use
//! it), and a basis composed with a constant coefficient matrix.
//!
//! `Φ` is stored per site on its support only (6 × Σ_s |cols_s|), not as 6 × n per site.

mod division;
#[cfg(test)]
mod tests;

pub use division::{fem_shape, DivisionBasis, FemDegree, COORDINATE_ORDER};

use super::{SiteJacobian, StrainEval, StrainParam};
use crate::discretize::Discretization;
use crate::error::ModelError;
use crate::lie::V6;
use nalgebra::{DMatrix, DVector, Matrix6xX};
use std::ops::Range;

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
