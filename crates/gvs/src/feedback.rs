//! Sampled-data feedback: a controller that reads the state at fixed instants and holds the
//! tensions it returns until the next one — a zero-order hold, as a digital controller drives a
//! robot.
//!
//! ```text
//!   u(t) = u_k = law(t_k, q(t_k), q̇(t_k); u_{k−1})   for t ∈ [t_k, t_{k+1}),   t_0 < t_1 < …
//! ```
//!
//! with `t_0` the run's start (`u_{−1} = 0`: the law finds the last value it returned, e.g. to
//! integrate an error). At a last output sample that is an instant the law is called too; that
//! value is recorded with the sample but drives no step.
//!
//! The instants are breakpoints of the run (the integrator steps onto each and restarts there with
//! the new value, as it does at a step of a held signal) and output samples of it: the dynamics
//! driver hands the state of every output sample to [`Actuation::observe`] before it reads `u`
//! there, and at a control instant the law is called. A closed loop is therefore one integration,
//! not one per control period: the fixed-step method, for one, keeps its Jacobian across periods.

use crate::error::ModelError;
use crate::inputs::Actuation;
use std::sync::{Mutex, PoisonError};

/// A control law: the tensions at a control instant from the state there.
pub trait FeedbackLaw {
    /// Writes the tensions at `t` from the state `(q, q̇)` into `u` (one per actuator; it holds the
    /// last period's values on entry). `Err(reason)` stops the run with that reason.
    fn tensions(&self, t: f64, q: &[f64], qd: &[f64], u: &mut [f64]) -> Result<(), String>;
}

impl<L: FeedbackLaw + ?Sized> FeedbackLaw for std::sync::Arc<L> {
    fn tensions(&self, t: f64, q: &[f64], qd: &[f64], u: &mut [f64]) -> Result<(), String> {
        (**self).tensions(t, q, qd, u)
    }
}

/// A [`FeedbackLaw`] held over the periods between its control instants (an [`Actuation`]).
pub struct SampledFeedback<L> {
    law: L,
    instants: Vec<f64>,
    held: Mutex<Held>,
}

/// The index of the next control instant and the value held since the last one.
struct Held {
    next: usize,
    u: Vec<f64>,
}

impl<L: FeedbackLaw> SampledFeedback<L> {
    /// `law` called at `instants` (ascending, the first the run's start: every one must be an
    /// output sample of the run) for `channels` actuators. Before the first instant `u` is NaN: a
    /// run evaluates nothing before its first sample. The law finds zeros in `u` at the first
    /// instant.
    pub fn new(law: L, instants: Vec<f64>, channels: usize) -> Self {
        SampledFeedback {
            law,
            instants,
            held: Mutex::new(Held {
                next: 0,
                u: vec![0.0; channels],
            }),
        }
    }

    /// The control law.
    pub fn law(&self) -> &L {
        &self.law
    }

    /// The control instants.
    pub fn instants(&self) -> &[f64] {
        &self.instants
    }

    /// Control instants reached so far (calls of the law).
    pub fn calls(&self) -> usize {
        self.held
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .next
    }
}

