//! Static equilibrium `R(q) = −K₁(q) + F(q) + B(q)u = 0` (paper eq. 9, gvs-spec §8) by the Powell
//! dogleg trust region with the analytic Jacobian, optional load ramping and warm starts.
//!
//! **Stopping rule** (spec §8.3, physical units, no magnifier): converged when
//! `‖R‖∞ ≤ ftol · max(‖K₁‖∞, ‖F + Bu‖∞, EI_max)` (default `ftol = 1e-10`): relative to the forces
//! at play, the spec's floor of 1 in the max replaced by the rod's largest bending stiffness
//! ([`crate::model::Model::residual_floor`]), since an absolute force would call a micrometre
//! rod's straight start converged under any load (docs/assumptions.md).
//!
//! **Jacobian** ([`StaticsJacobian`]): analytic (spec §8.2) by default; a model with at most
//! [`DIFFERENCE_MAX_DOF`] coordinates (a small reduced model) takes forward differences instead,
//! `n` residual evaluations against the analytic Jacobian's fixed ≈ 2 residuals' worth of work.
//! The Jacobian only steers the iteration: the converged `q` meets the same residual test.
//!
//! **Load ramping**: the loads and tensions are scaled by `λ_m = m/N` and each solve is warm-started
//! from the previous one; if a stage fails, the increment is halved (down to `min_increment`) before
//! the failure is reported. When the increment cannot be halved further in a solve from the
//! straight rod (no `q0`, `min_increment < 1`), pseudo-arc-length continuation
//! ([`super::continuation`]) follows the equilibria from the straight rod at λ = 0 (the one
//! equilibrium without load) through any folds to λ = 1, and a last dogleg stage at λ = 1 polishes
//! its solution. It starts from the straight rod, not from the ramp's last converged stage: the
//! ramp's large increments can converge onto another branch (on the six-tendon arm, loops of
//! equilibria folding back and forth below λ = 1, which continuation from there circles without
//! reaching λ = 1).
//!
//! **Bounded work**: the options are capped ([`MAX_RAMP_STEPS`], [`MAX_ITERATIONS`],
//! [`MIN_INCREMENT_FLOOR`]) and one solve stops with [`StaticsError::NotConverged`] after
//! [`MAX_LOAD_STAGES`] load stages or [`MAX_TOTAL_ITERATIONS`] dogleg iterations in all, so that no
//! input makes a solve run unbounded (e.g. ramping by a halved increment of 1e-6 for 1e6 stages).

use super::continuation::{self, ContinuationStats};
use super::dogleg::{
    self, DoglegError, DoglegOptions, DoglegWorkspace, EvalError, NonlinearSystem,
};
use super::{never_stop, StopCheck};
use crate::error::ModelError;
use crate::loads::Loads;
use crate::model::{Model, PreparedLoads, Workspace};
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};
use thiserror::Error;

mod descent;
mod options;
pub use options::*;

/// A converged equilibrium and its solver statistics.
#[derive(Debug, Clone)]
pub struct StaticsSolution {
    pub q: DVector<f64>,
    /// Dogleg iterations summed over load stages (and the continuation's, if it ran).
    pub iterations: usize,
    /// Residual evaluations, those of forward-difference Jacobians included.
    pub residual_evaluations: usize,
    /// Evaluations of `∂R/∂q`, by forward differences or analytic: the solver's, the
    /// continuation's and the descent's, and the stability check's (which costs no residual).
    pub jacobian_evaluations: usize,
    /// `‖R(q)‖∞` at the solution [generalized force units].
    pub residual_norm: f64,
    /// Load stages solved (including retries after halving).
    pub load_stages: usize,
    /// The continuation from the straight rod, if the ramp stalled or converged onto an unstable
    /// equilibrium (its q was then polished at λ = 1).
    pub continuation: Option<ContinuationStats>,
    /// `Some(ω²)`, the most negative real eigenvalue of `M⁻¹ K_T` \[1/s²\], if the equilibrium
    /// diverges ([`super::stability`]): no stable equilibrium was found, and the front-end says so.
    pub divergence: Option<f64>,
    /// `Some(ω²)` if the step from the straight rod first converged onto an equilibrium that
    /// diverges (with that eigenvalue): why the continuation then ran.
    pub unstable_start: Option<f64>,
    /// `Some(ω²)` if the equilibrium on the path from the straight rod diverged (with that
    /// eigenvalue; a bifurcation, e.g. a straight column compressed past buckling) and the rod,
    /// displaced along its divergent mode, settled on this stable equilibrium instead.
    pub buckled: Option<f64>,
    /// Pseudo-time steps of the descent along the rod's overdamped motion from a diverging
    /// equilibrium (0 if none ran), each with one `∂R/∂q` and one mass matrix.
    pub descent_steps: usize,
}

