//! The SDIRK4 integrator: its tableau (order conditions, L-stability), its order of convergence,
//! closed forms of free and damped oscillators with a breakpoint, and invalid options.

use super::sdirk::{A, B_HAT, C, GAMMA, STAGES};
use super::tests_galpha::{
    damped_oscillators, run_from_rest, step_response_errors, Integrator, Oscillators,
};
use super::tests_ndf_second_order::{bead, run_first, t_out, tight};
use super::*;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// The full Butcher matrix (diagonal `γ`) and the weights `b` (its last row).
fn tableau() -> (DMatrix<f64>, DVector<f64>) {
    let a = DMatrix::from_fn(STAGES, STAGES, |i, j| match i.cmp(&j) {
        std::cmp::Ordering::Greater => A[i][j],
        std::cmp::Ordering::Equal => GAMMA,
        std::cmp::Ordering::Less => 0.0,
    });
    let b = a.row(STAGES - 1).transpose();
    (a, b)
}

/// The eight order conditions up to order 4, `Σ b Φ(t) − 1/γ(t)`, for the trees of order 1–4.
fn order_defects(a: &DMatrix<f64>, b: &DVector<f64>) -> [f64; 8] {
    let one = DVector::from_element(STAGES, 1.0);
    let c = a * &one;
    let c2 = c.component_mul(&c);
    let c3 = c2.component_mul(&c);
    let ac = a * &c;
    [
        b.dot(&one) - 1.0,
        b.dot(&c) - 1.0 / 2.0,
        b.dot(&c2) - 1.0 / 3.0,
        b.dot(&ac) - 1.0 / 6.0,
        b.dot(&c3) - 1.0 / 4.0,
        b.dot(&c.component_mul(&ac)) - 1.0 / 8.0,
        b.dot(&(a * &c2)) - 1.0 / 12.0,
        b.dot(&(a * &ac)) - 1.0 / 24.0,
    ]
}

#[test]
fn tableau_is_fourth_order_with_a_third_order_embedding_and_l_stable() {
    let (a, b) = tableau();
    let c = &a * DVector::from_element(STAGES, 1.0);
    for i in 0..STAGES {
        assert!((c[i] - C[i]).abs() < 1e-15, "c_{i} = {} ≠ Σ_j a_ij", C[i]);
    }
    for (k, d) in order_defects(&a, &b).iter().enumerate() {
        assert!(d.abs() < 1e-14, "b: order condition {k} off by {d:e}");
    }
    let b_hat = DVector::from_column_slice(&B_HAT);
    let d_hat = order_defects(&a, &b_hat);
    for (k, d) in d_hat[..4].iter().enumerate() {
        assert!(d.abs() < 1e-14, "b̂: order condition {k} off by {d:e}");
    }
    // the embedding is of order 3 exactly, so the estimate does not vanish
    assert!(d_hat[4..].iter().any(|d| d.abs() > 1e-3), "{d_hat:?}");
    // R(z) = 1 + z bᵀ (I − zA)⁻¹ 1: |R(iy)| ≤ 1 (A-stable) and R(−∞) = 0 (L-stable)
    let stability = |z: nalgebra::Complex<f64>| {
        let m = DMatrix::from_fn(STAGES, STAGES, |i, j| {
            let id = if i == j { 1.0 } else { 0.0 };
            nalgebra::Complex::new(id, 0.0) - z * a[(i, j)]
        });
        let x = m
            .lu()
            .solve(&DVector::from_element(
                STAGES,
                nalgebra::Complex::new(1.0, 0.0),
            ))
            .unwrap();
        nalgebra::Complex::new(1.0, 0.0) + z * b.map(|v| nalgebra::Complex::new(v, 0.0)).dot(&x)
    };
    for k in 0..=400 {
        let y = 10f64.powf(-3.0 + 7.0 * k as f64 / 400.0);
        let r = stability(nalgebra::Complex::new(0.0, y)).norm();
        assert!(r <= 1.0 + 1e-12, "|R({y}i)| = {r}");
    }
    let r_inf = stability(nalgebra::Complex::new(-1e9, 0.0)).norm();
    assert!(r_inf < 1e-6, "|R(−10⁹)| = {r_inf:e}");
}

fn run(
    sys: &mut Oscillators,
    q0: f64,
    t_out: &[f64],
    breaks: &[f64],
    opts: &SdirkOptions,
) -> (Vec<DVector<f64>>, OdeStats) {
    let integrate: Integrator<'_> =
        &|s, t0, q, qd, t_out, b, out| integrate_sdirk(s, t0, q, qd, t_out, b, opts, out);
    run_from_rest(integrate, sys, q0, t_out, breaks)
}

/// `ω = 2π` from `q = 1` at rest: `q = cos 2πt`.
fn unit_oscillator() -> Oscillators {
    Oscillators {
        m: 2.0,
        c: 0.0,
        k: vec![2.0 * (2.0 * PI).powi(2)],
        f_after: 0.0,
        t_step: f64::INFINITY,
    }
}

/// Largest `|q − cos 2πt|` and `|q̇ + 2π sin 2πt|/(2π)` over the outputs.
fn cosine_error(t_out: &[f64], ys: &[DVector<f64>]) -> f64 {
    t_out
        .iter()
        .zip(ys)
        .map(|(t, y)| {
            let w = 2.0 * PI;
            (y[0] - (w * t).cos())
                .abs()
                .max((y[1] + w * (w * t).sin()).abs() / w)
        })
        .fold(0.0, f64::max)
}