impl<L: FeedbackLaw> Actuation for SampledFeedback<L> {
    fn eval(&self, _t: f64, out: &mut [f64]) {
        let held = self.held.lock().unwrap_or_else(PoisonError::into_inner);
        match held.next {
            0 => out.fill(f64::NAN),
            _ => out.copy_from_slice(&held.u),
        }
    }

    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        (self.instants.iter())
            .copied()
            .filter(|&t| t > t0 && t < t1)
            .collect()
    }

    fn validate(&self, field: &str, channels: usize) -> Result<(), ModelError> {
        let held = self.held.lock().unwrap_or_else(PoisonError::into_inner);
        if held.u.len() != channels {
            return Err(ModelError::invalid(
                field,
                format!(
                    "the feedback gives {} tensions; the model has {channels} actuators",
                    held.u.len()
                ),
            ));
        }
        match self.instants.first() {
            None => return Err(ModelError::invalid(field, "no control instant")),
            Some(t) if !t.is_finite() => {
                return Err(ModelError::invalid(
                    field,
                    format!("control instants must be finite: the first is {t}"),
                ))
            }
            Some(_) => {}
        }
        if let Some(w) = (self.instants.windows(2)).find(|w| {
            w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) || !w[1].is_finite()
        }) {
            return Err(ModelError::invalid(
                field,
                format!(
                    "control instants must be finite and ascending: {} then {}",
                    w[0], w[1]
                ),
            ));
        }
        Ok(())
    }

    /// At a control instant, calls the law with the state and holds what it returns; a sample past
    /// an instant that was never a sample is an error (the law would have been skipped), and so is
    /// a first sample before the first instant (nothing would be held). The first instant seen
    /// again starts over (another run of the same plan: the law is called afresh, from zeros).
    fn observe(&self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), String> {
        let mut held = self.held.lock().unwrap_or_else(PoisonError::into_inner);
        if held.next > 0 && self.instants.first() == Some(&t) {
            held.next = 0;
            held.u.fill(0.0);
        }
        let Some(&tk) = self.instants.get(held.next) else {
            return Ok(());
        };
        if t < tk {
            return match held.next {
                0 => Err(format!(
                    "the run starts at t = {t} s, before the first control instant {tk} s: no tension is held until then"
                )),
                _ => Ok(()),
            };
        }
        if t > tk {
            return Err(format!(
                "the control instant t = {tk} s is not an output sample of the run (the next sample is at {t} s): the control law was not called there"
            ));
        }
        let Held { next, u } = &mut *held;
        self.law.tensions(t, q, qd, u)?;
        if let Some(k) = u.iter().position(|v| !v.is_finite()) {
            return Err(format!(
                "the control law returned u[{k}] = {} at t = {t} s: expected finite tensions [N]",
                u[k]
            ));
        }
        *next += 1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `u = −t − q₀`, so each call is visible in the held value.
    struct Law;
    impl FeedbackLaw for Law {
        fn tensions(&self, t: f64, q: &[f64], _qd: &[f64], u: &mut [f64]) -> Result<(), String> {
            u[0] = -t - q[0];
            Ok(())
        }
    }

    #[test]
    fn the_value_is_held_between_instants_and_renewed_at_each() {
        let f = SampledFeedback::new(Law, vec![0.0, 0.1, 0.2], 1);
        let mut u = [0.0];
        f.eval(0.0, &mut u);
        assert!(u[0].is_nan(), "nothing is held before the first instant");
        f.observe(0.0, &[1.0], &[0.0]).unwrap();
        f.eval(0.05, &mut u);
        assert_eq!(u[0], -1.0);
        // a sample between instants calls nothing
        f.observe(0.05, &[5.0], &[0.0]).unwrap();
        f.eval(0.07, &mut u);
        assert_eq!(u[0], -1.0);
        f.observe(0.1, &[2.0], &[0.0]).unwrap();
        f.eval(0.15, &mut u);
        assert_eq!(u[0], -2.1);
        assert_eq!(f.calls(), 2);
        assert_eq!(f.breakpoints(0.0, 0.2), vec![0.1]);
    }

    #[test]
    fn a_second_run_starts_over_and_a_start_before_the_first_instant_is_an_error() {
        let f = SampledFeedback::new(Law, vec![0.0, 0.1], 1);
        let mut u = [0.0];
        f.observe(0.0, &[1.0], &[0.0]).unwrap();
        f.observe(0.1, &[2.0], &[0.0]).unwrap();
        assert_eq!(f.calls(), 2);
        // the same plan run again: the law is called at every instant again
        f.observe(0.0, &[3.0], &[0.0]).unwrap();
        f.eval(0.05, &mut u);
        assert_eq!((f.calls(), u[0]), (1, -3.0));
        let late = SampledFeedback::new(Law, vec![0.1, 0.2], 1);
        let e = late.observe(0.0, &[0.0], &[0.0]).unwrap_err();
        assert!(
            e.contains("starts at t = 0 s, before the first control instant 0.1 s"),
            "{e}"
        );
    }

    #[test]
    fn an_instant_that_is_no_sample_is_an_error() {
        let f = SampledFeedback::new(Law, vec![0.0, 0.1], 1);
        f.observe(0.0, &[0.0], &[0.0]).unwrap();
        let e = f.observe(0.15, &[0.0], &[0.0]).unwrap_err();
        assert!(e.contains("t = 0.1 s is not an output sample"), "{e}");
    }

    #[test]
    fn a_non_finite_tension_stops_the_run_naming_it() {
        struct Bad;
        impl FeedbackLaw for Bad {
            fn tensions(&self, _: f64, _: &[f64], _: &[f64], u: &mut [f64]) -> Result<(), String> {
                u[1] = f64::NAN;
                Ok(())
            }
        }
        let f = SampledFeedback::new(Bad, vec![0.0], 2);
        let e = f.observe(0.0, &[0.0], &[0.0]).unwrap_err();
        assert!(e.contains("u[1] = NaN"), "{e}");
    }

    #[test]
    fn validation_names_the_field_and_the_fault() {
        let f = SampledFeedback::new(Law, vec![0.0, 0.0], 1);
        let e = f.validate("actuation", 1).unwrap_err().to_string();
        assert!(e.contains("actuation") && e.contains("ascending"), "{e}");
        let e = (SampledFeedback::new(Law, vec![0.0], 2).validate("actuation", 1))
            .unwrap_err()
            .to_string();
        assert!(e.contains("2 tensions") && e.contains("1 actuators"), "{e}");
    }
}
