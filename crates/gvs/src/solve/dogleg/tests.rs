//! Tests of `solve::dogleg`.

use super::*;
use approx::assert_relative_eq;
use std::f64::consts::TAU;

type V = DVector<f64>;
/// A test system from plain functions; `fail` makes the residual return an error.
struct Sys {
    n: usize,
    r: fn(&V, &mut V),
    j: fn(&V, &mut DMatrix<f64>),
    fail: bool,
    scale: f64,
}
impl NonlinearSystem for Sys {
    fn dim(&self) -> usize {
        self.n
    }
    fn residual(&mut self, x: &V, f: &mut V) -> Result<(), EvalError> {
        (self.r)(x, f);
        match self.fail {
            true => Err(EvalError("contact solver diverged".into())),
            false => Ok(()),
        }
    }
    fn jacobian(&mut self, x: &V, _: &V, jac: &mut DMatrix<f64>) -> Result<(), EvalError> {
        (self.j)(x, jac);
        Ok(())
    }
    fn residual_scale(&self, _: &V) -> f64 {
        self.scale
    }
}
fn sys(n: usize, r: fn(&V, &mut V), j: fn(&V, &mut DMatrix<f64>)) -> Sys {
    Sys {
        n,
        r,
        j,
        fail: false,
        scale: 1.0,
    }
}
fn run(s: &mut Sys, x0: &[f64], opts: DoglegOptions) -> Result<DoglegReport, DoglegError> {
    let x0 = V::from_column_slice(x0);
    solve(s, &x0, &opts, &mut DoglegWorkspace::new(s.n))
}
fn ok(s: &mut Sys, x0: &[f64]) -> DoglegReport {
    let rep = run(s, x0, DoglegOptions::default()).unwrap();
    let mut f = V::zeros(s.n);
    (s.r)(&rep.x, &mut f);
    assert!(rep.residual_norm <= 1e-10 && f.amax() == rep.residual_norm);
    rep
}
fn no_broyden() -> DoglegOptions {
    DoglegOptions {
        broyden: false,
        ..Default::default()
    }
}
fn dsquare(x: &V, j: &mut DMatrix<f64>) {
    j[(0, 0)] = 2.0 * x[0];
}

fn rosenbrock() -> Sys {
    let r = |x: &V, f: &mut V| f.copy_from_slice(&[10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]]);
    let j = |x: &V, j: &mut DMatrix<f64>| j.copy_from_slice(&[-20.0 * x[0], -1.0, 10.0, 0.0]);
    sys(2, r, j)
}
/// MGH 7: F = (10(x₃ − 10θ), 10(‖(x₁, x₂)‖ − 1), x₃), θ = atan(x₂/x₁)/2π (+ ½ if x₁ < 0).
fn helical_valley() -> Sys {
    fn r(x: &V, f: &mut V) {
        let theta = (x[1] / x[0]).atan() / TAU + if x[0] < 0.0 { 0.5 } else { 0.0 };
        f[0] = 10.0 * (x[2] - 10.0 * theta);
        f[1] = 10.0 * (x[0].hypot(x[1]) - 1.0);
        f[2] = x[2];
    }
    sys(3, r, |x, j| {
        let (r2, c) = (x[0] * x[0] + x[1] * x[1], 100.0 / TAU);
        let rows = [x[1] / r2, -x[0] / r2, 0.1, x[0], x[1], 0.0, 0.0, 0.0, 0.1];
        j.copy_from(&DMatrix::from_row_slice(3, 3, &rows));
        j.row_mut(0).scale_mut(c);
        j.row_mut(1).scale_mut(10.0 / r2.sqrt());
        j[(2, 2)] = 1.0;
    })
}
/// MGH 28, discrete boundary value problem; F_i = 2x_i − x_{i−1} − x_{i+1} + h²(x_i + t_i + 1)³/2.
fn discrete_bvp(n: usize) -> (Sys, Vec<f64>) {
    let h = 1.0 / (n as f64 + 1.0);
    let r = |x: &V, f: &mut V| {
        let (n, h) = (x.len(), 1.0 / (x.len() as f64 + 1.0));
        for i in 0..n {
            let xl = if i > 0 { x[i - 1] } else { 0.0 };
            let xr = x.get(i + 1).copied().unwrap_or(0.0);
            let t = (i + 1) as f64 * h;
            f[i] = 2.0 * x[i] - xl - xr + h * h * (x[i] + t + 1.0).powi(3) / 2.0;
        }
    };
    let s = sys(n, r, |x, j| {
        let (n, h) = (x.len(), 1.0 / (x.len() as f64 + 1.0));
        j.fill(0.0);
        for i in 0..n {
            j[(i, i)] = 2.0 + 1.5 * h * h * (x[i] + (i + 1) as f64 * h + 1.0).powi(2);
            if i > 0 {
                (j[(i, i - 1)], j[(i - 1, i)]) = (-1.0, -1.0);
            }
        }
    });
    let x0 = (1..=n).map(|i| i as f64 * h * (i as f64 * h - 1.0));
    (s, x0.collect())
}

