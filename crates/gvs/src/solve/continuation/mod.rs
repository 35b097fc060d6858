//! Pseudo-arc-length continuation (Keller) of static equilibria `R(q, λ) = 0` in the load factor λ,
//! through limit points (folds): the fallback of [`super::statics`] when its load ramp stalls.
//!
//! **Why the ramp stalls** (the 7 of 20 000 six-tendon inputs of IV-C1 it missed): in 5 its large
//! increments converged onto another branch, which folds back and forth below λ = 1; in 2 the
//! dogleg stalled where `∂R/∂q` is nearly singular (σ_min ≈ 2e-4–5e-4) on the straight rod's own
//! branch. That branch has folds in one of the 7 (two, at λ ≈ 0.5966 and 0.5957). Continuation from
//! the straight rod reaches λ = 1 in all 7.
//!
//! **The curve and `∂R/∂λ`.** The ramp scales gravity, the wrenches and the tensions by λ. Each of
//! these terms of `R = −K₁(q) + F(q) + B(q)u` (paper eq. 9) is linear in them — gravity and wrenches
//! directly, the tendon forces as `B(q)·λu` (friction's `exp(−μΘ(q))` multiplies the tension) — so
//! `R(q, λ) = −K₁(q) + λ G(q)` is affine in λ with `G(q) = R(q; 1) − R(q; 0)`, the residuals under
//! the full and under no load. Hence `∂R/∂λ = G` exactly, with no difference step, and the same two
//! residuals give `R(q, λ) = R(q; 0) + λ G(q)` ([`StaticsPath`]).
//!
//! **One step** ([`follow`]) in the scaled coordinates `z = (x, μ)`, `μ = θλ` (θ below), from a point
//! on the curve with unit tangent `t`, arc step `Δs`:
//! - predictor `z_p = z + Δs t`;
//! - corrector: Newton on the bordered system `[∂R/∂x  ∂R/∂μ; t_xᵀ  t_μ] δz = −[R; 0]`, whose last
//!   row keeps `z` on the hyperplane through `z_p` normal to `t` (Keller's arclength condition),
//!   until `‖R‖∞ ≤ corrector_ftol · scale`;
//! - new tangent from the same bordered matrix at the converged point: `[∂R/∂x ∂R/∂μ; t_oldᵀ] t = e`,
//!   normalized (`e` the last unit vector), so `t_oldᵀ t > 0`: the orientation is kept and the
//!   tangent turns smoothly through a fold, where `t_μ` changes sign and `∂R/∂x` is singular while
//!   the bordered matrix is not;
//! - step control: a step is rejected and `Δs` halved when the corrector does not converge in
//!   `max_corrector_iterations`, stops contracting (`‖δz_k‖ > 0.9 ‖δz_{k−1}‖`), the tangent turns
//!   by more than `max_turn`, or `det ∂R/∂x` changes sign without `t_μ` doing so (or the reverse)
//!   while `Δs > singular_step · θ` (below: accepted as a bifurcation point or two folds too close
//!   to resolve); after an accepted step `Δs` is scaled by 2, 1.3, 1 or 0.7 for ≤ 2, 3, ≤ 5 or more
//!   corrector iterations, within `[min_step, max_step] · θ`.
//!
//! The determinant test keeps the corrector from jumping between two branches that pass close to
//! each other (a nearly singular `∂R/∂x` without a fold): on a regular path, `det ∂R/∂x` and `t_μ`
//! change sign together, at the folds. On the six-tendon arm (sample 7371 of the IV-C1 dataset)
//! two branches pass within `σ_min(∂R/∂q) ≈ 2e-5` near λ = 0.596; without the test, steps of 0.1
//! jumped onto a loop of four folds (λ = 0.737, 0.713, 0.940, 0.599) and back.
//!
//! **Scale θ.** `x` and λ have different units; the arclength is `‖(δx, θ δλ)‖₂` with
//! `θ = max(1, ‖∂x/∂λ‖₂)` at the start, so that the step options read as increments of λ at the
//! path's initial slope.
//!
//! **Folds and singular points.** A fold is a sign change of `t_μ` between accepted points; the
//! report lists its λ, and counts the sign changes of `det ∂R/∂x` (equal to the folds on a regular
//! path; an extra change means a bifurcation point was stepped over).
//!
//! **Landing.** When λ crosses the target, `x` is interpolated linearly in λ between the last two
//! points and solved at λ = target by the dogleg ([`ContinuationOptions::landing`]).
//!
//! **Bounded work.** At most `max_steps` steps (accepted or rejected); every failure names the λ
//! reached, the largest λ, the steps and the folds ([`ContinuationError`]).

