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

use crate::gemm::{mul_cols_strided, mul_tr_cols_into};
use crate::map::CoefficientMap;
use gvs::discretize::Discretization;
use gvs::lie::V6;
use gvs::strain::{project_with_psi_q, LinearBasis, StrainEval, StrainParam};
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

/// `Φ_s` stacked per strain component and run of sites: block `i` holds row `a_i` of `Φ_s` for the
/// consecutive sites `sites_i` whose non-zero entries in that row lie on the same coordinates
/// `cols_i` (`|sites_i| × |cols_i|`, column-major). For a global basis whose strain components and
/// divisions have coefficients of their own (Legendre per division), a block is one component of
/// one division: no stored zero. With the blocks, `Ψ`, `Ψ_q` (and `Ψ̇_q`) at all sites are one
/// product `Φ_i [c | C_z]_{cols_i}` per block, and `g = Σ_s Φ_sᵀ w_s` is `Σ_i Φ_iᵀ w_i`.
struct Stacked {
    blocks: Vec<Block>,
    /// `Σ_i |sites_i|`: the rows of all blocks.
    rows: usize,
    /// Whether the blocks cover every site's every strain component (a basis on all six): then a
    /// scatter writes every entry and needs no zeroing first.
    covers_all: bool,
}

struct Block {
    /// Index into the strain 6-vector.
    a: usize,
    sites: Range<usize>,
    cols: Range<usize>,
    mat: Vec<f64>,
}

impl Stacked {
    /// Stacks `basis` if its blocks are tall (four sites or more on average: global bases per
    /// division, Legendre and POD); `None` for local-support bases, where the per-site loop is
    /// cheaper.
    fn of(basis: &LinearBasis) -> Option<Stacked> {
        let ns = basis.n_sites();
        let mut blocks: Vec<Block> = Vec::new();
        for a in 0..6 {
            let mut open: Option<(usize, Range<usize>)> = None;
            for s in 0..=ns {
                let span = (s < ns).then(|| {
                    let block = basis.phi_at(s);
                    let (mut lo, mut hi) = (usize::MAX, 0);
                    for (j, col) in basis.columns(s).enumerate() {
                        if block[(a, j)] != 0.0 {
                            (lo, hi) = (lo.min(col), hi.max(col + 1));
                        }
                    }
                    lo..hi
                });
                let same = matches!((&open, &span), (Some((_, c)), Some(sp)) if c == sp);
                if same {
                    continue;
                }
                if let Some((start, cols)) = open.take() {
                    if !cols.is_empty() {
                        blocks.push(Block {
                            a,
                            sites: start..s,
                            cols,
                            mat: Vec::new(),
                        });
                    }
                }
                open = span.map(|sp| (s, sp));
            }
        }
        let rows: usize = blocks.iter().map(|b| b.sites.len()).sum();
        if blocks.is_empty() || blocks.len() * 4 > rows {
            return None;
        }
        for b in &mut blocks {
            let (h, w) = (b.sites.len(), b.cols.len());
            b.mat = vec![0.0; h * w];
            for (i, s) in b.sites.clone().enumerate() {
                let block = basis.phi_at(s);
                for (j, col) in basis.columns(s).enumerate() {
                    if b.cols.contains(&col) {
                        b.mat[i + (col - b.cols.start) * h] = block[(b.a, j)];
                    }
                }
            }
        }
        let covers_all = rows == 6 * ns;
        Some(Stacked {
            blocks,
            rows,
            covers_all,
        })
    }

    /// Length of the product buffer for `k` right-hand columns.
    fn y_len(&self, k: usize) -> usize {
        self.rows * k
    }

    /// `Y_i = Φ_i X[cols_i, :]` for every block, `X` column-major `m × k`; the `Y_i` one after the
    /// other in `y`, each column-major `|sites_i| × k`.
    fn mul(&self, x: &[f64], m: usize, k: usize, y: &mut [f64]) {
        let mut off = 0;
        for b in &self.blocks {
            let h = b.sites.len();
            let yb = &mut y[off..off + h * k];
            mul_cols_strided((h, b.cols.len(), k), &b.mat, &x[b.cols.start..], m, yb);
            off += h * k;
        }
    }

