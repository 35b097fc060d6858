//! A run that starts from a given state (`Start::State`, Python's `Robot.simulate(q0=…, qd0=…)`):
//! continuing a run from its own sample at `t₁` must land where the run itself is at `t₂` (the
//! flow of the equations of motion is a semigroup), to the integrators' tolerance; dropping the
//! velocity must not. A bad start is refused naming the field.

use gvs::inputs::Signal;
use gvsrom::simulate::{self, InputSource, IntegratorChoice, Request, Start, TrajectoryBuffer};

mod common;

/// Tight tolerances, so that the comparison measures the start, not the integrators' error.
fn tight() -> IntegratorChoice {
    IntegratorChoice {
        rtol: Some(1e-9),
        atol: Some(1e-11),
        ..IntegratorChoice::default()
    }
}

fn request(duration: f64, start: Start) -> Request {
    Request {
        duration,
        sample_rate: 50.0,
        input: InputSource::Rows(Signal::constant(&[-4.0])),
        start,
        load_schedule: None,
        integrator: tight(),
    }
}

fn run(built: &gvsrom::Built, request: Request) -> TrajectoryBuffer {
    common::run_to_buffer(built, request)
}

/// Sample `k`'s row of a (samples × width) buffer.
fn row(v: &[f64], width: usize, k: usize) -> Vec<f64> {
    v[k * width..(k + 1) * width].to_vec()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

#[test]
fn a_run_continued_from_its_own_state_lands_where_the_run_does() {
    let built = gvsrom::build(&gvsrom::presets::load("single-tendon", &[]).unwrap()).unwrap();
    let n = built.n_dof();
    // 0.4 s of the pulled arm from rest (samples every 0.02 s), and the same from its state at
    // 0.2 s, mid-swing: moving fast, so that the velocity matters
    let whole = run(&built, request(0.4, Start::Rest));
    let mid = 10;
    assert!((whole.t[mid] - 0.2).abs() < 1e-12);
    let (q1, qd1) = (row(&whole.q, n, mid), row(&whole.qd, n, mid));
    let speed = qd1.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!(
        speed > 1.0,
        "the arm is still moving at 0.2 s: ‖q̇‖ = {speed}"
    );
    let continued = run(
        &built,
        request(
            0.2,
            Start::State {
                q: q1.clone(),
                qd: qd1,
            },
        ),
    );
    let last = continued.t.len() - 1;
    assert_eq!(continued.t.len(), 11);
    assert_eq!(
        row(&continued.q, n, 0),
        q1,
        "the first sample is the given state"
    );
    let tip_whole = row(&whole.tip_position, 3, whole.t.len() - 1);
    let tip_continued = row(&continued.tip_position, 3, last);
    let length = 0.25;
    let gap = distance(&tip_whole, &tip_continued);
    assert!(
        gap < 1e-6 * length,
        "the continued run's tip at 0.4 s is {gap:e} m from the whole run's"
    );
    let dq = distance(
        &row(&whole.q, n, whole.t.len() - 1),
        &row(&continued.q, n, last),
    );
    let scale = row(&whole.q, n, whole.t.len() - 1)
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt();
    assert!(dq < 1e-5 * scale, "‖Δq‖ = {dq:e} against ‖q‖ = {scale:e}");

    // the velocity is used: the same q at rest goes elsewhere
    let at_rest = run(
        &built,
        request(
            0.2,
            Start::State {
                q: q1,
                qd: vec![0.0; n],
            },
        ),
    );
    let off = distance(&tip_whole, &row(&at_rest.tip_position, 3, last));
    assert!(
        off > 1e3 * gap.max(1e-12) && off > 1e-4 * length,
        "dropping q̇ moves the tip at 0.4 s by only {off:e} m"
    );
}

#[test]
fn a_bad_start_is_refused_naming_the_field() {
    let built = gvsrom::build(&gvsrom::presets::load("single-tendon", &[]).unwrap()).unwrap();
    let n = built.n_dof();
    let refused = |q: Vec<f64>, qd: Vec<f64>| {
        simulate::prepare(&built, request(0.1, Start::State { q, qd }))
            .err()
            .expect("the start is refused")
            .to_string()
    };
    let e = refused(vec![0.0; n - 1], vec![0.0; n]);
    assert!(
        e.contains("q0") && e.contains(&format!("{}", n - 1)) && e.contains(&format!("{n}")),
        "{e}"
    );
    let e = refused(vec![0.0; n], vec![0.0; n + 2]);
    assert!(
        e.contains("qd0") && e.contains(&format!("{}", n + 2)),
        "{e}"
    );
    let mut qd = vec![0.0; n];
    qd[3] = f64::NAN;
    let e = refused(vec![0.0; n], qd);
    assert!(e.contains("qd0[3]") && e.contains("NaN"), "{e}");
    let mut q = vec![0.0; n];
    q[0] = f64::INFINITY;
    let e = refused(q, vec![0.0; n]);
    assert!(e.contains("q0[0]") && e.contains("finite"), "{e}");
}
