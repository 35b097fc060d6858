//! Kernels of the Jacobian passes: the derivative `C_w` of a point wrench, one step's local maps of
//! the backward pass, and the row updates `out[c, j] += G t`; [`STEP_MATRIX_COLUMNS`] decides when
//! a step's 6×6 maps are formed as matrices rather than applied by 6-vector products.

use crate::lie::{coad_mul, coadbar, tilde, DTtf, M6, V3, V6};
use nalgebra::DMatrix;
use std::ops::{AddAssign, Range};

/// `C_w = coadbar(w) + [m̃_g 0; f̃_g 0]`: `∂w/∂J` of a point wrench, the second term from its
/// world-fixed part `wg = [m_g; f_g]` (gravity, global wrenches; spec §7.5).
pub(super) fn load_derivative(w: &V6, wg: &V6) -> M6 {
    let mut c = coadbar(w);
    c.fixed_view_mut::<3, 3>(0, 0)
        .add_assign(&tilde(&V3::new(wg[0], wg[1], wg[2])));
    c.fixed_view_mut::<3, 3>(3, 0)
        .add_assign(&tilde(&V3::new(wg[3], wg[4], wg[5])));
    c
}

/// `C_w x` for `C_w = coadbar(w) + [m̃_g 0; f̃_g 0]`: `∂w/∂J` of a point wrench, the second term
/// from its world-fixed part `wg = [m_g; f_g]` (gravity, global wrenches; spec §7.5), applied to
/// a Jacobian column `x = [δθ; δp]`: `coad_x w + [m_g × δθ; f_g × δθ]`.
#[inline]
pub(super) fn load_derivative_mul(w: &V6, wg: &V6, x: &V6) -> V6 {
    let dth = V3::new(x[0], x[1], x[2]);
    let m = V3::new(wg[0], wg[1], wg[2]).cross(&dth);
    let f = V3::new(wg[3], wg[4], wg[5]).cross(&dth);
    coad_mul(x, w) + V6::new(m[0], m[1], m[2], f[0], f[1], f[2])
}

/// The backward pass's maps of one step on its own columns: `A₁`, `A₂`, `k coadbar(v)` and
/// `D = ∂(TᵀF̄)/∂Ω` as matrices (wide steps), or `D` by its vectors and the rest by 6-vector
/// products (narrow steps; see [`STEP_MATRIX_COLUMNS`]). A stack value per step: boxing the large
/// variant would allocate in the pass.
#[allow(clippy::large_enum_variant)]
pub(super) enum LocalMaps {
    Matrices { a1: M6, a2: M6, cbv: M6, d: M6 },
    Products(DTtf),
}

/// Columns of a step beyond which the Jacobian passes form its 6×6 maps as matrices rather than
/// applying them by 6-vector products: `T(Ω)` (completing a lean Magnus step: the powers of `ad_Ω`,
/// three 6×6 products) and `Ad⁻¹` in the forward pass; `coAd`, `coadbar(F̄)`, `C_w` for the sweep
/// over the columns and `A₁`, `A₂`, `coadbar(v)`, `∂(TᵀF̄)/∂Ω` for the step's own in the backward
/// pass. A matrix–vector product is the cheapest per column; a reduced model's step has one or two
/// columns, where forming the matrices would cost more than all the products.
pub(super) const STEP_MATRIX_COLUMNS: usize = 4;

/// `out[c, j] += G t` for the `|c| × 6` column-major `g`: six axpys down column j of `out`.
#[inline]
pub(super) fn add_g_times(out: &mut DMatrix<f64>, c: &Range<usize>, j: usize, g: &[f64], t: &V6) {
    let nr = out.nrows();
    let col = &mut out.as_mut_slice()[j * nr + c.start..j * nr + c.end];
    let k = c.len();
    for a in 0..6 {
        let ta = t[a];
        for (o, gv) in col.iter_mut().zip(&g[a * k..(a + 1) * k]) {
            *o += gv * ta;
        }
    }
}

/// `out[c, j] += H [t; x₁; x₂]` for the `|c| × 18` column-major `h`: eighteen axpys down column j.
#[inline]
pub(super) fn add_h_times(
    out: &mut DMatrix<f64>,
    c: &Range<usize>,
    j: usize,
    h: &[f64],
    t: &V6,
    x1: &V6,
    x2: &V6,
) {
    let nr = out.nrows();
    let col = &mut out.as_mut_slice()[j * nr + c.start..j * nr + c.end];
    let k = c.len();
    for (b, x) in [t, x1, x2].into_iter().enumerate() {
        for a in 0..6 {
            let xa = x[a];
            let hb = &h[(6 * b + a) * k..(6 * b + a + 1) * k];
            for (o, hv) in col.iter_mut().zip(hb) {
                *o += hv * xa;
            }
        }
    }
}
