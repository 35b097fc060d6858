//! Reduced strain parameterizations on the high-order model's own basis.
//!
//! Snapshots, POD modes and decoders live at the `p` computational points, for the active strain
//! components only (paper eq. 13). The Magnus Z4 kinematics also needs the strain between the points
//! (gvs-spec §12.1). gvsrom's answer, for POD and autoencoders alike: map point strains back onto the
//! high-order model's (HOM) basis coefficients with the fixed least-squares projection
//!
//! ```text
//! P = (Φ̄ᵀ Φ̄)⁻¹ Φ̄ᵀ        Φ̄ = the HOM basis at the points, active rows (p·n_a × n)
//! ```
//!
//! and define the reduced strain at every site `s` (points and Magnus sub-points) as
//!
//! ```text
//! Ψ_s(q_r) = Φ_s c(q_r),   c(q_r) = P D(q_r)   (n HOM coefficients)
//! ```
//!
//! This is exact for every strain field in the HOM's span (all HOM snapshots are, so `P x = q` for a
//! snapshot `x` of the HOM state `q`); for a decoder it removes the part of `D(q_r)` the HOM could
//! not represent, a part [`projection_residual`] measures. Every derivative of `Ψ_s` is `Φ_s` times
//! the same derivative of `c`, so the engine's statics, dynamics and Jacobians apply unchanged.

use crate::map::CoefficientMap;
use gvs::discretize::Discretization;
use gvs::lie::V6;
use gvs::strain::{project_with_psi_q, LinearBasis, StrainEval, StrainParam};
use nalgebra::{DMatrix, DVector};
use thiserror::Error;

mod basis_rows;
mod site_rows;
mod stacked;
use basis_rows::BasisRows;

#[derive(Debug, Error, PartialEq)]
pub enum ReducedError {
    #[error("{field}: {message}")]
    Invalid { field: String, message: String },
}

fn invalid(field: &str, message: impl Into<String>) -> ReducedError {
    ReducedError::Invalid {
        field: field.into(),
        message: message.into(),
    }
}

/// Which strain components a snapshot holds at each computational point, in the order of the
/// engine's 6-vector `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]` (eq. 13 layout:
/// point-major, `row = [point 0 components…, point 1 components…, …]`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointLayout {
    pub n_points: usize,
    /// Indices into the strain 6-vector, ascending.
    pub active: Vec<usize>,
}

