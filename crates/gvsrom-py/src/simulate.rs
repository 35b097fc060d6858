//! `Robot.simulate`: a dynamics run as `gvsrom simulate` plans and runs it, its samples kept in
//! memory and returned as NumPy arrays; Ctrl-C interrupts it within one integrator step. The input
//! is the scenario's tensions, rows `t, u_1, …` or a Python callable `u(t)` ([`CallableInput`]).

use crate::arrays::{self, shaped, vector};
use crate::callable::Kind;
use crate::errors::{invalid, scenario as err};
use crate::robot::{warn, Robot};
use crate::simulate_args::{start, Args, Drive};
use gvsrom::simulate::{self, Ending, SampleSink, TrajectoryBuffer, TrajectoryWriter};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::ops::ControlFlow;

#[pymethods]
impl Robot {
    /// Simulates the dynamics as ``gvsrom simulate`` does (stiff adaptive integrator), keeping the
    /// samples in memory. Ctrl-C interrupts it (``KeyboardInterrupt``).
    ///
    /// Parameters
    /// ----------
    /// duration : float
    ///     Simulated time [s].
    /// sample_rate : float
    ///     Output samples per second [Hz].
    /// input : array_like of float, shape (k, 1 + n_actuators), or callable, optional
    ///     Rows ``t, u_1, …, u_na`` (times ascending from 0), held piecewise constant (each
    ///     time once) or linear with ``interpolate`` (a time given twice is a step); or a callable ``u(t) -> array of n_actuators tensions`` (or one
    ///     number for all), called by the integrator at every time it evaluates (in any order: a
    ///     rejected step goes back in time); an exception it raises stops the run and propagates.
    ///     Its values are checked as rows are: finite, and within the rod's elastic range (a
    ///     tension far beyond it stops the run after the step it was returned in, naming it).
    ///     Default: the scenario's tensions, constant. A tendon the scenario drives by its
    ///     ``displacement`` (with the thread's ``axial_stiffness``) takes its displacement [m]
    ///     in its column instead, and its tension follows from the thread's stretch.
    /// interpolate : bool
    ///     Interpolate ``input`` rows linearly.
    /// from_equilibrium : bool
    ///     Start at the static equilibrium under the scenario's tensions and displacements (else
    ///     straight at rest).
    /// q0, qd0 : array_like of float, shape (n,), optional
    ///     Start at this state instead (``qd0`` zeros if not given): the coordinates of the model
    ///     that runs (the reduced model's with one attached; an autoencoder's inside its training
    ///     encodings), e.g. ``tr["q"][-1], tr["qd"][-1]`` of an earlier run, to continue it under
    ///     another input — a controller's loop, one control period per call with the tensions held.
    /// method : str
    ///     ``"auto"``, ``"ndf"``, ``"sdirk"`` or ``"galpha"`` (``--method``).
    /// rtol, atol : float, optional
    ///     Tolerances of the adaptive integrator (default rtol: chosen by ``method``; atol 1e-6);
    ///     refused with ``fixed_step``, which controls no error.
    /// fixed_step : float, optional
    ///     A fixed step [s]: the fixed-step BDF2 (``--fixed-step``) instead of an adaptive method;
    ///     its cost is set by the number of steps, its accuracy by the step (not checked).
    /// load_schedule : str or os.PathLike, optional
    ///     A CSV file of rows ``t, λ`` scaling every external load and gravity over time (linear
    ///     between rows; ``--load-schedule``), e.g. a release: ``from_equilibrium=True`` with
    ///     ``0,0``.
    /// steps : sequence of 3 floats, optional
    ///     ``(lo, hi, period)``: new uniform random tensions in ``[lo, hi]`` [N] on every tendon
    ///     every ``period`` seconds (``--steps``; the paper's IV-C2 test input).
    /// babble : sequence of 4 floats, optional
    ///     ``(lo, hi, hold_min, hold_max)``: each tendon holds a uniform random tension in
    ///     ``[lo, hi]`` for a uniform random time in ``[hold_min, hold_max]`` (``--babble``).
    /// seed : int
    ///     Seed of ``steps`` and ``babble`` (same seed, same signal as the command line's; 1 by
    ///     default, as ``gvsrom simulate --seed``).
    /// max_order : int, optional
    ///     Highest order of the NDF, 1–5 (``--max-order``; default 5, or 2 for a lightly damped
    ///     rod).
    /// error_norm : str, optional
    ///     The adaptive methods' error test (``--error-norm``): ``"componentwise"`` (ode15s) or
    ///     ``"mass"`` (positions and velocities in the norm of the mass matrix); default chosen
    ///     by the method and the rod's damping.
    /// rho_inf : float, optional
    ///     Generalized-α's spectral radius at infinite frequency in [0, 1] (``--rho-inf``; default
    ///     0.8; only with ``method="galpha"``).
    /// fd_jacobian : bool
    ///     Finite differences of the right-hand side for the integrator's Jacobian instead of the
    ///     structured analytic one (``--fd-jacobian``; the NDF and the fixed step).
    /// controller : callable, optional
    ///     A sampled-data controller ``controller(t, q, qd) -> tensions`` (a displacement [m] for a
    ///     tendon the scenario drives by its displacement): called at ``t = 0`` and
    ///     every ``1 / control_rate`` seconds with the state there (``q``, ``qd``: the coordinates
    ///     of the model that runs, new arrays), its tensions held until the next call (a
    ///     zero-order hold, as a digital controller drives a robot). The closed loop is one
    ///     integration: the integrator restarts at each call as at a step of held rows, and keeps
    ///     what a restart need not renew (the fixed step's Jacobian). Its values are checked as ``input``'s
    ///     are; an exception it raises stops the run and propagates, with the samples computed
    ///     before as its ``trajectory`` attribute. The tip from ``q``:
    ///     ``robot.forward(q)["position"][-1]``. When the last sample falls
    ///     on a control instant the controller is called there too (its value is the sample's
    ///     ``u`` but drives no step). Instead of ``input``, ``steps`` and ``babble``.
    /// control_rate : float, optional
    ///     The controller's calls per second [Hz]: ``sample_rate`` (default) or a whole fraction
    ///     of it, so that every call is at an output sample.
    /// out : str or os.PathLike, optional
    ///     Also write the trajectory to this new directory, the files ``gvsrom simulate --out``
    ///     writes (``t.npy``, ``q.npy``, …, ``meta.json`` with how the run was made), for
    ///     :func:`plot`, ``gvsrom compare`` or a later session; a run that ended early is written
    ///     too, marked incomplete. An existing path is refused unless it is an earlier gvsrom
    ///     output and ``force`` is given.
    /// force : bool
    ///     Replace an earlier gvsrom output at ``out``.
    ///
    /// Returns
    /// -------
    /// dict
    ///     ``t`` (k,), ``q``/``qd`` (k, n), ``u`` (k, n_a: the tensions, a displacement-driven
    ///     tendon's found from its thread's stretch), ``tip_position`` (k, 3),
    ///     ``tip_rotation`` (k, 3, 3), ``strain`` (k, p, 6), ``strain_x`` (p,),
    ///     ``strain_reference`` (p, 6: the stress-free strain ξ*), ``centerline``
    ///     (k, c, 3), ``centerline_x`` (c,), ``tendon_paths`` (k, n_a, c, 3: each tendon's thread
    ///     at ``centerline_x`` clamped to its span), ``tendon_lengths`` (k, n_a: each tendon's
    ///     length [m] along its thread; at rest :attr:`Robot.tendon_rest_lengths`), with a tendon
    ///     driven by its displacement ``displacement`` (k, n_a: the displacements [m] its motor
    ///     was commanded, NaN for a tendon driven by its tension),
    ///     ``body_positions`` (k, n_b, 2, 3: each rigid body's section and centre of mass), ``steps``,
    ///     ``failed_steps``, ``wall_time_s``, and
    ///     ``model_extrapolated`` (list of str): how the reduced model was used outside what it
    ///     was trained on (``extrapolate=True``; the scenario, a signal's tensions, the values a
    ///     callable ``input`` returned), empty otherwise; for a conservative run (no damping,
    ///     tendon friction, loads or schedule; constant tensions) ``energy_balance``, a dict of
    ///     ``initial``, ``last``, ``largest_gain``, ``largest_loss``, ``kinetic_max`` [J] of
    ///     ``T + U_e + U_g − Σ u ℓ`` over the samples (a thread held at a constant displacement
    ///     counts its ``½ (ℓ − ℓ*)² / c`` in place of ``−u ℓ``), with a ``UserWarning`` when it rose by more
    ///     than 1 % of the largest kinetic energy (the integration added energy); with ``out``,
    ///     ``out``: the directory written. Started ``from_equilibrium`` at an equilibrium that
    ///     diverges (no stable one found), the run warns (``UserWarning``) and the dict holds its
    ///     ``start_divergence``, the eigenvalue ω² < 0 [1/s²].
    ///
    /// Raises
    /// ------
    /// IntegrationError
    ///     When the integrator failed (a reduced model that left its training region, a step
    ///     that could not converge), or a callable ``input`` or ``controller`` returned a value
    ///     refused after the run began: its ``trajectory`` attribute is the dict above for the
    ///     samples computed before (``energy_balance`` left out). An exception the callable
    ///     raised propagates as it is, with that dict as its ``trajectory`` attribute, and so
    ///     does ``KeyboardInterrupt`` (Ctrl-C).
    /// GvsromError
    ///     For bad options or input.
    #[pyo3(signature = (duration, sample_rate=100.0, input=None, interpolate=false, from_equilibrium=false, q0=None, qd0=None, method="auto", rtol=None, atol=None, fixed_step=None, load_schedule=None, steps=None, babble=None, seed=1, max_order=None, error_norm=None, rho_inf=None, fd_jacobian=false, controller=None, control_rate=None, out=None, force=false))]
    #[allow(clippy::too_many_arguments)]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = arrays::real)] duration: f64,
        #[pyo3(from_py_with = arrays::real)] sample_rate: f64,
        input: Option<Bound<'_, PyAny>>,
        interpolate: bool,
        from_equilibrium: bool,
        q0: Option<arrays::In1<'_>>,
        qd0: Option<arrays::In1<'_>>,
        method: &str,
        rtol: Option<f64>,
        atol: Option<f64>,
        fixed_step: Option<f64>,
        load_schedule: Option<std::path::PathBuf>,
        steps: Option<Vec<f64>>,
        babble: Option<Vec<f64>>,
        #[pyo3(from_py_with = crate::arrays::whole)] seed: i128,
        #[pyo3(from_py_with = crate::arrays::whole_or_none)] max_order: Option<i128>,
        error_norm: Option<&str>,
        rho_inf: Option<f64>,
        fd_jacobian: bool,
        controller: Option<Bound<'_, PyAny>>,
        control_rate: Option<f64>,
        out: Option<std::path::PathBuf>,
        force: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let seed = arrays::unsigned("seed", seed)?;
        let max_order = max_order
            .map(|v| arrays::size("max_order", v, 1))
            .transpose()?;
        let args = Args {
            duration,
            sample_rate,
            input,
            interpolate,
            from_equilibrium,
            q0: q0.as_ref().map(arrays::vec1),
            qd0: qd0.as_ref().map(arrays::vec1),
            method,
            rtol,
            atol,
            fixed_step,
            load_schedule,
            steps,
            babble,
            seed,
            max_order,
            error_norm,
            rho_inf,
            fd_jacobian,
            controller,
            control_rate,
            out,
            force,
        };
        run(self, py, args)
    }
}

