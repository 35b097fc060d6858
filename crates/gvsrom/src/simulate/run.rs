//! Running a plan: the integrator streams samples to a [`SampleSink`] (a trajectory directory or a
//! buffer in memory) and ends complete, failed or interrupted ([`Outcome`]).

use super::energy::{not_conservative, EnergyBalance, EnergyMonitor};
use super::plan::*;
use crate::build::Built;
use crate::error::ScenarioError;
use gvs::inputs::Actuation;
use gvs::lie::Pose;
use gvs::model::Model;
use gvs::solve::dynamics::drive::DisplacementDriven;
use gvs::solve::dynamics::InitialState;
use gvs::solve::dynamics::{
    simulate_streaming_interruptible, IntegratorOptions, RunSummary, Sample, SimulationError,
};
use gvs::solve::ode::OdeError;
use gvs::strain::StrainParam;
use std::ops::ControlFlow;

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Ending {
    /// Every sample up to the requested duration was computed.
    Complete,
    /// Stopped on request after the last sample delivered: an interrupt, or the actuation itself
    /// (a controller that raised, `gvs::inputs::Actuation::observe`), with its reason.
    Interrupted { reason: String },
    /// The run failed (`failure` says why); the samples before the failure were delivered.
    Failed { error: String, failure: Failure },
}

/// Why a run failed: what the meta's `reason` records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Failure {
    /// The integrator gave up (a step below its minimum, Newton's iteration diverged).
    Integration,
    /// A reduced trajectory left its training region, or its displacement drives needed tensions
    /// the model was not trained for.
    LeftTrainingRegion,
    /// The state left the rod's elastic range, or a driven thread pulled beyond the tension that
    /// keeps it there.
    LeftElasticRange,
}

impl Failure {
    /// The sentence recorded as the run's `reason`.
    pub fn reason(self) -> &'static str {
        match self {
            Failure::Integration => "the integration failed",
            Failure::LeftTrainingRegion => "the reduced model left its training region",
            Failure::LeftElasticRange => "the run left the rod's elastic range",
        }
    }
}

/// The result of `run`: the summary of the streamed simulation and the last sample's tip.
#[derive(Debug)]
pub struct Outcome {
    pub summary: RunSummary,
    pub ending: Ending,
    /// Tip pose of the last sample.
    pub last_tip: Option<Pose>,
    /// Tensions \[N\] at the last sample (empty if none was delivered): a displacement-driven
    /// tendon's found from its thread's stretch.
    pub last_u: Vec<f64>,
    /// The run failed because a reduced trajectory left its training region (the decoder would
    /// extrapolate), or its displacement drives needed tensions the model was not trained for,
    /// not because the integrator did.
    pub left_training_region: bool,
    /// The wall time of every timed run \[s\]: this one's, then those of [`Outcome::time_again`].
    pub wall_times_s: Vec<f64>,
    /// How the run used its reduced model outside what the model was made from, found while it
    /// ran: a POD trajectory that left its training encodings, tensions found for displacement
    /// drives outside the training inputs under `--extrapolate` (the first time of each).
    pub model_extrapolated: Vec<String>,
    /// The energy balance over the samples, for a conservative run (no damping, no tendon
    /// friction, no point or distributed loads, no load schedule, constant tensions;
    /// [`not_conservative`]): `None` otherwise.
    pub energy: Option<EnergyBalance>,
}

impl Outcome {
    /// Simulated time per wall-clock time.
    pub fn real_time_factor(&self) -> f64 {
        self.summary.t_last.unwrap_or(0.0) / self.summary.wall_time_s.max(1e-12)
    }

