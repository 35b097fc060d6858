//! A run's [`Plan`]: everything checked, and the sample times and signal built, before anything is
//! computed.

use super::integrator::{choose_integrator, integrator_record, IntegratorChoice};
use super::options::*;
use crate::build::Built;
use crate::error::ScenarioError;
use gvs::feedback::SampledFeedback;
use gvs::inputs::{Actuation, Interpolation, Signal};
use gvs::solve::dynamics::{InitialState, Method};
use nalgebra::DVector;
use std::path::PathBuf;
use std::sync::Arc;

/// Most output samples of one run.
pub const MAX_SAMPLES: usize = 10_000_000;

/// Most steps of one fixed-step run (`--duration / --fixed-step`).
pub const MAX_FIXED_STEPS: f64 = 1e7;

/// Most input switches of a random-step or babbling signal (`--duration / period`).
pub const MAX_INPUT_SWITCHES: f64 = 1e7;

/// Shortest run \[s\]: a microsecond, below every time scale of a soft arm's motion that matters;
/// at 1e-300 s the run took no step and wrote the start alone.
pub const MIN_DURATION: f64 = 1e-6;

/// The output times `t_k = k / rate` for `t_k ≤ duration`, followed by `duration` itself when it is
/// not a multiple of the sample period, so the last sample is always at `duration`.
pub fn sample_times(duration: f64, rate: f64) -> Result<Vec<f64>, ScenarioError> {
    positive("--duration", duration, "s")?;
    if duration < MIN_DURATION {
        return Err(ScenarioError::value(
            "--duration",
            duration,
            format!("at least {MIN_DURATION:e} s (a microsecond)"),
        ));
    }
    positive("--sample-rate", rate, "Hz")?;
    let periods = (duration * rate * (1.0 + 4.0 * f64::EPSILON)).floor();
    if !periods.is_finite() || periods >= (MAX_SAMPLES - 1) as f64 {
        return Err(ScenarioError::invalid(
            "--duration",
            format!(
                "{} s at --sample-rate {} Hz gives {} samples (accepted <= {MAX_SAMPLES}); lower --duration or --sample-rate",
                gvs::error::fmt_value(duration),
                gvs::error::fmt_value(rate),
                // the count itself: a rounded 1.00e7 would read as the limit
                match periods < 1e15 {
                    true => format!("{}", periods + 1.0),
                    false => format!("{:.3e}", periods + 1.0),
                }
            ),
        ));
    }
    let m = periods as usize;
    let mut t: Vec<f64> = (0..=m).map(|k| k as f64 / rate).collect();
    let last = t[m];
    if last > duration {
        t[m] = duration; // rounding put k/rate a hair past the end
    } else if duration - last > 1e-9 * duration.max(1.0) / rate.max(1.0) {
        t.push(duration);
    }
    Ok(t)
}

/// The control instants of a sampled-data controller running at `control_rate` in a run sampled
/// at `sample_rate` for `duration` ([`sample_times`]): every `m`-th sample from the start,
/// `m = sample_rate / control_rate`, which must be a whole number (within 1e-9), so that every
/// instant is a sample at which the controller reads the state
/// ([`gvs::feedback::SampledFeedback`]). The last sample is an instant only if it falls on the
/// control period.
pub fn control_instants(
    duration: f64,
    sample_rate: f64,
    control_rate: f64,
) -> Result<Vec<f64>, ScenarioError> {
    let t = sample_times(duration, sample_rate)?;
    positive("--control-rate", control_rate, "Hz")?;
    let ratio = sample_rate / control_rate;
    let m = ratio.round();
    if !(m >= 1.0 && (ratio - m).abs() <= 1e-9 * ratio) {
        return Err(ScenarioError::value(
            "--control-rate",
            control_rate,
            format!(
                "a whole fraction of --sample-rate {} Hz ({} Hz, {} Hz, …): the controller reads the state at output samples",
                gvs::error::fmt_value(sample_rate),
                gvs::error::fmt_value(sample_rate),
                gvs::error::fmt_value(sample_rate / 2.0),
            ),
        ));
    }
    let m = m as usize;
    // the samples on the grid k / rate (a last sample at `duration` off it is not an instant)
    let on_grid = (duration * sample_rate * (1.0 + 4.0 * f64::EPSILON)).floor() as usize + 1;
    Ok(t.iter().take(on_grid).step_by(m).copied().collect())
}