use super::dogleg::{self, DoglegOptions, DoglegWorkspace, EvalError, NonlinearSystem};
use crate::error::ModelError;
use nalgebra::{DMatrix, DVector};
use thiserror::Error;

mod statics_path;
pub use statics_path::{follow_statics, StaticsPath};

/// A system `R(x, λ) = 0` of `n` equations in `n` unknowns and a parameter.
pub trait ParametrizedSystem {
    fn dim(&self) -> usize;
    /// `R(x, λ)` into `r` and `∂R/∂λ(x, λ)` into `r_lambda`; returns the scale `s` of the residual
    /// test `‖R‖∞ ≤ ftol · s`.
    fn residual(
        &mut self,
        x: &DVector<f64>,
        lambda: f64,
        r: &mut DVector<f64>,
        r_lambda: &mut DVector<f64>,
    ) -> f64;
    /// `∂R/∂x(x, λ)` into `jac` (called after [`Self::residual`] at the same point).
    fn jacobian(&mut self, x: &DVector<f64>, lambda: f64, jac: &mut DMatrix<f64>);
    /// Polled before every continuation step: `Some(reason)` stops [`follow`] with
    /// [`Stop::Requested`] (an interrupt; [`super::StopCheck`]).
    fn stop_requested(&mut self) -> Option<String> {
        None
    }
}

/// Options of [`follow`]; step sizes in units of λ at the initial slope (see the module doc).
#[derive(Debug, Clone)]
pub struct ContinuationOptions {
    /// The λ to reach.
    pub target: f64,
    /// The path has turned back when λ falls below this.
    pub min_lambda: f64,
    /// Steps (accepted or rejected) before giving up.
    pub max_steps: usize,
    pub initial_step: f64,
    pub min_step: f64,
    pub max_step: f64,
    pub max_corrector_iterations: usize,
    /// Relative residual tolerance of the points on the path.
    pub corrector_ftol: f64,
    /// Largest angle between consecutive tangents \[rad\].
    pub max_turn: f64,
    /// Step below which a sign change of `det ∂R/∂x` without a fold (or the reverse) is accepted.
    pub singular_step: f64,
    /// The dogleg that solves at λ = target.
    pub landing: DoglegOptions,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        ContinuationOptions {
            target: 1.0,
            min_lambda: 0.0,
            max_steps: 1000,
            initial_step: 0.02,
            min_step: 1e-8,
            max_step: 0.1,
            max_corrector_iterations: 8,
            corrector_ftol: 1e-8,
            max_turn: 0.35,
            singular_step: 1e-4,
            landing: DoglegOptions::default(),
        }
    }
}

/// An accepted point of the path.
#[derive(Debug, Clone)]
pub struct PathPoint {
    pub x: DVector<f64>,
    pub lambda: f64,
    /// `dλ/ds` (of the unit tangent in the scaled norm, divided by θ).
    pub dlambda_ds: f64,
    /// Sign of `det ∂R/∂x` (0 if the LU met a zero pivot).
    pub det_sign: f64,
}

/// How a path was followed.
#[derive(Debug, Clone, Default)]
pub struct ContinuationStats {
    /// λ of the starting point.
    pub start_lambda: f64,
    /// Accepted and rejected steps.
    pub steps: usize,
    pub rejected: usize,
    /// λ at each fold passed, in order.
    pub folds: Vec<f64>,
    pub det_sign_changes: usize,
    pub lambda_max: f64,
    /// Corrector Newton iterations plus the landing's dogleg iterations.
    pub iterations: usize,
}