#[test]
fn constant_steps_converge_at_fourth_order() {
    // one period with h = 1/10 and 1/20 (error test out of the way): the error falls by 2⁴
    let t_out: Vec<f64> = (0..=20).map(|i| i as f64 * 0.05).collect();
    let err = |h: f64| {
        let opts = SdirkOptions {
            rtol: 0.9,
            atol: 10.0,
            initial_step: Some(h),
            max_step: h,
            ..Default::default()
        };
        let (ys, stats) = run(&mut unit_oscillator(), 1.0, &t_out, &[], &opts);
        assert_eq!(stats.steps, (1.0 / h).round() as usize, "{stats:?}");
        cosine_error(&t_out, &ys)
    };
    let (e1, e2) = (err(0.1), err(0.05));
    let order = (e1 / e2).log2();
    assert!(
        (3.7..4.5).contains(&order),
        "errors {e1:e} (h = 0.1), {e2:e} (h = 0.05): observed order {order}"
    );
}

#[test]
fn free_undamped_oscillator_follows_the_cosine() {
    // ten periods at rtol 1e-6, outputs between the steps by the quintic Hermite interpolant
    let t_out: Vec<f64> = (0..=200).map(|i| i as f64 * 0.05).collect();
    let opts = SdirkOptions {
        rtol: 1e-6,
        atol: 1e-9,
        ..Default::default()
    };
    let (ys, stats) = run(&mut unit_oscillator(), 1.0, &t_out, &[], &opts);
    let worst = cosine_error(&t_out, &ys);
    assert!(worst < 1e-5, "max error {worst:e} ({stats:?})");
}

#[test]
fn tolerance_tenfold_tighter_lowers_the_error() {
    let t_out: Vec<f64> = (0..=40).map(|i| i as f64 * 0.05).collect();
    let err = |rtol: f64| {
        let opts = SdirkOptions {
            rtol,
            atol: rtol * 1e-3,
            ..Default::default()
        };
        let (ys, _) = run(&mut unit_oscillator(), 1.0, &t_out, &[], &opts);
        cosine_error(&t_out, &ys)
    };
    let (e3, e5) = (err(1e-3), err(1e-5));
    assert!(e5 < 0.1 * e3, "rtol 1e-3: {e3:e}, rtol 1e-5: {e5:e}");
}

#[test]
fn damped_oscillators_with_a_step_force_match_the_closed_form() {
    let (mut sys, t_out) = damped_oscillators();
    let opts = SdirkOptions {
        rtol: 1e-7,
        atol: 1e-10,
        ..Default::default()
    };
    let (ys, _) = run(&mut sys, 0.0, &t_out, &[0.5], &opts);
    for (j, worst) in step_response_errors(&sys, &t_out, &ys).iter().enumerate() {
        assert!(
            *worst < 1e-5,
            "oscillator {j}: max error {worst:e} of the static deflection"
        );
    }
}

#[test]
fn invalid_options_are_refused_with_the_field() {
    let mut sys = unit_oscillator();
    for (opts, field) in [
        (
            SdirkOptions {
                rtol: 0.0,
                ..Default::default()
            },
            "rtol",
        ),
        (
            SdirkOptions {
                atol: -1.0,
                ..Default::default()
            },
            "atol",
        ),
        (
            SdirkOptions {
                max_step: 0.0,
                ..Default::default()
            },
            "max_step",
        ),
        (
            SdirkOptions {
                initial_step: Some(f64::NAN),
                ..Default::default()
            },
            "initial_step",
        ),
    ] {
        let e = integrate_sdirk(
            &mut sys,
            0.0,
            &DVector::zeros(1),
            &DVector::zeros(1),
            &[0.0, 1.0],
            &[],
            &opts,
            &mut |_, _| ControlFlow::Continue(()),
        )
        .unwrap_err();
        assert!(e.to_string().contains(field), "{e}");
    }
}

#[test]
fn after_a_newton_failure_the_mass_matrix_follows_the_stages() {
    // The bead of `tests_ndf_second_order`, M(q) = 1 + q², swings from q = 1.2 through 0 every
    // half period, so M moves between 2.44 and 1 within a few steps; given D = K = 0 for its
    // iteration matrix (exact_parts false), M is all that keeps Newton contracting. After a Newton
    // failure each stage renews M at its configuration: measured 2 Newton failures in 57 steps
    // (7 Jacobians), against 7 in 62 (25 Jacobians) with M kept from the start of the step. The
    // run still solves the same equations: the tight first-order solution within the
    // tolerance's global error.
    let t = t_out();
    let reference = run_first(&mut bead(0.3, 2.0, true), &t, &[1.5], &tight());
    let opts = SdirkOptions {
        rtol: 1e-4,
        atol: 1e-7,
        ..Default::default()
    };
    let mut ys = Vec::new();
    let mut sys = bead(0.3, 2.0, false);
    let (q0, qd0) = (DVector::from_element(1, 1.2), DVector::from_element(1, 0.0));
    let stats = integrate_sdirk(&mut sys, 0.0, &q0, &qd0, &t, &[1.5], &opts, &mut |_, y| {
        ys.push(y.clone());
        ControlFlow::Continue(())
    })
    .unwrap();
    let err = reference
        .iter()
        .zip(&ys)
        .map(|(a, b)| (a - b).amax())
        .fold(0.0, f64::max);
    assert_eq!(ys.len(), t.len());
    assert!(err < 5e-3, "max |Δy| = {err:e} ({stats:?})");
    // Newton did fail (the renewal ran), seldom, and the iteration matrix was seldom re-evaluated
    assert!(stats.newton_failures >= 1, "{stats:?}");
    assert!(stats.jacobian_evals < 15, "{stats:?}");
    assert!(
        stats.newton_failures * 10 < stats.steps,
        "{} Newton failures in {} steps ({stats:?})",
        stats.newton_failures,
        stats.steps
    );
}