/// What pseudo-arc-length continuation did in a solve that did not converge
/// ([`StaticsError::NotConverged`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContinuationOutcome {
    /// Not tried: the ramp alone failed (or a warm start, or `min_increment = 1`, forbade it).
    NotTried,
    /// It stopped before the full load (the reason says where and why).
    Stopped,
    /// It reached the full load, but the last solve there did not converge, or the work budget
    /// ran out after it.
    Reached,
}

#[derive(Debug, Error)]
pub enum StaticsError {
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("the scenario has {expected} actuators but {got} tensions were given")]
    ActuatorCount { expected: usize, got: usize },
    #[error("statics did not converge at load factor {load_factor:.4} after {iterations} iterations: ‖R‖∞ = {residual_norm:.3e} (tolerance {tolerance:.3e}); {reason}")]
    NotConverged {
        load_factor: f64,
        iterations: usize,
        residual_norm: f64,
        tolerance: f64,
        reason: String,
        /// What pseudo-arc-length continuation from the straight rod did before the failure: a
        /// failure after it is not one a finer ramp would avoid.
        continuation: ContinuationOutcome,
    },
    /// Tendons driven by displacement ([`super::tendon_drive`]) did not reach their lengths.
    #[error("the tendons' displacements were not reached after {iterations} tension update{}: the largest length error is {length_error:.3e} m (tolerance {tolerance:.1e} m); {reason}", if *iterations == 1 { "" } else { "s" })]
    DriveNotReached {
        iterations: usize,
        length_error: f64,
        tolerance: f64,
        reason: String,
    },
    /// The caller's [`StopCheck`] asked to stop (an interrupt) before the load stage at
    /// `load_factor` or a continuation step.
    #[error("statics stopped at load factor {load_factor:.4}: {reason}")]
    Stopped { load_factor: f64, reason: String },
}

/// A statics solver bound to one model, owning its workspaces so repeated solves do not allocate.
pub struct StaticsSolver<'m, P: StrainParam> {
    model: &'m Model<P>,
    ws: Workspace,
    dws: DoglegWorkspace,
    at: DVector<f64>,
    xh: DVector<f64>,
    fh: DVector<f64>,
    pub options: StaticsOptions,
}

struct System<'a, 'm, P: StrainParam> {
    model: &'m Model<P>,
    ws: &'a mut Workspace,
    u: Vec<f64>,
    loads: PreparedLoads,
    /// Where the last residual was evaluated, if `ws` still holds its forward pass: a Jacobian
    /// asked for at that same point (the dogleg always asks at its current, evaluated point)
    /// reuses the strains, poses and Magnus steps.
    at: &'a mut DVector<f64>,
    fresh: bool,
    /// Forward differences instead of the analytic Jacobian.
    differences: bool,
    /// Scratch of the differences: the perturbed point and its residual.
    xh: &'a mut DVector<f64>,
    fh: &'a mut DVector<f64>,
}

impl<P: StrainParam> NonlinearSystem for System<'_, '_, P> {
    fn dim(&self) -> usize {
        self.model.n_dof()
    }
    fn residual(&mut self, x: &DVector<f64>, f: &mut DVector<f64>) -> Result<(), EvalError> {
        self.model
            .statics_residual(x, &self.u, &self.loads, self.ws, f);
        self.at.copy_from(x);
        self.fresh = true;
        Ok(())
    }
    fn jacobian(
        &mut self,
        x: &DVector<f64>,
        f: &DVector<f64>,
        jac: &mut DMatrix<f64>,
    ) -> Result<(), EvalError> {
        if self.differences {
            // the scale of the convergence test stays the one of R(x)
            let scale = self.ws.residual_scale;
            self.xh.copy_from(x);
            for j in 0..x.len() {
                let h = f64::EPSILON.sqrt() * x[j].abs().max(1.0);
                self.xh[j] = x[j] + h;
                let h = self.xh[j] - x[j]; // the step as represented
                self.model
                    .statics_residual(self.xh, &self.u, &self.loads, self.ws, self.fh);
                for i in 0..x.len() {
                    jac[(i, j)] = (self.fh[i] - f[i]) / h;
                }
                self.xh[j] = x[j];
            }
            self.ws.residual_scale = scale;
            self.fresh = false;
            return Ok(());
        }
        if self.fresh && *self.at == *x {
            self.model
                .statics_jacobian_after_forward(x, &self.u, &self.loads, self.ws, jac);
        } else {
            self.model
                .statics_jacobian(x, &self.u, &self.loads, self.ws, jac);
        }
        self.fresh = false;
        Ok(())
    }
    fn residual_scale(&self, _x: &DVector<f64>) -> f64 {
        self.ws.residual_scale
    }
}