/// The solution at λ = target and the path that led there.
#[derive(Debug, Clone)]
pub struct ContinuationReport {
    pub x: DVector<f64>,
    /// `‖R(x, target)‖∞`.
    pub residual_norm: f64,
    pub stats: ContinuationStats,
    /// The starting point and every accepted point (the landing not included).
    pub path: Vec<PathPoint>,
}

#[derive(Debug, Error)]
pub enum ContinuationError {
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("continuation cannot start at λ = {lambda:.4}: ‖R‖∞ = {residual_norm:.3e} (tolerance {tolerance:.3e}) or a singular bordered Jacobian")]
    Start {
        lambda: f64,
        residual_norm: f64,
        tolerance: f64,
    },
    #[error("continuation stopped at λ = {lambda:.4} (largest λ {lambda_max:.4}) after {steps} steps and {folds} folds without reaching λ = {target}: {why}")]
    Stopped {
        why: Stop,
        lambda: f64,
        lambda_max: f64,
        steps: usize,
        folds: usize,
        target: f64,
    },
    #[error("continuation crossed λ = {target} after {steps} steps and {folds} folds, but the dogleg there did not converge: {reason}")]
    Landing {
        target: f64,
        steps: usize,
        folds: usize,
        reason: String,
    },
}

/// Why [`follow`] stopped short of the target.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Stop {
    #[error("the step limit ({0})")]
    MaxSteps(usize),
    #[error("the path turned back below λ = {0}")]
    TurnedBack(f64),
    #[error(
        "the arc step fell below {0:e} (a singular point, or a corrector that cannot converge)"
    )]
    StepCollapsed(f64),
    /// The caller asked to stop ([`ParametrizedSystem::stop_requested`]), with its reason.
    #[error("{0}")]
    Requested(String),
}

/// Scratch of [`follow`]: residual, `∂R/∂λ`, `∂R/∂x` and the bordered matrix.
struct Scratch {
    r: DVector<f64>,
    rl: DVector<f64>,
    jac: DMatrix<f64>,
    a: DMatrix<f64>,
    rhs: DVector<f64>,
}

/// A converged corrector: the point, its unit tangent, sign of `det ∂R/∂x`, iterations.
struct Corrected {
    x: DVector<f64>,
    mu: f64,
    t: DVector<f64>,
    det_sign: f64,
    iterations: usize,
}

/// `[J  rl/θ; cᵀ]` into `s.a` from `s.jac`, `s.rl`.
fn border(s: &mut Scratch, c: &DVector<f64>, theta: f64) {
    let n = s.jac.nrows();
    s.a.view_mut((0, 0), (n, n)).copy_from(&s.jac);
    for i in 0..n {
        s.a[(i, n)] = s.rl[i] / theta;
    }
    for j in 0..=n {
        s.a[(n, j)] = c[j];
    }
}

/// Sign of `det J` from its LU: the product of the pivots' signs and the permutation's parity.
fn det_sign(jac: &DMatrix<f64>) -> f64 {
    let lu = jac.clone().lu();
    let u = lu.u();
    let mut s = lu.p().determinant::<f64>();
    for i in 0..u.nrows() {
        s *= u[(i, i)].signum() * (u[(i, i)] != 0.0) as u8 as f64;
    }
    s
}

