//! Time integration of the GVS equations of motion (paper eq. 8, gvs-spec §9) with the state
//! `y = [q; q̇]`, `y' = [q̇; M(q)⁻¹ τ(q, q̇, t)]`: a stiff variable-order NDF integrator (ode15s
//! class) — by default in second-order form, each Newton iteration evaluating the recursive residual
//! `M q̈ − τ` and solving with the `n × n` matrix `M + c D + c² K`
//! ([`super::ode::integrate_ndf_second_order`]) —, a fixed-step implicit method or generalized-α;
//! piecewise-constant or ramped actuation `u(t)`, a scalar load schedule `λ(t)` on the external
//! loads, and initial states at rest, given, or at a static equilibrium.
//!
//! Input switching times are passed to the integrator as breakpoints (it steps onto them and restarts).
//! On failure the samples computed so far are kept and the error carries the time reached.

use super::ode::{
    integrate_fixed, integrate_fixed_second_order, integrate_generalized_alpha, integrate_ndf,
    integrate_ndf_second_order, integrate_sdirk, FixedStepOptions, GeneralizedAlphaOptions,
    MechanicalSystem, NdfOptions, OdeError, OdeStats, OdeSystem, RhsError, SdirkOptions,
};
use super::statics::{StaticsError, StaticsOptions, StaticsSolver};
use crate::error::ModelError;
use crate::inputs::{Actuation, Signal};
use crate::lie::{Pose, V6};
use crate::loads::Loads;
use crate::model::{Model, PreparedLoads, Workspace};
use crate::strain::StrainParam;
use nalgebra::DVector;
use std::ops::ControlFlow;
use std::time::Instant;

pub mod drive;
mod regime;
#[cfg(test)]
mod tests_drive;
use drive::TendonSprings;
pub use regime::{
    damping_regime, method_for_rod, ndf_for_regime, ndf_for_rod, DampingRegime, LIGHT_DAMPING_RTOL,
};

/// The integration method.
#[derive(Debug, Clone)]
pub enum Method {
    /// Variable-step, variable-order NDF/BDF (ode15s class).
    Ndf(NdfOptions),
    /// Fixed-step implicit method for real-time use.
    Fixed(FixedStepOptions),
    /// Adaptive generalized-α in second-order form (lightly damped rods).
    GeneralizedAlpha(GeneralizedAlphaOptions),
    /// Adaptive L-stable SDIRK of order 4 in second-order form (lightly damped rods).
    Sdirk(SdirkOptions),
}

/// Integrator and Jacobian choice.
#[derive(Debug, Clone, Default)]
pub struct IntegratorOptions {
    pub method: Method,
    pub jacobian: OdeJacobian,
}

impl Method {
    /// The method's short name (`ndf`, `fixed`, `galpha`, `sdirk`: the CLI's `--method` values).
    pub fn name(&self) -> &'static str {
        match self {
            Method::Ndf(_) => "ndf",
            Method::Fixed(_) => "fixed",
            Method::GeneralizedAlpha(_) => "galpha",
            Method::Sdirk(_) => "sdirk",
        }
    }

    /// The relative tolerance of an adaptive method (`None` for the fixed step).
    pub fn rtol(&self) -> Option<f64> {
        match self {
            Method::Ndf(o) => Some(o.rtol),
            Method::Fixed(_) => None,
            Method::GeneralizedAlpha(o) => Some(o.rtol),
            Method::Sdirk(o) => Some(o.rtol),
        }
    }
}

impl Default for Method {
    fn default() -> Self {
        Method::Ndf(NdfOptions::default())
    }
}

