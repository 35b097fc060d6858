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
use nalgebra::{DMatrix, DVector, Matrix6xX};
use std::ops::Range;
use thiserror::Error;

mod stacked;
use stacked::Stacked;

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
    /// HOM basis: `Φ_s` restricted to `cols[s]`, stored side by side (6 × Σ|cols|).
    phi: Matrix6xX<f64>,
    offsets: Vec<usize>,
    cols: Vec<Range<usize>>,
    /// The same `Φ_s` stacked densely for one GEMM per evaluation, when the basis is dense enough.
    stacked: Option<Stacked>,
    m: usize,
    r: usize,
    rest: DVector<f64>,
}

/// Where the parts of [`StrainEval::scratch`] start: `c`, `C_z` (adjacent: `[c | C_z]` is one
/// `m × (1 + r)` matrix), `Ċ_z`, `g`, `H`, the motion `[c | ċ | c̈]` (`m × 3`), `C_zᵀ g`, the
/// stacked products `Y`, the map's own.
#[derive(Debug, Clone, Copy)]
struct Layout {
    /// `c` starts at 0.
    cz: usize,
    czd: usize,
    g: usize,
    h: usize,
    mo: usize,
    zt: usize,
    y: usize,
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
        let ns = basis.n_sites();
        let cols: Vec<Range<usize>> = (0..ns).map(|s| basis.columns(s)).collect();
        let mut offsets = Vec::with_capacity(ns);
        let mut total = 0;
        for c in &cols {
            offsets.push(total);
            total += c.len();
        }
        let mut phi = Matrix6xX::zeros(total);
        for s in 0..ns {
            phi.columns_mut(offsets[s], cols[s].len())
                .copy_from(&basis.phi_at(s));
        }
        let stacked = Stacked::of(basis);
        Ok(ReducedParam {
            map,
            phi,
            stacked,
            offsets,
            cols,
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
        let y = zt + r;
        let map = y + self
            .stacked
            .as_ref()
            .map_or(0, |st| st.y_len((1 + r).max(3)));
        Layout {
            cz,
            czd,
            g,
            h,
            mo,
            zt,
            y,
            map,
            end: map + self.map.scratch_len(),
        }
    }

    /// `g = Σ_s Φ_sᵀ w_s` (m) for one 6-vector per site (zeros skipped): by the stacked blocks
    /// (`buf`: their gather buffer, `n_sites` or more) or site by site.
    fn basis_transpose_times(&self, w: &[V6], buf: &mut [f64], g: &mut [f64]) {
        match &self.stacked {
            Some(st) => st.mul_tr(w, buf, g),
            None => {
                g.fill(0.0);
                for (s, cols) in self.cols.iter().enumerate() {
                    if w[s] == V6::zeros() {
                        continue;
                    }
                    let phi = self.phi.columns(self.offsets[s], cols.len());
                    for (j, col) in cols.clone().enumerate() {
                        g[col] += phi.column(j).dot(&w[s]);
                    }
                }
            }
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

/// At site `s`: returns `Φ_s c[cols]` (zero if `c` is empty) and writes `Φ_s D[cols, :]` (6 × r,
/// column-major) into `out`, for `D` given column-major `m × r`. One pass over `Φ_s`.
#[inline]
/// `Φ_s c` on the site's columns (no allocation).
fn site_value<M: CoefficientMap>(p: &ReducedParam<M>, s: usize, c: &[f64]) -> V6 {
    let cols = &p.cols[s];
    let phi = &p.phi.as_slice()[6 * p.offsets[s]..6 * (p.offsets[s] + cols.len())];
    let mut acc = V6::zeros();
    for (ph, &cj) in phi.chunks_exact(6).zip(&c[cols.clone()]) {
        for a in 0..6 {
            acc[a] += ph[a] * cj;
        }
    }
    acc
}

fn site_products<M: CoefficientMap>(
    p: &ReducedParam<M>,
    s: usize,
    c: &[f64],
    d: &[f64],
    out: &mut [f64],
) -> V6 {
    let (m, r) = (p.m, p.r);
    let cols = &p.cols[s];
    let phi = &p.phi.as_slice()[6 * p.offsets[s]..6 * (p.offsets[s] + cols.len())];
    out.fill(0.0);
    for (j, col) in cols.clone().enumerate() {
        let ph = &phi[6 * j..6 * j + 6];
        for k in 0..r {
            let w = d[k * m + col];
            if w != 0.0 {
                let o = &mut out[6 * k..6 * k + 6];
                for a in 0..6 {
                    o[a] += ph[a] * w;
                }
            }
        }
    }
    if c.is_empty() {
        V6::zeros()
    } else {
        site_value(p, s, c)
    }
}

impl<M: CoefficientMap> StrainParam for ReducedParam<M> {
    fn n_dof(&self) -> usize {
        self.r
    }

    fn n_sites(&self) -> usize {
        self.cols.len()
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
        {
            let (c, cz) = cc.split_at_mut(l.cz);
            self.map.eval(q.as_slice(), c, cz, map_scratch);
        }
        let out = ev.psi_q.as_mut_slice();
        match &self.stacked {
            Some(st) => {
                // Y_i = Φ_i [c | C_z]   (|sites_i| × (1 + r) per block)
                let y = &mut rest[l.y - l.czd..l.map - l.czd];
                st.mul(cc, m, 1 + r, y);
                st.scatter(y, r, Some(&mut ev.psi), out);
            }
            None => {
                let (c, cz) = cc.split_at(l.cz);
                for (s, psi) in ev.psi.iter_mut().enumerate() {
                    *psi = site_products(self, s, c, cz, &mut out[6 * s * r..6 * (s + 1) * r]);
                }
            }
        }
    }

    /// `Ψ̇_q,s = Φ_s (∂²c/∂z² ż)` (eq. 17).
    fn eval_rate(&self, q: &DVector<f64>, qd: &DVector<f64>, ev: &mut StrainEval) {
        let l = self.layout();
        let (m, r) = (self.m, self.r);
        let (head, map_scratch) = ev.scratch.split_at_mut(l.map);
        let (czd, y) = head[l.czd..].split_at_mut(l.y - l.czd);
        let czd = &mut czd[..m * r];
        self.map
            .eval_rate(q.as_slice(), qd.as_slice(), czd, map_scratch);
        let out = ev.psi_q_dot.as_mut_slice();
        match &self.stacked {
            Some(st) => {
                st.mul(czd, m, r, y);
                st.scatter(y, r, None, out);
            }
            None => {
                for s in 0..self.cols.len() {
                    site_products(self, s, &[], czd, &mut out[6 * s * r..6 * (s + 1) * r]);
                }
            }
        }
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
        let (g, rest) = head[l.g..].split_at_mut(l.h - l.g);
        let (h, y) = rest.split_at_mut(l.y - l.h);
        self.basis_transpose_times(w, y, g);
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
        let (front, y) = head.split_at_mut(l.y);
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
        match &self.stacked {
            Some(st) => {
                st.mul(mo, m, 3, y);
                st.scatter_motion(y, [&mut ev.psi, &mut ev.xi_dot, &mut ev.xi_acc]);
            }
            None => {
                let (c, rest) = mo.split_at(m);
                let (c_dot, c_acc) = rest.split_at(m);
                for s in 0..self.cols.len() {
                    ev.psi[s] = site_value(self, s, c);
                    ev.xi_dot[s] = site_value(self, s, c_dot);
                    ev.xi_acc[s] = site_value(self, s, c_acc);
                }
            }
        }
        true
    }

    /// `c` alone by the map ([`CoefficientMap::eval_value`]), then `Ψ_s = Φ_s c`: one column
    /// through the network and the basis instead of `1 + r`.
    fn eval_strains(&self, q: &DVector<f64>, ev: &mut StrainEval) -> bool {
        let l = self.layout();
        let m = self.m;
        let (head, map_scratch) = ev.scratch.split_at_mut(l.map);
        let (front, y) = head.split_at_mut(l.y);
        let c = &mut front[l.mo..l.mo + m];
        self.map.eval_value(q.as_slice(), c, map_scratch);
        match &self.stacked {
            Some(st) => {
                st.mul(c, m, 1, y);
                st.scatter_values(y, &mut ev.psi);
            }
            None => {
                for (s, psi) in ev.psi.iter_mut().enumerate() {
                    *psi = site_value(self, s, c);
                }
            }
        }
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
        let (front, buf) = head.split_at_mut(l.y);
        let (front, zt) = front.split_at_mut(l.zt);
        let g = &mut front[l.g..l.g + m];
        self.basis_transpose_times(y, buf, g);
        let zt = &mut zt[..rr];
        self.map.vjp(g, zt, map_scratch);
        for (ri, z) in r.iter_mut().zip(zt.iter()) {
            *ri += z;
        }
    }
}

#[cfg(test)]
mod tests;