impl PointLayout {
    /// Length of one snapshot, `p · n_a`.
    pub fn len(&self) -> usize {
        self.n_points * self.active.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The components a basis can excite anywhere: a row of `Φ_s` non-zero at some site (points
    /// and Magnus sub-points).
    pub fn active_in(basis: &LinearBasis, disc: &Discretization) -> PointLayout {
        let mut on = [false; 6];
        for s in 0..basis.n_sites() {
            let phi = basis.phi_at(s);
            for (a, flag) in on.iter_mut().enumerate() {
                *flag |= phi.row(a).iter().any(|v| *v != 0.0);
            }
        }
        PointLayout {
            n_points: disc.n_points(),
            active: (0..6).filter(|&a| on[a]).collect(),
        }
    }
}

/// `Φ̄`: the HOM basis at the computational points, rows in the layout's order (`p·n_a × n`).
pub fn point_matrix(basis: &LinearBasis, layout: &PointLayout) -> DMatrix<f64> {
    let n = basis.n_dof();
    let na = layout.active.len();
    let mut m = DMatrix::zeros(layout.len(), n);
    for i in 0..layout.n_points {
        let cols = basis.columns(i);
        let phi = basis.phi_at(i);
        for (k, &a) in layout.active.iter().enumerate() {
            for (j, col) in cols.clone().enumerate() {
                m[(i * na + k, col)] = phi[(a, j)];
            }
        }
    }
    m
}

/// The least-squares projection `P = Φ̄⁺` (n × p·n_a) from point strains onto HOM coefficients.
/// Errors if a HOM coordinate is (numerically) invisible at the points: `σ_min < 1e-10 σ_max`.
pub fn projection(point_matrix: &DMatrix<f64>) -> Result<DMatrix<f64>, ReducedError> {
    let (rows, n) = point_matrix.shape();
    if rows < n {
        return Err(invalid(
            "basis",
            format!("{n} HOM coordinates but only {rows} point values: cannot be recovered"),
        ));
    }
    let svd = point_matrix.clone().svd(true, true);
    let smax = svd.singular_values.max();
    let smin = svd.singular_values.min();
    if smin.is_nan() || smin <= 1e-10 * smax {
        return Err(invalid(
            "basis",
            format!(
                "the HOM basis is rank-deficient at the computational points (σ_min/σ_max = {:.1e}); \
                 its coefficients cannot be recovered from point strains",
                smin / smax
            ),
        ));
    }
    svd.pseudo_inverse(0.0)
        .map_err(|e| invalid("basis", e.to_string()))
}

/// Relative size of what the HOM basis cannot represent in the point strains `x`:
/// `‖x − Φ̄ P x‖ / ‖x‖` (0 for a field in the HOM's span).
pub fn projection_residual(point_matrix: &DMatrix<f64>, p: &DMatrix<f64>, x: &DVector<f64>) -> f64 {
    let back = point_matrix * (p * x);
    let norm = x.norm();
    if norm == 0.0 {
        0.0
    } else {
        (x - back).norm() / norm
    }
}

/// A nonlinear reduced parameterization `Ψ_s(z) = Φ_s c(z)` over the sites of a discretization,
/// `c` a [`CoefficientMap`] (a decoder folded with the projection `P`).
pub struct ReducedParam<M: CoefficientMap> {
    map: M,
    /// HOM basis `Φ_s` at every site.
    rows: BasisRows,
    n_sites: usize,
    m: usize,
    r: usize,
    rest: DVector<f64>,
}

/// Where the parts of [`StrainEval::scratch`] start: `c`, `C_z` (adjacent: `[c | C_z]` is one
/// `m × (1 + r)` matrix), `Ċ_z`, `g`, `H`, the motion `[c | ċ | c̈]` (`m × 3`), `C_zᵀ g`, the
/// basis products' work space ([`SiteRows::products`]), the map's own.
#[derive(Debug, Clone, Copy)]
struct Layout {
    /// `c` starts at 0.
    cz: usize,
    czd: usize,
    g: usize,
    h: usize,
    mo: usize,
    zt: usize,
    work: usize,
    map: usize,
    end: usize,
}

impl<M: CoefficientMap> ReducedParam<M> {
    /// Binds `map` (coefficients of `basis`) to the sites of `basis`. `rest` are the coordinates of the
    /// straight rod (see [`ReducedParam::find_rest`]).
    pub fn new(basis: &LinearBasis, map: M, rest: DVector<f64>) -> Result<Self, ReducedError> {
        let m = basis.n_dof();
        if map.n_out() != m {
            return Err(invalid(
                "model",
                format!(
                    "the decoder gives {} coefficients, the scenario's basis has {m}",
                    map.n_out()
                ),
            ));
        }
        let r = map.n_in();
        if r == 0 || rest.len() != r || rest.iter().any(|v| !v.is_finite()) {
            return Err(invalid(
                "model.rest",
                format!("expected {r} finite rest coordinates, got {}", rest.len()),
            ));
        }
        Ok(ReducedParam {
            map,
            rows: BasisRows::of(basis),
            n_sites: basis.n_sites(),
            m,
            r,
            rest,
        })
    }

    pub fn map(&self) -> &M {
        &self.map
    }

    fn layout(&self) -> Layout {
        let (m, r) = (self.m, self.r);
        let cz = m; // c at 0
        let czd = cz + m * r;
        let g = czd + m * r;
        let h = g + m;
        let mo = h + r * r;
        let zt = mo + 3 * m;
        let work = zt + r;
        let map = work + self.rows.work_len(m, (1 + r).max(3), self.n_sites);
        Layout {
            cz,
            czd,
            g,
            h,
            mo,
            zt,
            work,
            map,
            end: map + self.map.scratch_len(),
        }
    }

    /// Refines a guess `z0` of the straight rod's coordinates (e.g. the encoder of the zero strain) by
    /// Gauss–Newton on `½‖c(z)‖²` (at most 50 iterations); returns the best `z` found and `‖c(z)‖`.
    pub fn find_rest(map: &M, z0: &DVector<f64>) -> (DVector<f64>, f64) {
        let (m, r) = (map.n_out(), map.n_in());
        let mut scratch = vec![0.0; map.scratch_len()];
        let mut c = vec![0.0; m];
        let mut cz = vec![0.0; m * r];
        let mut z = z0.clone();
        map.eval(z.as_slice(), &mut c, &mut cz, &mut scratch);
        let mut best = DVector::from_column_slice(&c).norm();
        for _ in 0..50 {
            let jz = DMatrix::from_column_slice(m, r, &cz);
            let cv = DVector::from_column_slice(&c);
            // least-squares step of J dz = −c (SVD: robust where J loses rank)
            let Ok(dz) = jz.svd(true, true).solve(&(-&cv), 1e-12) else {
                break;
            };
            let mut step = 1.0;
            let mut improved = false;
            while step > 1e-6 {
                let zt = &z + &dz * step;
                map.eval(zt.as_slice(), &mut c, &mut cz, &mut scratch);
                let norm = DVector::from_column_slice(&c).norm();
                if norm < best {
                    best = norm;
                    z = zt;
                    improved = true;
                    break;
                }
                step *= 0.5;
            }
            map.eval(z.as_slice(), &mut c, &mut cz, &mut scratch);
            if !improved || best < 1e-14 {
                break;
            }
        }
        (z, best)
    }
}

impl<M: CoefficientMap> StrainParam for ReducedParam<M> {
    fn n_dof(&self) -> usize {
        self.r
    }

    fn n_sites(&self) -> usize {
        self.n_sites
    }

    fn is_linear(&self) -> bool {
        false
    }

    fn new_eval(&self) -> StrainEval {
        let mut ev = StrainEval::zeros(self.r, self.n_sites());
        ev.scratch = vec![0.0; self.layout().end];
        ev
    }

    /// `c, C_z` once, then `Ψ_s = Φ_s c` and `Ψ_q,s = Φ_s C_z` at every site.
    fn eval(&self, q: &DVector<f64>, ev: &mut StrainEval) {
        let l = self.layout();
        let (m, r) = (self.m, self.r);
        let (head, map_scratch) = ev.scratch.split_at_mut(l.map);
        let (cc, rest) = head.split_at_mut(l.czd);
        let work = &mut rest[l.work - l.czd..];
        {
            let (c, cz) = cc.split_at_mut(l.cz);
            self.map.eval(q.as_slice(), c, cz, map_scratch);
        }
        let (psi, out) = (Some(&mut ev.psi[..]), ev.psi_q.as_mut_slice());
        self.rows.products(cc, m, r, psi, out, work);
    }

    /// `Ψ̇_q,s = Φ_s (∂²c/∂z² ż)` (eq. 17).
    fn eval_rate(&self, q: &DVector<f64>, qd: &DVector<f64>, ev: &mut StrainEval) {
        let l = self.layout();
        let (m, r) = (self.m, self.r);
        let (head, map_scratch) = ev.scratch.split_at_mut(l.map);
        let (front, work) = head.split_at_mut(l.work);
        let czd = &mut front[l.czd..l.czd + m * r];
        self.map
            .eval_rate(q.as_slice(), qd.as_slice(), czd, map_scratch);
        let out = ev.psi_q_dot.as_mut_slice();
        self.rows.products(czd, m, r, None, out, work);
    }

    /// `Σ_s Σ_a w_{s,a} ∇²Ψ_{s,a} = Σ_k g_k ∇²c_k` with `g = Σ_s Φ_sᵀ w_s`.
    fn add_weighted_hessian(
        &self,
        q: &DVector<f64>,
        w: &[V6],
        ev: &mut StrainEval,
        out: &mut DMatrix<f64>,
    ) {
        let l = self.layout();
        let r = self.r;
        let (head, map_scratch) = ev.scratch.split_at_mut(l.map);
        let (front, work) = head.split_at_mut(l.work);
        let (g, rest) = front[l.g..].split_at_mut(l.h - l.g);
        let h = &mut rest[..r * r];
        self.rows.mul_tr(w, g, work);
        h.fill(0.0);
        self.map
            .add_weighted_hessian(q.as_slice(), g, h, &mut map_scratch[..]);
        for j in 0..r {
            for i in 0..r {
                out[(i, j)] += h[i + j * r];
            }
        }
    }

    fn rest_coordinates(&self) -> DVector<f64> {
        self.rest.clone()
    }

    /// `[c | ċ | c̈]` by the map's motion evaluation, then `Ψ_s`, `ξ̇_s`, `ξ̈ᵇ_s` as `Φ_s` times
    /// each: three columns through the basis instead of `1 + 2r`.
    fn eval_motion(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: Option<&DVector<f64>>,
        ev: &mut StrainEval,
    ) -> bool {
        let l = self.layout();
        let m = self.m;
        let (head, map_scratch) = ev.scratch.split_at_mut(l.map);
        let (front, work) = head.split_at_mut(l.work);
        let mo = &mut front[l.mo..l.mo + 3 * m];
        {
            let (c, rest) = mo.split_at_mut(m);
            let (c_dot, c_acc) = rest.split_at_mut(m);
            self.map.eval_motion(
                q.as_slice(),
                qd.as_slice(),
                qdd.map(|v| v.as_slice()),
                c,
                c_dot,
                c_acc,
                map_scratch,
            );
        }
        let out = [&mut ev.psi[..], &mut ev.xi_dot[..], &mut ev.xi_acc[..]];
        self.rows.motion(mo, m, out, work);
        true
    }

    /// `c` alone by the map ([`CoefficientMap::eval_value`]), then `Ψ_s = Φ_s c`: one column
    /// through the network and the basis instead of `1 + r`.
    fn eval_strains(&self, q: &DVector<f64>, ev: &mut StrainEval) -> bool {
        let l = self.layout();
        let m = self.m;
        let (head, map_scratch) = ev.scratch.split_at_mut(l.map);
        let (front, work) = head.split_at_mut(l.work);
        let c = &mut front[l.mo..l.mo + m];
        self.map.eval_value(q.as_slice(), c, map_scratch);
        self.rows.values(c, m, &mut ev.psi, work);
        true
    }

    /// After a motion evaluation: `g = Σ_s Φ_sᵀ y_s`, then `C_zᵀ g` by the map's reverse pass;
    /// otherwise from `Ψ_q`.
    fn project(&self, y: &[V6], ev: &mut StrainEval, r: &mut DVector<f64>) {
        if !ev.motion {
            project_with_psi_q(self, y, ev, r);
            return;
        }
        let l = self.layout();
        let (m, rr) = (self.m, self.r);
        let (head, map_scratch) = ev.scratch.split_at_mut(l.map);
        let (front, rest) = head.split_at_mut(l.zt);
        let (zt, work) = rest.split_at_mut(l.work - l.zt);
        let g = &mut front[l.g..l.g + m];
        self.rows.mul_tr(y, g, work);
        let zt = &mut zt[..rr];
        self.map.vjp(g, zt, map_scratch);
        for (ri, z) in r.iter_mut().zip(zt.iter()) {
            *ri += z;
        }
    }
}

#[cfg(test)]
mod tests;