impl<'m, P: StrainParam> StaticsSolver<'m, P> {
    pub fn new(model: &'m Model<P>, options: StaticsOptions) -> Self {
        StaticsSolver {
            model,
            ws: model.workspace(),
            dws: DoglegWorkspace::new(model.n_dof()),
            at: DVector::zeros(model.n_dof()),
            xh: DVector::zeros(model.n_dof()),
            fh: DVector::zeros(model.n_dof()),
            options,
        }
    }

    /// Solves for the equilibrium under tensions `u` and `loads`, starting from `q0` (the straight
    /// reference, [`StrainParam::rest_coordinates`], if `None`).
    pub fn solve(
        &mut self,
        u: &[f64],
        loads: &Loads,
        q0: Option<&DVector<f64>>,
    ) -> Result<StaticsSolution, StaticsError> {
        self.solve_within(
            u,
            loads,
            q0,
            MAX_LOAD_STAGES,
            MAX_TOTAL_ITERATIONS,
            &never_stop,
        )
    }

    /// [`Self::solve`] that polls `stop` before every load stage and every continuation step: a
    /// `Some(reason)` ends the solve with [`StaticsError::Stopped`] within one stage (one dogleg
    /// solve), however many stages the ramp still has.
    pub fn solve_interruptible(
        &mut self,
        u: &[f64],
        loads: &Loads,
        q0: Option<&DVector<f64>>,
        stop: &StopCheck<'_>,
    ) -> Result<StaticsSolution, StaticsError> {
        self.solve_within(u, loads, q0, MAX_LOAD_STAGES, MAX_TOTAL_ITERATIONS, stop)
    }

