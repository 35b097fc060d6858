//! A Python callable as a run's actuation: `u(t)`, a function of time the integrator evaluates
//! ([`CallableInput`] as a [`gvs::inputs::Actuation`]), or a controller `u(t, q, q̇)` called at
//! the control instants with the state there and held between them (the same struct as a
//! [`gvs::feedback::FeedbackLaw`], inside a [`gvs::feedback::SampledFeedback`]). Either way its
//! values are checked as a signal's are.

use crate::arrays;
use crate::errors::invalid;
use gvs::error::ModelError;
use gvs::inputs::Actuation;
use pyo3::prelude::*;
use std::sync::{Mutex, PoisonError};

/// A Python callable as a run's tensions: `u(t)` ([`Kind::Input`]), called with the GIL at every
/// time the integrator evaluates, or a controller `u(t, q, q̇)` ([`Kind::Controller`]), called at
/// each control instant; its value checked (one tension per tendon or one for all, finite). The
/// first exception (the callable's own, or a `GvsromError` for a bad value) is kept and stops the
/// run at its next step attempt; until then the actuation is zero. The largest |u| of each tendon
/// so far is kept with the time it was returned: the run's control checks it against the rod's
/// elastic range after each step ([`CallableInput::check_range`]), as `gvsrom simulate` checks a
/// signal's tensions before it starts. With a reduced model attached, every value returned is
/// checked too against what the model was trained on, as a signal of rows is
/// ([`gvsrom::build::reduced::Reduced::check_signal`]): outside, the run stops with the model's
/// verdict, or, with `extrapolate`, goes on and its result says so.
pub struct CallableInput {
    function: Py<PyAny>,
    kind: Kind,
    n_actuators: usize,
    error: Mutex<Option<Failure>>,
    largest: Mutex<Largest>,
    /// With a reduced model: the values returned since the last check, with their times.
    returned: Option<Mutex<Returned>>,
    /// How the values lay outside the model's training, with `extrapolate` (the first sentence
    /// of each kind is kept).
    extrapolated: Mutex<Vec<String>>,
}

/// Why a callable stopped its run: an exception it raised (its own, kept as it is), or a value it
/// returned that was refused (a `GvsromError` naming it).
pub struct Failure {
    pub err: PyErr,
    pub raised: bool,
}

impl Failure {
    fn raised(err: PyErr) -> Self {
        Failure { err, raised: true }
    }
    fn refused(err: PyErr) -> Self {
        Failure { err, raised: false }
    }
}

/// What the callable is: the argument it came as, and what it is called with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `input=u(t)`.
    Input,
    /// `controller=u(t, q, qd)`.
    Controller,
}

/// The values `u` a callable input returned since the last check, each with the time `t` it was
/// asked for (a value repeated over many evaluations, a held input, once), and the last one.
#[derive(Default)]
struct Returned {
    unchecked: Vec<(f64, Vec<f64>)>,
    last: Vec<f64>,
}

/// The largest |u| per tendon returned so far, the time of each, and whether it grew since the
/// last check.
#[derive(Default)]
struct Largest {
    abs: Vec<f64>,
    at: Vec<f64>,
    grown: bool,
}

impl CallableInput {
    /// `function` as `kind` for `n_actuators` tendons; `model_attached`: its values are checked
    /// against a reduced model's training too.
    pub fn new(function: Py<PyAny>, kind: Kind, n_actuators: usize, model_attached: bool) -> Self {
        CallableInput {
            function,
            kind,
            n_actuators,
            error: Mutex::new(None),
            largest: Mutex::new(Largest::default()),
            returned: model_attached.then(Mutex::default),
            extrapolated: Mutex::new(vec![]),
        }
    }

    /// What the callable is.
    pub fn kind(&self) -> Kind {
        self.kind
    }

    /// How a call at `t` reads in a message: `input(t)` or `controller(t, q, qd)`.
    fn named(&self, t: f64) -> String {
        match self.kind {
            Kind::Input => format!("`input({t})`"),
            Kind::Controller => format!("`controller({t}, q, qd)`"),
        }
    }

