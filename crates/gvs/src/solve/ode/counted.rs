//! The system as the integrators see it: evaluation counters, finiteness checks, the time
//! convention of a piece between breakpoints and the finite-difference Jacobian.

use super::{next_down, next_up, OdeError, OdeStats, OdeSystem, RhsError};
use nalgebra::{DMatrix, DVector};

/// The system with evaluation counters, finiteness checks and the time convention of a piece.
pub(super) struct Counted<'a, S: OdeSystem> {
    pub(super) sys: &'a mut S,
    pub(super) stats: OdeStats,
    /// `None` until the first Jacobian request; then whether `sys.jacobian` provides it.
    pub(super) analytic: Option<bool>,
    /// Evaluation times of the current piece.
    pub(super) clamp: Clamp,
}

/// Evaluation times are clamped to `[lo, hi]`: the open piece when its ends are breakpoints.
#[derive(Debug, Clone, Copy)]
pub(super) struct Clamp {
    pub(super) lo: f64,
    pub(super) hi: f64,
}

impl Default for Clamp {
    fn default() -> Self {
        Clamp {
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
        }
    }
}

impl Clamp {
    /// The piece `[a, b]`: evaluation times are kept strictly inside where an end is a breakpoint.
    pub(super) fn piece(a: f64, a_is_break: bool, b: f64, b_is_break: bool) -> Self {
        Clamp {
            lo: if a_is_break {
                next_up(a)
            } else {
                f64::NEG_INFINITY
            },
            hi: if b_is_break {
                next_down(b)
            } else {
                f64::INFINITY
            },
        }
    }

    pub(super) fn apply(&self, t: f64) -> f64 {
        t.max(self.lo).min(self.hi)
    }
}

impl<'a, S: OdeSystem> Counted<'a, S> {
    pub(super) fn new(sys: &'a mut S) -> Self {
        Counted {
            sys,
            stats: OdeStats::default(),
            analytic: None,
            clamp: Clamp::default(),
        }
    }

    pub(super) fn clamp(&self, t: f64) -> f64 {
        self.clamp.apply(t)
    }

    /// `dy = f(t, y)`; `Ok(false)` if `dy` is not finite. `t_acc` is the last accepted time (for errors).
    pub(super) fn f(
        &mut self,
        t_acc: f64,
        t: f64,
        y: &DVector<f64>,
        dy: &mut DVector<f64>,
    ) -> Result<bool, OdeError> {
        self.stats.rhs_evals += 1;
        let te = self.clamp(t);
        let n = y.len();
        self.sys
            .rhs(te, y, dy)
            .map_err(|source| OdeError::Rhs { t: t_acc, source })?;
        if dy.len() != n {
            let message = format!(
                "the right-hand side has {} entries, the system has dimension {n}",
                dy.len()
            );
            return Err(OdeError::Rhs {
                t: t_acc,
                source: RhsError(message),
            });
        }
        Ok(dy.iter().all(|v| v.is_finite()))
    }

    /// `jac = ∂f/∂y (t, y)`, analytic or by forward differences (`thresh_j = atol_j/rtol`);
    /// `Ok(false)` if the result (or `f(t, y)`) is not finite.
    pub(super) fn jacobian(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        thresh: &DVector<f64>,
        jac: &mut DMatrix<f64>,
        jw: &mut JacWork,
    ) -> Result<bool, OdeError> {
        self.stats.jacobian_evals += 1;
        let te = self.clamp(t);
        if self.analytic != Some(false) {
            let given = self
                .sys
                .jacobian(te, y, jac)
                .map_err(|source| OdeError::Rhs { t, source })?;
            self.analytic = Some(given);
            if given && jac.shape() != (y.len(), y.len()) {
                let message = format!(
                    "the Jacobian is {:?}, the system has dimension {}",
                    jac.shape(),
                    y.len()
                );
                return Err(OdeError::Rhs {
                    t,
                    source: RhsError(message),
                });
            }
            if given {
                return Ok(jac.iter().all(|v| v.is_finite()));
            }
        }
        if jac.shape() != (y.len(), y.len()) {
            *jac = DMatrix::zeros(y.len(), y.len()); // only if `jacobian` resized it and declined
        }
        if !self.f(t, t, y, &mut jw.f0)? {
            return Ok(false);
        }
        let sqrt_eps = f64::EPSILON.sqrt();
        jw.ydel.copy_from(y);
        for j in 0..y.len() {
            let yj = y[j];
            let mut del = sqrt_eps * yj.abs().max(thresh[j]);
            if del == 0.0 || !del.is_finite() {
                del = sqrt_eps;
            }
            if yj < 0.0 {
                del = -del;
            }
            jw.ydel[j] = yj + del;
            let del = jw.ydel[j] - yj; // the increment actually representable
            let ok = self.f(t, t, &jw.ydel, &mut jw.fdel)?;
            jw.ydel[j] = yj;
            if !ok {
                return Ok(false);
            }
            let inv = 1.0 / del;
            for i in 0..y.len() {
                jac[(i, j)] = (jw.fdel[i] - jw.f0[i]) * inv;
            }
        }
        Ok(jac.iter().all(|v| v.is_finite()))
    }
}

/// Buffers of the finite-difference Jacobian.
pub(super) struct JacWork {
    pub(super) f0: DVector<f64>,
    pub(super) ydel: DVector<f64>,
    pub(super) fdel: DVector<f64>,
}

impl JacWork {
    pub(super) fn new(n: usize) -> Self {
        JacWork {
            f0: DVector::zeros(n),
            ydel: DVector::zeros(n),
            fdel: DVector::zeros(n),
        }
    }
}