    /// Scatters the products of [`Stacked::mul`] (`k = 1 + r`: value then `r` tangents, or
    /// `k = r` tangents only) into the site vectors `psi` (if given) and the site matrices `out`
    /// (`6 × r` per site, column-major), zeroed first unless the blocks cover every entry.
    fn scatter(&self, y: &[f64], r: usize, mut psi: Option<&mut [V6]>, out: &mut [f64]) {
        if !self.covers_all {
            out.fill(0.0);
            if let Some(psi) = psi.as_deref_mut() {
                psi.iter_mut().for_each(|p| *p = V6::zeros());
            }
        }
        let k = r + usize::from(psi.is_some());
        let t0 = k - r;
        let mut off = 0;
        for b in &self.blocks {
            let h = b.sites.len();
            let yb = &y[off..off + h * k];
            for (i, s) in b.sites.clone().enumerate() {
                if let Some(psi) = psi.as_deref_mut() {
                    psi[s][b.a] = yb[i];
                }
                for l in 0..r {
                    out[6 * (s * r + l) + b.a] = yb[(t0 + l) * h + i];
                }
            }
            off += h * k;
        }
    }

    /// Scatters the products of [`Stacked::mul`] with `k = 1` (`c`) into the site vectors `psi`,
    /// zeroed first unless the blocks cover every entry.
    fn scatter_values(&self, y: &[f64], psi: &mut [V6]) {
        if !self.covers_all {
            psi.iter_mut().for_each(|p| *p = V6::zeros());
        }
        let mut off = 0;
        for b in &self.blocks {
            let h = b.sites.len();
            for (p, v) in psi[b.sites.clone()].iter_mut().zip(&y[off..off + h]) {
                p[b.a] = *v;
            }
            off += h;
        }
    }

    /// Scatters the products of [`Stacked::mul`] with `k = 3` (`[c | ċ | c̈]`) into the site
    /// vectors `out[0]` (`Ψ`), `out[1]` (`ξ̇`), `out[2]` (`ξ̈ᵇ`), zeroed first unless the blocks
    /// cover every entry.
    fn scatter_motion(&self, y: &[f64], out: [&mut [V6]; 3]) {
        let [psi, xi_dot, xi_acc] = out;
        if !self.covers_all {
            for v in [&mut *psi, &mut *xi_dot, &mut *xi_acc] {
                v.iter_mut().for_each(|p| *p = V6::zeros());
            }
        }
        let mut off = 0;
        for b in &self.blocks {
            let h = b.sites.len();
            let yb = &y[off..off + 3 * h];
            for (i, s) in b.sites.clone().enumerate() {
                psi[s][b.a] = yb[i];
                xi_dot[s][b.a] = yb[h + i];
                xi_acc[s][b.a] = yb[2 * h + i];
            }
            off += 3 * h;
        }
    }