pub fn run<'py>(robot: &Robot, py: Python<'py>, a: Args<'_>) -> PyResult<Bound<'py, PyDict>> {
    let na = robot.built.model.n_actuators();
    let start = start(&a.q0, &a.qd0, a.from_equilibrium)?;
    let attached = robot.attached.is_some();
    let Drive {
        input,
        callable,
        signal,
    } = a.drive(py, na, attached)?;
    let built = match signal && !a.from_equilibrium {
        true => robot.built_for_signal(py)?,
        false => &robot.built,
    };
    let choice = a.integrator()?;
    if a.force && a.out.is_none() {
        return Err(invalid(
            "`force` replaces an earlier output at `out`: give `out` (or leave `force` out)",
        ));
    }
    let prepared = simulate::prepare(
        built,
        simulate::Request {
            duration: a.duration,
            sample_rate: a.sample_rate,
            input,
            start,
            load_schedule: a.load_schedule.clone(),
            integrator: choice,
        },
    )
    .map_err(err)?;
    let (opts, plan) = (&prepared.opts, &prepared.plan);
    // the output is staged before the run, as `gvsrom simulate --out` does
    let mut writer = match &a.out {
        Some(dir) => {
            simulate::check_output_size(built, plan).map_err(err)?;
            let mut w = TrajectoryWriter::create(dir, a.force, built)
                .map_err(|e| crate::errors::any(e.into()))?;
            w.set_provenance(
                &prepared.record(provenance(robot, built)?.seed("input", a.seed), &choice),
            );
            Some(w)
        }
        None => None,
    };
    for o in &plan.model_extrapolated {
        warn(py, &format!("extrapolating (--extrapolate): {o}"))?;
    }
    if let Some(w2) = plan.start_divergence {
        warn(py, &simulate::unstable_start_note(w2))?;
    }
    crate::robot::warn_motion_note(py, built)?;
    // as `simulate --out`'s `model_extrapolated`: the scenario's, then the input's
    let mut extrapolated: Vec<String> = (built.reduced.iter())
        .flat_map(|r| r.extrapolated.iter())
        .chain(&plan.model_extrapolated)
        .cloned()
        .collect();
    let mut buffer = TrajectoryBuffer::new(built);
    let mut signals = crate::interrupt::SignalPoll::new();
    let mut outcome = py.detach(|| {
        let mut control = |_t: f64| {
            if let Some(c) = callable.as_ref() {
                if !c.check_range(built) || c.failed() {
                    // the reason a written trajectory records: the callable's error itself
                    let why = c.error_message();
                    return ControlFlow::Break(why.unwrap_or_else(|| "the callable failed".into()));
                }
            }
            match signals.interrupted() {
                false => ControlFlow::Continue(()),
                true => ControlFlow::Break("interrupted".to_string()),
            }
        };
        let sink: &mut dyn SampleSink = match writer.as_mut() {
            Some(w) => &mut (&mut buffer, w),
            None => &mut buffer,
        };
        simulate::run_into(built, plan, &opts.integrator, Some(sink), &mut control)
    });
    // what the callable's values lay outside the model's training, in the result and the files
    let from_callable = callable
        .as_ref()
        .map(|c| c.take_extrapolated())
        .unwrap_or_default();
    // the trajectory is written (partial, if the run ended early) before any error is raised
    let written = match (writer, outcome.as_mut()) {
        (Some(w), Ok(o)) => {
            // (recorded as the callable's first, as the result lists them)
            o.model_extrapolated
                .splice(0..0, from_callable.iter().cloned());
            let dir = w.finish(built, plan, o);
            o.model_extrapolated.drain(0..from_callable.len());
            Some(dir)
        }
        _ => None,
    };
    for o in from_callable {
        warn(py, &format!("extrapolating (--extrapolate): {o}"))?;
        extrapolated.push(o);
    }
    // the callable's own error first, with the samples before it: a failure to write comes after
    if let Some(c) = &callable {
        if let Some(failure) = c.take_error() {
            let dir = written.as_ref().and_then(|w| w.as_ref().ok());
            // a controller's failure stops the run before the sample it was called at; an input
            // callable's first sample is delivered before it is first called (the failure at
            // the start is raised as it is)
            let first = match c.kind() {
                Kind::Controller => 1,
                Kind::Input => 2,
            };
            let before = match &outcome {
                Ok(o) if buffer.t.len() >= first => Some(trajectory(py, built, &buffer, o)?),
                _ => None,
            };
            return Err(with_samples_before(py, failure, before, extrapolated, dir)?);
        }
    }
    let written = (written.transpose()).map_err(|e| crate::errors::any(e.into()))?;
    // Ctrl-C (or another signal handler's exception): raised as it is, with the samples before
    if let Some(e) = signals.caught() {
        let before = match &outcome {
            Ok(o) if !buffer.t.is_empty() => Some(trajectory(py, built, &buffer, o)?),
            _ => None,
        };
        let failure = crate::callable::Failure {
            err: e,
            raised: true,
        };
        let dir = written.as_ref();
        return Err(with_samples_before(py, failure, before, extrapolated, dir)?);
    }
    let outcome = outcome.map_err(err)?;
    // what the run found of the model's use beyond its data, kept with a failed run's samples too
    if !matches!(outcome.ending, Ending::Interrupted { .. }) {
        for o in &outcome.model_extrapolated {
            warn(py, o)?;
            extrapolated.push(o.clone());
        }
    }
    match &outcome.ending {
        Ending::Complete => {}
        Ending::Failed { error, failure } => {
            let partial = trajectory(py, built, &buffer, &outcome)?;
            partial.set_item("model_extrapolated", extrapolated)?;
            partial.set_item("reason", failure.reason())?;
            if let Some(dir) = &written {
                partial.set_item("out", dir)?;
            }
            let files = match &written {
                Some(dir) => format!("; written to {}, marked incomplete", dir.display()),
                None => String::new(),
            };
            return Err(crate::errors::integration(
                &format!(
                    "{error} ({} samples computed: the exception's `trajectory`{files})",
                    buffer.t.len()
                ),
                &partial,
            ));
        }
        Ending::Interrupted { reason } => return Err(invalid(reason.clone())),
    }
    let d = trajectory(py, built, &buffer, &outcome)?;
    d.set_item("model_extrapolated", extrapolated)?;
    if let Some(w2) = plan.start_divergence {
        d.set_item("start_divergence", w2)?;
    }
    if let Some(dir) = &written {
        d.set_item("out", dir)?;
    }
    if let Some(e) = &outcome.energy {
        let b = PyDict::new(py);
        b.set_item("initial", e.initial)?;
        b.set_item("last", e.last)?;
        b.set_item("largest_gain", e.largest_gain)?;
        b.set_item("largest_loss", e.largest_loss)?;
        b.set_item("kinetic_max", e.kinetic_max)?;
        d.set_item("energy_balance", b)?;
        for note in e.notes(["rtol", "atol"]) {
            warn(py, &note)?;
        }
    }
    Ok(d)
}