/// A run checked before anything is computed or written: its sample times, actuation, load schedule
/// and initial state. Inputs whose loads or tensions lie far beyond the rod's elastic range are
/// refused here (see [`crate::plausibility`]).
pub struct Plan {
    pub t_out: Vec<f64>,
    pub signal: Signal,
    pub schedule: Option<Signal>,
    pub initial: InitialState,
    /// Output samples per second.
    pub sample_rate: f64,
    /// What `meta.json` records of the run's input ([`input_record`]).
    pub input: serde_json::Value,
    /// How the input signal lies outside a reduced model's training inputs, when used with
    /// `--extrapolate` (`Reduced::check_signal`; without it such a signal is refused).
    pub model_extrapolated: Vec<String>,
    /// A function input, which the run evaluates in place of `signal`.
    pub function: Option<InputFunction>,
    /// `Some(ω²)` \[1/s²\] < 0 when the run starts from an equilibrium (`--from-equilibrium`)
    /// that diverges, no stable one having been found ([`super::unstable_start_note`]).
    pub start_divergence: Option<f64>,
}

impl Plan {
    /// The actuation the integrator evaluates: the function input, else the signal.
    pub fn actuation(&self) -> &dyn Actuation {
        match &self.function {
            Some(f) => f.0.as_ref(),
            None => &self.signal,
        }
    }
}

impl Plan {
    /// The threads of the tendons driven by displacement, when every such displacement is
    /// constant over the run (an input signal, not a function): their springs then store energy
    /// and do no work, and the run's energy balance holds with them
    /// ([`super::energy::ThreadSprings`]).
    pub fn constant_displacements(&self, built: &Built) -> Option<super::energy::ThreadSprings> {
        if !built.displacement_driven() || self.function.is_some() {
            return None;
        }
        let first = self.signal.values.first()?;
        let driven = built.drive_flags();
        let constant = self
            .signal
            .values
            .iter()
            .all(|row| (row.iter().zip(first).zip(&driven)).all(|((a, b), &d)| !d || a == b));
        constant.then(|| super::energy::ThreadSprings::new(&built.model, &driven, first))
    }
}

/// A linear input signal is checked against a model's training inputs at this many points per
/// segment between knots (the knots included).
const SEGMENT_CHECKS: usize = 16;
/// At most this many points of an input signal are checked in all.
const MAX_SIGNAL_CHECKS: usize = 100_000;