#[test]
fn rosenbrock_system_converges_to_one_one() {
    let rep = ok(&mut rosenbrock(), &[-1.2, 1.0]);
    assert_relative_eq!(rep.x, V::from_column_slice(&[1.0, 1.0]), epsilon = 1e-10);
    assert!(rep.iterations > 0 && rep.jacobian_evaluations >= 1);
}

#[test]
fn powell_badly_scaled_converges_to_known_root() {
    fn r(x: &V, f: &mut V) {
        f[0] = 1e4 * x[0] * x[1] - 1.0;
        f[1] = (-x[0]).exp() + (-x[1]).exp() - 1.0001;
    }
    let j = |x: &V, j: &mut DMatrix<f64>| {
        j.copy_from_slice(&[1e4 * x[1], -(-x[0]).exp(), 1e4 * x[0], -(-x[1]).exp()])
    };
    let mut s = sys(2, r, j);
    let rep = ok(&mut s, &[0.0, 1.0]);
    assert_relative_eq!(rep.x[0], 1.098_159_329_699_76e-5, max_relative = 1e-8);
    assert_relative_eq!(rep.x[1], 9.106_146_739_867_318, max_relative = 1e-8);
}

#[test]
fn helical_valley_converges_to_one_zero_zero() {
    let rep = ok(&mut helical_valley(), &[-1.0, 0.0, 0.0]);
    let root = V::from_column_slice(&[1.0, 0.0, 0.0]);
    assert_relative_eq!(rep.x, root, epsilon = 1e-10);
}

#[test]
fn powell_singular_converges_although_jacobian_is_singular_at_root() {
    fn r(x: &V, f: &mut V) {
        f[0] = x[0] + 10.0 * x[1];
        f[1] = 5f64.sqrt() * (x[2] - x[3]);
        f[2] = (x[1] - 2.0 * x[2]).powi(2);
        f[3] = 10f64.sqrt() * (x[0] - x[3]).powi(2);
    }
    let mut s = sys(4, r, |x, j| {
        let (c, d) = (5f64.sqrt(), 2.0 * 10f64.sqrt() * (x[0] - x[3]));
        let (a, a2, mc, md) = (
            2.0 * (x[1] - 2.0 * x[2]),
            -4.0 * (x[1] - 2.0 * x[2]),
            -c,
            -d,
        );
        let rows = [
            1.0, 10.0, 0.0, 0.0, 0.0, 0.0, c, mc, 0.0, a, a2, 0.0, d, 0.0, 0.0, md,
        ];
        j.copy_from(&DMatrix::from_row_slice(4, 4, &rows));
    });
    let rep = ok(&mut s, &[3.0, -1.0, 0.0, 1.0]);
    assert!(rep.x.amax() < 1e-4, "x = {}", rep.x);
}

