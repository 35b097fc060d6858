//! `Robot.stepper`: a run advanced one control period per call, for a loop the user drives
//! (reinforcement learning's `env.step(action)`, a controller in another program).
//!
//! One integration, as `simulate(controller=…)` runs it, on a thread of its own: its controller
//! ([`ChannelLaw`], a [`gvs::feedback::FeedbackLaw`]) hands the state at each control instant to
//! [`Stepper::step`] and waits for the tensions of the next period. So the integrator keeps what
//! a restart need not renew across periods, as in `simulate(controller=…)`, and the Python side
//! sees a call per period. The thread holds the robot (a strong reference) and never touches
//! Python; `step` waits for it with the GIL released.

use crate::arrays;
use crate::errors::{invalid, scenario as err};
use crate::robot::{warn, Robot};
use gvsrom::simulate::{self, ControlLaw, InputSource, IntegratorChoice, MethodChoice};
use pyo3::prelude::*;
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;

/// What the run hands to the Python side.
enum Event {
    /// The state at a control instant.
    State { t: f64, q: Vec<f64>, qd: Vec<f64> },
    /// The run ended: why.
    Ended(String),
}

/// The control law of the run: the state out, the next period's tensions in (`None`: close).
/// The tensions were checked by [`Stepper::step`] before they were sent.
struct ChannelLaw {
    events: Mutex<Sender<Event>>,
    tensions: Mutex<Receiver<Option<Vec<f64>>>>,
}

impl gvs::feedback::FeedbackLaw for ChannelLaw {
    fn tensions(&self, t: f64, q: &[f64], qd: &[f64], u: &mut [f64]) -> Result<(), String> {
        let state = Event::State {
            t,
            q: q.to_vec(),
            qd: qd.to_vec(),
        };
        let events = self.events.lock().unwrap_or_else(PoisonError::into_inner);
        events
            .send(state)
            .map_err(|_| "the stepper was closed".to_string())?;
        let next = self
            .tensions
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .recv();
        let Ok(Some(v)) = next else {
            return Err("the stepper was closed".into());
        };
        u.copy_from_slice(&v);
        Ok(())
    }
}

/// The run on its thread and the two ends of its channels.
struct Running {
    tensions: Sender<Option<Vec<f64>>>,
    events: Mutex<Receiver<Event>>,
    handle: Option<JoinHandle<()>>,
    /// Set to stop the run within one step of its integrator (Ctrl-C during a step).
    stop: Arc<AtomicBool>,
}

impl Drop for Running {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        let _ = self.tensions.send(None);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// A run of a robot advanced one control period per :meth:`step`, its tensions held over each
/// (a zero-order hold), from one integration: made by :meth:`Robot.stepper`.
#[pyclass(module = "gvsrom")]
pub struct Stepper {
    running: Option<Running>,
    /// The robot that runs (its scenario as built for a signal checks the tensions).
    robot: Py<Robot>,
    dt: f64,
    n_actuators: usize,
    t: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    /// Why the run ended, once it has.
    ended: Option<String>,
    /// A reduced model's extrapolation was warned of (once per run: each step's sentence names
    /// its own time and value).
    warned: bool,
}

impl Stepper {
    /// Waits for the run's next event with the GIL released, and takes it in.
    fn receive(&mut self, py: Python<'_>) -> PyResult<()> {
        let Some(r) = &self.running else {
            return Err(self.ended_error());
        };
        // waits in slices, running Python's signal handlers between them: Ctrl-C stops the run
        // within one step of its integrator and is raised once the run has ended
        let event = loop {
            let e = py.detach(|| {
                let events = r.events.lock().unwrap_or_else(PoisonError::into_inner);
                events.recv_timeout(crate::interrupt::SIGNAL_POLL)
            });
            match e {
                Err(RecvTimeoutError::Timeout) => {
                    if let Err(interrupt) = py.check_signals() {
                        r.stop.store(true, Ordering::SeqCst);
                        // (and should the run reach an instant first, its law finds "close")
                        let _ = r.tensions.send(None);
                        py.detach(|| {
                            let events = r.events.lock().unwrap_or_else(PoisonError::into_inner);
                            while let Ok(Event::State { .. }) = events.recv() {}
                        });
                        self.running = None;
                        self.ended = Some("interrupted (KeyboardInterrupt)".into());
                        return Err(interrupt);
                    }
                }
                Ok(event) => break Ok(event),
                Err(RecvTimeoutError::Disconnected) => break Err(()),
            }
        };
        match event {
            Ok(Event::State { t, q, qd }) => {
                (self.t, self.q, self.qd) = (t, q, qd);
                Ok(())
            }
            Ok(Event::Ended(reason)) => {
                self.ended = Some(reason);
                self.running = None;
                Err(self.ended_error())
            }
            Err(_) => {
                self.ended.get_or_insert_with(|| "the run ended".into());
                self.running = None;
                Err(self.ended_error())
            }
        }
    }