/// Validates `opts` against `built` and builds the [`Plan`] of the run.
pub fn plan(built: &Built, opts: &SimulateOptions) -> Result<Plan, ScenarioError> {
    check_drives(built, opts)?;
    let t_out = sample_times(opts.duration, opts.sample_rate)?;
    // a controller's instants are output samples (checked before anything is computed)
    let function = match &opts.input {
        InputSource::Function(f) => Some(f.clone()),
        InputSource::Feedback { law, control_rate } => {
            let rate = control_rate.unwrap_or(opts.sample_rate);
            let instants = control_instants(opts.duration, opts.sample_rate, rate)?;
            let na = built.model.n_actuators();
            Some(InputFunction(Arc::new(SampledFeedback::new(
                law.0.clone(),
                instants,
                na,
            ))))
        }
        _ => None,
    };
    if let Method::Fixed(f) = &opts.integrator.method {
        let h = positive("--fixed-step", f.h, "s")?;
        if h > opts.duration {
            return Err(ScenarioError::invalid(
                "--fixed-step",
                format!(
                    "{} s is longer than the run itself (--duration {} s), which would then be one step of its duration, not of the step given; use a step ≤ the duration",
                    gvs::error::fmt_value(h),
                    gvs::error::fmt_value(opts.duration)
                ),
            ));
        }
        if opts.duration / h > MAX_FIXED_STEPS {
            return Err(ScenarioError::invalid(
                "--fixed-step",
                format!(
                    "{} s over --duration {} s is {:.2e} steps (accepted <= {}); use a larger step or the adaptive integrator",
                    gvs::error::fmt_value(h),
                    gvs::error::fmt_value(opts.duration),
                    opts.duration / h,
                    gvs::error::fmt_value(MAX_FIXED_STEPS)
                ),
            ));
        }
    }
    let switch_period = match &opts.input {
        InputSource::Steps { period, .. } => Some(("--steps period", *period)),
        InputSource::Babble { hold_min, .. } => Some(("--babble hold_min", *hold_min)),
        _ => None,
    };
    if let Some((field, p)) = switch_period {
        let p = positive(field, p, "s")?;
        if opts.duration / p > MAX_INPUT_SWITCHES {
            return Err(ScenarioError::invalid(
                field,
                format!(
                    "{} s over --duration {} s is {:.2e} input switches (accepted <= {})",
                    gvs::error::fmt_value(p),
                    gvs::error::fmt_value(opts.duration),
                    opts.duration / p,
                    gvs::error::fmt_value(MAX_INPUT_SWITCHES)
                ),
            ));
        }
    }
    let signal = input_signal(built, opts)?;
    // a reduced model answers only for tensions it was trained on: the signal's, at its knots
    // (where a held or linear signal takes its extremes) and at both ends of the run
    let mut model_extrapolated = match (&built.reduced, &opts.input) {
        (Some(r), input)
            if !matches!(
                input,
                InputSource::Constant | InputSource::Function(_) | InputSource::Feedback { .. }
            ) =>
        {
            let end = t_out.last().copied().unwrap_or(0.0);
            let mut times: Vec<f64> = signal
                .times
                .iter()
                .copied()
                .filter(|t| (0.0..=end).contains(t))
                .chain([0.0, end])
                .collect();
            times.sort_by(f64::total_cmp);
            // a linear signal between two knots passes combinations neither knot is: the joint
            // check is not convex, so each segment is checked at interior points too, and just
            // before each knot (a time given twice is a step: `eval` at it gives the value after,
            // the integrator runs up to the value before)
            if signal.interpolation == gvs::inputs::Interpolation::Linear && times.len() > 1 {
                let per = (MAX_SIGNAL_CHECKS / times.len()).clamp(1, SEGMENT_CHECKS);
                let knots = times.clone();
                for w in knots.windows(2) {
                    times.extend((1..per).map(|i| w[0] + (w[1] - w[0]) * i as f64 / per as f64));
                }
                times.extend(knots.iter().filter(|t| **t > 0.0).map(|t| t.next_down()));
                times.sort_by(f64::total_cmp);
            }
            let mut u = vec![0.0; signal.channels()];
            // a displacement channel's tensions are checked as the run finds them
            r.check_signal(&times, &built.drive_flags(), |t| {
                // just before a knot: the knot's own value, the left limit of a linear signal
                let k = signal.times.partition_point(|&tk| tk < t.next_up());
                match signal.times.get(k) {
                    Some(&tk) if tk == t.next_up() => u.copy_from_slice(&signal.values[k]),
                    _ => signal.eval(t, &mut u),
                }
                u.clone()
            })?
        }
        _ => vec![],
    };
    let schedule = match &opts.load_schedule {
        Some(path) => {
            crate::scenario::check_regular_file("--load-schedule", path)?;
            let s = crate::csv_input::read_csv_signal(
                "--load-schedule",
                path,
                1,
                Interpolation::Linear,
            )?;
            covers_start("--load-schedule", path, &s, t_out[0])?;
            Some(s)
        }
        None => None,
    };
    // a reduced model answers only for the loads it was trained under: λ = 1 throughout
    if let (Some(r), Some(s)) = (&built.reduced, &schedule) {
        let scales_something = built.loads != built.loads.scaled(0.0);
        let end = t_out.last().copied().unwrap_or(0.0);
        let off = s
            .times
            .iter()
            .zip(&s.values)
            .filter(|(t, _)| **t <= end)
            .map(|(t, v)| (*t, v[0]))
            .filter(|(_, v)| v.is_nan() || (v - 1.0).abs() > 1e-12)
            .max_by(|a, b| (a.1 - 1.0).abs().total_cmp(&(b.1 - 1.0).abs()));
        if let (true, Some((t, v))) = (scales_something, off) {
            let sentence = format!(
                "the load schedule scales the loads and gravity by λ = {v} at t = {t} s, but training held them at λ = 1"
            );
            if !r.extrapolate {
                return Err(ScenarioError::invalid(
                    "--model",
                    format!(
                        "`{}` was not trained for this input: {sentence}; pass --extrapolate to use it anyway (its answer is then an extrapolation, and is marked so)",
                        r.path.display()
                    ),
                ));
            }
            model_extrapolated.push(sentence);
        }
    }
    check_displacements(built, opts, &signal)?;
    // a displacement channel is no tension: its tension is found as the run goes
    let mut u_max = crate::csv_input::max_abs_per_column(&signal);
    for (u, d) in u_max.iter_mut().zip(&built.displacement) {
        if d.is_some() {
            *u = 0.0;
        }
    }
    let lambda_max = schedule
        .as_ref()
        .map(|s| crate::csv_input::max_abs_per_column(s)[0])
        .unwrap_or(1.0);
    crate::plausibility::check(built, &u_max, lambda_max).map_err(|e| {
        // a signal's tensions: name the signal and when it reaches the largest of them (the
        // scenario's `tendons[k].tension` was not what was given)
        let option = match &opts.input {
            InputSource::Csv { .. } => "--input",
            InputSource::Steps { .. } => "--steps",
            InputSource::Babble { .. } => "--babble",
            InputSource::Rows(_) => "input",
            InputSource::Constant | InputSource::Function(_) | InputSource::Feedback { .. } => {
                return e
            }
        };
        let largest = (signal.times.iter().zip(&signal.values))
            .flat_map(|(t, v)| v.iter().enumerate().map(move |(k, u)| (*t, k, *u)))
            // a displacement channel holds metres, not a tension
            .filter(|(_, k, _)| built.displacement.get(*k).is_none_or(Option::is_none))
            // the first time it is reached
            .fold(None::<(f64, usize, f64)>, |best, x| match best {
                Some(b) if b.2.abs() >= x.2.abs() => Some(b),
                _ => Some(x),
            });
        let at = match largest {
            Some((t, k, u)) => format!(
                " reaches u[{k}] = {} N at t = {t} s:",
                gvs::error::fmt_value(u)
            ),
            None => ":".into(),
        };
        let what = opts.input.describe().unwrap_or_default();
        ScenarioError::invalid(option, format!("{what}{at} {e}"))
    })?;
    // the tensions at a driven equilibrium start: those the displacements need
    let mut start_tensions = None;
    let mut start_divergence = None;
    let initial = match &opts.start {
        Start::Rest => InitialState::Rest,
        // the equilibrium `gvsrom statics` finds under the scenario's tensions and loads (with a
        // reduced model: from its anchors, and checked against its training encodings), not the
        // engine's ramp from rest, which a decoder can lead to a spurious root
        Start::Equilibrium => {
            // under the scenario's drives: where a tendon is driven by its displacement, the
            // equilibrium of its elastic thread at that displacement (the run's own rest)
            let report = crate::statics::solve_as_built(built).map_err(|e| {
                ScenarioError::invalid(
                    "--from-equilibrium",
                    format!("the start, the static equilibrium under the scenario's tensions and loads, failed: {e:#}"),
                )
            })?;
            if built.displacement_driven() {
                start_tensions = Some(report.u.clone());
            }
            start_divergence = report.divergence;
            InitialState::Given {
                q: DVector::from_vec(report.q),
                qd: DVector::zeros(built.n_dof()),
            }
        }
        Start::State { q, qd } => initial_state(built, q, qd)?,
    };
    let mut input = input_record(built, opts)?;
    if let Some(u) = start_tensions {
        input["start_tensions"] = serde_json::json!(u);
    }
    Ok(Plan {
        t_out,
        signal,
        schedule,
        initial,
        sample_rate: opts.sample_rate,
        input,
        model_extrapolated,
        function,
        start_divergence,
    })
}

