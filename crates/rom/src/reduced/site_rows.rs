//! The HOM basis `Φ_s` stored row by row: for every site `s` and strain component `a`, the
//! coefficients on which row `a` of `Φ_s` is non-zero and its values there, padded with zeros to a
//! common count `w`: the most non-zeros of any row (a Legendre or POD basis per component has its
//! order + 1, a local-support basis one or two), rounded up to one of the counts the loops are
//! compiled for (1, 2, 3, 4, 6, 8: fully unrolled, no branch); more take a plain loop. A product
//! `Φ_s X` costs `w` multiply-adds per active component, site and column (four columns at a time)
//! and writes straight into the engine's per-site layout (`Ψ_s`, and `Ψ_q,s` as `6 × r`
//! column-major per site): no block products to scatter.

use crate::gemm::madd;
use gvs::lie::V6;
use gvs::strain::{LinearBasis, StrainParam};

/// The row lengths with loops of their own (a `const` length; 0 marks the plain loop).
const WIDTHS: [usize; 6] = [1, 2, 3, 4, 6, 8];

/// Calls `$body::<FMA, W>(args)` with `W` the row length as a constant where it is one of
/// [`WIDTHS`], else `W = 0` (the plain loop).
macro_rules! with_width {
    ($self:ident, $f:ident::<$fma:tt>($($arg:expr),*)) => {
        match $self.width {
            1 => $self.$f::<$fma, 1>($($arg),*),
            2 => $self.$f::<$fma, 2>($($arg),*),
            3 => $self.$f::<$fma, 3>($($arg),*),
            4 => $self.$f::<$fma, 4>($($arg),*),
            6 => $self.$f::<$fma, 6>($($arg),*),
            8 => $self.$f::<$fma, 8>($($arg),*),
            _ => $self.$f::<$fma, 0>($($arg),*),
        }
    };
}

/// `Φ_s` of every site, by rows.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct SiteRows {
    /// The row length `w`.
    width: usize,
    /// Row `(s, a)`'s coefficients, at `(6 s + a) w ..` (padding: the row's last, or 0).
    idx: Vec<usize>,
    /// Row `(s, a)`'s values there (padding: 0).
    vals: Vec<f64>,
    /// Whether component `a` is non-zero at some site: the products skip the others (their rows
    /// are zero) and write zeros.
    active: [bool; 6],
}

impl SiteRows {
    /// The rows of `basis` at every site: their non-zeros, padded to a common length.
    pub(super) fn of(basis: &LinearBasis) -> SiteRows {
        let ns = basis.n_sites();
        // each row's non-zeros: (coefficient, value)
        let mut rows: Vec<Vec<(usize, f64)>> = Vec::with_capacity(6 * ns);
        for s in 0..ns {
            let phi = basis.phi_at(s);
            let cols = basis.columns(s);
            for a in 0..6 {
                rows.push(
                    cols.clone()
                        .enumerate()
                        .filter(|&(j, _)| phi[(a, j)] != 0.0)
                        .map(|(j, col)| (col, phi[(a, j)]))
                        .collect(),
                );
            }
        }
        let mut active = [false; 6];
        for (i, row) in rows.iter().enumerate() {
            active[i % 6] |= !row.is_empty();
        }
        let longest = rows.iter().map(Vec::len).max().unwrap_or(0);
        let width = WIDTHS
            .into_iter()
            .find(|&w| w >= longest)
            .unwrap_or(longest);
        let mut idx = Vec::with_capacity(6 * ns * width);
        let mut vals = Vec::with_capacity(6 * ns * width);
        for row in rows {
            let pad = row.last().map_or(0, |&(col, _)| col);
            for t in 0..width {
                let (col, v) = row.get(t).copied().unwrap_or((pad, 0.0));
                idx.push(col);
                vals.push(v);
            }
        }
        SiteRows {
            width,
            idx,
            vals,
            active,
        }
    }

    pub(super) fn n_sites(&self) -> usize {
        self.vals.len() / (6 * self.width.max(1))
    }

    /// Row `(s, a)`: its values and their coefficients.
    #[inline(always)]
    fn row(&self, s: usize, a: usize) -> (&[f64], &[usize]) {
        let i = (6 * s + a) * self.width;
        let w = self.width;
        (&self.vals[i..i + w], &self.idx[i..i + w])
    }

    /// `Φ_s x` at site `s` (`x` of length m).
    #[inline]
    pub(super) fn value(&self, s: usize, x: &[f64]) -> V6 {
        let mut v = V6::zeros();
        for a in 0..6 {
            let (phi, idx) = self.row(s, a);
            v[a] = phi.iter().zip(idx).map(|(p, &j)| p * x[j]).sum();
        }
        v
    }

