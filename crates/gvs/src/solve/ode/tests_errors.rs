//! Tests of the failure paths: NaN, blow-up, right-hand side errors, step limits, invalid input.

use super::tests::{forced_rhs, linspace, ndf, sys};
use super::*;
use nalgebra::DVector;

#[test]
fn nan_rhs_stops_with_nonfinite_near_the_nan_and_keeps_earlier_outputs() {
    let mut s = sys(1, |t, y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy[0] = if t > 0.5 { f64::NAN } else { -y[0] }
    });
    let t_out = linspace(0.0, 1.0, 11);
    let (out, r) = ndf(&mut s, &[1.0], &t_out, &[], &NdfOptions::default());
    let e = r.unwrap_err();
    assert!(matches!(e, OdeError::NonFinite { .. }), "{e}");
    let tr = e.t_reached().unwrap();
    assert!((tr - 0.5).abs() < 1e-6 && tr <= 0.5, "t_reached = {tr}");
    let delivered: Vec<f64> = out.iter().map(|(t, _)| *t).collect();
    assert!(delivered.len() >= 5 && delivered.iter().all(|&t| t <= tr));
    assert_eq!(delivered[..5], t_out[..5]);
    for (t, y) in &out {
        assert!(y[0].is_finite() && (y[0] - (-t).exp()).abs() < 1e-2);
    }
}

#[test]
fn blow_up_stops_before_the_singularity() {
    // y' = y², y(0) = 1: y = 1/(1 − t). With the default rtol the global error moves the numerical
    // singularity slightly earlier; with rtol 1e-6 the integration gets within 1e-3 of t = 1.
    for (o, t_min, y09_tol) in [
        (NdfOptions::default(), 0.95, 1.0),
        (
            NdfOptions {
                rtol: 1e-6,
                atol: 1e-9,
                ..Default::default()
            },
            0.999,
            1e-2,
        ),
    ] {
        let mut s = sys(1, |_t, y: &DVector<f64>, dy: &mut DVector<f64>| {
            dy[0] = y[0] * y[0]
        });
        let (out, r) = ndf(&mut s, &[1.0], &[0.0, 0.5, 0.9, 2.0], &[], &o);
        let e = r.unwrap_err();
        println!("y' = y^2, rtol {}: {e}", o.rtol);
        assert!(
            matches!(
                e,
                OdeError::StepSizeUnderflow { .. }
                    | OdeError::NonFinite { .. }
                    | OdeError::NewtonFailure { .. }
            ),
            "{e}"
        );
        let tr = e.t_reached().unwrap();
        assert!(tr < 1.0 && tr > t_min, "t_reached = {tr}");
        assert_eq!(out.len(), 3);
        assert!(
            (out[2].1[0] - 10.0).abs() < y09_tol,
            "y(0.9) = {}",
            out[2].1[0]
        );
    }
}

#[test]
fn bad_input_is_rejected_without_panic() {
    let mut s = sys(1, forced_rhs);
    let y0 = DVector::from_vec(vec![1.0]);
    let good = NdfOptions::default();
    let mut run = |y0: &DVector<f64>, t_out: &[f64], bps: &[f64], o: &NdfOptions| {
        integrate_ndf(&mut s, 0.0, y0, t_out, bps, o, &mut |_, _| {
            std::ops::ControlFlow::Continue(())
        })
        .unwrap_err()
        .error
    };
    let cases: Vec<(&str, OdeError)> = vec![
        (
            "rtol",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    rtol: 0.0,
                    ..good.clone()
                },
            ),
        ),
        (
            "rtol",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    rtol: -1e-3,
                    ..good.clone()
                },
            ),
        ),
        (
            "rtol",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    rtol: f64::NAN,
                    ..good.clone()
                },
            ),
        ),
        (
            "atol",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    atol: 0.0,
                    ..good.clone()
                },
            ),
        ),
        (
            "atol_components",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    atol_components: Some(vec![1e-6, 1e-6]),
                    ..good.clone()
                },
            ),
        ),
        (
            "max_order",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    max_order: 0,
                    ..good.clone()
                },
            ),
        ),
        (
            "max_order",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    max_order: 6,
                    ..good.clone()
                },
            ),
        ),
        (
            "initial_step",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    initial_step: Some(-1.0),
                    ..good.clone()
                },
            ),
        ),
        (
            "max_step",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    max_step: f64::NAN,
                    ..good.clone()
                },
            ),
        ),
        (
            "max_steps",
            run(
                &y0,
                &[1.0],
                &[],
                &NdfOptions {
                    max_steps: 0,
                    ..good.clone()
                },
            ),
        ),
        ("t_out", run(&y0, &[1.0, 0.5], &[], &good)),
        ("t_out", run(&y0, &[0.5, 0.5], &[], &good)),
        ("t_out", run(&y0, &[-1.0, 1.0], &[], &good)),
        ("t_out", run(&y0, &[], &[], &good)),
        ("t_out", run(&y0, &[f64::NAN], &[], &good)),
        ("breakpoints", run(&y0, &[1.0], &[0.6, 0.3], &good)),
        ("breakpoints", run(&y0, &[1.0], &[f64::INFINITY], &good)),
        (
            "y0",
            run(&DVector::from_vec(vec![f64::NAN]), &[1.0], &[], &good),
        ),
        (
            "y0",
            run(&DVector::from_vec(vec![1.0, 2.0]), &[1.0], &[], &good),
        ),
    ];
    for (field, e) in cases {
        assert!(
            matches!(&e, OdeError::Invalid { field: f, .. } if *f == field),
            "expected Invalid({field}), got {e}"
        );
        assert_eq!(e.t_reached(), None);
    }
    // A NaN right-hand side at t0 is NonFinite, not a panic.
    let mut s = sys(1, |_t, _y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy[0] = f64::NAN
    });
    let (_, r) = ndf(&mut s, &[1.0], &[1.0], &[], &good);
    assert!(matches!(r, Err(OdeError::NonFinite { t }) if t == 0.0));
}

#[test]
fn too_many_steps_and_rhs_errors_are_reported_with_the_time_reached() {
    let mut s = sys(1, forced_rhs);
    let (out, r) = ndf(
        &mut s,
        &[1.0],
        &linspace(0.0, 10.0, 11),
        &[],
        &NdfOptions {
            max_steps: 5,
            ..Default::default()
        },
    );
    let e = r.unwrap_err();
    assert!(
        matches!(e, OdeError::TooManySteps { max_steps: 5, .. }),
        "{e}"
    );
    assert!(out.iter().all(|(t, _)| *t <= e.t_reached().unwrap()));

    struct Failing;
    impl OdeSystem for Failing {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) -> Result<(), RhsError> {
            if t > 0.3 {
                return Err(RhsError("model failed".into()));
            }
            dy[0] = -y[0];
            Ok(())
        }
    }
    let (out, r) = ndf(
        &mut Failing,
        &[1.0],
        &linspace(0.0, 1.0, 11),
        &[],
        &NdfOptions::default(),
    );
    let e = r.unwrap_err();
    assert!(
        matches!(&e, OdeError::Rhs { source, .. } if source.0 == "model failed"),
        "{e}"
    );
    let tr = e.t_reached().unwrap();
    assert!(tr <= 0.3 && out.iter().all(|(t, _)| *t <= tr));
    assert!(e.to_string().contains("model failed"));
}