/// A run with tendons driven by their displacement (`tendons[k].displacement`; the law in
/// `gvs::solve::dynamics::drive`): each such tendon needs its thread's axial stiffness (an
/// inextensible one is a constraint the integrators do not impose), and its input channel is a
/// displacement, which random tension steps and babbling are not. A reduced model runs it as the
/// full model does, the tensions its threads pull with checked against its training as the run
/// finds them (`Reduced::found_tensions_outside` at every sample).
fn check_drives(built: &Built, opts: &SimulateOptions) -> Result<(), ScenarioError> {
    let Some(first) = built.displacement.iter().position(Option::is_some) else {
        return Ok(());
    };
    built.require_threads("a motion")?;
    match &opts.input {
        InputSource::Steps { .. } | InputSource::Babble { .. } => {
            let option = match &opts.input {
                InputSource::Steps { .. } => "--steps",
                _ => "--babble",
            };
            Err(ScenarioError::invalid(
                option,
                format!(
                    "random tension steps drive every tendon by its tension, but tendons[{first}] is driven by its displacement; give the displacements over time as --input (a CSV whose column k is tendon k's displacement in m, or its tension in N for a tendon driven by tension)"
                ),
            ))
        }
        _ => Ok(()),
    }
}

/// The displacements of a signal's driven channels at its knots: finite, and shorter than the
/// tendon (a motor cannot wind a tendon in by its whole length, nor pay out as much).
fn check_displacements(
    built: &Built,
    opts: &SimulateOptions,
    signal: &Signal,
) -> Result<(), ScenarioError> {
    let function = matches!(
        opts.input,
        InputSource::Function(_) | InputSource::Feedback { .. }
    );
    if !built.displacement_driven() || function {
        return Ok(());
    }
    let option = match &opts.input {
        InputSource::Csv { .. } => "--input",
        InputSource::Rows(_) => "input",
        _ => "displacement",
    };
    for (t, row) in signal.times.iter().zip(&signal.values) {
        check_channel_displacements(built, row, &|k| match option {
            "displacement" => format!("tendons[{k}].displacement"),
            o => format!("{o} (tendon {k}'s displacement at t = {t} s)"),
        })?;
    }
    Ok(())
}