    /// `psi[s] = Φ_s x` at every site.
    pub(super) fn values(&self, x: &[f64], psi: &mut [V6]) {
        for (s, p) in psi.iter_mut().enumerate() {
            *p = self.value(s, x);
        }
    }

    /// `Φ_s X` for `X = [x_0 | D]` column-major `m × (1 + r)` (or `D` alone, `m × r`, without
    /// `psi`): `psi[s] = Φ_s x_0` and `out` (`6 × r` column-major per site) `= Φ_s D`. `work`:
    /// [`SiteRows::work_len`].
    pub(super) fn products(
        &self,
        x: &[f64],
        m: usize,
        r: usize,
        psi: Option<&mut [V6]>,
        out: &mut [f64],
        work: &mut [f64],
    ) {
        #[cfg(target_arch = "x86_64")]
        if crate::gemm::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA, all the function requires.
            unsafe { self.products_avx2(x, m, r, psi, out, work) };
            return;
        }
        with_width!(self, products_body::<false>(x, m, r, psi, out, work));
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn products_avx2(
        &self,
        x: &[f64],
        m: usize,
        r: usize,
        psi: Option<&mut [V6]>,
        out: &mut [f64],
        work: &mut [f64],
    ) {
        with_width!(self, products_body::<true>(x, m, r, psi, out, work));
    }

    #[inline(always)]
    fn products_body<const FMA: bool, const W: usize>(
        &self,
        x: &[f64],
        m: usize,
        r: usize,
        psi: Option<&mut [V6]>,
        out: &mut [f64],
        work: &mut [f64],
    ) {
        let t0 = usize::from(psi.is_some());
        let (xt, ng) = transpose(x, m, t0 + r, work);
        let cols = (ng, t0, r);
        match ng {
            1 => self.products_window::<FMA, 1, W>(xt, cols, 0, psi, out),
            2 => self.products_window::<FMA, 2, W>(xt, cols, 0, psi, out),
            3 => self.products_window::<FMA, 3, W>(xt, cols, 0, psi, out),
            _ => {
                let mut psi = psi;
                for g0 in (0..ng).step_by(4) {
                    self.products_window::<FMA, 4, W>(xt, cols, g0, psi.take(), out);
                }
            }
        }
    }

    /// The columns `4 g0 .. 4 (g0 + NG)` of [`SiteRows::products`] (those that exist) for
    /// `(ng, t0, r)`: `ng` groups per row of `xt`, and `t0 + r` columns of which the first `t0`
    /// (0 or 1) is the value for `psi` (given with the window that holds it), then tangent `l` at
    /// column `t0 + l`.
    #[inline(always)]
    fn products_window<const FMA: bool, const NG: usize, const W: usize>(
        &self,
        xt: &[[f64; 4]],
        (ng, t0, r): (usize, usize, usize),
        g0: usize,
        mut psi: Option<&mut [V6]>,
        out: &mut [f64],
    ) {
        // this window holds columns c0..c1; its tangents start at column `first`, tangent `l0`
        let c0 = 4 * g0;
        let c1 = (c0 + 4 * NG).min(t0 + r);
        let first = c0.max(t0);
        let l0 = first - t0;
        for s in 0..self.n_sites() {
            let site = &mut out[6 * r * s..6 * r * (s + 1)];
            for a in 0..6 {
                let acc = self.row_times::<FMA, NG, W>(s, a, xt, ng, g0);
                let flat = acc.as_flattened();
                if let Some(psi) = psi.as_deref_mut() {
                    psi[s][a] = flat[0];
                }
                let tangents = &flat[first - c0..c1 - c0];
                for (col, v) in site[6 * l0..].chunks_exact_mut(6).zip(tangents) {
                    col[a] = *v;
                }
            }
        }
    }

    /// `[c | ċ | c̈]` (column-major `m × 3`) into `out[0][s] = Φ_s c`, `out[1][s] = Φ_s ċ`,
    /// `out[2][s] = Φ_s c̈`; `work` as in [`SiteRows::products`].
    pub(super) fn motion(&self, x: &[f64], m: usize, out: [&mut [V6]; 3], work: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if crate::gemm::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA, all the function requires.
            unsafe { self.motion_avx2(x, m, out, work) };
            return;
        }
        with_width!(self, motion_body::<false>(x, m, out, work));
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn motion_avx2(&self, x: &[f64], m: usize, out: [&mut [V6]; 3], work: &mut [f64]) {
        with_width!(self, motion_body::<true>(x, m, out, work));
    }