    /// Runs `plan` `extra` more times without a sink, for timing on a shared machine
    /// (`gvsrom simulate --repeat`): each wall time joins [`Outcome::wall_times_s`] and
    /// `summary.wall_time_s` becomes the smallest of them (other load only adds time). The samples
    /// and the ending stay this run's: the same plan gives the same trajectory, complete or failed
    /// alike. `Some(reason)` if a repetition was interrupted (through `control`): the timing ends
    /// there, with the runs before it.
    pub fn time_again(
        &mut self,
        built: &Built,
        plan: &Plan,
        integrator: &IntegratorOptions,
        extra: usize,
        control: &mut dyn FnMut(f64) -> ControlFlow<String>,
    ) -> Result<Option<String>, ScenarioError> {
        let mut stopped = None;
        for _ in 0..extra {
            let again = run_into(built, plan, integrator, None, &mut *control)?;
            if let Ending::Interrupted { reason } = again.ending {
                stopped = Some(reason);
                break;
            }
            self.wall_times_s.push(again.summary.wall_time_s);
        }
        self.summary.wall_time_s = self
            .wall_times_s
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        Ok(stopped)
    }

    /// The median of [`Outcome::wall_times_s`] \[s\].
    pub fn median_wall_time_s(&self) -> f64 {
        let mut t = self.wall_times_s.clone();
        t.sort_by(f64::total_cmp);
        match t.len() {
            0 => self.summary.wall_time_s,
            n if n % 2 == 1 => t[n / 2],
            n => 0.5 * (t[n / 2 - 1] + t[n / 2]),
        }
    }
}