fn trajectory<'py>(
    py: Python<'py>,
    built: &gvsrom::Built,
    b: &TrajectoryBuffer,
    outcome: &simulate::Outcome,
) -> PyResult<Bound<'py, PyDict>> {
    let k = b.t.len();
    let n = built.n_dof();
    let na = built.model.n_actuators();
    let p = built.model.disc.n_points();
    let c = b.centerline_x().len();
    let d = PyDict::new(py);
    d.set_item("t", vector(py, &b.t))?;
    d.set_item("q", shaped(py, b.q.clone(), [k, n])?)?;
    d.set_item("qd", shaped(py, b.qd.clone(), [k, n])?)?;
    d.set_item("u", shaped(py, b.u.clone(), [k, na])?)?;
    d.set_item("tip_position", shaped(py, b.tip_position.clone(), [k, 3])?)?;
    d.set_item(
        "tip_rotation",
        shaped(py, b.tip_rotation.clone(), [k, 3, 3])?,
    )?;
    d.set_item("strain", shaped(py, b.strain.clone(), [k, p, 6])?)?;
    let x: Vec<f64> = built.model.disc.points.iter().map(|pt| pt.x).collect();
    d.set_item("strain_x", vector(py, &x))?;
    let xi_star: Vec<f64> = (0..p)
        .flat_map(|i| built.model.xi_star(i).iter().copied().collect::<Vec<_>>())
        .collect();
    d.set_item("strain_reference", shaped(py, xi_star, [p, 6])?)?;
    d.set_item("centerline", shaped(py, b.centerline.clone(), [k, c, 3])?)?;
    d.set_item("centerline_x", vector(py, b.centerline_x()))?;
    d.set_item(
        "tendon_paths",
        shaped(py, b.tendon_paths.clone(), [k, na, c, 3])?,
    )?;
    d.set_item(
        "tendon_lengths",
        shaped(py, b.tendon_lengths.clone(), [k, na])?,
    )?;
    if built.displacement_driven() {
        d.set_item("displacement", shaped(py, b.displacement.clone(), [k, na])?)?;
    }
    let nb = built.model.bodies().len();
    d.set_item(
        "body_positions",
        shaped(py, b.body_positions.clone(), [k, nb, 2, 3])?,
    )?;
    let s = &outcome.summary;
    d.set_item("steps", s.stats.steps)?;
    d.set_item("failed_steps", s.stats.failed_steps)?;
    d.set_item("wall_time_s", s.wall_time_s)?;
    Ok(d)
}