    fn ended_error(&self) -> PyErr {
        invalid(format!(
            "the stepper's run has ended at t = {} s: {}",
            self.t,
            self.ended.as_deref().unwrap_or("it was closed")
        ))
    }
}

#[pymethods]
impl Stepper {
    /// Holds the tensions ``u`` [N] (one per tendon, or one number for all) for one period and
    /// returns the state ``(q, qd)`` at its end; :attr:`t` advances by :attr:`dt`. A tendon the
    /// scenario drives by its ``displacement`` takes its displacement [m] here instead (its
    /// tension follows from the thread's stretch).
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     For tensions of the wrong count, not finite, beyond the rod's elastic range or outside
    ///     a reduced model's training (without ``extrapolate``; for a displacement, the tension
    ///     its thread pulls with as the period starts), or a displacement not below its tendon's
    ///     rest length: checked before the run sees them, so the run stays where it was and the
    ///     next ``step`` goes on from there. Also once the run has ended (closed, past its
    ///     horizon, or its integration failed).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        u: arrays::Tensions<'_>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        if self.running.is_none() {
            return Err(self.ended_error());
        }
        let u = gvsrom::scenario::tensions_for(self.n_actuators, &u.values())
            .map_err(|e| invalid(format!("`u`: {e}")))?;
        if let Some(k) = u.iter().position(|x| !x.is_finite()) {
            return Err(invalid(format!(
                "`u[{k}]` = {}: expected finite values (tensions [N], or displacements [m] for tendons driven by their displacement)",
                u[k]
            )));
        }
        // checked as a signal's tensions are (the elastic range, a reduced model's training),
        // before the run sees them: a refused value leaves the run as it was
        let t = self.t;
        let refused = |e: &dyn std::fmt::Display| {
            invalid(format!(
                "`step(u)` at t = {t} s: {e}; the run goes on from there: step again with other tensions"
            ))
        };
        let robot = self.robot.clone_ref(py);
        let built = robot.get().built_for_signal_ready();
        // a tendon driven by its displacement: its entry is that displacement [m], whose
        // tension the run finds from the thread's stretch
        gvsrom::simulate::check_channel_displacements(built, &u, &|k| format!("u[{k}]"))
            .map_err(|e| refused(&e))?;
        let abs: Vec<f64> = (u.iter().zip(&built.displacement))
            .map(|(x, d)| if d.is_some() { 0.0 } else { x.abs() })
            .collect();
        gvsrom::plausibility::check(built, &abs, 1.0).map_err(|e| refused(&e))?;
        if let Some(model) = &built.reduced {
            let notes = model
                .check_signal(&[t], &built.drive_flags(), |_| u.clone())
                .map_err(|e| refused(&e))?;
            if let (Some(n), false) = (notes.first(), self.warned) {
                warn(py, &format!("extrapolating (--extrapolate): {n} (further values outside the training are not warned of)"))?;
                self.warned = true;
            }
        }
        // the tensions the threads of displacement-driven tendons pull with as the period starts
        // (the run's first sample of it), against a reduced model's training: refused as a given
        // tension is, or with `extrapolate` warned of
        if let (Some(model), true) = (&built.reduced, built.displacement_driven()) {
            let found = built.found_tensions(&self.q, &u);
            if let Some(n) = model
                .found_tensions_outside(&found, &built.drive_flags())
                .first()
            {
                let why = format!("the tensions found from the threads of the tendons driven by displacement lie outside the model's training: {n}");
                if !model.extrapolate {
                    return Err(refused(&format!("{why} (extrapolate=True uses it anyway)")));
                }
                if !self.warned {
                    warn(py, &format!("extrapolating (extrapolate=True): at t = {t} s {why} (further values outside the training are not warned of)"))?;
                    self.warned = true;
                }
            }
        }
        let sent = (self.running.as_ref()).is_some_and(|r| r.tensions.send(Some(u)).is_ok());
        if !sent {
            self.running = None;
        }
        self.receive(py)?;
        Ok((arrays::vector(py, &self.q), arrays::vector(py, &self.qd)))
    }

    /// The time of the state [s].
    #[getter]
    fn t(&self) -> f64 {
        self.t
    }

    /// The control period [s].
    #[getter]
    fn dt(&self) -> f64 {
        self.dt
    }

    /// The coordinates ``q`` of the model that runs at :attr:`t`.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arrays::vector(py, &self.q)
    }

    /// The velocities ``qd`` at :attr:`t`.
    #[getter]
    fn qd<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arrays::vector(py, &self.qd)
    }

    /// Whether the run still takes steps (not closed, not ended).
    #[getter]
    fn running(&self) -> bool {
        self.running.is_some()
    }

    /// Ends the run (also when the stepper is garbage-collected, or leaves a ``with`` block).
    fn close(&mut self, py: Python<'_>) {
        let r = self.running.take();
        self.ended.get_or_insert_with(|| "closed".into());
        py.detach(|| drop(r));
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    fn __exit__(
        &mut self,
        py: Python<'_>,
        _ty: Option<Bound<'_, PyAny>>,
        _value: Option<Bound<'_, PyAny>>,
        _tb: Option<Bound<'_, PyAny>>,
    ) -> bool {
        self.close(py);
        false
    }
}

