//! Tests of the fixed-step BDF2 integrator.

use super::tests::{forced_exact, forced_rhs, linspace, stiff_exact, stiff_matrix, sys, Samples};
use super::*;
use nalgebra::DVector;

fn fixed<S: OdeSystem>(
    s: &mut S,
    y0: &[f64],
    t_out: &[f64],
    bps: &[f64],
    o: &FixedStepOptions,
) -> (Samples, Result<OdeStats, OdeError>) {
    let mut out = Vec::new();
    let r = integrate_fixed(
        s,
        0.0,
        &DVector::from_column_slice(y0),
        t_out,
        bps,
        o,
        &mut |t, y| {
            out.push((t, y.clone()));
            std::ops::ControlFlow::Continue(())
        },
    );
    (out, r.map_err(|f| f.error))
}

fn opts(h: f64) -> FixedStepOptions {
    FixedStepOptions {
        h,
        newton_tol: 1e-12,
        max_newton: 8,
        ..FixedStepOptions::default()
    }
}

/// Max error on `y' = −y + sin t` over `[0, 5]`, sampled off the step grid.
fn forced_fixed_error(h: f64) -> f64 {
    let mut s = sys(1, forced_rhs);
    let t_out: Vec<f64> = linspace(0.0, 5.0, 51).iter().map(|t| t * 0.999).collect();
    let (out, r) = fixed(&mut s, &[1.0], &t_out, &[], &opts(h));
    r.unwrap();
    assert_eq!(out.len(), t_out.len());
    out.iter()
        .map(|(t, y)| (y[0] - forced_exact(*t, 1.0)).abs())
        .fold(0.0, f64::max)
}

#[test]
fn fixed_step_is_second_order() {
    let e: Vec<f64> = [0.04, 0.02, 0.01, 0.005]
        .iter()
        .map(|&h| forced_fixed_error(h))
        .collect();
    println!("fixed-step errors for h = 0.04 .. 0.005: {e:?}");
    for i in 1..e.len() {
        let ratio = e[i - 1] / e[i];
        assert!(
            (3.4..=4.6).contains(&ratio),
            "halving h reduced the error by {ratio} (expected ~4)"
        );
    }
    assert!(e[3] < 1e-4);
}

#[test]
fn fixed_step_is_stable_on_the_stiff_linear_system_with_large_steps() {
    let a = stiff_matrix();
    let mut s = sys(2, move |_t, y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy.gemv(1.0, &a, y, 0.0)
    });
    let y0 = DVector::from_vec(vec![1.0, 1.0]);
    let t_out = linspace(0.0, 10.0, 101);
    let o = opts(0.01); // 100 × the fast time constant
    let (out, r) = fixed(&mut s, y0.as_slice(), &t_out, &[], &o);
    let st = r.unwrap();
    println!("fixed step on the stiff system: {st:?}");
    for (t, y) in out.iter().skip(1) {
        let ex = stiff_exact(*t, &y0);
        assert!(
            (y - &ex).amax() < 1e-3 * (-t).exp().max(1e-3),
            "t = {t}: {y} vs {ex}"
        );
    }
    assert_eq!(st.steps, 1000);
    // Linear problem: one Jacobian, a few factorizations, ~1 Newton iteration per step.
    assert_eq!(st.jacobian_evals, 1);
    assert!(st.lu_decompositions <= 3, "{st:?}");
    assert!(st.newton_iterations < 2 * st.steps + 10, "{st:?}");
}

#[test]
fn fixed_step_hits_breakpoints_exactly() {
    let u = |t: f64| {
        if t < 1.0 {
            1.0
        } else if t < 2.0 {
            -2.0
        } else {
            0.5
        }
    };
    let exact = |t: f64| {
        if t < 1.0 {
            t
        } else if t < 2.0 {
            1.0 - 2.0 * (t - 1.0)
        } else {
            -1.0 + 0.5 * (t - 2.0)
        }
    };
    let mut s = sys(1, move |t, _y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy[0] = u(t)
    });
    let t_out = linspace(0.0, 3.0, 31);
    // h = 0.3 does not divide the breakpoints: they are hit by shortened steps.
    let (out, r) = fixed(&mut s, &[0.0], &t_out, &[1.0, 2.0], &opts(0.3));
    r.unwrap();
    for (t, y) in &out {
        assert!(
            (y[0] - exact(*t)).abs() < 1e-10,
            "t = {t}: {} vs {}",
            y[0],
            exact(*t)
        );
    }
    for b in [1.0f64, 2.0] {
        assert!(s.calls.contains(&next_down(b)), "no step ended at {b}");
        assert!(!s.calls.contains(&b));
    }
}