/// Newton on the bordered system from the predictor `(x, μ)` with the hyperplane normal `t`
/// (see the module doc); `None` if it does not converge.
fn correct<S: ParametrizedSystem>(
    sys: &mut S,
    s: &mut Scratch,
    mut x: DVector<f64>,
    mut mu: f64,
    t: &DVector<f64>,
    theta: f64,
    opts: &ContinuationOptions,
) -> Option<Corrected> {
    let n = x.len();
    let mut last = f64::INFINITY;
    for k in 0..=opts.max_corrector_iterations {
        let scale = sys.residual(&x, mu / theta, &mut s.r, &mut s.rl);
        let rn = s.r.amax();
        if !rn.is_finite() || !s.rl.iter().all(|v| v.is_finite()) {
            return None;
        }
        sys.jacobian(&x, mu / theta, &mut s.jac);
        border(s, t, theta);
        let lu = s.a.clone().lu();
        if rn <= opts.corrector_ftol * scale {
            s.rhs.fill(0.0);
            s.rhs[n] = 1.0;
            let mut tn = lu.solve(&s.rhs)?;
            let norm = tn.norm();
            if !(norm.is_finite() && norm > 0.0) {
                return None;
            }
            tn /= norm;
            let det_sign = det_sign(&s.jac);
            return Some(Corrected {
                x,
                mu,
                t: tn,
                det_sign,
                iterations: k,
            });
        }
        if k == opts.max_corrector_iterations {
            return None;
        }
        for i in 0..n {
            s.rhs[i] = -s.r[i];
        }
        s.rhs[n] = 0.0;
        let dz = lu.solve(&s.rhs)?;
        let step = dz.norm();
        if !step.is_finite() || (k > 0 && step > 0.9 * last) {
            return None;
        }
        last = step;
        for i in 0..n {
            x[i] += dz[i];
        }
        mu += dz[n];
    }
    None
}

/// [`ParametrizedSystem`] at a fixed λ, for the dogleg.
struct AtLambda<'a, S: ParametrizedSystem> {
    sys: &'a mut S,
    lambda: f64,
    rl: DVector<f64>,
    scale: f64,
}

impl<S: ParametrizedSystem> NonlinearSystem for AtLambda<'_, S> {
    fn dim(&self) -> usize {
        self.sys.dim()
    }
    fn residual(&mut self, x: &DVector<f64>, f: &mut DVector<f64>) -> Result<(), EvalError> {
        self.scale = self.sys.residual(x, self.lambda, f, &mut self.rl);
        Ok(())
    }
    fn jacobian(
        &mut self,
        x: &DVector<f64>,
        _f: &DVector<f64>,
        jac: &mut DMatrix<f64>,
    ) -> Result<(), EvalError> {
        self.sys.jacobian(x, self.lambda, jac);
        Ok(())
    }
    fn residual_scale(&self, _x: &DVector<f64>) -> f64 {
        self.scale
    }
}

