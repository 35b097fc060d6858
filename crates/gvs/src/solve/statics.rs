//! Static equilibrium `R(q) = −K₁(q) + F(q) + B(q)u = 0` (paper eq. 9, gvs-spec §8) by the Powell
//! dogleg trust region with the analytic Jacobian, optional load ramping and warm starts.
//!
//! **Stopping rule** (spec §8.3, physical units, no magnifier): converged when
//! `‖R‖∞ ≤ ftol · max(1, ‖K₁‖∞, ‖F + Bu‖∞)` (default `ftol = 1e-10`).
//!
//! **Load ramping**: the loads and tensions are scaled by `λ_m = m/N` and each solve is warm-started
//! from the previous one; if a stage fails, the increment is halved (down to `min_increment`) before
//! the failure is reported.

use super::dogleg::{
    self, DoglegError, DoglegOptions, DoglegWorkspace, EvalError, NonlinearSystem,
};
use crate::error::ModelError;
use crate::loads::Loads;
use crate::model::{Model, PreparedLoads, Workspace};
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Options of a statics solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StaticsOptions {
    /// Number of equal load increments (1 = apply everything at once).
    pub ramp_steps: usize,
    /// Smallest load increment tried after halving on failure.
    pub min_increment: f64,
    /// Relative residual tolerance (see the module doc).
    pub ftol: f64,
    /// Step tolerance `‖Δq‖∞ ≤ xtol (1 + ‖q‖∞)` below which a stalled solve is reported.
    pub xtol: f64,
    /// Iteration limit per load stage.
    pub max_iterations: usize,
}

impl Default for StaticsOptions {
    fn default() -> Self {
        StaticsOptions {
            ramp_steps: 1,
            min_increment: 1.0 / 64.0,
            ftol: 1e-10,
            xtol: 1e-12,
            max_iterations: 400,
        }
    }
}

impl StaticsOptions {
    pub fn validate(&self) -> Result<(), ModelError> {
        if self.ramp_steps == 0 {
            return Err(ModelError::value(
                "solver.ramp_steps",
                0.0,
                "an integer >= 1",
            ));
        }
        crate::error::check_range(
            "solver.min_increment",
            self.min_increment,
            Some((0.0, false)),
            Some((1.0, true)),
            "a number in (0, 1]",
        )?;
        crate::error::check_positive("solver.ftol", self.ftol, "")?;
        crate::error::check_positive("solver.xtol", self.xtol, "")?;
        if self.max_iterations == 0 {
            return Err(ModelError::value(
                "solver.max_iterations",
                0.0,
                "an integer >= 1",
            ));
        }
        Ok(())
    }
}

/// A converged equilibrium and its solver statistics.
#[derive(Debug, Clone)]
pub struct StaticsSolution {
    pub q: DVector<f64>,
    /// Dogleg iterations summed over load stages.
    pub iterations: usize,
    pub residual_evaluations: usize,
    pub jacobian_evaluations: usize,
    /// `‖R(q)‖∞` at the solution [generalized force units].
    pub residual_norm: f64,
    /// Load stages solved (including retries after halving).
    pub load_stages: usize,
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
    },
}

/// A statics solver bound to one model, owning its workspaces so repeated solves do not allocate.
pub struct StaticsSolver<'m, P: StrainParam> {
    model: &'m Model<P>,
    ws: Workspace,
    dws: DoglegWorkspace,
    pub options: StaticsOptions,
}

struct System<'a, 'm, P: StrainParam> {
    model: &'m Model<P>,
    ws: &'a mut Workspace,
    u: Vec<f64>,
    loads: PreparedLoads,
}

impl<P: StrainParam> NonlinearSystem for System<'_, '_, P> {
    fn dim(&self) -> usize {
        self.model.n_dof()
    }
    fn residual(&mut self, x: &DVector<f64>, f: &mut DVector<f64>) -> Result<(), EvalError> {
        self.model
            .statics_residual(x, &self.u, &self.loads, self.ws, f);
        Ok(())
    }
    fn jacobian(
        &mut self,
        x: &DVector<f64>,
        _f: &DVector<f64>,
        jac: &mut DMatrix<f64>,
    ) -> Result<(), EvalError> {
        self.model
            .statics_jacobian(x, &self.u, &self.loads, self.ws, jac);
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
            options,
        }
    }

    /// Solves for the equilibrium under tensions `u` and `loads`, starting from `q0` (straight
    /// reference `q = 0` if `None`).
    pub fn solve(
        &mut self,
        u: &[f64],
        loads: &Loads,
        q0: Option<&DVector<f64>>,
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
            None => DVector::zeros(n),
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
        };
        let mut lambda = 0.0;
        let mut inc = 1.0 / self.options.ramp_steps as f64;
        while lambda < 1.0 {
            let target = (lambda + inc).min(1.0);
            let loads_l = if target == 1.0 {
                loads.clone()
            } else {
                loads.scaled(target)
            };
            let mut sys = System {
                model: self.model,
                ws: &mut self.ws,
                u: u.iter().map(|v| v * target).collect(),
                loads: self.model.prepare_loads(&loads_l)?,
            };
            total.load_stages += 1;
            match dogleg::solve(&mut sys, &q, &opts, &mut self.dws) {
                Ok(rep) => {
                    total.iterations += rep.iterations;
                    total.residual_evaluations += rep.residual_evaluations;
                    total.jacobian_evaluations += rep.jacobian_evaluations;
                    total.residual_norm = rep.residual_norm;
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
                    if inc / 2.0 >= self.options.min_increment * (1.0 - 1e-12) {
                        inc /= 2.0;
                        continue;
                    }
                    return Err(StaticsError::NotConverged {
                        load_factor: target,
                        iterations: total.iterations,
                        residual_norm,
                        tolerance,
                        reason: format!("{reason} (load increment already reduced to {inc})"),
                    });
                }
            }
        }
        total.q = q;
        Ok(total)
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