#[test]
fn fixed_step_nonlinear_problem_reuses_the_jacobian() {
    // Van der Pol, mu = 10 (moderately stiff): compare with a tight NDF run.
    let f = |_t: f64, y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy[0] = y[1];
        dy[1] = 10.0 * (1.0 - y[0] * y[0]) * y[1] - y[0];
    };
    let t_out = linspace(0.0, 10.0, 11);
    let mut s = sys(2, f);
    let (out, r) = fixed(
        &mut s,
        &[2.0, 0.0],
        &t_out,
        &[],
        &FixedStepOptions {
            h: 1e-3,
            ..Default::default()
        },
    );
    let st = r.unwrap();
    println!("fixed step, Van der Pol mu = 10: {st:?}");
    let mut s = sys(2, f);
    let mut reference = Vec::new();
    let o = NdfOptions {
        rtol: 1e-10,
        atol: 1e-12,
        ..Default::default()
    };
    integrate_ndf(
        &mut s,
        0.0,
        &DVector::from_vec(vec![2.0, 0.0]),
        &t_out,
        &[],
        &o,
        &mut |_, y| {
            reference.push(y.clone());
            std::ops::ControlFlow::Continue(())
        },
    )
    .unwrap();
    let err = out
        .iter()
        .zip(&reference)
        .map(|((_, y), yr)| (y[0] - yr[0]).abs())
        .fold(0.0, f64::max);
    println!("max error vs. reference: {err:e}");
    assert!(err < 1e-3, "max error {err:e}");
    assert_eq!(st.steps, 10_000);
    assert!(st.jacobian_evals * 20 < st.steps, "{st:?}");
}

#[test]
fn fixed_step_failures_and_bad_options() {
    let mut s = sys(1, |t, y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy[0] = if t > 0.5 { f64::NAN } else { -y[0] }
    });
    let t_out = linspace(0.0, 1.0, 11);
    let (out, r) = fixed(&mut s, &[1.0], &t_out, &[], &opts(0.01));
    let e = r.unwrap_err();
    assert!(matches!(e, OdeError::NonFinite { .. }), "{e}");
    let tr = e.t_reached().unwrap();
    assert!((tr - 0.5).abs() < 0.011 && tr <= 0.5, "t_reached = {tr}");
    assert_eq!(out.len(), 6);
    assert!(out.iter().all(|(t, y)| (y[0] - (-t).exp()).abs() < 1e-3));

    let mut s = sys(1, forced_rhs);
    let y0 = DVector::from_vec(vec![1.0]);
    let mut run = |o: &FixedStepOptions, y0: &DVector<f64>, t_out: &[f64]| {
        integrate_fixed(&mut s, 0.0, y0, t_out, &[], o, &mut |_, _| {
            std::ops::ControlFlow::Continue(())
        })
        .unwrap_err()
        .error
    };
    let good = FixedStepOptions::default();
    for (field, e) in [
        (
            "h",
            run(
                &FixedStepOptions {
                    h: 0.0,
                    ..good.clone()
                },
                &y0,
                &[1.0],
            ),
        ),
        (
            "h",
            run(
                &FixedStepOptions {
                    h: f64::NAN,
                    ..good.clone()
                },
                &y0,
                &[1.0],
            ),
        ),
        (
            "h",
            run(
                &FixedStepOptions {
                    h: 1e-300,
                    ..good.clone()
                },
                &y0,
                &[1.0],
            ),
        ),
        (
            "newton_tol",
            run(
                &FixedStepOptions {
                    newton_tol: -1.0,
                    ..good.clone()
                },
                &y0,
                &[1.0],
            ),
        ),
        (
            "max_newton",
            run(
                &FixedStepOptions {
                    max_newton: 0,
                    ..good.clone()
                },
                &y0,
                &[1.0],
            ),
        ),
        ("t_out", run(&good, &y0, &[1.0, 0.0])),
        (
            "y0",
            run(&good, &DVector::from_vec(vec![f64::INFINITY]), &[1.0]),
        ),
    ] {
        assert!(
            matches!(&e, OdeError::Invalid { field: f, .. } if *f == field),
            "expected Invalid({field}), got {e}"
        );
    }
}