    /// [`Self::solve`] with explicit caps on the load stages and total iterations of the solve.
    fn solve_within(
        &mut self,
        u: &[f64],
        loads: &Loads,
        q0: Option<&DVector<f64>>,
        max_stages: usize,
        max_total_iterations: usize,
        stop: &StopCheck<'_>,
    ) -> Result<StaticsSolution, StaticsError> {
        self.options.validate()?;
        let n = self.model.n_dof();
        if u.len() != self.model.n_actuators() {
            return Err(StaticsError::ActuatorCount {
                expected: self.model.n_actuators(),
                got: u.len(),
            });
        }
        for (k, v) in u.iter().enumerate() {
            crate::error::check_finite(&format!("actuation[{k}]"), *v)?;
        }
        self.model.prepare_loads(loads)?; // validate once, with field names
        let mut q = match q0 {
            Some(q0) if q0.len() == n => q0.clone(),
            Some(q0) => {
                return Err(ModelError::invalid(
                    "q0",
                    format!("{} entries for {} coordinates", q0.len(), n),
                )
                .into())
            }
            None => self.model.param.rest_coordinates(),
        };
        let opts = DoglegOptions {
            max_iterations: self.options.max_iterations,
            ftol: self.options.ftol,
            xtol: self.options.xtol,
            ..DoglegOptions::default()
        };
        let mut total = StaticsSolution {
            q: q.clone(),
            iterations: 0,
            residual_evaluations: 0,
            jacobian_evaluations: 0,
            residual_norm: f64::NAN,
            load_stages: 0,
            continuation: None,
            divergence: None,
            unstable_start: None,
            buckled: None,
            descent_steps: 0,
        };
        let mut lambda = 0.0;
        let mut inc = 1.0 / self.options.ramp_steps as f64;
        // ‖R‖∞ and its tolerance at the end of the last stage (converged or not)
        let mut last_tolerance = f64::NAN;
        // the first equilibrium found, if it diverges and a continuation from the straight rod
        // follows
        let mut unstable: Option<StaticsSolution> = None;
        // the ramp (and continuation after a failure); then, if its equilibrium diverges, once more
        // by continuation from the straight rod
        loop {
            while lambda < 1.0 {
                if let Some(reason) = stop() {
                    return Err(StaticsError::Stopped {
                        load_factor: lambda,
                        reason,
                    });
                }
                if total.load_stages >= max_stages || total.iterations >= max_total_iterations {
                    return Err(StaticsError::NotConverged {
                    load_factor: lambda,
                    iterations: total.iterations,
                    residual_norm: total.residual_norm,
                    tolerance: last_tolerance,
                    reason: format!(
                        "stopped after {} load stages and {} iterations (limits per solve: {max_stages} stages, {max_total_iterations} iterations) with the load increment at {inc:.3e}",
                        total.load_stages, total.iterations
                    ),
                    continuation: match total.continuation {
                        Some(_) => ContinuationOutcome::Reached,
                        None => ContinuationOutcome::NotTried,
                    },
                });
                }
                let target = (lambda + inc).min(1.0);
                let loads_l = if target == 1.0 {
                    loads.clone()
                } else {
                    loads.scaled(target)
                };
                let (u_l, loads_l) = (
                    u.iter().map(|v| v * target).collect(),
                    self.model.prepare_loads(&loads_l)?,
                );
                total.load_stages += 1;
                match self.stage(u_l, loads_l, &q, &opts) {
                    Ok(rep) => {
                        total.iterations += rep.iterations;
                        total.residual_evaluations += self.residuals_of(&rep);
                        total.jacobian_evaluations += rep.jacobian_evaluations;
                        total.residual_norm = rep.residual_norm;
                        last_tolerance = self.options.ftol * self.ws.residual_scale;
                        q = rep.x;
                        lambda = target;
                    }
                    Err(e) => {
                        let (iterations, residual_norm, tolerance, reason) = match e {
                            DoglegError::NotConverged {
                                iterations,
                                residual_norm,
                                tolerance,
                                reason,
                                ..
                            } => (iterations, residual_norm, tolerance, reason),
                            other => (0, f64::NAN, f64::NAN, other.to_string()),
                        };
                        total.iterations += iterations;
                        total.residual_norm = residual_norm;
                        last_tolerance = tolerance;
                        if inc / 2.0 >= self.options.min_increment * (1.0 - 1e-12)
                            && total.continuation.is_none()
                        {
                            inc /= 2.0;
                            continue;
                        }
                        let mut reason =
                            format!("{reason} (load increment already reduced to {inc})");
                        // only from the straight rod (a warm start's caller has its own fallback) and
                        // with ramping allowed (min_increment = 1 asks for one stage)
                        let may_continue = q0.is_none() && self.options.min_increment < 1.0;
                        let mut outcome = match total.continuation {
                            Some(_) => ContinuationOutcome::Reached,
                            None => ContinuationOutcome::NotTried,
                        };
                        if may_continue && total.continuation.is_none() {
                            outcome = ContinuationOutcome::Stopped;
                            match self.follow_from_straight(&mut total, u, loads, &opts, stop)? {
                                Ok(x) => {
                                    q = x;
                                    inc = 1.0; // a last stage at λ = 1 polishes q
                                    continue;
                                }
                                Err(e) => {
                                    reason = format!("{reason}; then from the straight rod, {e}")
                                }
                            }
                        } else if let Some(mut first) = unstable.take() {
                            // the continuation's end did not converge: the unstable equilibrium stands
                            first.iterations = total.iterations;
                            first.residual_evaluations = total.residual_evaluations;
                            first.jacobian_evaluations = total.jacobian_evaluations;
                            first.load_stages = total.load_stages;
                            // the continuation ran (to λ = 1) after this equilibrium diverged
                            first.continuation = total.continuation.clone();
                            first.unstable_start = total.unstable_start;
                            // (`first.divergence` is the exact check's at `first.q`)
                            if first.divergence.is_some() {
                                let at = first.q.clone();
                                if let Some(x) = self.leave_along_divergent_mode(
                                    &at, &mut first, u, loads, &opts, stop,
                                )? {
                                    first.q = x;
                                }
                            }
                            return Ok(first);
                        } else if total.continuation.is_some() {
                            reason = format!("{reason}, at λ = 1 after the continuation");
                        }
                        return Err(StaticsError::NotConverged {
                            load_factor: target,
                            iterations: total.iterations,
                            residual_norm,
                            tolerance,
                            reason,
                            continuation: outcome,
                        });
                    }
                }
            }
            total.divergence = if self.options.check_stability {
                self.divergence_screened(&q, u, loads, &mut total.jacobian_evaluations)?
            } else {
                None
            };
            // A step from the straight rod (the one equilibrium without load) can converge onto an
            // unstable equilibrium at full load: follow the equilibria from it instead, as after a
            // failure, and polish at λ = 1. A warm start's caller has its own fallback.
            let may_continue = q0.is_none() && self.options.min_increment < 1.0;
            if total.divergence.is_none() || !may_continue || total.continuation.is_some() {
                break;
            }
            // kept if the continuation's equilibrium does not converge at λ = 1
            let first = StaticsSolution {
                q: q.clone(),
                ..total.clone()
            };
            match self.follow_from_straight(&mut total, u, loads, &opts, stop)? {
                Ok(x) => {
                    unstable = Some(first);
                    total.unstable_start = total.divergence;
                    q = x;
                    (lambda, inc) = (0.0, 1.0); // one stage at λ = 1 polishes q
                }
                // no path from the straight rod: the unstable equilibrium is all there is
                Err(_) => break,
            }
        }
        // still diverging from the straight rod's path: a bifurcation the continuation passes
        // straight through; leave it along the divergent mode
        if total.divergence.is_some() && q0.is_none() && self.options.min_increment < 1.0 {
            if let Some(x) =
                self.leave_along_divergent_mode(&q, &mut total, u, loads, &opts, stop)?
            {
                q = x;
            }
        }
        total.q = q;
        Ok(total)
    }

