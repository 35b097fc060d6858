//! The HOM basis stacked for one product per block: the strains and their derivatives at all
//! sites of a [`super::ReducedParam`] from `[c | C_z]`, and its transposed product. For bases of
//! tall blocks (a global basis on one long division: the IV-A arm's 304 sites × 11 coefficients
//! per component), where a block product vectorizes down the sites; shorter blocks go by
//! [`super::site_rows`].

use crate::gemm::{mul_cols_strided, mul_tr_cols_into};
use gvs::lie::V6;
use gvs::strain::{LinearBasis, StrainParam};
use std::ops::Range;

/// `Φ_s` stacked per strain component and run of sites: block `i` holds row `a_i` of `Φ_s` for the
/// consecutive sites `sites_i` whose non-zero entries in that row lie on the same coordinates
/// `cols_i` (`|sites_i| × |cols_i|`, column-major). For a global basis whose strain components and
/// divisions have coefficients of their own (Legendre per division), a block is one component of
/// one division: no stored zero. With the blocks, `Ψ`, `Ψ_q` (and `Ψ̇_q`) at all sites are one
/// product `Φ_i [c | C_z]_{cols_i}` per block, and `g = Σ_s Φ_sᵀ w_s` is `Σ_i Φ_iᵀ w_i`.
pub(super) struct Stacked {
    pub(super) blocks: Vec<Block>,
    /// `Σ_i |sites_i|`: the rows of all blocks.
    pub(super) rows: usize,
    /// Whether the blocks cover every site's every strain component (a basis on all six): then a
    /// scatter writes every entry and needs no zeroing first.
    pub(super) covers_all: bool,
}

/// The fewest sites per block, on average, for which the stacked products beat the per-site rows.
/// Measured by callgrind, instructions per dynamics residual with and without the mass matrix of
/// an AE: on the IV-C2 arm's blocks (9.5 sites × 2–3 coefficients on average) the per-site rows
/// take 15 % fewer than the blocks; on the IV-A arm's (304 sites × 11) the blocks take 32 % fewer.
pub(super) const TALL: usize = 32;

pub(super) struct Block {
    /// Index into the strain 6-vector.
    pub(super) a: usize,
    pub(super) sites: Range<usize>,
    pub(super) cols: Range<usize>,
    pub(super) mat: Vec<f64>,
}

impl Stacked {
    /// Stacks `basis` if its blocks are tall ([`TALL`] sites or more on average: a global basis on
    /// few long divisions); `None` otherwise, where the per-site rows are cheaper.
    pub(super) fn of(basis: &LinearBasis) -> Option<Stacked> {
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
        if blocks.is_empty() || blocks.len() * TALL > rows {
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
    pub(super) fn y_len(&self, k: usize) -> usize {
        self.rows * k
    }

    /// `Y_i = Φ_i X[cols_i, :]` for every block, `X` column-major `m × k`; the `Y_i` one after the
    /// other in `y`, each column-major `|sites_i| × k`.
    pub(super) fn mul(&self, x: &[f64], m: usize, k: usize, y: &mut [f64]) {
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
    pub(super) fn scatter(&self, y: &[f64], r: usize, mut psi: Option<&mut [V6]>, out: &mut [f64]) {
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
    pub(super) fn scatter_values(&self, y: &[f64], psi: &mut [V6]) {
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
    pub(super) fn scatter_motion(&self, y: &[f64], out: [&mut [V6]; 3]) {
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
    pub(super) fn mul_tr(&self, w: &[V6], buf: &mut [f64], g: &mut [f64]) {
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
