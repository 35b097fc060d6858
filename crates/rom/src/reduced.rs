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
use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use gvs::discretize::Discretization;
use gvs::lie::V6;
use gvs::strain::{LinearBasis, StrainEval, StrainParam};
use nalgebra::{DMatrix, DVector, Matrix6xX};
use std::ops::Range;
use thiserror::Error;

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

/// `Φ_s` of every site stacked per active strain component: block `i` holds row `active[i]` of every
/// `Φ_s` (`n_sites × width`, column-major) on the coordinates `cols` where that row is non-zero at
/// some site. For a global basis whose strain components have coefficients of their own (Legendre),
/// a block is one component's coefficients only, a third or less of all `Φ_s`. With the blocks,
/// `Ψ`, `Ψ_q` (and `Ψ̇_q`) at all sites are one product `Φ_i [c | C_z]_{cols}` per component, and
/// `g = Σ_s Φ_sᵀ w_s` is `Σ_i Φ_iᵀ w_i`.
struct Stacked {
    n_sites: usize,
    blocks: Vec<Block>,
}

struct Block {
    /// Index into the strain 6-vector.
    a: usize,
    cols: Range<usize>,
    mat: Vec<f64>,
}

impl Stacked {
    /// Stacks `basis` if the blocks store at most twice the entries of its per-site blocks (global
    /// bases: Legendre, POD); `None` for local-support bases, where the per-site loop is cheaper.
    fn of(basis: &LinearBasis, phi: &Matrix6xX<f64>) -> Option<Stacked> {
        let ns = basis.n_sites();
        let mut blocks = Vec::new();
        for a in 0..6 {
            let (mut lo, mut hi) = (usize::MAX, 0);
            for s in 0..ns {
                let block = basis.phi_at(s);
                for (j, col) in basis.columns(s).enumerate() {
                    if block[(a, j)] != 0.0 {
                        (lo, hi) = (lo.min(col), hi.max(col + 1));
                    }
                }
            }
            if lo < hi {
                blocks.push(Block {
                    a,
                    cols: lo..hi,
                    mat: vec![0.0; ns * (hi - lo)],
                });
            }
        }
        let stored: usize = blocks.iter().map(|b| b.mat.len()).sum();
        if stored > 2 * blocks.len() * phi.ncols() {
            return None;
        }
        for b in &mut blocks {
            for s in 0..ns {
                let block = basis.phi_at(s);
                for (j, col) in basis.columns(s).enumerate() {
                    if b.cols.contains(&col) {
                        b.mat[s + (col - b.cols.start) * ns] = block[(b.a, j)];
                    }
                }
            }
        }
        Some(Stacked {
            n_sites: ns,
            blocks,
        })
    }

    /// Length of the product buffer for `k` right-hand columns.
    fn y_len(&self, k: usize) -> usize {
        self.blocks.len() * self.n_sites * k
    }

    /// `Y_i = Φ_i X[cols_i, :]` for every block, `X` column-major `m × k`; `Y_i` at
    /// `i·n_sites·k` in `y`, column-major `n_sites × k`.
    fn mul(&self, x: &[f64], m: usize, k: usize, y: &mut [f64]) {
        let ns = self.n_sites;
        for (b, yb) in self.blocks.iter().zip(y.chunks_exact_mut(ns * k)) {
            let w = b.cols.len();
            let phi = MatRef::from_column_major_slice(&b.mat, ns, w);
            let xb = MatRef::from_column_major_slice_with_stride(&x[b.cols.start..], w, k, m);
            let yb = MatMut::from_column_major_slice_mut(yb, ns, k);
            matmul(yb, Accum::Replace, phi, xb, 1.0, Par::Seq);
        }
        gvs::cpu::clear_upper_state();
    }