/// The arguments of `Robot.stepper`.
pub struct Args {
    pub dt: f64,
    pub horizon: f64,
    pub q0: Option<Vec<f64>>,
    pub qd0: Option<Vec<f64>>,
    pub from_equilibrium: bool,
    pub method: MethodChoice,
    pub fixed_step: Option<f64>,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
}

#[pymethods]
impl Robot {
    /// A run advanced one control period per :meth:`Stepper.step`, for a loop you drive (a
    /// reinforcement-learning environment's ``step(action)``, a controller elsewhere): each call
    /// holds its tensions for ``dt`` seconds and returns the state at the end. One integration
    /// on a thread of its own, as ``simulate(controller=…)`` runs it (the same numbers), so the
    /// integrator keeps what a restart need not renew between periods.
    ///
    /// Parameters
    /// ----------
    /// dt : float
    ///     The control period [s].
    /// horizon : float, optional
    ///     The longest the run may go [s]: the steps stop at its last whole period, and a step
    ///     past it is an error. Default: an hour or 100 000 periods, whichever is shorter (the
    ///     run's sample times are laid out up front: at most 10 000 000 periods).
    /// q0, qd0 : array_like of float, shape (n,), optional
    ///     Start at this state (the coordinates of the model that runs); else straight at rest, or
    ///     with ``from_equilibrium`` at the scenario's equilibrium.
    /// from_equilibrium : bool
    ///     Start at the static equilibrium under the scenario's tensions.
    /// method, rtol, atol, fixed_step
    ///     The integrator, as for :meth:`simulate` (``fixed_step=dt`` or a fraction of it for a
    ///     fixed cost per period).
    ///
    /// Returns
    /// -------
    /// Stepper
    ///     At ``t = 0`` (``stepper.q``, ``stepper.qd``); a context manager that ends the run.
    #[pyo3(signature = (dt, horizon=None, q0=None, qd0=None, from_equilibrium=false, method="auto", rtol=None, atol=None, fixed_step=None))]
    #[allow(clippy::too_many_arguments)]
    fn stepper(
        slf: Py<Self>,
        py: Python<'_>,
        #[pyo3(from_py_with = arrays::real)] dt: f64,
        #[pyo3(from_py_with = arrays::real_or_none)] horizon: Option<f64>,
        q0: Option<arrays::In1<'_>>,
        qd0: Option<arrays::In1<'_>>,
        from_equilibrium: bool,
        method: &str,
        rtol: Option<f64>,
        atol: Option<f64>,
        fixed_step: Option<f64>,
    ) -> PyResult<Stepper> {
        // a period from a microsecond (the shortest run) to an hour (the longest default horizon)
        if !(dt.is_finite() && (simulate::MIN_DURATION..=3600.0).contains(&dt)) {
            return Err(invalid(format!(
                "invalid value for `dt`: {} (expected the control period in [{}, 3600] s)",
                gvs::error::fmt_value(dt),
                gvs::error::fmt_value(simulate::MIN_DURATION),
            )));
        }
        if let Some(h) = fixed_step.filter(|&h| !(h.is_finite() && h > 0.0)) {
            return Err(invalid(format!(
                "invalid value for `fixed_step`: {} (expected a finite step > 0 s, at most dt)",
                gvs::error::fmt_value(h)
            )));
        }
        if let Some(h) = fixed_step.filter(|&h| h > dt) {
            return Err(invalid(format!(
                "invalid value for `fixed_step`: {} (expected a step ≤ dt = {} s: the integrator restarts at every period, so a longer step would be cut to the period)",
                gvs::error::fmt_value(h),
                gvs::error::fmt_value(dt)
            )));
        }
        let horizon = horizon.unwrap_or((100_000.0 * dt).min(3600.0));
        let periods = horizon / dt;
        let most = (simulate::MAX_SAMPLES - 2) as f64;
        let steps = fixed_step.map_or(0.0, |h| horizon / h);
        if !(horizon.is_finite()
            && horizon >= dt
            && periods <= most
            && steps <= simulate::MAX_FIXED_STEPS)
        {
            return Err(invalid(format!(
                "invalid value for `horizon`: {} (expected a finite number of seconds ≥ dt = {}, at most {} periods{}: {} s)",
                gvs::error::fmt_value(horizon),
                gvs::error::fmt_value(dt),
                most,
                match fixed_step {
                    Some(_) => " and 10 000 000 fixed steps",
                    None => "",
                },
                gvs::error::fmt_value((most * dt).min(fixed_step.map_or(f64::INFINITY, |h| simulate::MAX_FIXED_STEPS * h)))
            )));
        }
        let args = Args {
            dt,
            horizon,
            q0: q0.as_ref().map(arrays::vec1),
            qd0: qd0.as_ref().map(arrays::vec1),
            from_equilibrium,
            method: crate::simulate_args::method(method)?,
            fixed_step,
            rtol,
            atol,
        };
        start(slf, py, args)
    }
}