/// How the integrator gets `∂f/∂y`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OdeJacobian {
    /// First-order form `y' = f(y)`, `f = [q̇; M⁻¹τ]` evaluated by [`Model::accelerations`], with
    /// finite differences of `f` (2n evaluations) for the `2n × 2n` iteration matrix, reused
    /// across steps. Slow; a cross-check of the structured path.
    FiniteDifference,
    /// The structured parts `M`, `D`, `K_T` ([`Model::iteration_parts`]: the analytic statics
    /// Jacobian and the damping matrix). The NDF then runs in second-order form
    /// ([`super::ode::integrate_ndf_second_order`]): each Newton iteration is one recursive
    /// residual `M q̈ − τ` ([`Model::dynamics_residual`]) and an `n × n` solve; so does the
    /// fixed-step method ([`super::ode::integrate_fixed_second_order`]) unless its options say
    /// otherwise (`FixedStepOptions::second_order`) or the strain parameterization is nonlinear
    /// ([`fixed_step_in_second_order`]), when it uses the first-order form with
    /// `[0 I; −M⁻¹K_T −M⁻¹D]` ([`Model::ode_jacobian_approx`]).
    #[default]
    Structured,
}

/// Where the simulation starts.
#[derive(Debug, Clone)]
pub enum InitialState {
    /// Straight reference configuration at rest (`q` = [`StrainParam::rest_coordinates`]: 0 for
    /// linear bases; `q̇ = 0`).
    Rest,
    /// A given state.
    Given { q: DVector<f64>, qd: DVector<f64> },
    /// At rest in the static equilibrium under these tensions and loads (then released to the
    /// simulation's own inputs at t = 0: a release test).
    Equilibrium { u: Vec<f64>, loads: Loads },
}

/// Samples of a simulation.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    pub t: Vec<f64>,
    pub q: Vec<DVector<f64>>,
    pub qd: Vec<DVector<f64>>,
    /// Tensions at each sample: the actuation's, and a displacement-driven tendon's from its
    /// stretch ([`drive`]).
    pub u: Vec<Vec<f64>>,
    pub tip: Vec<Pose>,
    /// Strain `ξ` at the computational points at each sample (point-major).
    pub strain: Vec<Vec<V6>>,
}

/// A simulation's result: the samples up to the end (or up to a failure), statistics and timing.
#[derive(Debug)]
pub struct Simulation {
    pub trajectory: Trajectory,
    /// The integrator's work, up to the end or to where it stopped.
    pub stats: OdeStats,
    pub wall_time_s: f64,
    /// `Some` if the integration stopped early; the trajectory holds the samples before it.
    pub error: Option<OdeError>,
}

