//! A run driven by a function of time (`InputSource::Function`, Python's callable input) through
//! the library: the integrator must evaluate the function, for the full model as for a reduced
//! one. A function that returns the rows' held values gives the rows' trajectory.

use gvs::error::ModelError;
use gvs::inputs::{Actuation, Interpolation, Signal};
use gvsrom::simulate::{
    self, InputFunction, InputSource, IntegratorChoice, Request, TrajectoryBuffer,
};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

mod common;

/// `u(t) = -4 N` for `t ≥ 0.05 s`, else 0, counting its calls.
struct Step {
    calls: AtomicUsize,
}

impl Actuation for Step {
    fn eval(&self, t: f64, out: &mut [f64]) {
        self.calls.fetch_add(1, Ordering::Relaxed);
        out.fill(if t >= 0.05 { -4.0 } else { 0.0 });
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        (t0 < 0.05 && 0.05 < t1)
            .then_some(0.05)
            .into_iter()
            .collect()
    }
    fn validate(&self, _field: &str, _channels: usize) -> Result<(), ModelError> {
        Ok(())
    }
}

fn run(built: &gvsrom::Built, input: InputSource) -> TrajectoryBuffer {
    common::run_to_buffer(
        built,
        Request {
            duration: 0.2,
            sample_rate: 50.0,
            input,
            start: simulate::Start::Rest,
            load_schedule: None,
            integrator: IntegratorChoice::default(),
        },
    )
}

#[test]
fn a_function_input_drives_the_full_model_as_the_same_held_rows_do() {
    let built = gvsrom::build(&gvsrom::presets::load("single-tendon", &[]).unwrap()).unwrap();
    let step = Arc::new(Step {
        calls: AtomicUsize::new(0),
    });
    let by_function = run(&built, InputSource::Function(InputFunction(step.clone())));
    assert!(
        step.calls.load(Ordering::Relaxed) > 10,
        "the integrator evaluated the function {} times",
        step.calls.load(Ordering::Relaxed)
    );
    let rows = Signal {
        times: vec![0.0, 0.05],
        values: vec![vec![0.0], vec![-4.0]],
        interpolation: Interpolation::Hold,
    };
    let by_rows = run(&built, InputSource::Rows(rows));
    assert_eq!(by_function.t, by_rows.t);
    assert_eq!(by_function.u, by_rows.u, "the recorded tensions");
    // the same steps on the same held input: the same numbers
    assert_eq!(by_function.q, by_rows.q);
    let tip_z = by_function.tip_position[by_function.tip_position.len() - 1];
    let rest = run(&built, InputSource::Rows(Signal::constant(&[0.0])));
    let rest_z = rest.tip_position[rest.tip_position.len() - 1];
    assert!(
        (tip_z - rest_z).abs() > 1e-3,
        "the pulled rod moves away from the unpulled one: tip z {tip_z} against {rest_z}"
    );
}