/// A model that refuses a trial state (as the rod's right-hand side refuses a `q` whose mass matrix
/// is not positive definite): a step too long for it is halved, as after a Newton failure, and the
/// run goes on; the refusal is reported only when halving cannot help. `y' = −y`, refused more than
/// 0.5 away from the exact `e^{−t}` — the first backward-Euler predictor of a 1 s step is 0.63 away.
#[test]
fn a_refused_newton_iterate_halves_the_step_instead_of_ending_the_run() {
    struct Picky;
    impl OdeSystem for Picky {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) -> Result<(), RhsError> {
            if (y[0] - (-t).exp()).abs() > 0.5 {
                return Err(RhsError("trial state refused".into()));
            }
            dy[0] = -y[0];
            Ok(())
        }
    }
    let (out, r) = fixed(&mut Picky, &[1.0], &[0.0, 3.0], &[], &opts(1.0));
    let stats = r.unwrap();
    assert!(stats.failed_steps >= 1, "{stats:?}");
    let y3 = out.last().unwrap().1[0];
    assert!((y3 - (-3.0f64).exp()).abs() < 0.05, "y(3) = {y3}");
    // refused everywhere but at the start: no halving helps, the model's error is reported
    struct Never;
    impl OdeSystem for Never {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) -> Result<(), RhsError> {
            if t > 0.0 {
                return Err(RhsError("model failed".into()));
            }
            dy[0] = -y[0];
            Ok(())
        }
    }
    let (_, r) = fixed(&mut Never, &[1.0], &[0.0, 1.0], &[], &opts(0.1));
    let e = r.unwrap_err();
    assert!(
        matches!(&e, OdeError::Rhs { source, .. } if source.0 == "model failed"),
        "{e}"
    );
}

/// The fixed step in second-order form solves the same BDF2 equations as in first-order form: on
/// a bead whose mass depends on its position (`(1 + q²) q̈ + q q̇² + k q = f(t)`), damped, forced
/// from a breakpoint, both give the same samples to the Newton tolerance, whether the
/// second-order iteration matrix is exact or `M` alone (`D = K = 0`), with `M` renewed when slow
/// or at every attempt.
#[test]
fn second_order_form_takes_the_same_bdf2_steps_as_the_first_order_form() {
    use super::tests_ndf_second_order::bead;
    let t = linspace(0.0, 3.0, 61);
    let o = opts(0.01);
    let mut ys = Vec::new();
    let first = integrate_fixed(
        &mut bead(0.3, 2.0, true),
        0.0,
        &DVector::from_vec(vec![1.2, 0.0]),
        &t,
        &[1.5],
        &o,
        &mut |_, y| {
            ys.push(y.clone());
            std::ops::ControlFlow::Continue(())
        },
    )
    .unwrap();
    let first_ys = ys;
    assert_eq!(first.failed_steps, 0, "{first:?}");
    let cases = [true, false].map(|exact| {
        [MassRenewal::WhenSlow, MassRenewal::EveryAttempt].map(|mass_renewal| (exact, mass_renewal))
    });
    for (exact, mass_renewal) in cases.into_iter().flatten() {
        let mut ys2 = Vec::new();
        let stats = integrate_fixed_second_order(
            &mut bead(0.3, 2.0, exact),
            0.0,
            &DVector::from_element(1, 1.2),
            &DVector::from_element(1, 0.0),
            &t,
            &[1.5],
            &FixedStepOptions {
                mass_renewal,
                ..o.clone()
            },
            &mut |_, y| {
                ys2.push(y.clone());
                std::ops::ControlFlow::Continue(())
            },
        )
        .unwrap();
        assert_eq!(ys2.len(), t.len());
        // the same steps: 300 of 0.01 s, none halved
        let case = format!("exact parts {exact}, {mass_renewal:?}");
        assert_eq!(stats.steps, first.steps, "{case}: {stats:?}");
        let err = first_ys
            .iter()
            .zip(&ys2)
            .map(|(a, b)| (a - b).amax())
            .fold(0.0, f64::max);
        assert!(err < 1e-9, "{case}: max |Δy| = {err:e}");
        // the forcing moved the bead: the comparison is not of two resting states
        assert!((ys2[60][0] - ys2[30][0]).abs() > 0.1, "{:?}", ys2[60]);
    }
}