    #[inline(always)]
    fn motion_body<const FMA: bool, const W: usize>(
        &self,
        x: &[f64],
        m: usize,
        out: [&mut [V6]; 3],
        work: &mut [f64],
    ) {
        let [psi, xi_dot, xi_acc] = out;
        let (xt, ng) = transpose(x, m, 3, work);
        for s in 0..self.n_sites() {
            for a in 0..6 {
                let [[v, vd, va, _]] = self.row_times::<FMA, 1, W>(s, a, xt, ng, 0);
                psi[s][a] = v;
                xi_dot[s][a] = vd;
                xi_acc[s][a] = va;
            }
        }
    }

    /// Length of the `work` of [`SiteRows::products`] for `k` columns of `m` rows: `X` transposed
    /// in groups of four columns ([`transpose`]).
    pub(super) fn work_len(m: usize, k: usize) -> usize {
        m * groups(k) * 4
    }

    /// Row `(s, a)` of `Φ_s` times the columns `4 g0 .. 4 (g0 + NG)` of `X`, given transposed
    /// (`xt`, `ng` groups of four per row of `X`, [`transpose`]): one 4-wide multiply-add per
    /// coefficient of the row and group.
    #[inline(always)]
    fn row_times<const FMA: bool, const NG: usize, const W: usize>(
        &self,
        s: usize,
        a: usize,
        xt: &[[f64; 4]],
        ng: usize,
        g0: usize,
    ) -> [[f64; 4]; NG] {
        let mut acc = [[0.0; 4]; NG];
        if !self.active[a] {
            return acc;
        }
        let (phi, idx) = self.row(s, a);
        let mut add = |t: usize, p: f64| {
            let base = idx[t] * ng + g0;
            let xr: &[[f64; 4]; NG] = xt[base..base + NG].try_into().expect("NG groups");
            for (o, x) in acc.iter_mut().zip(xr) {
                *o = std::array::from_fn(|i| madd::<FMA>(x[i], p, o[i]));
            }
        };
        if W > 0 {
            let phi: &[f64; W] = phi.try_into().expect("the row length");
            for t in 0..W {
                add(t, phi[t]);
            }
        } else {
            for (t, &p) in phi.iter().enumerate() {
                add(t, p);
            }
        }
        acc
    }

    /// `g = Σ_s Φ_sᵀ w_s` (`g` of length m).
    pub(super) fn mul_tr(&self, w: &[V6], g: &mut [f64]) {
        with_width!(self, mul_tr_body::<false>(w, g));
    }

    #[inline(always)]
    fn mul_tr_body<const FMA: bool, const W: usize>(&self, w: &[V6], g: &mut [f64]) {
        g.fill(0.0);
        for (s, ws) in w.iter().enumerate() {
            for a in 0..6 {
                if !self.active[a] {
                    continue;
                }
                let (phi, idx) = self.row(s, a);
                let wa = ws[a];
                if W > 0 {
                    let phi: &[f64; W] = phi.try_into().expect("the row length");
                    for t in 0..W {
                        g[idx[t]] = madd::<FMA>(phi[t], wa, g[idx[t]]);
                    }
                } else {
                    for (p, &j) in phi.iter().zip(idx) {
                        g[j] = madd::<FMA>(*p, wa, g[j]);
                    }
                }
            }
        }
    }
}

/// Groups of four columns per row of a transposed `X` of `k` columns: `⌈k/4⌉`, rounded up to a
/// multiple of four beyond three groups (the products then run in windows of four groups).
fn groups(k: usize) -> usize {
    let ng = k.div_ceil(4);
    if ng <= 3 {
        ng
    } else {
        ng.div_ceil(4) * 4
    }
}

/// `X` (column-major `m × k`) transposed into the front of `work` in groups of four columns:
/// row `j`'s group `g` at `j · ng + g` ([`groups`]), the padding zero. Returns it and `ng`.
fn transpose<'w>(x: &[f64], m: usize, k: usize, work: &'w mut [f64]) -> (&'w [[f64; 4]], usize) {
    let ng = groups(k);
    let (xt, _) = work[..m * ng * 4].as_chunks_mut::<4>();
    for j in 0..m {
        let row = xt[j * ng..(j + 1) * ng].as_flattened_mut();
        for (l, v) in row.iter_mut().enumerate() {
            *v = if l < k { x[l * m + j] } else { 0.0 };
        }
    }
    (xt, ng)
}