impl Simulation {
    /// Simulated time per wall-clock time.
    pub fn real_time_factor(&self) -> f64 {
        let span = match (self.trajectory.t.first(), self.trajectory.t.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        span / self.wall_time_s.max(1e-12)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SimulationError {
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("initial equilibrium: {0}")]
    Initial(#[from] StaticsError),
}

/// The rod as a first-order ODE system.
struct RodOde<'m, P: StrainParam> {
    model: &'m Model<P>,
    ws: Workspace,
    actuation: &'m dyn Actuation,
    load_scale: Option<&'m Signal>,
    base_loads: PreparedLoads,
    loads: PreparedLoads,
    u: Vec<f64>,
    lambda: [f64; 1],
    q: DVector<f64>,
    qd: DVector<f64>,
    qdd: DVector<f64>,
    jacobian: OdeJacobian,
    /// The displacement-driven tendons' springs ([`drive`]), `None` when every channel is a tension.
    springs: Option<TendonSprings>,
    /// Polled before every step attempt ([`simulate_streaming_interruptible`]).
    stop: &'m StopCheck<'m>,
}

pub use super::StopCheck;

impl<P: StrainParam> OdeSystem for RodOde<'_, P> {
    fn stop_requested(&mut self) -> Option<String> {
        (self.stop)()
    }

    fn jacobian(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        jac: &mut nalgebra::DMatrix<f64>,
    ) -> Result<bool, RhsError> {
        if self.jacobian == OdeJacobian::FiniteDifference {
            return Ok(false);
        }
        let n = self.model.n_dof();
        self.q.copy_from(&y.rows(0, n));
        self.inputs_at(t);
        let taut = match &mut self.springs {
            Some(s) => {
                s.tensions(self.model, &self.q, &mut self.ws, &mut self.u);
                s.evaluate(self.model, &self.q, &self.u, &mut self.ws)
            }
            None => false,
        };
        self.model
            .ode_jacobian_approx(&self.q, &self.u, &self.loads, &mut self.ws, jac)
            .map_err(|e| RhsError(e.to_string()))?;
        if let (true, Some(s)) = (taut, &mut self.springs) {
            // `ws.mass` holds the Cholesky factor of `M` the approximation left
            s.add_to_first_order(&self.u, &self.ws.mass, jac);
        }
        Ok(true)
    }

    fn dim(&self) -> usize {
        2 * self.model.n_dof()
    }

    fn rhs(&mut self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) -> Result<(), RhsError> {
        let n = self.model.n_dof();
        self.q.copy_from(&y.rows(0, n));
        self.qd.copy_from(&y.rows(n, n));
        self.inputs_at(t);
        if let Some(s) = &mut self.springs {
            s.tensions(self.model, &self.q, &mut self.ws, &mut self.u);
        }
        self.model
            .accelerations(
                &self.q,
                &self.qd,
                &self.u,
                &self.loads,
                &mut self.ws,
                &mut self.qdd,
            )
            .map_err(|e| RhsError(e.to_string()))?;
        dy.rows_mut(0, n).copy_from(&self.qd);
        dy.rows_mut(n, n).copy_from(&self.qdd);
        Ok(())
    }
}

impl<P: StrainParam> RodOde<'_, P> {
    /// Inputs at `t`: `self.u` and the scaled loads.
    fn inputs_at(&mut self, t: f64) {
        self.actuation.eval(t, &mut self.u);
        if let Some(s) = self.load_scale {
            s.eval(t, &mut self.lambda);
            self.loads.scale_from(&self.base_loads, self.lambda[0]);
        }
    }

    /// The driven tendons' tensions at `q` in place of their displacements in `self.u` (after
    /// [`Self::inputs_at`]).
    fn tensions_at(&mut self, q: &DVector<f64>) {
        if let Some(s) = &mut self.springs {
            s.tensions(self.model, q, &mut self.ws, &mut self.u);
        }
    }
}

impl<P: StrainParam> MechanicalSystem for RodOde<'_, P> {
    fn dim(&self) -> usize {
        self.model.n_dof()
    }

    fn stop_requested(&mut self) -> Option<String> {
        (self.stop)()
    }

    fn residual(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        eps: &mut DVector<f64>,
    ) -> Result<(), RhsError> {
        self.inputs_at(t);
        self.tensions_at(q);
        self.model
            .dynamics_residual(q, qd, qdd, &self.u, &self.loads, &mut self.ws, eps);
        Ok(())
    }

    fn accelerations(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &mut DVector<f64>,
    ) -> Result<(), RhsError> {
        self.inputs_at(t);
        self.tensions_at(q);
        self.model
            .accelerations(q, qd, &self.u, &self.loads, &mut self.ws, qdd)
            .map_err(|e| RhsError(e.to_string()))
    }

    fn mass(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        m: &mut nalgebra::DMatrix<f64>,
    ) -> Result<(), RhsError> {
        self.inputs_at(t);
        self.model.forward(q, &mut self.ws, true);
        self.model.assemble_mass(&mut self.ws);
        m.copy_from(&self.ws.mass);
        Ok(())
    }

    fn residual_and_mass(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        eps: &mut DVector<f64>,
        m: &mut nalgebra::DMatrix<f64>,
    ) -> Result<(), RhsError> {
        self.inputs_at(t);
        self.tensions_at(q);
        self.model
            .dynamics_residual_and_mass(q, qd, qdd, &self.u, &self.loads, &mut self.ws, eps);
        m.copy_from(&self.ws.mass);
        Ok(())
    }

    fn iteration_parts(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        _qd: &DVector<f64>,
        m: &mut nalgebra::DMatrix<f64>,
        d: &mut nalgebra::DMatrix<f64>,
        k: &mut nalgebra::DMatrix<f64>,
    ) -> Result<(), RhsError> {
        self.inputs_at(t);
        self.tensions_at(q);
        self.model
            .iteration_parts(q, &self.u, &self.loads, &mut self.ws, m, d, k);
        if let Some(s) = &mut self.springs {
            if s.evaluate(self.model, q, &self.u, &mut self.ws) {
                s.add_stiffness(&self.u, k);
            }
        }
        Ok(())
    }
}

