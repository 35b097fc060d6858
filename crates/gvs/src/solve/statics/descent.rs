//! Descent from a diverging equilibrium onto a stable one, along the rod's overdamped motion.
//!
//! A Newton or dogleg solve finds roots of `R(q)`, stable or not: started beside a saddle it
//! returns to it. The rod itself, released there, leaves along its divergent mode and settles on a
//! stable equilibrium. This follows that motion in its overdamped form, `M q̇ = R(q)` (mass-
//! proportional damping; about an equilibrium `M δq̇ = −K_T δq`, `K_T = −∂R/∂q`, which grows along
//! exactly the directions where [`super::super::stability`] finds `ω² < 0`), by implicit
//! pseudo-time steps
//!
//! ```text
//! (M/Δτ + K_T) δ = R(q),   q ← q + δ,
//! ```
//!
//! with `Δτ` kept small enough that `sym(M/(2Δτ) + K_T)` is positive definite (so `M/Δτ + K_T` is,
//! with a margin: `Δτ |ω²| < 1/2` along a divergent mode): then each step is one of a damped
//! motion, which a saddle repels (a longer implicit step would be attracted back to it, since
//! backward Euler damps a growing mode with `Δτ |ω²| > 2`, and at `Δτ |ω²| = 1` its matrix is
//! singular). Steps grow at most 4× from one to the next, and stay below half of `max(1, ‖q‖∞)`. `Δτ` doubles after every step,
//! so that near the stable equilibrium (where `K_T` is positive definite) the step becomes
//! Newton's and converges quadratically. This is pseudo-transient continuation (Kelley & Keyes,
//! SIAM J. Numer. Anal. 35, 1998) with the positivity of the shifted matrix as its step rule.

use super::super::dogleg::linalg::Lu;
use super::super::stability::positive_definite;
use super::super::StopCheck;
use super::StaticsError;
use crate::model::{Model, PreparedLoads, Workspace};
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};

/// Pseudo-time steps of one descent. The presets' buckled arms need 20–40.
pub(super) const MAX_STEPS: usize = 200;
/// Largest step `‖δ‖∞` relative to `max(1, ‖q‖∞)`: a long implicit step through a strongly
/// nonlinear region can land anywhere (measured on the six-tendon arm pushed at 30 N: 20 steps at
/// 0.5, where an uncapped first step leaves the range of an elastic rod).
const STEP_CAP: f64 = 0.5;
/// Largest growth of `‖δ‖∞` from one step to the next: the motion away from a saddle grows
/// geometrically, and a step far longer than the last one is a jump, not that motion.
const STEP_GROWTH: f64 = 4.0;
/// The margin of the step rule: `sym(M/(MARGIN Δτ) + K_T)` must be positive definite, not merely
/// `sym(M/Δτ + K_T)`, whose factorization passes pivots within round-off of zero. Without it
/// the second step from a saddle (`Δτ = 1/|ω²|` after one doubling) was taken with a singular
/// matrix and jumped as far as the cap allowed (a review, 2026-12-06).
const MARGIN: f64 = 2.0;
/// Halvings of `Δτ` (to make `M/Δτ + K_T` positive definite, or after a non-finite residual)
/// allowed in one step before the descent gives up.
const MAX_HALVINGS: usize = 60;

/// The work of one descent.
#[derive(Debug, Clone, Default)]
pub(super) struct DescentStats {
    pub steps: usize,
    pub residual_evaluations: usize,
    pub jacobian_evaluations: usize,
}

/// Descends from `start` along `M q̇ = R(q)` (tensions `u`, `loads`) until
/// `‖R‖∞ ≤ ftol · scale` (the dogleg's test, `scale = ws.residual_scale`): `Ok((Some(q), stats))`
/// there, `Ok((None, stats))` if it did not within [`MAX_STEPS`] or ended where the rod is turned
/// inside out (a stretch `ν ≤ 0` at a point: no state of a rod). `tau` is the first pseudo-time
/// step, `~ 1/|ω²|` of the divergence left; `first_step` the size of the displacement that
/// started it, the scale of the first step. Whether the end is stable is the caller's to check.
#[allow(clippy::too_many_arguments)]
pub(super) fn descend<P: StrainParam>(
    model: &Model<P>,
    ws: &mut Workspace,
    start: &DVector<f64>,
    u: &[f64],
    loads: &PreparedLoads,
    mut tau: f64,
    first_step: f64,
    ftol: f64,
    stop: &StopCheck<'_>,
) -> Result<(Option<DVector<f64>>, DescentStats), StaticsError> {
    let n = model.n_dof();
    let mut stats = DescentStats::default();
    let mut q = start.clone();
    let mut r = DVector::zeros(n);
    let mut trial = DVector::zeros(n);
    let mut r_trial = DVector::zeros(n);
    let mut jac = DMatrix::zeros(n, n);
    let mut lu = Lu::new(n);
    let mut delta = DVector::zeros(n);
    model.statics_residual(&q, u, loads, ws, &mut r);
    stats.residual_evaluations += 1;
    if !r.iter().all(|v| v.is_finite()) {
        return Ok((None, stats));
    }
    let mut last_step = first_step;
    loop {
        if r.amax() <= ftol * ws.residual_scale {
            // an equilibrium; one with a stretch ν ≤ 0 somewhere is no state of a rod
            let inside_out =
                (model.strains_at(&q, ws).iter()).any(|xi| xi[3].is_nan() || xi[3] <= 0.0);
            return Ok((if inside_out { None } else { Some(q) }, stats));
        }
        if stats.steps >= MAX_STEPS {
            return Ok((None, stats));
        }
        if let Some(reason) = stop() {
            return Err(StaticsError::Stopped {
                load_factor: 1.0,
                reason,
            });
        }
        model.statics_jacobian(&q, u, loads, ws, &mut jac);
        stats.jacobian_evaluations += 1;
        let mass = model.mass_matrix(&q, ws);
        let mut accepted = false;
        for _ in 0..MAX_HALVINGS {
            // A = M/Δτ + K_T = M/Δτ − ∂R/∂q, with sym(M/(2Δτ) + K_T) positive definite
            let margin = &mass / (MARGIN * tau) - &jac;
            let mut sym = &margin + margin.transpose();
            if !positive_definite(&mut sym) {
                tau *= 0.5;
                continue;
            }
            let a = &mass / tau - &jac;
            // faer's blocked LU (the dogleg's): nalgebra's took 1 s per step at 1806 DOF
            if !lu.factor(&a) {
                tau *= 0.5;
                continue;
            }
            delta.copy_from(&r);
            lu.solve(&mut delta);
            let cap = (STEP_CAP * q.amax().max(1.0)).min(STEP_GROWTH * last_step);
            let size = delta.amax();
            if size > cap {
                delta *= cap / size;
            }
            trial.copy_from(&q);
            trial += &delta;
            model.statics_residual(&trial, u, loads, ws, &mut r_trial);
            stats.residual_evaluations += 1;
            if r_trial.iter().all(|v| v.is_finite()) {
                accepted = true;
                break;
            }
            tau *= 0.5;
        }
        if !accepted {
            return Ok((None, stats));
        }
        last_step = (&trial - &q).amax();
        std::mem::swap(&mut q, &mut trial);
        std::mem::swap(&mut r, &mut r_trial);
        stats.steps += 1;
        tau *= 2.0;
    }
}
