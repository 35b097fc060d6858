//! The buffers of one NDF integration and its error norms (componentwise, or the mass norm).

use super::super::scaled_norm::ScaledNorm;
use super::super::wnorm;
use nalgebra::{DMatrix, DVector};

/// All buffers of one integration.
pub(super) struct Work {
    pub(super) n: usize,
    pub(super) y: DVector<f64>,
    pub(super) yp: DVector<f64>,
    pub(super) ynew: DVector<f64>,
    pub(super) pred: DVector<f64>,
    pub(super) psi: DVector<f64>,
    pub(super) difkp1: DVector<f64>,
    pub(super) del: DVector<f64>,
    pub(super) f: DVector<f64>,
    pub(super) tmp: DVector<f64>,
    pub(super) invwt: DVector<f64>,
    pub(super) thresh: DVector<f64>,
    pub(super) out: DVector<f64>,
    /// Backward differences `∇^j y_n`, `j = 1..maxk+2`, in columns `0..maxk+2`.
    pub(super) dif: DMatrix<f64>,
    /// [`ErrorNorm::Mass`](super::super::ErrorNorm::Mass): the norm of `M̂`, the scales of the `q` and `q̇` halves, and a buffer.
    pub(super) mass_norm: bool,
    pub(super) mnorm: ScaledNorm,
    pub(super) scale_q: f64,
    pub(super) scale_v: f64,
    /// `(mhat_of, ‖y_q‖, ‖y_v‖)` of the current `y` (the same for every attempt at a step).
    pub(super) ynorm: Option<(usize, f64, f64)>,
    pub(super) nbuf: DVector<f64>,
}

impl Work {
    pub(super) fn new(n: usize) -> Self {
        let v = || DVector::zeros(n);
        Work {
            n,
            y: v(),
            yp: v(),
            ynew: v(),
            pred: v(),
            psi: v(),
            difkp1: v(),
            del: v(),
            f: v(),
            tmp: v(),
            invwt: v(),
            thresh: v(),
            out: v(),
            dif: DMatrix::zeros(n, 7),
            mass_norm: false,
            mnorm: ScaledNorm::new(0),
            scale_q: 1.0,
            scale_v: 1.0,
            ynorm: None,
            nbuf: v(),
        }
    }

    /// The error norm of `x` (relative, as `‖x‖ / scale`): componentwise
    /// `max_i |x_i| / max(|y_i|, |y⁽⁰⁾_i|, atol_i/rtol)`, or with [`ErrorNorm::Mass`](super::super::ErrorNorm::Mass)
    /// `max(‖x_q‖_M̂ / s_q, ‖x_v‖_M̂ / s_v)`, `s = max(‖y‖_M̂, ‖y⁽⁰⁾‖_M̂, max_i atol_i/rtol)` per half.
    pub(super) fn norm(&self, x: &DVector<f64>) -> f64 {
        if !self.mass_norm {
            return wnorm(x, &self.invwt);
        }
        let m = self.n / 2;
        let q = self.mnorm.half(&x.as_slice()[..m]) / self.scale_q;
        let v = self.mnorm.half(&x.as_slice()[m..]) / self.scale_v;
        if q.is_nan() || v.is_nan() {
            f64::NAN
        } else {
            q.max(v)
        }
    }

    /// The norm of a Newton correction: componentwise, `max_i |x_i| / max(|y_i|, |y⁽⁰⁾_i|,
    /// atol_i/rtol)`, whichever norm the error test uses. The mass norm lets the error test
    /// ignore the coordinates that move little mass (shear and elongation, a strain at the tip),
    /// leaving them to the formula's A-stability; that holds only if the corrector equation is
    /// solved in them too. With `M` kept from earlier steps the simplified Newton iteration can
    /// contract slowly or diverge in exactly those coordinates while their mass-weighted share
    /// stays small, and a step accepted so leaves them a residual force no physics supplies: an
    /// undamped rod falling under gravity (`examples/undamped-release.toml` without its tip
    /// force, 4 s, orders ≤ 2 at rtol 1e-3) gained 164 % of its largest kinetic energy with the
    /// mass-norm Newton test, 0.23 % with this one.
    pub(super) fn newton_norm(&self, x: &DVector<f64>) -> f64 {
        wnorm(x, &self.invwt)
    }

    /// [`Work::norm`] of column `col` of the difference table, plus `difkp1` if asked.
    pub(super) fn norm_col(&mut self, col: usize, plus_difkp1: bool) -> f64 {
        self.nbuf.copy_from(&self.dif.column(col));
        if plus_difkp1 {
            self.nbuf += &self.difkp1;
        }
        self.norm(&self.nbuf)
    }

    /// The scales of the mass norm at the predictor (after `mnorm` is set).
    pub(super) fn set_mass_scales(&mut self) {
        let m = self.n / 2;
        let thr = |lo: usize| self.thresh.rows(lo, m).amax();
        let (yq, yv) = match self.ynorm {
            Some((of, q, v)) if of == self.mnorm.of() => (q, v),
            _ => {
                let y = self.y.as_slice();
                let (q, v) = (self.mnorm.half(&y[..m]), self.mnorm.half(&y[m..]));
                self.ynorm = Some((self.mnorm.of(), q, v));
                (q, v)
            }
        };
        let p = self.pred.as_slice();
        let (pq, pv) = (self.mnorm.half(&p[..m]), self.mnorm.half(&p[m..]));
        self.scale_q = yq.max(pq).max(thr(0));
        self.scale_v = yv.max(pv).max(thr(m));
    }
}