    /// Calls the function at `t` (with the state `(q, q̇)` for a controller) and checks its value.
    fn call(
        &self,
        py: Python<'_>,
        t: f64,
        state: Option<(&[f64], &[f64])>,
    ) -> Result<Vec<f64>, Failure> {
        let f = self.function.bind(py);
        let value = match state {
            None => f.call1((t,)),
            Some((q, qd)) => f.call1((t, arrays::vector(py, q), arrays::vector(py, qd))),
        }
        .map_err(Failure::raised)?;
        let repr = |v: &Bound<'_, PyAny>| v.repr().map(|r| r.to_string()).unwrap_or_default();
        let na = self.n_actuators;
        let named = self.named(t);
        let values = match value.extract::<arrays::Tensions<'_>>() {
            Ok(u) => u.values(),
            Err(_) => {
                let shape = match value.getattr("shape") {
                    Ok(sh) => format!(" of shape {}", repr(&sh)),
                    Err(_) => String::new(),
                };
                return Err(Failure::refused(invalid(format!(
                    "{named} returned `{}`{shape}: expected {na} tension{} [N] (a 1-D array or sequence, one per tendon, or one number for all)",
                    repr(&value),
                    if na == 1 { "" } else { "s" },
                ))));
            }
        };
        let u = gvsrom::scenario::tensions_for(na, &values)
            .map_err(|e| Failure::refused(invalid(format!("{named}: {e}"))))?;
        if let Some(k) = u.iter().position(|x| !x.is_finite()) {
            return Err(Failure::refused(invalid(format!(
                "{named} returned u[{k}] = {}: expected finite values (tensions [N], or displacements [m] for tendons driven by their displacement)",
                u[k]
            ))));
        }
        Ok(u)
    }

    /// Records `u`, returned at `t`, in the largest |u| per tendon (and for the model's check).
    fn record(&self, t: f64, u: &[f64]) {
        if let Some(r) = &self.returned {
            let mut r = r.lock().unwrap_or_else(PoisonError::into_inner);
            // a value held over many evaluations (a step input) is checked once
            if r.last != u {
                r.last = u.to_vec();
                r.unchecked.push((t, u.to_vec()));
            }
        }
        let mut l = self.largest.lock().unwrap_or_else(PoisonError::into_inner);
        if l.abs.len() != u.len() {
            l.abs = vec![0.0; u.len()];
            l.at = vec![t; u.len()];
        }
        for (k, v) in u.iter().enumerate() {
            if v.abs() > l.abs[k] {
                l.abs[k] = v.abs();
                l.at[k] = t;
                l.grown = true;
            }
        }
    }

    /// If the largest |u| grew since the last call: checks it against the rod's elastic range
    /// (`gvsrom::plausibility::check`, as for a signal given as rows); a value far beyond it
    /// becomes the run's error, naming the time it was returned, and `false` is returned.
    pub fn check_range(&self, built: &gvsrom::Built) -> bool {
        self.check_model(built) && self.check_elastic_range(built)
    }

    /// The values returned since the last call against the reduced model's training
    /// ([`gvsrom::build::reduced::Reduced::check_signal`] at their times): outside, the model's
    /// verdict becomes the run's error and `false` is returned; with `extrapolate` the reasons are
    /// kept for the result.
    fn check_model(&self, built: &gvsrom::Built) -> bool {
        let (Some(returned), Some(r)) = (&self.returned, &built.reduced) else {
            return true;
        };
        let values = std::mem::take(
            &mut returned
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .unchecked,
        );
        if values.is_empty() {
            return true;
        }
        let times: Vec<f64> = values.iter().map(|(t, _)| *t).collect();
        let verdict = r.check_signal(&times, &built.drive_flags(), |t| {
            let at = values.iter().find(|(tv, _)| tv.to_bits() == t.to_bits());
            at.map_or_else(Vec::new, |(_, u)| u.clone())
        });
        match verdict {
            Ok(sentences) => {
                let mut kept = self
                    .extrapolated
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner);
                for s in sentences {
                    // one sentence per way of lying outside (a tendon's range, the combination)
                    let kind = match s.starts_with("at t = ") {
                        true => "at t = ".to_string(),
                        false => s.split(" reaches ").next().unwrap_or(&s).to_string(),
                    };
                    if !kept.iter().any(|k| k.starts_with(&kind)) {
                        kept.push(s);
                    }
                }
                true
            }
            Err(e) => {
                // as for a signal of rows: the message names the tension, its value and time
                let whose = match self.kind {
                    Kind::Input => "`input(t)`",
                    Kind::Controller => "`controller(t, q, qd)`",
                };
                let message =
                    format!("{whose} returned tensions the reduced model was not trained for: {e}");
                let mut slot = self.error.lock().unwrap_or_else(PoisonError::into_inner);
                slot.get_or_insert_with(|| Failure::refused(invalid(message)));
                false
            }
        }
    }

    /// The largest |u| against the rod's elastic range, if it grew since the last call.
    fn check_elastic_range(&self, built: &gvsrom::Built) -> bool {
        let (abs, at) = {
            let mut l = self.largest.lock().unwrap_or_else(PoisonError::into_inner);
            if !l.grown {
                return true;
            }
            l.grown = false;
            (l.abs.clone(), l.at.clone())
        };
        // a displacement channel [m]: shorter than its tendon; its tension, found from the
        // thread's stretch, is checked as the run goes
        if let Err(e) =
            gvsrom::simulate::check_channel_displacements(built, &abs, &|k| format!("u[{k}]"))
        {
            // the channel refused: the first displacement not below its tendon's length
            let rest = built.model.tendon_rest_lengths();
            let k = (0..abs.len())
                .find(|&k| {
                    built.displacement[k].is_some() && (!abs[k].is_finite() || abs[k] >= rest[k])
                })
                .unwrap_or(0);
            let message = format!("{}: {e}", self.named(at[k]));
            let mut slot = self.error.lock().unwrap_or_else(PoisonError::into_inner);
            slot.get_or_insert_with(|| Failure::refused(invalid(message)));
            return false;
        }
        let abs: Vec<f64> = (abs.iter().zip(&built.displacement))
            .map(|(a, d)| if d.is_some() { 0.0 } else { *a })
            .collect();
        match gvsrom::plausibility::check(built, &abs, 1.0) {
            Ok(()) => true,
            Err(e) => {
                let k = (0..abs.len())
                    .max_by(|&i, &j| abs[i].total_cmp(&abs[j]))
                    .unwrap_or(0);
                // the error names the tendon and its largest |u|; the time says when it came
                let message = format!("{}: {e}", self.named(at[k]));
                let mut slot = self.error.lock().unwrap_or_else(PoisonError::into_inner);
                slot.get_or_insert_with(|| Failure::refused(invalid(message)));
                false
            }
        }
    }

    /// Takes the error the callable raised or its refused value, if any.
    pub fn take_error(&self) -> Option<Failure> {
        self.error
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
    }

    /// The message of the error the callable raised (or of the bad value it returned), if any:
    /// the reason a run it stopped records.
    pub fn error_message(&self) -> Option<String> {
        let slot = self.error.lock().unwrap_or_else(PoisonError::into_inner);
        slot.as_ref().map(|f| f.err.to_string())
    }

    /// Whether the callable raised (or returned a bad value).
    pub fn failed(&self) -> bool {
        self.error
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .is_some()
    }
}