#[test]
fn broyden_updates_save_jacobian_evaluations_on_discrete_bvp_30() {
    let (mut s, x0) = discrete_bvp(30);
    let on = run(&mut s, &x0, DoglegOptions::default()).unwrap();
    let off = run(&mut s, &x0, no_broyden()).unwrap();
    assert!(on.residual_norm <= 1e-10 && off.residual_norm <= 1e-10);
    assert!((&on.x - &off.x).amax() < 1e-8);
    let (j_on, j_off) = (on.jacobian_evaluations, off.jacobian_evaluations);
    eprintln!("DBV(30) Jacobian evaluations: {j_on} with Broyden updates, {j_off} without");
    assert!(j_on < j_off);
}

#[test]
fn broyden_updates_correct_a_wrong_jacobian_on_a_linear_system() {
    // F = A x − b with the supplied Jacobian 2A: without updates every step is half a
    // Newton step (error × ½ per iteration); secant updates repair J within a few steps.
    const A: [f64; 9] = [4.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 2.0];
    fn r(x: &V, f: &mut V) {
        f.gemv(1.0, &DMatrix::from_row_slice(3, 3, &A), x, 0.0);
        f.add_scalar_mut(-1.0);
    }
    let mut s = sys(3, r, |_, j| {
        j.copy_from(&(DMatrix::from_row_slice(3, 3, &A) * 2.0))
    });
    let on = ok(&mut s, &[10.0, -10.0, 10.0]);
    let off = run(&mut s, &[10.0, -10.0, 10.0], no_broyden()).unwrap();
    assert!(
        on.iterations <= 10 && off.iterations >= 20,
        "{} vs {}",
        on.iterations,
        off.iterations
    );
}

#[test]
fn singular_initial_jacobian_falls_back_to_steepest_descent() {
    // J = [[1, 1], [1, 2 x₂]] is exactly singular at x₂ = ½; the roots are (1, 2) and (4, −1).
    fn r(x: &V, f: &mut V) {
        f[0] = x[0] + x[1] - 3.0;
        f[1] = x[0] + x[1] * x[1] - 5.0;
    }
    let mut s = sys(2, r, |x, j| j.copy_from_slice(&[1.0, 1.0, 1.0, 2.0 * x[1]]));
    let rep = ok(&mut s, &[1.0, 0.5]);
    let near = |a: f64, b: f64| (rep.x[0] - a).abs() < 1e-9 && (rep.x[1] - b).abs() < 1e-9;
    assert!(near(1.0, 2.0) || near(4.0, -1.0), "x = {}", rep.x);
}

#[test]
fn system_without_root_reports_not_converged_with_residual_one() {
    let mut s = sys(1, |x, f| f[0] = x[0] * x[0] + 1.0, dsquare);
    let err = run(&mut s, &[2.0], DoglegOptions::default()).unwrap_err();
    let msg = err.to_string();
    let DoglegError::NotConverged {
        iterations: it,
        residual_norm: fn_,
        x,
        ..
    } = err
    else {
        panic!("expected NotConverged, got {msg}");
    };
    assert!(
        it > 0 && it < 400 && (fn_ - 1.0).abs() < 1e-6 && x[0].abs() < 1e-3,
        "{msg}"
    );
    assert!(
        msg.contains(&format!("after {it} iterations: ‖F‖∞ = 1.000e0")),
        "{msg}"
    );
    assert!(
        msg.ends_with("step size below xtol = 1.0e-12 (relative to 1 + ‖x‖∞)"),
        "{msg}"
    );
}

#[test]
fn iteration_limit_is_reported_as_not_converged() {
    let opts = DoglegOptions {
        max_iterations: 1,
        ..Default::default()
    };
    let err = run(&mut rosenbrock(), &[-1.2, 1.0], opts).unwrap_err();
    assert!(matches!(err, DoglegError::NotConverged { .. }));
    let msg = err.to_string();
    assert!(msg.contains("after 1 iterations") && msg.contains("maximum number of iterations"));
}

#[test]
fn residual_scale_sets_the_residual_tolerance() {
    // F = x² converges linearly (singular root), so a looser tolerance saves iterations.
    let mut s = sys(1, |x, f| f[0] = x[0] * x[0], dsquare);
    let tight = ok(&mut s, &[1.0]);
    s.scale = 1e6;
    let loose = run(&mut s, &[1.0], DoglegOptions::default()).unwrap();
    assert!(loose.residual_norm <= 1e-4 && loose.residual_norm > 1e-10);
    assert!(loose.iterations < tight.iterations);
}