/// Follows the curve `R(x, λ) = 0` from the equilibrium `(x0, λ0)`, λ increasing at first, to
/// λ = `opts.target` (see the module doc).
pub fn follow<S: ParametrizedSystem>(
    sys: &mut S,
    x0: &DVector<f64>,
    lambda0: f64,
    opts: &ContinuationOptions,
) -> Result<ContinuationReport, ContinuationError> {
    let n = sys.dim();
    let mut s = Scratch {
        r: DVector::zeros(n),
        rl: DVector::zeros(n),
        jac: DMatrix::zeros(n, n),
        a: DMatrix::zeros(n + 1, n + 1),
        rhs: DVector::zeros(n + 1),
    };
    let mut stats = ContinuationStats {
        start_lambda: lambda0,
        lambda_max: lambda0,
        ..ContinuationStats::default()
    };
    // the start: an equilibrium, and its tangent with dλ > 0: [J rl; e_λᵀ] (t_x, 1) = (0, 1)
    let scale = sys.residual(x0, lambda0, &mut s.r, &mut s.rl);
    let rn = s.r.amax();
    let start_error = ContinuationError::Start {
        lambda: lambda0,
        residual_norm: rn,
        tolerance: opts.corrector_ftol * scale,
    };
    // a NaN residual fails too
    if rn.is_nan() || rn > opts.corrector_ftol * scale {
        return Err(start_error);
    }
    sys.jacobian(x0, lambda0, &mut s.jac);
    let dx_dl = match s.jac.clone().lu().solve(&(-&s.rl)) {
        Some(v) if v.iter().all(|c| c.is_finite()) => v,
        _ => return Err(start_error),
    };
    let theta = dx_dl.norm().max(1.0);
    // dμ = θ dλ: t ∝ (∂x/∂λ, θ)
    let mut t = DVector::zeros(n + 1);
    t.rows_mut(0, n).copy_from(&dx_dl);
    t[n] = theta;
    t /= t.norm();
    let mut x = x0.clone();
    let mut mu = theta * lambda0;
    let mut det = det_sign(&s.jac);
    let mut path = vec![PathPoint {
        x: x.clone(),
        lambda: lambda0,
        dlambda_ds: t[n] / theta,
        det_sign: det,
    }];
    let mut ds = opts.initial_step * theta;
    let cos_turn = opts.max_turn.cos();
    let stopped = |why, lambda, stats: &ContinuationStats| ContinuationError::Stopped {
        why,
        lambda,
        lambda_max: stats.lambda_max,
        steps: stats.steps,
        folds: stats.folds.len(),
        target: opts.target,
    };
    loop {
        let lambda = mu / theta;
        if stats.steps >= opts.max_steps {
            return Err(stopped(Stop::MaxSteps(opts.max_steps), lambda, &stats));
        }
        if let Some(reason) = sys.stop_requested() {
            return Err(stopped(Stop::Requested(reason), lambda, &stats));
        }
        stats.steps += 1;
        let xp = &x + t.rows(0, n) * ds;
        let mup = mu + t[n] * ds;
        let c = correct(sys, &mut s, xp, mup, &t, theta, opts).filter(|c| {
            let fold = c.t[n].signum() != t[n].signum();
            let flip = c.det_sign * det < 0.0;
            c.t.dot(&t) >= cos_turn && (fold == flip || ds <= opts.singular_step * theta)
        });
        let Some(c) = c else {
            stats.rejected += 1;
            ds /= 2.0;
            if ds < opts.min_step * theta {
                return Err(stopped(Stop::StepCollapsed(opts.min_step), lambda, &stats));
            }
            continue;
        };
        stats.iterations += c.iterations;
        let lambda_new = c.mu / theta;
        if c.t[n].signum() != t[n].signum() {
            // a fold: λ at the extreme of the two points
            stats.folds.push(if t[n] > 0.0 {
                lambda.max(lambda_new)
            } else {
                lambda.min(lambda_new)
            });
        }
        if c.det_sign * det < 0.0 {
            stats.det_sign_changes += 1;
        }
        stats.lambda_max = stats.lambda_max.max(lambda_new);
        if lambda_new >= opts.target && lambda < opts.target {
            let w = (opts.target - lambda) / (lambda_new - lambda);
            let xi = &x + (&c.x - &x) * w;
            let mut at = AtLambda {
                sys: &mut *sys,
                lambda: opts.target,
                rl: DVector::zeros(n),
                scale: 1.0,
            };
            let mut dws = DoglegWorkspace::new(n);
            return match dogleg::solve(&mut at, &xi, &opts.landing, &mut dws) {
                Ok(rep) => {
                    stats.iterations += rep.iterations;
                    path.push(PathPoint {
                        x: c.x,
                        lambda: lambda_new,
                        dlambda_ds: c.t[n] / theta,
                        det_sign: c.det_sign,
                    });
                    Ok(ContinuationReport {
                        x: rep.x,
                        residual_norm: rep.residual_norm,
                        stats,
                        path,
                    })
                }
                Err(e) => Err(ContinuationError::Landing {
                    target: opts.target,
                    steps: stats.steps,
                    folds: stats.folds.len(),
                    reason: e.to_string(),
                }),
            };
        }
        if lambda_new < opts.min_lambda {
            let why = Stop::TurnedBack(opts.min_lambda);
            return Err(stopped(why, lambda_new, &stats));
        }
        ds = match c.iterations {
            0..=2 => 2.0 * ds,
            3 => 1.3 * ds,
            4 | 5 => ds,
            _ => 0.7 * ds,
        }
        .clamp(opts.min_step * theta, opts.max_step * theta);
        x = c.x;
        mu = c.mu;
        t = c.t;
        if c.det_sign != 0.0 {
            det = c.det_sign;
        }
        path.push(PathPoint {
            x: x.clone(),
            lambda: lambda_new,
            dlambda_ds: t[n] / theta,
            det_sign: det,
        });
    }
}