    /// From the diverging equilibrium `q`, the rod's own way off it: displaced by `±ε φ` (`φ` its
    /// divergent mode, `‖φ‖∞ = 1`, `ε = 0.01 max(1, ‖q‖∞)`; `+` first) and released, it follows
    /// its overdamped motion `M q̇ = R(q)` ([`descent`]) onto a stable equilibrium, which a
    /// full-load dogleg stage then polishes. The first stable equilibrium reached, with `total`
    /// updated (`buckled`, `divergence`, statistics); `None` if none is.
    fn leave_along_divergent_mode(
        &mut self,
        q: &DVector<f64>,
        total: &mut StaticsSolution,
        u: &[f64],
        loads: &Loads,
        opts: &DoglegOptions,
        stop: &StopCheck<'_>,
    ) -> Result<Option<DVector<f64>>, StaticsError> {
        let prepared = self.model.prepare_loads(loads)?;
        // the modes evaluate `∂R/∂q` (and `M`) at `q`
        total.jacobian_evaluations += 1;
        let Some((w2, phi)) =
            super::stability::divergent_mode(self.model, q, u, &prepared, &mut self.ws)
        else {
            return Ok(None);
        };
        let eps = 0.01 * q.amax().max(1.0);
        for sign in [1.0, -1.0] {
            let start = q + &phi * (sign * eps);
            let (end, work) = descent::descend(
                self.model,
                &mut self.ws,
                &start,
                u,
                &prepared,
                0.5 / w2.abs(),
                eps,
                self.options.ftol,
                stop,
            )?;
            total.residual_evaluations += work.residual_evaluations;
            total.jacobian_evaluations += work.jacobian_evaluations;
            total.descent_steps += work.steps;
            let Some(end) = end else { continue };
            total.load_stages += 1;
            match self.stage(u.to_vec(), prepared.clone(), &end, opts) {
                Ok(rep) => {
                    total.iterations += rep.iterations;
                    total.residual_evaluations += self.residuals_of(&rep);
                    total.jacobian_evaluations += rep.jacobian_evaluations;
                    // the exact test: the dogleg's Jacobian, if the polish took no step, is
                    // an earlier solve's at another point
                    let jacobians = &mut total.jacobian_evaluations;
                    if self.divergence(&rep.x, u, loads, jacobians)?.is_none() {
                        total.buckled = Some(w2);
                        total.divergence = None;
                        total.residual_norm = rep.residual_norm;
                        return Ok(Some(rep.x));
                    }
                }
                Err(DoglegError::NotConverged { iterations, .. }) => {
                    total.iterations += iterations;
                }
                Err(_) => {}
            }
        }
        Ok(None)
    }

    /// The residual evaluations of a load stage, its forward-difference Jacobians' (`n` each)
    /// included.
    fn residuals_of(&self, rep: &dogleg::DoglegReport) -> usize {
        rep.residual_evaluations
            + if self.differences() {
                self.model.n_dof() * rep.jacobian_evaluations
            } else {
                0
            }
    }

