//! A sampled-data controller through the library (`InputSource::Feedback`, Python's
//! `controller=`, run at `control_instants`): its instants, and an integral controller on the tip
//! height of the IV-A arm, which must settle where the statics put the tip under the tension it
//! settles at.

use gvs::feedback::FeedbackLaw;
use gvs::solve::statics::{solve_statics, StaticsOptions};
use gvsrom::simulate::{self, control_instants, ControlLaw, InputSource, IntegratorChoice};
use nalgebra::DVector;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

mod common;

#[test]
fn control_instants_are_every_mth_sample_and_a_rate_off_the_samples_is_refused() {
    let t = control_instants(0.1, 100.0, 50.0).unwrap();
    assert_eq!(t, vec![0.0, 0.02, 0.04, 0.06, 0.08, 0.1]);
    assert_eq!(control_instants(0.1, 100.0, 100.0).unwrap().len(), 11);
    // a last sample at the duration, off the sample grid, is not an instant
    let t = control_instants(0.105, 100.0, 50.0).unwrap();
    assert_eq!(*t.last().unwrap(), 0.1);
    for (rate, why) in [
        (30.0, "whole fraction"),
        (200.0, "whole fraction"),
        (0.0, "> 0"),
    ] {
        let e = control_instants(0.1, 100.0, rate).unwrap_err().to_string();
        assert!(
            e.contains("--control-rate") && e.contains(why),
            "{rate}: {e}"
        );
    }
}

/// `u_{k+1} = u_k + k_i (z_tip − z_target)`: pulls harder while the tip is low.
struct Integral {
    built: gvsrom::Built,
    ws: Mutex<gvs::model::Workspace>,
    z_target: f64,
    gain: f64,
    calls: AtomicUsize,
}

impl FeedbackLaw for Integral {
    fn tensions(&self, _t: f64, q: &[f64], _qd: &[f64], u: &mut [f64]) -> Result<(), String> {
        let mut ws = self.ws.lock().unwrap();
        let model = &self.built.model;
        model.forward(&DVector::from_column_slice(q), &mut ws, false);
        let z = ws.g.last().unwrap().pos[2];
        u[0] += self.gain * (z - self.z_target);
        self.calls.fetch_add(1, Ordering::Relaxed);
        Ok(())
    }
}

#[test]
fn an_integral_controller_settles_the_tip_where_the_statics_put_it_under_the_settled_tension() {
    let built = gvsrom::build(&gvsrom::presets::load("single-tendon", &[]).unwrap()).unwrap();
    let law_built = gvsrom::build(&gvsrom::presets::load("single-tendon", &[]).unwrap()).unwrap();
    let ws = Mutex::new(law_built.model.workspace());
    let z_target = -0.02;
    let (duration, sample_rate, control_rate) = (6.0, 100.0, 20.0);
    let law = Arc::new(Integral {
        built: law_built,
        ws,
        z_target,
        // the arm's static gain is about −0.05 m/N: a tenth of the error per period
        gain: 2.0,
        calls: AtomicUsize::new(0),
    });
    let b = common::run_to_buffer(
        &built,
        simulate::Request {
            duration,
            sample_rate,
            input: InputSource::Feedback {
                law: ControlLaw(law.clone()),
                control_rate: Some(control_rate),
            },
            start: simulate::Start::Rest,
            load_schedule: None,
            integrator: IntegratorChoice {
                fixed_step: Some(2e-3),
                ..IntegratorChoice::default()
            },
        },
    );
    // at 0, 0.05, … 6 s
    assert_eq!(law.calls.load(Ordering::Relaxed), 121);
    let k = b.t.len();
    let z: Vec<f64> = (0..k).map(|i| b.tip_position[3 * i + 2]).collect();
    let u_end = b.u[k - 1];
    // the tip starts below the target (gravity), the controller pulls it up to it
    assert!(z[10] < z_target - 0.01, "tip z at 0.1 s: {}", z[10]);
    assert!(
        (z[k - 1] - z_target).abs() < 1e-4,
        "tip z at the end {} against the target {z_target}",
        z[k - 1]
    );
    assert!(u_end < -0.5, "the settled tension {u_end} N pulls");
    // the settled state is the static equilibrium under the settled tension
    let eq = solve_statics(
        &built.model,
        &[u_end],
        &built.loads,
        None,
        &StaticsOptions::default(),
    )
    .unwrap();
    let mut ws = built.model.workspace();
    built.model.forward(&eq.q, &mut ws, false);
    let z_statics = ws.g.last().unwrap().pos[2];
    assert!(
        (z[k - 1] - z_statics).abs() < 1e-5,
        "closed-loop tip z {} against the statics' {z_statics} at u = {u_end} N",
        z[k - 1]
    );
}