/// How a run of `robot` was made, for `meta.json` (`provenance`, as `gvsrom simulate` records
/// it): the scenario as the robot read it (preset or file, overrides, the resolved TOML) and the
/// reduced model it runs, by its manifest's hashes.
fn provenance(robot: &Robot, built: &gvsrom::Built) -> PyResult<gvsrom::provenance::Provenance> {
    let s = &robot.scenario;
    let toml = s
        .scenario
        .to_toml()
        .map_err(|e| crate::errors::any(e.into()))?;
    let p = s.src.provenance(&s.overrides, toml);
    Ok(match &built.reduced {
        Some(r) => p.model(&r.origin),
        None => p,
    })
}

/// The error a callable raised (or a `GvsromError` for a value it returned) after the run computed
/// the samples `before`: a `GvsromError` becomes an `IntegrationError` whose `trajectory` is
/// them (a subclass: `except GvsromError` still catches it); the callable's own exception is
/// raised as it was, with them as its `trajectory` attribute and a note saying so.
fn with_samples_before(
    py: Python<'_>,
    failure: crate::callable::Failure,
    before: Option<Bound<'_, PyDict>>,
    extrapolated: Vec<String>,
    written: Option<&std::path::PathBuf>,
) -> PyResult<PyErr> {
    let e = failure.err;
    let Some(partial) = before else {
        return Ok(e);
    };
    partial.set_item("model_extrapolated", extrapolated)?;
    if let Some(dir) = written {
        partial.set_item("out", dir)?;
    }
    let samples = partial.get_item("t")?.map_or(Ok(0), |t| t.len())?;
    if !failure.raised {
        let message = e.value(py).to_string();
        return Ok(crate::errors::integration(
            &format!("{message} ({samples} samples computed before: the exception's `trajectory`)"),
            &partial,
        ));
    }
    let value = e.value(py);
    // an attribute of the exception's own is kept; an exception that takes none keeps none (its
    // message is unchanged either way)
    if !value.hasattr("trajectory")? && value.setattr("trajectory", &partial).is_ok() {
        let note = format!(
            "gvsrom: the run stopped here; its {samples} samples before are this exception's `trajectory`"
        );
        // `add_note` from Python 3.11; before, the list it appends to
        if value.call_method1("add_note", (note.clone(),)).is_err() {
            let notes = pyo3::types::PyList::new(py, [note])?;
            let _ = value.setattr("__notes__", notes);
        }
    }
    Ok(e)
}