/// The displacement channels of one row of actuation channels (`row[k]` for each tendon driven
/// by its displacement, `built.displacement[k]` set): finite, and shorter than the tendon; the
/// error names the channel by `field(k)`.
pub fn check_channel_displacements(
    built: &Built,
    row: &[f64],
    field: &dyn Fn(usize) -> String,
) -> Result<(), ScenarioError> {
    if !built.displacement_driven() {
        return Ok(());
    }
    let rest = built.model.tendon_rest_lengths();
    for (k, (&v, d)) in row.iter().zip(&built.displacement).enumerate() {
        if d.is_some() && !(v.is_finite() && v.abs() < rest[k]) {
            return Err(ScenarioError::value(
                field(k),
                v,
                format!(
                    "a displacement in m of magnitude below {:.6} m, the tendon's rest length",
                    rest[k]
                ),
            ));
        }
    }
    Ok(())
}

/// The given start `(q, q̇)` of a run ([`Start::State`]) as the integrator's initial state: `n`
/// finite values each, `n` the degrees of freedom of the model that runs; for an autoencoder model,
/// `q` inside its training encodings ([`crate::build::Reduced::range_violation`]), where its decoder
/// answers (a POD basis is linear: its range is not bounded); and a state of an elastic rod
/// ([`crate::plausibility::coordinates_violation`], the bounds that end a run at a sample).
fn initial_state(built: &Built, q: &[f64], qd: &[f64]) -> Result<InitialState, ScenarioError> {
    let n = built.n_dof();
    for (field, v) in [("q0", q), ("qd0", qd)] {
        if v.len() != n {
            return Err(ScenarioError::invalid(
                field,
                format!(
                    "{} values given: expected {n}, one per degree of freedom of the model that runs{}",
                    v.len(),
                    if built.reduced.is_some() { " (the reduced model's coordinates)" } else { "" }
                ),
            ));
        }
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            return Err(ScenarioError::value(
                format!("{field}[{k}]"),
                v[k],
                "a finite number",
            ));
        }
    }
    if let Some(v) = built.reduced.as_ref().and_then(|r| r.range_violation(q)) {
        return Err(ScenarioError::invalid(
            "q0",
            format!("{v}: the decoder extrapolates there; start inside the training region"),
        ));
    }
    if let Some(v) = crate::plausibility::coordinates_violation(built, q) {
        return Err(ScenarioError::invalid(
            "q0",
            format!("no state of an elastic rod: {v}; start within the bounds that end a run"),
        ));
    }
    Ok(InitialState::Given {
        q: DVector::from_column_slice(q),
        qd: DVector::from_column_slice(qd),
    })
}