    /// `g = Σ_i Φ_iᵀ w_i` (`g` of length m) with `w_i` the component `a_i` of `w` at every site,
    /// gathered into `buf` (`n_sites`).
    fn mul_tr(&self, w: &[V6], buf: &mut [f64], g: &mut [f64]) {
        g.fill(0.0);
        let ns = self.n_sites;
        for b in &self.blocks {
            for (v, ws) in buf[..ns].iter_mut().zip(w) {
                *v = ws[b.a];
            }
            let phi = MatRef::from_column_major_slice(&b.mat, ns, b.cols.len());
            let wb = MatRef::from_column_major_slice(&buf[..ns], ns, 1);
            let gb = MatMut::from_column_major_slice_mut(&mut g[b.cols.clone()], b.cols.len(), 1);
            matmul(gb, Accum::Add, phi.transpose(), wb, 1.0, Par::Seq);
        }
        gvs::cpu::clear_upper_state();
    }
}

/// Where the parts of [`StrainEval::scratch`] start: `c`, `C_z` (adjacent: `[c | C_z]` is one
/// `m × (1 + r)` matrix), `Ċ_z`, `g`, `H`, the stacked products `Y`, the map's own.
#[derive(Debug, Clone, Copy)]
struct Layout {
    /// `c` starts at 0.
    cz: usize,
    czd: usize,
    g: usize,
    h: usize,
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
        let stacked = Stacked::of(basis, &phi);
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
        let y = h + r * r;
        let map = y + self.stacked.as_ref().map_or(0, |st| st.y_len(1 + r));
        Layout {
            cz,
            czd,
            g,
            h,
            y,
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

/// At site `s`: returns `Φ_s c[cols]` (zero if `c` is empty) and writes `Φ_s D[cols, :]` (6 × r,
/// column-major) into `out`, for `D` given column-major `m × r`. One pass over `Φ_s`.
#[inline]
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
    let mut acc = [0.0f64; 6];
    for (j, col) in cols.clone().enumerate() {
        let ph = &phi[6 * j..6 * j + 6];
        if !c.is_empty() {
            let cj = c[col];
            for a in 0..6 {
                acc[a] += ph[a] * cj;
            }
        }
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
    V6::from_column_slice(&acc)
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
                // Y_i = Φ_i [c | C_z]   (n_sites × (1 + r) per component)
                let y = &mut rest[l.y - l.czd..l.map - l.czd];
                st.mul(cc, m, 1 + r, y);
                ev.psi.iter_mut().for_each(|psi| *psi = V6::zeros());
                let ns = st.n_sites;
                for (b, yb) in st.blocks.iter().zip(y.chunks_exact(ns * (1 + r))) {
                    for (s, psi) in ev.psi.iter_mut().enumerate() {
                        psi[b.a] = yb[s];
                        for k in 0..r {
                            out[6 * (s * r + k) + b.a] = yb[(k + 1) * ns + s];
                        }
                    }
                }
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
                let ns = st.n_sites;
                for (b, yb) in st.blocks.iter().zip(y.chunks_exact(ns * r)) {
                    for s in 0..ns {
                        for k in 0..r {
                            out[6 * (s * r + k) + b.a] = yb[k * ns + s];
                        }
                    }
                }
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
        match &self.stacked {
            Some(st) => st.mul_tr(w, y, g),
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use gvs::discretize::{MagnusOrder, Quadrature};
    use gvs::rod::{Material, Rod};
    use gvs::strain::testing::derivative_errors;
    use gvs::strain::DivisionBasis;

    /// `c(z) = A tanh(B z + b)`: a one-hidden-layer map with closed-form derivatives
    /// (`σ' = 1 − t²`, `σ'' = −2 t σ'`).
    struct TanhMap {
        a: DMatrix<f64>,
        b: DMatrix<f64>,
        bias: DVector<f64>,
    }

    impl CoefficientMap for TanhMap {
        fn n_in(&self) -> usize {
            self.b.ncols()
        }
        fn n_out(&self) -> usize {
            self.a.nrows()
        }
        fn scratch_len(&self) -> usize {
            self.b.nrows()
        }
        fn eval(&self, z: &[f64], c: &mut [f64], c_z: &mut [f64], scratch: &mut [f64]) {
            let t = (&self.b * DVector::from_column_slice(z) + &self.bias).map(f64::tanh);
            scratch.copy_from_slice(t.as_slice());
            c.copy_from_slice((&self.a * &t).as_slice());
            let d = DMatrix::from_diagonal(&t.map(|t| 1.0 - t * t));
            c_z.copy_from_slice((&self.a * d * &self.b).as_slice());
        }
        fn eval_rate(&self, z: &[f64], zd: &[f64], c_z_dot: &mut [f64], scratch: &mut [f64]) {
            let _ = z;
            let t = DVector::from_column_slice(scratch);
            let v = &self.b * DVector::from_column_slice(zd);
            let d = DMatrix::from_fn(t.len(), t.len(), |i, j| {
                if i == j {
                    -2.0 * t[i] * (1.0 - t[i] * t[i]) * v[i]
                } else {
                    0.0
                }
            });
            c_z_dot.copy_from_slice((&self.a * d * &self.b).as_slice());
        }
        fn add_weighted_hessian(&self, z: &[f64], g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
            let _ = z;
            let t = DVector::from_column_slice(scratch);
            let ag = self.a.transpose() * DVector::from_column_slice(g);
            let d = DMatrix::from_fn(t.len(), t.len(), |i, j| {
                if i == j {
                    -2.0 * t[i] * (1.0 - t[i] * t[i]) * ag[i]
                } else {
                    0.0
                }
            });
            let h = self.b.transpose() * d * &self.b;
            for (o, v) in out.iter_mut().zip(h.iter()) {
                *o += v;
            }
        }
    }

    fn single_tendon_like() -> (Discretization, LinearBasis) {
        let rod = Rod::tapered(
            Material {
                youngs_modulus: 6.17e5,
                poisson_ratio: 0.5,
                density: 1121.0,
                damping: 0.0,
            },
            0.25,
            0.0125,
            0.005,
        );
        let disc = Discretization::new(&rod, &[Quadrature::Gauss { n: 10 }], MagnusOrder::Z4, &[])
            .unwrap();
        let basis = LinearBasis::per_division(
            &disc,
            &[DivisionBasis::Legendre {
                modes: [false, true, false, true, false, true],
                orders: [0, 4, 0, 3, 0, 3],
            }],
        )
        .unwrap();
        (disc, basis)
    }

    fn pattern(rows: usize, cols: usize, k: usize) -> DMatrix<f64> {
        DMatrix::from_fn(rows, cols, |i, j| {
            (((i * 7 + j * 13 + k) % 11) as f64 - 5.0) / 5.0
        })
    }

    #[test]
    fn the_projection_recovers_hom_coefficients_from_point_strains() {
        let (disc, basis) = single_tendon_like();
        let layout = PointLayout::active_in(&basis, &disc);
        assert_eq!(layout.active, vec![1, 3, 5]);
        assert_eq!(layout.len(), 3 * disc.n_points());
        let pm = point_matrix(&basis, &layout);
        let p = projection(&pm).unwrap();
        let q = DVector::from_fn(basis.n_dof(), |i, _| (i as f64 * 0.37).sin());
        let x = &pm * &q;
        assert!((&p * &x - &q).amax() < 1e-12);
        assert!(projection_residual(&pm, &p, &x) < 1e-13);
        // a field outside the span (a bend-y spike at one point) is not represented
        let mut spike = DVector::zeros(layout.len());
        spike[3 * 5] = 1.0;
        assert!(projection_residual(&pm, &p, &spike) > 0.5);
    }

    #[test]
    fn reduced_derivatives_match_central_differences() {
        let (_disc, basis) = single_tendon_like();
        let m = basis.n_dof();
        for r in [1, 2, 3] {
            let map = TanhMap {
                a: pattern(m, 6, r) * 0.5,
                b: pattern(6, r, 2 * r + 1),
                bias: DVector::from_fn(6, |i, _| 0.1 * i as f64 - 0.2),
            };
            let p = ReducedParam::new(&basis, map, DVector::zeros(r)).unwrap();
            let q = DVector::from_fn(r, |i, _| 0.3 - 0.25 * i as f64);
            let qd = DVector::from_fn(r, |i, _| 0.7 + 0.5 * i as f64);
            let e = derivative_errors(&p, &q, &qd, 1e-6);
            assert!(e.max() < 1e-6, "r = {r}: {e:?}");
        }
    }

    #[test]
    fn the_stacked_products_equal_the_per_site_loop() {
        let (_disc, basis) = single_tendon_like();
        let m = basis.n_dof();
        for r in [1, 3] {
            let map = || TanhMap {
                a: pattern(m, 6, r) * 0.5,
                b: pattern(6, r, 2 * r + 1),
                bias: DVector::from_fn(6, |i, _| 0.1 * i as f64 - 0.2),
            };
            let stacked = ReducedParam::new(&basis, map(), DVector::zeros(r)).unwrap();
            assert!(stacked.stacked.is_some(), "a global basis is stacked");
            let mut looped = ReducedParam::new(&basis, map(), DVector::zeros(r)).unwrap();
            looped.stacked = None;
            let q = DVector::from_fn(r, |i, _| 0.3 - 0.25 * i as f64);
            let qd = DVector::from_fn(r, |i, _| 0.7 + 0.5 * i as f64);
            let w: Vec<V6> = (0..basis.n_sites())
                .map(|s| V6::from_fn(|a, _| ((s * 5 + a * 3) % 7) as f64 - 3.0))
                .collect();
            let run = |p: &ReducedParam<TanhMap>| {
                let mut ev = p.new_eval();
                p.eval(&q, &mut ev);
                p.eval_rate(&q, &qd, &mut ev);
                let mut h = DMatrix::zeros(r, r);
                p.add_weighted_hessian(&q, &w, &mut ev, &mut h);
                (ev, h)
            };
            let ((a, ha), (b, hb)) = (run(&stacked), run(&looped));
            let close = |x: &[f64], y: &[f64]| {
                let scale = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                x.iter().zip(y).all(|(u, v)| (u - v).abs() <= 1e-12 * scale)
            };
            let psi = |e: &StrainEval| {
                e.psi
                    .iter()
                    .flat_map(|v| v.iter().copied())
                    .collect::<Vec<_>>()
            };
            assert!(close(&psi(&a), &psi(&b)), "Ψ, r = {r}");
            assert!(
                close(a.psi_q.as_slice(), b.psi_q.as_slice()),
                "Ψ_q, r = {r}"
            );
            assert!(
                close(a.psi_q_dot.as_slice(), b.psi_q_dot.as_slice()),
                "Ψ̇_q, r = {r}"
            );
            assert!(
                close(ha.as_slice(), hb.as_slice()),
                "weighted Hessian, r = {r}"
            );
        }
    }

    #[test]
    fn the_rest_point_of_a_map_is_found_from_a_rough_guess() {
        let (_disc, basis) = single_tendon_like();
        let m = basis.n_dof();
        // c(z) = A tanh(B z + b) vanishes where B z + b = 0: z* = −b/B for r = 1
        let map = TanhMap {
            a: pattern(m, 1, 3),
            b: DMatrix::from_element(1, 1, 2.0),
            bias: DVector::from_element(1, 0.6),
        };
        let (z, norm) = ReducedParam::find_rest(&map, &DVector::from_element(1, 0.4));
        assert!((z[0] + 0.3).abs() < 1e-10 && norm < 1e-10, "{z} {norm}");
        let p = ReducedParam::new(&basis, map, z.clone()).unwrap();
        assert_eq!(p.rest_coordinates(), z);
    }

    #[test]
    fn a_map_of_the_wrong_size_is_refused() {
        let (_disc, basis) = single_tendon_like();
        let map = TanhMap {
            a: pattern(basis.n_dof() + 1, 2, 0),
            b: pattern(2, 1, 0),
            bias: DVector::zeros(2),
        };
        let e = ReducedParam::new(&basis, map, DVector::zeros(1))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("coefficients"), "{e}");
    }
}