/// One output sample of a simulation, lent to the sample callback of [`simulate_streaming`].
#[derive(Debug, Clone, Copy)]
pub struct Sample<'a> {
    pub t: f64,
    pub q: &'a [f64],
    pub qd: &'a [f64],
    /// Tensions `u(t)`: the actuation's, and a displacement-driven tendon's from its stretch at
    /// this `q` ([`drive`]).
    pub u: &'a [f64],
    /// The actuation's channels at `t` as it gave them: `u` for a tension channel, the
    /// displacement \[m\] for a displacement-driven tendon ([`drive`]).
    pub input: &'a [f64],
    /// Tip pose `g(L)`.
    pub tip: &'a Pose,
    /// Strain `ξ` at the computational points.
    pub strain: &'a [V6],
}

/// What a streamed simulation reports besides its samples.
#[derive(Debug)]
pub struct RunSummary {
    /// Samples delivered.
    pub samples: usize,
    /// Time of the last sample delivered (`None` if none was).
    pub t_last: Option<f64>,
    /// The integrator's work, up to the end or to where it stopped.
    pub stats: OdeStats,
    pub wall_time_s: f64,
    /// `Some` if the integration stopped before the last output time: a failure of the method, or
    /// [`OdeError::Stopped`] when the sample callback asked to stop. The samples before it were
    /// delivered.
    pub error: Option<OdeError>,
    /// `Some(ω²)` \[1/s²\] if the run started from an equilibrium
    /// ([`InitialState::Equilibrium`]) that diverges, and no stable one was found: the most
    /// negative real eigenvalue of `M⁻¹ K_T`. The rod leaves such a start at the smallest
    /// disturbance, or rests there only by symmetry and round-off.
    pub start_divergence: Option<f64>,
}

/// Whether [`simulate`] runs the fixed-step method of `options` on `model` in second-order form
/// (with the structured Jacobian): as [`FixedStepOptions::second_order`] asks, except for a
/// nonlinear strain parameterization (a decoder's reduced model), which always runs in the
/// first-order form (see that field: the second-order Newton jumped to a spurious root there).
pub fn fixed_step_in_second_order<P: StrainParam>(
    model: &Model<P>,
    options: &FixedStepOptions,
) -> bool {
    options.second_order && model.param.is_linear()
}

/// Simulates `model` under actuation `actuation(t)` and `loads` scaled by `load_scale(t)` (1 if
/// `None`) from `initial`, sampling at `t_out` (ascending, the first is the start time), and keeps
/// the samples in memory. See [`simulate_streaming`] for runs too long to hold.
pub fn simulate<P: StrainParam>(
    model: &Model<P>,
    actuation: &Signal,
    loads: &Loads,
    load_scale: Option<&Signal>,
    initial: &InitialState,
    t_out: &[f64],
    options: &IntegratorOptions,
) -> Result<Simulation, SimulationError> {
    let mut traj = Trajectory::default();
    let summary = simulate_streaming(
        model,
        actuation,
        loads,
        load_scale,
        initial,
        t_out,
        options,
        &mut |s| {
            traj.t.push(s.t);
            traj.q.push(DVector::from_column_slice(s.q));
            traj.qd.push(DVector::from_column_slice(s.qd));
            traj.u.push(s.u.to_vec());
            traj.tip.push(*s.tip);
            traj.strain.push(s.strain.to_vec());
            ControlFlow::Continue(())
        },
    )?;
    Ok(Simulation {
        trajectory: traj,
        stats: summary.stats,
        wall_time_s: summary.wall_time_s,
        error: summary.error,
    })
}