/// A dynamics run as a front-end asks for it (the options of `gvsrom simulate`).
#[derive(Debug, Clone)]
pub struct Request {
    /// Simulated time \[s\].
    pub duration: f64,
    /// Output samples per second \[Hz\].
    pub sample_rate: f64,
    pub input: InputSource,
    /// Where the run starts ([`Start`]).
    pub start: Start,
    /// A CSV load schedule (`--load-schedule`).
    pub load_schedule: Option<PathBuf>,
    /// The integrator asked for (`--method`, tolerances …).
    pub integrator: IntegratorChoice,
}

/// A run ready to go: its options with the integrator chosen ([`choose_integrator`]), its
/// [`Plan`], and the note to print when the rod's damping chose the method.
pub struct Prepared {
    pub opts: SimulateOptions,
    pub plan: Plan,
    pub note: Option<String>,
}

impl Prepared {
    /// The run's record in `meta.json`'s provenance: the input, the sampling and the integrator.
    pub fn record(
        &self,
        provenance: crate::provenance::Provenance,
        choice: &IntegratorChoice,
    ) -> crate::provenance::Provenance {
        provenance
            .input(self.plan.input.clone())
            .sampling(self.opts.duration, self.opts.sample_rate)
            .integrator(integrator_record(&self.opts.integrator, choice))
    }
}

/// Chooses the integrator of `request` for `built` and plans the run ([`plan`]): everything is
/// checked before anything is computed. What `gvsrom simulate` and Python's `Robot.simulate` do.
pub fn prepare(built: &Built, request: Request) -> Result<Prepared, ScenarioError> {
    let (integrator, note) = choose_integrator(built, &request.integrator)?;
    let opts = SimulateOptions {
        duration: request.duration,
        sample_rate: request.sample_rate,
        input: request.input,
        start: request.start,
        integrator,
        load_schedule: request.load_schedule,
    };
    let plan = plan(built, &opts)?;
    Ok(Prepared { opts, plan, note })
}