/// Where [`run_into`] delivers the samples: a `TrajectoryWriter` (files) or a
/// `TrajectoryBuffer` (memory).
pub trait SampleSink {
    /// Appends one sample of the run of `built`.
    fn push(&mut self, built: &Built, s: &Sample<'_>) -> std::io::Result<()>;
}

/// Both sinks, the first first (a run kept in memory and written to a directory).
impl<A: SampleSink + ?Sized, B: SampleSink + ?Sized> SampleSink for (&mut A, &mut B) {
    fn push(&mut self, built: &Built, s: &Sample<'_>) -> std::io::Result<()> {
        self.0.push(built, s)?;
        self.1.push(built, s)
    }
}

/// Refuses to start a reduced model's dynamics where its mass matrix `M = Ψ_qᵀ … Ψ_q` is not
/// positive definite: its coordinates degenerate there (a scaled decoder's rest `z₁ = 0` decodes
/// every `z₂` to the straight rod, so `∂ξ/∂z₂ = 0`) and no integrator can take a step. Checked at
/// the rest coordinates or the given state (an initial equilibrium is found by the run itself).
fn check_start_mass<P: StrainParam>(
    model: &Model<P>,
    initial: &InitialState,
) -> Result<(), ScenarioError> {
    let q = match initial {
        InitialState::Rest => model.param.rest_coordinates(),
        InitialState::Given { q, .. } => q.clone(),
        InitialState::Equilibrium { .. } => return Ok(()),
    };
    let mass = model.mass_matrix(&q, &mut model.workspace());
    let scale = mass.amax();
    if scale > 0.0
        && nalgebra::Cholesky::new(mass.clone()).is_some_and(|c| {
            let d = c.l_dirty().diagonal();
            d.min() * d.min() > 1e-12 * scale
        })
    {
        return Ok(());
    }
    let eig = nalgebra::SymmetricEigen::new(mass).eigenvalues;
    Err(ScenarioError::invalid(
        "--model",
        format!(
            "the reduced model's mass matrix is singular at its initial coordinates q_r = {:?} (eigenvalues {:.3e} … {:.3e}): its coordinates degenerate there, as a scaled decoder's do on z₁ = 0, where every z₂ decodes to the straight rod; no step can be taken from there. Simulate with a plain decoder (`gvsrom train --decoder plain`), or start from another state",
            q.as_slice(),
            eig.min(),
            eig.max()
        ),
    ))
}

/// What to tell of a run that started from an equilibrium that diverges (`ω²` = `w2` < 0,
/// [`gvs::solve::dynamics::RunSummary::start_divergence`]).
pub fn unstable_start_note(w2: f64) -> String {
    format!(
        "the equilibrium the run starts from diverges (M⁻¹K_T has the real eigenvalue ω² = {} 1/s² < 0) and no stable one was found: the rod leaves it at the smallest disturbance, or stays only by symmetry and round-off",
        gvs::error::fmt_sci(w2, 3)
    )
}

/// The reason a sample `s` of a run on `built` (points at the abscissae `x`) is no state of an
/// elastic rod ([`crate::plausibility::state_violation`]), with the run's largest load; `None` for
/// a physical one. It ends a simulation and a dynamic dataset alike.
pub fn non_physical_state(built: &Built, x: &[f64], s: &Sample<'_>) -> Option<String> {
    let model = &built.model;
    let v = crate::plausibility::state_violation(
        s.strain,
        x,
        |j| model.xi_star(j),
        model.disc.length(),
    )?;
    Some(format!(
        "the state left the rod's elastic range at t = {:.4} s: {v}{}",
        s.t,
        crate::plausibility::largest_load(built, s.u, 1.0)
            .map(|l| format!("; {l}"))
            .unwrap_or_default()
    ))
}

/// The first displacement-driven tendon whose thread pulls beyond `limits` (per tendon, from
/// [`crate::plausibility::tension_limits`]) at the sample `s` of a run starting at `t0`, as the
/// message that ends the run.
fn thread_beyond_limits(built: &Built, limits: &[f64], t0: f64, s: &Sample<'_>) -> Option<String> {
    let k = (0..limits.len()).find(|&k| {
        built.displacement[k].is_some() && (!s.u[k].is_finite() || s.u[k].abs() > limits[k])
    })?;
    // at the first sample the rod has not moved: the thread takes the motor's whole displacement
    // as stretch, however little the rod would need at rest
    let why = match s.t <= t0 {
        true => "the rod has not moved yet, so the thread's stretch is the motor's whole displacement: wind it in over time (an `--input` ramp) or start `--from-equilibrium` (`gvsrom statics` says whether the rod takes the displacement at rest, and at what tension)",
        false => "the displacement asks more than the rod can take, or winds in faster than the rod follows (`gvsrom statics` gives the tension it needs at rest, or refuses it)",
    };
    Some(format!(
        "tendons[{k}].displacement: at t = {} s its thread pulls {} N, beyond the tension limit |u| = {} N (the rod's elastic range): {why}",
        s.t,
        crate::build::significant(s.u[k]),
        crate::build::significant(limits[k]),
    ))
}

/// `run` with the samples delivered to any [`SampleSink`].
pub fn run_into(
    built: &Built,
    plan: &Plan,
    integrator: &IntegratorOptions,
    mut writer: Option<&mut dyn SampleSink>,
    control: &mut dyn FnMut(f64) -> ControlFlow<String>,
) -> Result<Outcome, ScenarioError> {
    let mut last_tip = None;
    let mut last_u = Vec::with_capacity(built.model.n_actuators());
    let mut write_error: Option<std::io::Error> = None;
    let mut off_manifold = None;
    let mut non_physical = None;
    let mut off_data = None::<String>;
    // a reduced model's tensions found for displacement drives, outside its training
    let mut off_inputs = None::<String>;
    let mut found_outside = Vec::<String>::new();
    let found_tensions_checked = built.displacement_driven().then(|| built.drive_flags());
    let x: Vec<f64> = built.model.disc.points.iter().map(|p| p.x).collect();
    // `control` is called from the sink and from the integrator's per-attempt poll, never nested
    let control = std::cell::RefCell::new(control);
    let interrupted = std::cell::RefCell::new(None::<String>);
    let last_t = std::cell::Cell::new(plan.t_out.first().copied().unwrap_or(0.0));
    let check = |t: f64| {
        let flow = (*control.borrow_mut())(t);
        if let ControlFlow::Break(reason) = &flow {
            *interrupted.borrow_mut() = Some(reason.clone());
        }
        flow
    };
    let stop = || match check(last_t.get()) {
        ControlFlow::Break(reason) => Some(reason),
        ControlFlow::Continue(()) => None,
    };
    let mut energy = not_conservative(built, plan.schedule.is_some())
        .is_none()
        .then(|| match &built.reduced {
            Some(r) => EnergyMonitor::new(&r.model, None),
            // constant displacements keep the threads' springs conservative
            None => EnergyMonitor::new(&built.model, plan.constant_displacements(built)),
        });
    // the tension each displacement-driven tendon may carry: where the rod leaves its elastic
    // range (as the statics drive bounds it)
    let t_start = plan.t_out.first().copied().unwrap_or(0.0);
    let limits = match built.displacement_driven() {
        true => crate::plausibility::tension_limits(built),
        false => vec![],
    };
    let mut sink = |s: &Sample<'_>| {
        // a state no elastic rod holds (a diverged integration, a load the estimate underrated)
        // ends the run before it is written: its samples would be taken for a motion
        if let Some(msg) = non_physical_state(built, &x, s) {
            non_physical = Some(msg.clone());
            return ControlFlow::Break(msg);
        }
        // a displacement whose thread pulls beyond the rod's elastic range: no motion of the rod
        if let Some(msg) = thread_beyond_limits(built, &limits, t_start, s) {
            non_physical = Some(msg.clone());
            return ControlFlow::Break(msg);
        }
        // A reduced model answers for the tensions it was trained on: those the threads of
        // displacement-driven tendons pull with are known only now (checked at each sample,
        // which is not written if they lie outside)
        if let (Some(driven), Some(r)) = (&found_tensions_checked, &built.reduced) {
            if let Some(msg) = found_tensions_off_training(r, driven, s, &mut found_outside) {
                off_inputs = Some(msg.clone());
                return ControlFlow::Break(msg);
            }
        }
        if let Some(e) = energy.as_mut() {
            match &built.reduced {
                Some(r) => e.push(&r.model, &built.loads.gravity, s),
                None => e.push(&built.model, &built.loads.gravity, s),
            }
        }
        last_t.set(s.t);
        last_tip = Some(*s.tip);
        last_u.clear();
        last_u.extend_from_slice(s.u);
        if let Some(w) = writer.as_deref_mut() {
            if let Err(e) = w.push(built, s) {
                let msg = format!("cannot write the trajectory: {e}");
                write_error = Some(e);
                return ControlFlow::Break(msg);
            }
        }
        // A reduced trajectory far outside its training encodings is off the learned manifold
        // (the decoder saturates, `Ψ_q → 0`, `M → 0`): stop there with the reason rather than
        // integrating a spurious motion until Newton fails.
        if let Some(v) = built.reduced.as_ref().and_then(|r| r.range_violation(s.q)) {
            let msg = format!(
                "the reduced trajectory left the training region at t = {:.4} s: {v}; the decoder extrapolates there (an input outside the dataset, or a poor model)",
                s.t
            );
            off_manifold = Some(msg.clone());
            return ControlFlow::Break(msg);
        }
        // A POD basis is linear and defined everywhere: leaving its data is noted, not refused
        if off_data.is_none() {
            off_data = (built.reduced.as_ref().and_then(|r| r.data_range_violation(s.q))).map(|v| {
                format!(
                    "the POD trajectory left the training encodings at t = {:.4} s: {v}; its basis is linear and holds there, but no snapshot checked it",
                    s.t
                )
            });
        }
        check(s.t)
    };
    if let Some(r) = &built.reduced {
        check_start_mass(&r.model, &plan.initial)?;
    }
    // the channels of tendons driven by displacement are their motors' displacements
    let driven = DisplacementDriven::new(plan.actuation(), built.drive_flags());
    let actuation: &dyn Actuation = match built.displacement_driven() {
        true => &driven,
        false => plan.actuation(),
    };
    let summary = match &built.reduced {
        Some(r) => simulate_streaming_interruptible(
            &r.model,
            actuation,
            &built.loads,
            plan.schedule.as_ref(),
            &plan.initial,
            &plan.t_out,
            integrator,
            &mut sink,
            &stop,
        ),
        None => simulate_streaming_interruptible(
            &built.model,
            actuation,
            &built.loads,
            plan.schedule.as_ref(),
            &plan.initial,
            &plan.t_out,
            integrator,
            &mut sink,
            &stop,
        ),
    }
    .map_err(|e| match e {
        SimulationError::Model(m) => ScenarioError::from(m),
        SimulationError::Initial(s) => ScenarioError::invalid(
            "--from-equilibrium",
            format!(
                "the initial equilibrium failed: {s}{}",
                crate::plausibility::largest_load(built, &built.u, 1.0)
                    .map(|l| format!("; {l}"))
                    .unwrap_or_default()
            ),
        ),
    })?;
    if let Some(e) = write_error {
        return Err(ScenarioError::invalid(
            "--out",
            format!(
                "cannot write the trajectory at t = {}: {e}",
                summary.t_last.unwrap_or(0.0)
            ),
        ));
    }
    let left_training_region =
        summary.error.is_some() && (off_manifold.is_some() || off_inputs.is_some());
    let stopped_by = (off_manifold
        .or(off_inputs)
        .map(|e| (e, Failure::LeftTrainingRegion)))
    .or(non_physical.map(|e| (e, Failure::LeftElasticRange)));
    let ending = match (&summary.error, stopped_by, interrupted.into_inner()) {
        (None, _, _) => Ending::Complete,
        (Some(_), Some((error, failure)), _) => Ending::Failed { error, failure },
        (Some(_), None, Some(reason)) => Ending::Interrupted { reason },
        // the actuation stopped the run (a controller's error, `Actuation::observe`): its reason
        (Some(OdeError::Stopped { reason, .. }), None, None) => Ending::Interrupted {
            reason: reason.clone(),
        },
        (Some(e), None, None) => Ending::Failed {
            error: e.to_string(),
            failure: Failure::Integration,
        },
    };
    let energy = energy.and_then(|e| e.finish(summary.samples));
    Ok(Outcome {
        energy,
        wall_times_s: vec![summary.wall_time_s],
        summary,
        ending,
        last_tip,
        last_u,
        left_training_region,
        model_extrapolated: off_data.into_iter().chain(found_outside).collect(),
    })
}