/// [`simulate`], handing every sample to `sink` instead of keeping it, so memory does not grow with
/// the number of samples. `sink` returning `ControlFlow::Break(reason)` stops the integration after
/// that sample; the summary then reports [`OdeError::Stopped`].
#[allow(clippy::too_many_arguments)]
pub fn simulate_streaming<P: StrainParam>(
    model: &Model<P>,
    actuation: &Signal,
    loads: &Loads,
    load_scale: Option<&Signal>,
    initial: &InitialState,
    t_out: &[f64],
    options: &IntegratorOptions,
    sink: &mut dyn FnMut(&Sample<'_>) -> ControlFlow<String>,
) -> Result<RunSummary, SimulationError> {
    simulate_streaming_interruptible(
        model,
        actuation,
        loads,
        load_scale,
        initial,
        t_out,
        options,
        sink,
        &|| None,
    )
}

/// [`simulate_streaming`] that also polls `stop` before every step attempt of the integrator, so
/// an interrupt stops the run within one step even when the next sample is far away (tight
/// tolerances, a stiff transient); the summary then reports [`OdeError::Stopped`] with `stop`'s
/// reason, and the samples before it were delivered. The actuation is a [`Signal`] or any other
/// [`Actuation`] (a function of time); its channels marked by [`Actuation::displacement_driven`]
/// are tendon displacements ([`drive`]: an elastic tendon's tension follows from its stretch).
#[allow(clippy::too_many_arguments)]
pub fn simulate_streaming_interruptible<P: StrainParam>(
    model: &Model<P>,
    actuation: &dyn Actuation,
    loads: &Loads,
    load_scale: Option<&Signal>,
    initial: &InitialState,
    t_out: &[f64],
    options: &IntegratorOptions,
    sink: &mut dyn FnMut(&Sample<'_>) -> ControlFlow<String>,
    stop: &StopCheck<'_>,
) -> Result<RunSummary, SimulationError> {
    let n = model.n_dof();
    actuation.validate("actuation", model.n_actuators())?;
    if let Some(s) = load_scale {
        s.validate("load_scale", 1)?;
    }
    if t_out.is_empty() {
        return Err(
            ModelError::invalid("sample_times", "at least one sample time is required").into(),
        );
    }
    let mut start_divergence = None;
    let (q0, qd0) = match initial {
        InitialState::Rest => (model.param.rest_coordinates(), DVector::zeros(n)),
        InitialState::Given { q, qd } => {
            if q.len() != n || qd.len() != n {
                return Err(ModelError::invalid(
                    "initial_state",
                    format!(
                        "q has {} and q̇ {} entries; the model has {n} coordinates",
                        q.len(),
                        qd.len()
                    ),
                )
                .into());
            }
            if q.iter().chain(qd.iter()).any(|v| !v.is_finite()) {
                return Err(ModelError::invalid(
                    "initial_state",
                    "contains NaN or infinite values",
                )
                .into());
            }
            (q.clone(), qd.clone())
        }
        InitialState::Equilibrium { u, loads } => {
            let sol = StaticsSolver::new(
                model,
                StaticsOptions {
                    ramp_steps: 2,
                    ..Default::default()
                },
            )
            .solve_interruptible(u, loads, None, stop)?;
            start_divergence = sol.divergence;
            (sol.q, DVector::zeros(n))
        }
    };
    let base_loads = model.prepare_loads(loads)?;
    let mut springs = TendonSprings::new(model, actuation.displacement_driven())?;
    let mut sys = RodOde {
        model,
        ws: model.workspace(),
        actuation,
        load_scale,
        loads: base_loads.clone(),
        base_loads,
        u: vec![0.0; model.n_actuators()],
        lambda: [1.0],
        q: DVector::zeros(n),
        qd: DVector::zeros(n),
        qdd: DVector::zeros(n),
        jacobian: options.jacobian,
        springs: springs.clone(),
        stop,
    };
    let mut y0 = DVector::zeros(2 * n);
    y0.rows_mut(0, n).copy_from(&q0);
    y0.rows_mut(n, n).copy_from(&qd0);
    let t0 = t_out[0];
    let tf = *t_out.last().unwrap();
    let mut breaks = actuation.breakpoints(t0, tf);
    if let Some(s) = load_scale {
        breaks.extend(s.breakpoints(t0, tf));
        breaks.sort_by(|a, b| a.partial_cmp(b).unwrap());
        breaks.dedup();
    }
    let mut out_ws = model.workspace();
    let mut qbuf = DVector::zeros(n);
    let mut ubuf = vec![0.0; model.n_actuators()];
    let mut cbuf = vec![0.0; model.n_actuators()];
    let mut samples = 0;
    let mut t_last = None;
    let mut record = |t: f64, y: &DVector<f64>| {
        // a sampled-data controller reads the state before `u(t)` is read for the sample
        if let Err(reason) = actuation.observe(t, &y.as_slice()[..n], &y.as_slice()[n..]) {
            return ControlFlow::Break(reason);
        }
        qbuf.copy_from(&y.rows(0, n));
        model.forward(&qbuf, &mut out_ws, false);
        actuation.eval(t, &mut cbuf);
        ubuf.copy_from_slice(&cbuf);
        // a driven tendon's sample is its tension, not the displacement asked
        if let Some(s) = &mut springs {
            s.tensions_after_forward(model, &out_ws, &mut ubuf);
        }
        samples += 1;
        t_last = Some(t);
        sink(&Sample {
            t,
            q: &y.as_slice()[..n],
            qd: &y.as_slice()[n..],
            u: &ubuf,
            input: &cbuf,
            tip: out_ws.g.last().unwrap(),
            strain: &out_ws.xi[..model.disc.n_points()],
        })
    };
    let start = Instant::now();
    let result = match &options.method {
        Method::Ndf(o) => match options.jacobian {
            OdeJacobian::Structured => {
                integrate_ndf_second_order(&mut sys, t0, &q0, &qd0, t_out, &breaks, o, &mut record)
            }
            _ => integrate_ndf(&mut sys, t0, &y0, t_out, &breaks, o, &mut record),
        },
        Method::Fixed(o) => match options.jacobian {
            OdeJacobian::Structured if fixed_step_in_second_order(model, o) => {
                integrate_fixed_second_order(
                    &mut sys,
                    t0,
                    &q0,
                    &qd0,
                    t_out,
                    &breaks,
                    o,
                    &mut record,
                )
            }
            _ => integrate_fixed(&mut sys, t0, &y0, t_out, &breaks, o, &mut record),
        },
        Method::GeneralizedAlpha(o) => {
            integrate_generalized_alpha(&mut sys, t0, &q0, &qd0, t_out, &breaks, o, &mut record)
        }
        Method::Sdirk(o) => {
            integrate_sdirk(&mut sys, t0, &q0, &qd0, t_out, &breaks, o, &mut record)
        }
    };
    let wall_time_s = start.elapsed().as_secs_f64();
    let (stats, error) = match result {
        Ok(s) => (s, None),
        Err(e) => (e.stats, Some(e.error)),
    };
    Ok(RunSummary {
        samples,
        t_last,
        stats,
        wall_time_s,
        error,
        start_divergence,
    })
}