/// Plans the run (everything checked before the thread starts), starts it and waits for its first
/// state.
pub fn start(robot: Py<Robot>, py: Python<'_>, a: Args) -> PyResult<Stepper> {
    let r = robot.get();
    let built = r.built_for_signal(py)?;
    // (a rod without tendons steps with `step([])`: its free motion under its loads)
    let na = built.model.n_actuators();
    let start = crate::simulate_args::start(&a.q0, &a.qd0, a.from_equilibrium)?;
    let (to_law, from_user) = channel::<Option<Vec<f64>>>();
    let (to_user, from_law) = channel::<Event>();
    let law = Arc::new(ChannelLaw {
        events: Mutex::new(to_user.clone()),
        tensions: Mutex::new(from_user),
    });
    let prepared = simulate::prepare(
        built,
        simulate::Request {
            duration: a.horizon,
            sample_rate: 1.0 / a.dt,
            input: InputSource::Feedback {
                law: ControlLaw(law),
                control_rate: None,
            },
            start,
            load_schedule: None,
            integrator: IntegratorChoice {
                method: a.method,
                rtol: a.rtol,
                atol: a.atol,
                fixed_step: a.fixed_step,
                ..IntegratorChoice::default()
            },
        },
    )
    .map_err(err)?;
    crate::robot::warn_motion_note(py, built)?;
    let thread_robot = robot.clone_ref(py);
    let stop = Arc::new(AtomicBool::new(false));
    let thread_stop = stop.clone();
    let handle = std::thread::spawn(move || {
        let run = std::panic::AssertUnwindSafe(|| {
            let built = thread_robot.get().built_for_signal_ready();
            let mut control = |_t: f64| match thread_stop.load(Ordering::SeqCst) {
                true => ControlFlow::Break("interrupted".to_string()),
                false => ControlFlow::Continue(()),
            };
            let outcome = simulate::run_into(
                built,
                &prepared.plan,
                &prepared.opts.integrator,
                None,
                &mut control,
            );
            match outcome {
                Ok(o) => match o.ending {
                    simulate::Ending::Complete => "it reached its horizon".to_string(),
                    simulate::Ending::Interrupted { reason } => reason,
                    simulate::Ending::Failed { error, .. } => error,
                },
                Err(e) => e.to_string(),
            }
        });
        // a panic of the run is its reason too (else `step` would only learn that it ended)
        let why = std::panic::catch_unwind(run).unwrap_or_else(|p| {
            let what = (p.downcast_ref::<String>().cloned())
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            format!("the run panicked (a bug of gvsrom; please report it): {what}")
        });
        let _ = to_user.send(Event::Ended(why));
    });
    let mut stepper = Stepper {
        running: Some(Running {
            tensions: to_law,
            events: Mutex::new(from_law),
            handle: Some(handle),
            stop,
        }),
        robot,
        dt: a.dt,
        n_actuators: na,
        t: 0.0,
        q: vec![],
        qd: vec![],
        ended: None,
        warned: false,
    };
    stepper.receive(py)?;
    Ok(stepper)
}
