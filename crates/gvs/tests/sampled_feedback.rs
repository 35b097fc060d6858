//! A sampled-data closed loop ([`gvs::feedback::SampledFeedback`]) is the open-loop run of the
//! tensions its law returned, held over the periods: the same integration, for every method. The
//! law is called once per control instant, with the state the run delivers there, and an error it
//! returns stops the run with its reason after the samples before it.

mod common;

use gvs::feedback::{FeedbackLaw, SampledFeedback};
use gvs::inputs::{Interpolation, Signal};
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::solve::dynamics::{
    simulate, simulate_streaming_interruptible, InitialState, IntegratorOptions, Method,
    OdeJacobian,
};
use gvs::solve::ode::{
    FixedStepOptions, GeneralizedAlphaOptions, NdfOptions, OdeError, SdirkOptions,
};
use gvs::strain::LinearBasis;
use std::ops::ControlFlow;
use std::sync::Mutex;

/// The IV-A arm in the x-z plane, damped, its tendon with friction.
fn arm() -> Model<LinearBasis> {
    common::iva_arm(1e4, 0.3)
}

fn gravity() -> Loads {
    Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    }
}

/// A PD law on the first bending coordinate about `q_ref` (`u = −1 − k_p (q₀ − q_ref) − k_d q̇₀`,
/// pulls only), keeping every `(t, u)` it returned and the states it was handed.
struct Pd {
    calls: Mutex<Vec<(f64, f64, Vec<f64>)>>,
    fail_at: Option<f64>,
}

impl Pd {
    fn new(fail_at: Option<f64>) -> Self {
        Pd {
            calls: Mutex::new(vec![]),
            fail_at,
        }
    }
}

impl FeedbackLaw for Pd {
    fn tensions(&self, t: f64, q: &[f64], qd: &[f64], u: &mut [f64]) -> Result<(), String> {
        if self.fail_at.is_some_and(|tf| t >= tf) {
            return Err(format!("the law gave up at t = {t}"));
        }
        u[0] = (-1.0 - 0.5 * (q[0] + 2.0) - 0.05 * qd[0]).min(0.0);
        self.calls.lock().unwrap().push((t, u[0], q.to_vec()));
        Ok(())
    }
}

fn methods() -> Vec<IntegratorOptions> {
    let structured = |method| IntegratorOptions {
        method,
        jacobian: OdeJacobian::Structured,
    };
    vec![
        structured(Method::Ndf(NdfOptions::default())),
        structured(Method::Fixed(FixedStepOptions {
            h: 2e-3,
            ..FixedStepOptions::default()
        })),
        structured(Method::GeneralizedAlpha(GeneralizedAlphaOptions::default())),
        structured(Method::Sdirk(SdirkOptions::default())),
    ]
}

/// Samples every 5 ms over 0.3 s; the controller runs at every second one (100 Hz).
fn times() -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..=60).map(|k| k as f64 / 200.0).collect();
    let instants = t.iter().step_by(2).copied().collect();
    (t, instants)
}

#[test]
fn a_closed_loop_is_the_open_loop_run_of_the_tensions_it_applied() {
    let m = arm();
    let (t, instants) = times();
    for opts in methods() {
        let name = opts.method.name();
        let feedback = SampledFeedback::new(Pd::new(None), instants.clone(), 1);
        let closed = simulate_streaming_collect(&m, &feedback, &t, &opts);
        assert!(closed.1.is_none(), "{name}: {:?}", closed.1);
        let calls = std::mem::take(&mut *feedback.law().calls.lock().unwrap());
        // once per instant, at the instant, with the state the run delivered there
        assert_eq!(calls.len(), instants.len(), "{name}");
        for ((tk, _, q), ti) in calls.iter().zip(&instants) {
            assert_eq!(tk, ti, "{name}");
            let i = t.iter().position(|s| s == tk).unwrap();
            assert_eq!(q, &closed.0[i].0, "{name}: the state handed at t = {tk}");
        }
        // the tensions vary (the test would not see a wrong hold otherwise)
        let (lo, hi) = calls
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), c| (a.min(c.1), b.max(c.1)));
        assert!(hi - lo > 0.05, "{name}: tensions {lo} … {hi}");
        // (the call at the end time applies to no step: a knot there would be read by the last
        // one, which ends on it)
        let applied = &calls[..calls.len() - 1];
        let open = simulate(
            &m,
            &Signal {
                times: applied.iter().map(|c| c.0).collect(),
                values: applied.iter().map(|c| vec![c.1]).collect(),
                interpolation: Interpolation::Hold,
            },
            &gravity(),
            None,
            &InitialState::Rest,
            &t,
            &opts,
        )
        .unwrap();
        assert!(open.error.is_none(), "{name}");
        for (i, (q, u)) in closed.0.iter().enumerate() {
            let qo = open.trajectory.q[i].as_slice();
            let dq = q
                .iter()
                .zip(qo)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let scale = qo.iter().fold(1.0f64, |a, b| a.max(b.abs()));
            assert!(
                dq <= 1e-12 * scale,
                "{name}: q at t = {} differs by {dq:e}",
                t[i]
            );
            let u_open = match i + 1 == t.len() {
                true => calls.last().unwrap().1,
                false => open.trajectory.u[i][0],
            };
            assert_eq!(*u, u_open, "{name}: u at t = {}", t[i]);
        }
    }
}

#[test]
fn an_error_of_the_law_stops_the_run_with_its_reason_after_the_samples_before_it() {
    let m = arm();
    let (t, instants) = times();
    for opts in methods() {
        let name = opts.method.name();
        let feedback = SampledFeedback::new(Pd::new(Some(0.1)), instants.clone(), 1);
        let (samples, error) = simulate_streaming_collect(&m, &feedback, &t, &opts);
        match error {
            Some(OdeError::Stopped { reason, .. }) => {
                assert!(reason.contains("gave up at t = 0.1"), "{name}: {reason}")
            }
            other => panic!("{name}: {other:?}"),
        }
        // the samples up to 0.095 s: the one at 0.1 s needed the law
        assert_eq!(samples.len(), 20, "{name}");
    }
}

/// Runs `m` from rest under gravity with `feedback`, keeping each sample's `q` and `u`.
#[allow(clippy::type_complexity)]
fn simulate_streaming_collect(
    m: &Model<LinearBasis>,
    feedback: &SampledFeedback<Pd>,
    t: &[f64],
    opts: &IntegratorOptions,
) -> (Vec<(Vec<f64>, f64)>, Option<OdeError>) {
    let mut samples = vec![];
    let summary = simulate_streaming_interruptible(
        m,
        feedback,
        &gravity(),
        None,
        &InitialState::Rest,
        t,
        opts,
        &mut |s| {
            samples.push((s.q.to_vec(), s.u[0]));
            ControlFlow::Continue(())
        },
        &|| None,
    )
    .unwrap();
    (samples, summary.error)
}