    /// `g = Σ_i Φ_iᵀ w_i` (`g` of length m) with `w_i` the component `a_i` of `w` at the sites
    /// of block `i`, gathered into `buf` (`n_sites`).
    fn mul_tr(&self, w: &[V6], buf: &mut [f64], g: &mut [f64]) {
        g.fill(0.0);
        for b in &self.blocks {
            let h = b.sites.len();
            for (v, ws) in buf[..h].iter_mut().zip(&w[b.sites.clone()]) {
                *v = ws[b.a];
            }
            let w = b.cols.len();
            mul_tr_cols_into((h, w, 1), &b.mat, &buf[..h], &mut g[b.cols.clone()], true);
        }
    }
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
        fn eval_value(&self, z: &[f64], c: &mut [f64], _scratch: &mut [f64]) {
            let t = (&self.b * DVector::from_column_slice(z) + &self.bias).map(f64::tanh);
            c.copy_from_slice((&self.a * &t).as_slice());
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
        fn eval_motion(
            &self,
            z: &[f64],
            zd: &[f64],
            zdd: Option<&[f64]>,
            c: &mut [f64],
            c_dot: &mut [f64],
            c_acc: &mut [f64],
            scratch: &mut [f64],
        ) {
            // closed form: a = B z + b, ȧ = B ż, ä = B z̈; t = tanh a; ċ = A (σ' ȧ),
            // c̈ = A (σ' ä + σ'' ȧ²)
            let t = (&self.b * DVector::from_column_slice(z) + &self.bias).map(f64::tanh);
            scratch.copy_from_slice(t.as_slice());
            let ad = &self.b * DVector::from_column_slice(zd);
            let add = match zdd {
                Some(zdd) => &self.b * DVector::from_column_slice(zdd),
                None => DVector::zeros(t.len()),
            };
            let d1 = t.map(|t| 1.0 - t * t);
            let hd = d1.component_mul(&ad);
            let hdd = DVector::from_fn(t.len(), |i, _| {
                d1[i] * add[i] - 2.0 * t[i] * d1[i] * ad[i] * ad[i]
            });
            c.copy_from_slice((&self.a * &t).as_slice());
            c_dot.copy_from_slice((&self.a * hd).as_slice());
            c_acc.copy_from_slice((&self.a * hdd).as_slice());
        }
        fn vjp(&self, g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
            let t = DVector::from_column_slice(scratch);
            let ag = self.a.transpose() * DVector::from_column_slice(g);
            let mu = DVector::from_fn(t.len(), |i, _| (1.0 - t[i] * t[i]) * ag[i]);
            out.copy_from_slice((self.b.transpose() * mu).as_slice());
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

    /// Two divisions (0.15 + 0.1 m), each with Legendre coefficients of its own on every strain
    /// component: the stacked blocks are one component of one division.
    fn two_division_legendre() -> (Discretization, LinearBasis) {
        let material = Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.5,
            density: 1000.0,
            damping: 0.0,
        };
        let rod = Rod {
            material,
            divisions: vec![
                gvs::rod::DivisionGeometry {
                    length: 0.15,
                    radius_start: 0.02,
                    radius_end: 0.015,
                },
                gvs::rod::DivisionGeometry {
                    length: 0.1,
                    radius_start: 0.015,
                    radius_end: 0.01,
                },
            ],
        };
        let q = Quadrature::Gauss { n: 4 };
        let disc = Discretization::new(&rod, &[q, q], MagnusOrder::Z4, &[]).unwrap();
        let legendre = DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [1, 2, 2, 1, 1, 0],
        };
        let basis = LinearBasis::per_division(&disc, &[legendre.clone(), legendre]).unwrap();
        (disc, basis)
    }