impl Actuation for CallableInput {
    fn eval(&self, t: f64, out: &mut [f64]) {
        out.fill(0.0);
        if self.failed() {
            return;
        }
        match Python::attach(|py| self.call(py, t, None)) {
            Ok(u) => {
                self.record(t, &u);
                out.copy_from_slice(&u)
            }
            Err(f) => *self.error.lock().unwrap_or_else(PoisonError::into_inner) = Some(f),
        }
    }

    /// Once the callable has failed, no further sample is delivered: the step under way evaluated
    /// zero tensions after the failure.
    fn observe(&self, _t: f64, _q: &[f64], _qd: &[f64]) -> Result<(), String> {
        match self.error_message() {
            Some(message) => Err(message),
            None => Ok(()),
        }
    }

    fn breakpoints(&self, _t0: f64, _t1: f64) -> Vec<f64> {
        vec![]
    }

    fn validate(&self, _field: &str, _channels: usize) -> Result<(), ModelError> {
        Ok(()) // every value is checked where it is returned
    }
}

impl gvs::feedback::FeedbackLaw for CallableInput {
    fn tensions(&self, t: f64, q: &[f64], qd: &[f64], u: &mut [f64]) -> Result<(), String> {
        match Python::attach(|py| self.call(py, t, Some((q, qd)))) {
            Ok(v) => {
                self.record(t, &v);
                u.copy_from_slice(&v);
                Ok(())
            }
            Err(f) => {
                let reason = match f.raised {
                    true => format!("the controller raised {}", f.err),
                    false => f.err.to_string(),
                };
                let mut slot = self.error.lock().unwrap_or_else(PoisonError::into_inner);
                slot.get_or_insert(f);
                Err(reason)
            }
        }
    }
}

impl CallableInput {
    /// Takes how its values lay outside the reduced model's training (with `extrapolate`).
    pub fn take_extrapolated(&self) -> Vec<String> {
        std::mem::take(
            &mut *self
                .extrapolated
                .lock()
                .unwrap_or_else(PoisonError::into_inner),
        )
    }
}