/// A singular iteration matrix (`M = D = K = 0`) ends both second-order integrators with an
/// error: the cheap remedy (renewing `M`) is not retried for ever on a matrix it never reached
/// (it was, until a review on 2026-12-06 found the loop).
#[test]
fn a_singular_iteration_matrix_stops_the_second_order_forms_instead_of_looping() {
    use super::tests_galpha::Oscillators;
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let singular = || Oscillators {
            m: 0.0,
            c: 0.0,
            k: vec![0.0],
            f_after: 1.0,
            t_step: 0.0,
        };
        let (q0, v0) = (DVector::from_element(1, 0.0), DVector::from_element(1, 0.0));
        let t = [0.0, 0.1];
        let mut out = |_: f64, _: &DVector<f64>| std::ops::ControlFlow::Continue(());
        let fixed = integrate_fixed_second_order(
            &mut singular(),
            0.0,
            &q0,
            &v0,
            &t,
            &[],
            &opts(0.01),
            &mut out,
        )
        .map_err(|f| f.error);
        let ndf = integrate_ndf_second_order(
            &mut singular(),
            0.0,
            &q0,
            &v0,
            &t,
            &[],
            &NdfOptions::default(),
            &mut out,
        )
        .map_err(|f| f.error);
        tx.send((fixed.is_err(), ndf.is_err(), format!("{fixed:?} / {ndf:?}")))
            .unwrap();
    });
    let (fixed, ndf, what) = rx
        .recv_timeout(std::time::Duration::from_secs(30))
        .expect("an integrator with a singular iteration matrix did not return within 30 s");
    assert!(fixed && ndf, "{what}");
}

/// `y' = −k(t) (y − cos 10t)` with `k` switching between 1 and 10⁴ at every breakpoint, one step per piece
/// (a sampled-data controller's pattern): a Jacobian kept across a breakpoint is off by 10⁴ and
/// stalls Newton there, so after a stall it is renewed up front at the next
/// [`super::fixed::REFRESH_AFTER_STALL`] breakpoints: 11 failed attempts in 100 steps (99 without
/// the renewal). The discrete solution is the backward Euler step of each piece,
/// `y_{n+1} = (y_n + h k_n cos 10t_{n+1}) / (1 + h k_n)`, to the Newton tolerance: the rate
/// carried across a breakpoint once accepted a first correction of the wrong Jacobian (y = −97
/// for 0.0098 at t = 0.02 on `y' = −k y`, before 2026-12-07), and a first correction alone still
/// left errors of 1 % at y = 9e-9 until a second iteration measured the contraction there.
#[test]
fn a_jacobian_the_input_jumps_spoil_is_renewed_at_the_breakpoints_after_a_stall() {
    let h = 0.01;
    let bps: Vec<f64> = (1..100).map(|i| i as f64 * h).collect();
    // the piece of `t` by the breakpoints themselves (the integrator evaluates just inside them)
    let k = |t: f64| match bps.partition_point(|&b| b <= t) % 2 {
        0 => 1.0,
        _ => 1e4,
    };
    // y' = −k (y − cos 10t): y stays of order 1 and moves, so each step's Newton has work to do
    let mut s = sys(1, |t, y, dy| dy[0] = -k(t) * (y[0] - (10.0 * t).cos()));
    let t_out = linspace(0.0, 1.0, 101);
    let (out, r) = fixed(&mut s, &[1.0], &t_out, &bps, &opts(h));
    let stats = r.unwrap();
    assert_eq!(stats.steps, 100, "{stats:?}");
    assert!(stats.newton_failures <= 15, "{stats:?}");
    let mut y = 1.0;
    for (i, (t, yi)) in out.iter().enumerate().skip(1) {
        let kn = k(t - 0.5 * h);
        y = (y + h * kn * (10.0 * t).cos()) / (1.0 + h * kn);
        assert!(
            (yi[0] - y).abs() <= 1e-10,
            "step {i}: {} against {y}",
            yi[0]
        );
    }
}