    /// The same `TanhMap` (r inputs) bound to `basis` twice: with its stacked blocks, and forced to
    /// the per-site loop.
    fn stacked_and_looped(
        basis: &LinearBasis,
        r: usize,
    ) -> (ReducedParam<TanhMap>, ReducedParam<TanhMap>) {
        let m = basis.n_dof();
        let map = || TanhMap {
            a: pattern(m, 6, r) * 0.5,
            b: pattern(6, r, 2 * r + 1),
            bias: DVector::from_fn(6, |i, _| 0.1 * i as f64 - 0.2),
        };
        let stacked = ReducedParam::new(basis, map(), DVector::zeros(r)).unwrap();
        let mut looped = ReducedParam::new(basis, map(), DVector::zeros(r)).unwrap();
        looped.stacked = None;
        (stacked, looped)
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
        for r in [1, 3] {
            let (stacked, looped) = stacked_and_looped(&basis, r);
            assert!(stacked.stacked.is_some(), "a global basis is stacked");
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
    fn the_motion_and_strain_evaluations_and_the_projection_equal_those_from_psi_q_stacked_and_looped(
    ) {
        // ξ̇_s = Ψ_q,s q̇, Ψ̇_q,s q̇ + Ψ_q,s q̈ and Σ_s Ψ_q,sᵀ w_s from eval + eval_rate (checked against
        // central differences in `reduced_derivatives_match_central_differences`) against the
        // motion evaluation's direct ones, on a one- and a two-division basis
        for (label, (_disc, basis)) in [
            ("one division", single_tendon_like()),
            ("two divisions", two_division_legendre()),
        ] {
            for r in [1, 3] {
                let (stacked, looped) = stacked_and_looped(&basis, r);
                // one block per component and run of sites on the same coefficients: one division,
                // all sites (3 components); two divisions, each division's points and then its
                // Magnus sub-points (sites are numbered points first): 6 × 2 × 2 blocks, each on
                // that component's coefficients of that division only
                let st = stacked
                    .stacked
                    .as_ref()
                    .expect("a per-division basis is stacked");
                let (n_blocks, widest) = match label {
                    "one division" => (3, 5),
                    _ => (24, 3),
                };
                assert_eq!(st.blocks.len(), n_blocks, "{label}");
                assert!(st.blocks.iter().all(|b| b.cols.len() <= widest), "{label}");
                let q = DVector::from_fn(r, |i, _| 0.3 - 0.25 * i as f64);
                let qd = DVector::from_fn(r, |i, _| 0.7 + 0.5 * i as f64);
                let qdd = DVector::from_fn(r, |i, _| -1.3 + 0.9 * i as f64);
                let w: Vec<V6> = (0..basis.n_sites())
                    .map(|s| V6::from_fn(|a, _| ((s * 5 + a * 3) % 7) as f64 - 3.0))
                    .collect();
                for p in [&stacked, &looped] {
                    let mut ev = p.new_eval();
                    p.eval(&q, &mut ev);
                    p.eval_rate(&q, &qd, &mut ev);
                    let mut proj = DVector::zeros(r);
                    p.project(&w, &mut ev, &mut proj);
                    let mut mo = p.new_eval();
                    for with_qdd in [true, false] {
                        let qdd = with_qdd.then_some(&qdd);
                        assert!(p.eval_motion(&q, &qd, qdd, &mut mo));
                        mo.motion = true;
                        mo.psi_q_stale = true;
                        let close = |x: &V6, y: &V6| (x - y).amax() <= 1e-12 * y.amax().max(1.0);
                        for s in 0..basis.n_sites() {
                            let c = 0..r;
                            let xid: V6 = ev.psi_q_at(s, &c) * &qd;
                            let mut acc: V6 = ev.psi_q_dot_at(s, &c) * &qd;
                            if let Some(qdd) = qdd {
                                acc += ev.psi_q_at(s, &c) * qdd;
                            }
                            assert!(close(&mo.psi[s], &ev.psi[s]), "{label} r = {r}: Ψ at {s}");
                            assert!(close(&mo.xi_dot[s], &xid), "{label} r = {r}: ξ̇ at {s}");
                            assert!(close(&mo.xi_acc[s], &acc), "{label} r = {r}: ξ̈ᵇ at {s}");
                        }
                        let mut sv = p.new_eval();
                        assert!(p.eval_strains(&q, &mut sv));
                        for s in 0..basis.n_sites() {
                            assert!(
                                close(&sv.psi[s], &ev.psi[s]),
                                "{label} r = {r}: Ψ alone at {s}"
                            );
                        }
                        let mut proj_mo = DVector::zeros(r);
                        p.project(&w, &mut mo, &mut proj_mo);
                        let err = (&proj_mo - &proj).amax() / proj.amax();
                        assert!(err < 1e-12, "{label} r = {r}: Σ Ψ_qᵀ w off by {err:e}");
                    }
                }
            }
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