    /// Whether `∂R/∂q` is taken by forward differences ([`StaticsJacobian`]).
    fn differences(&self) -> bool {
        match self.options.jacobian {
            StaticsJacobian::Auto => self.model.n_dof() <= DIFFERENCE_MAX_DOF,
            StaticsJacobian::Analytic => false,
            StaticsJacobian::Differences => true,
        }
    }

    /// One dogleg solve of `R(q) = 0` under tensions `u` and `loads` from `start` (a load stage).
    fn stage(
        &mut self,
        u: Vec<f64>,
        loads: PreparedLoads,
        start: &DVector<f64>,
        opts: &DoglegOptions,
    ) -> Result<dogleg::DoglegReport, DoglegError> {
        let differences = self.differences();
        let mut sys = System {
            model: self.model,
            ws: &mut self.ws,
            u,
            loads,
            at: &mut self.at,
            fresh: false,
            differences,
            xh: &mut self.xh,
            fh: &mut self.fh,
        };
        dogleg::solve(&mut sys, start, opts, &mut self.dws)
    }

    /// Follows the equilibria from the straight rod to the full load by pseudo-arc-length
    /// continuation ([`continuation::follow_statics`]), adding its work to `total`: `Ok(Ok(q))` at
    /// λ = 1, `Ok(Err(why))` if it stopped short, `Err` if `stop` asked to stop.
    fn follow_from_straight(
        &mut self,
        total: &mut StaticsSolution,
        u: &[f64],
        loads: &Loads,
        opts: &DoglegOptions,
        stop: &StopCheck<'_>,
    ) -> Result<Result<DVector<f64>, String>, StaticsError> {
        match continuation::follow_statics(self.model, &mut self.ws, u, loads, opts, stop) {
            Ok((path, residuals, jacobians)) => {
                total.iterations += path.stats.iterations;
                total.residual_evaluations += residuals;
                total.jacobian_evaluations += jacobians;
                total.continuation = Some(path.stats);
                Ok(Ok(path.x))
            }
            Err(continuation::ContinuationError::Stopped {
                why: continuation::Stop::Requested(reason),
                lambda,
                ..
            }) => Err(StaticsError::Stopped {
                load_factor: lambda,
                reason,
            }),
            Err(e) => Ok(Err(e.to_string())),
        }
    }

    /// [`super::stability::divergence_at`] at the equilibrium `q` of the full load, screened first
    /// with the last dogleg solve's Jacobian (at `q`, Broyden-updated): when its tangent stiffness
    /// has a positive definite symmetric part, the equilibrium is taken as stable without
    /// evaluating `∂R/∂q` again (that evaluation cost as much as the rest of a solve on the
    /// presets). Call it right after the dogleg converged at `q`. `jacobians` counts the
    /// evaluation if there is one.
    fn divergence_screened(
        &mut self,
        q: &DVector<f64>,
        u: &[f64],
        loads: &Loads,
        jacobians: &mut usize,
    ) -> Result<Option<f64>, StaticsError> {
        if super::stability::surely_stable(self.dws.jacobian()) {
            return Ok(None);
        }
        self.divergence(q, u, loads, jacobians)
    }

    /// [`super::stability::divergence_at`] at the equilibrium `q` of the full load (one evaluation
    /// of `∂R/∂q`, added to `jacobians`).
    fn divergence(
        &mut self,
        q: &DVector<f64>,
        u: &[f64],
        loads: &Loads,
        jacobians: &mut usize,
    ) -> Result<Option<f64>, StaticsError> {
        *jacobians += 1;
        let prepared = self.model.prepare_loads(loads)?;
        Ok(super::stability::divergence_at(
            self.model,
            q,
            u,
            &prepared,
            &mut self.ws,
        ))
    }

    /// The workspace of the last evaluation (poses, strains at the solution after [`Self::solve`]).
    pub fn workspace(&mut self) -> &mut Workspace {
        &mut self.ws
    }
}

/// One-shot convenience wrapper around [`StaticsSolver`].
pub fn solve_statics<P: StrainParam>(
    model: &Model<P>,
    u: &[f64],
    loads: &Loads,
    q0: Option<&DVector<f64>>,
    options: &StaticsOptions,
) -> Result<StaticsSolution, StaticsError> {
    StaticsSolver::new(model, options.clone()).solve(u, loads, q0)
}

#[cfg(test)]
mod tests;