#[test]
fn nan_residual_is_reported_as_non_finite() {
    // NaN at x0, and NaN at a trial point (the too-small Jacobian overshoots into x < 0).
    let mut s = sys(1, |x, f| f[0] = x[0].sqrt() - 0.5, |_, j| j[(0, 0)] = 0.1);
    let msg = "non-finite value (NaN or infinity) in the residual at iteration";
    let at_x0 = run(&mut s, &[-1.0], DoglegOptions::default()).unwrap_err();
    assert!(matches!(at_x0, DoglegError::NonFinite { .. }));
    assert_eq!(at_x0.to_string(), format!("{msg} 0"));
    let at_trial = run(&mut s, &[1.0], DoglegOptions::default()).unwrap_err();
    assert_eq!(at_trial.to_string(), format!("{msg} 1"));
}

#[test]
fn nan_in_initial_point_is_reported_as_non_finite() {
    let x0 = [f64::NAN, 1.0];
    let err = run(&mut rosenbrock(), &x0, DoglegOptions::default()).unwrap_err();
    assert!(matches!(err, DoglegError::NonFinite { .. }));
    assert!(
        err.to_string().contains("initial point at iteration 0"),
        "{err}"
    );
}

#[test]
fn infinite_jacobian_is_reported_as_non_finite() {
    let mut s = sys(
        1,
        |x, f| f[0] = x[0] - 1.0,
        |_, j| j[(0, 0)] = f64::INFINITY,
    );
    let err = run(&mut s, &[0.0], DoglegOptions::default()).unwrap_err();
    assert!(matches!(err, DoglegError::NonFinite { .. }));
    assert!(err.to_string().contains("in the Jacobian"), "{err}");
}

#[test]
fn evaluation_error_is_propagated() {
    let mut s = rosenbrock();
    s.fail = true;
    let err = run(&mut s, &[1.0, 1.0], DoglegOptions::default()).unwrap_err();
    assert!(matches!(err, DoglegError::Evaluation { .. }));
    assert!(
        err.to_string()
            .ends_with("iteration 0: contact solver diverged"),
        "{err}"
    );
}

#[test]
fn dimension_mismatch_is_reported() {
    let x0 = [1.0, 2.0, 3.0];
    let err = run(&mut rosenbrock(), &x0, DoglegOptions::default()).unwrap_err();
    assert!(matches!(
        err,
        DoglegError::Dimension {
            expected: 2,
            got: 3
        }
    ));
}

#[test]
fn workspace_is_reused_across_solves_of_different_sizes() {
    let (mut ws, opts) = (DoglegWorkspace::new(0), DoglegOptions::default());
    let (mut bvp, x0) = discrete_bvp(30);
    let fresh = run(&mut bvp, &x0, opts.clone()).unwrap();
    let (x0, rx0) = (V::from_vec(x0), V::from_column_slice(&[-1.2, 1.0]));
    let a = solve(&mut rosenbrock(), &rx0, &opts, &mut ws).unwrap();
    let b = solve(&mut bvp, &x0, &opts, &mut ws).unwrap();
    let hx0 = V::from_column_slice(&[-1.0, 0.0, 0.0]);
    let c = solve(&mut helical_valley(), &hx0, &opts, &mut ws).unwrap();
    let b2 = solve(&mut bvp, &x0, &opts, &mut ws).unwrap();
    assert!(a.residual_norm <= 1e-10 && c.residual_norm <= 1e-10);
    // Results do not depend on what the workspace held before.
    assert!(b.x == fresh.x && b2.x == fresh.x && b.iterations == fresh.iterations);
}

#[test]
fn converged_initial_point_returns_without_iterating() {
    let rep = ok(&mut rosenbrock(), &[1.0, 1.0]);
    let counts = (
        rep.iterations,
        rep.residual_evaluations,
        rep.jacobian_evaluations,
    );
    assert_eq!(counts, (0, 1, 0));
}