/// The tensions of sample `s` of a reduced model's run with the tendons `driven` by
/// displacement, found from their threads' stretch, against the model's training
/// (`Reduced::found_tensions_outside`): outside it, the message that ends the run, or, with
/// `--extrapolate`, `None` with the sentence kept in `noted` — the first sample of each way of
/// lying outside (a tendon's range, the inputs together).
fn found_tensions_off_training(
    r: &crate::build::reduced::Reduced,
    driven: &[bool],
    s: &Sample<'_>,
    noted: &mut Vec<String>,
) -> Option<String> {
    let outside = r.found_tensions_outside(s.u, driven);
    if outside.is_empty() {
        return None;
    }
    let at = format!(
        "at t = {:.4} s the tensions found from the threads of the tendons driven by displacement lie outside the model's training: ",
        s.t
    );
    if r.extrapolate {
        for why in outside {
            // one sentence per way: `tendons.k.tension = …`, or the inputs together
            let kind = match why.starts_with("tendons.") {
                true => why.split(" = ").next().unwrap_or(&why).to_string(),
                false => "the inputs together".to_string(),
            };
            if !noted.iter().any(|n| n.contains(&format!(": {kind}"))) {
                noted.push(format!("{at}{why}"));
            }
        }
        return None;
    }
    Some(format!(
        "{at}{}; `{}` answers only inside its training (wind the displacement in more slowly, start --from-equilibrium, or pass --extrapolate to use it anyway, its answer then marked an extrapolation)",
        outside.join("; "),
        r.path.display()
    ))
}
