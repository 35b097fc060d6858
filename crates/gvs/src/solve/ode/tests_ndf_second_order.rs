//! The NDF in second-order form ([`integrate_ndf_second_order`]) against the first-order form of the
//! same system, a closed form, an invariant (energy) and bad input.
//!
//! The test system has a configuration-dependent mass, so that the renewal of `M` matters:
//! `T = ½ (1 + q²) q̇²`, `V = ½ k q²`, `(1 + q²) q̈ + q q̇² + k q = f(t)` (Lagrange), with energy
//! `E = T + V` conserved when `f = 0`.

use super::*;
use nalgebra::{DMatrix, DVector};
use std::ops::ControlFlow;

pub(super) struct Bead {
    k: f64,
    /// Linear damping coefficient.
    c: f64,
    /// Force after `t_step` (0 before).
    f_after: f64,
    t_step: f64,
    /// Whether `iteration_parts` returns exact `M`, `D`, `K` (else `M` only, `D = K = 0`).
    exact_parts: bool,
}

impl Bead {
    fn force(&self, t: f64) -> f64 {
        if t >= self.t_step {
            self.f_after
        } else {
            0.0
        }
    }
    fn tau(&self, t: f64, q: f64, v: f64) -> f64 {
        self.force(t) - q * v * v - self.k * q - self.c * v
    }
    fn energy(&self, y: &DVector<f64>) -> f64 {
        0.5 * (1.0 + y[0] * y[0]) * y[1] * y[1] + 0.5 * self.k * y[0] * y[0]
    }
}

impl MechanicalSystem for Bead {
    fn dim(&self) -> usize {
        1
    }
    fn residual(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        eps: &mut DVector<f64>,
    ) -> Result<(), RhsError> {
        eps[0] = (1.0 + q[0] * q[0]) * qdd[0] - self.tau(t, q[0], qd[0]);
        Ok(())
    }
    fn accelerations(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &mut DVector<f64>,
    ) -> Result<(), RhsError> {
        qdd[0] = self.tau(t, q[0], qd[0]) / (1.0 + q[0] * q[0]);
        Ok(())
    }
    fn mass(&mut self, _t: f64, q: &DVector<f64>, m: &mut DMatrix<f64>) -> Result<(), RhsError> {
        m[(0, 0)] = 1.0 + q[0] * q[0];
        Ok(())
    }
    fn iteration_parts(
        &mut self,
        _t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        m: &mut DMatrix<f64>,
        d: &mut DMatrix<f64>,
        k: &mut DMatrix<f64>,
    ) -> Result<(), RhsError> {
        let (q, v) = (q[0], qd[0]);
        m[(0, 0)] = 1.0 + q * q;
        // ∂ε/∂q̇ and ∂ε/∂q at q̈ = 0 (the ∂M/∂q q̈ term is left out, as the rod's parts do)
        d[(0, 0)] = if self.exact_parts {
            2.0 * q * v + self.c
        } else {
            0.0
        };
        k[(0, 0)] = if self.exact_parts {
            v * v + self.k
        } else {
            0.0
        };
        Ok(())
    }
}

/// The same system in first-order form, `y = [q; v]`.
impl OdeSystem for Bead {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) -> Result<(), RhsError> {
        dy[0] = y[1];
        dy[1] = self.tau(t, y[0], y[1]) / (1.0 + y[0] * y[0]);
        Ok(())
    }
}

pub(super) fn bead(c: f64, f_after: f64, exact_parts: bool) -> Bead {
    Bead {
        k: 4.0,
        c,
        f_after,
        t_step: 1.5,
        exact_parts,
    }
}

fn run_second(
    sys: &mut Bead,
    t_out: &[f64],
    breaks: &[f64],
    opts: &NdfOptions,
) -> (Vec<DVector<f64>>, OdeStats) {
    let mut ys = Vec::new();
    let stats = integrate_ndf_second_order(
        sys,
        0.0,
        &DVector::from_element(1, 1.2),
        &DVector::from_element(1, 0.0),
        t_out,
        breaks,
        opts,
        &mut |_, y| {
            ys.push(y.clone());
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    (ys, stats)
}

pub(super) fn run_first(
    sys: &mut Bead,
    t_out: &[f64],
    breaks: &[f64],
    opts: &NdfOptions,
) -> Vec<DVector<f64>> {
    let mut ys = Vec::new();
    integrate_ndf(
        sys,
        0.0,
        &DVector::from_vec(vec![1.2, 0.0]),
        t_out,
        breaks,
        opts,
        &mut |_, y| {
            ys.push(y.clone());
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    ys
}

pub(super) fn t_out() -> Vec<f64> {
    (0..=120).map(|i| i as f64 * 0.05).collect()
}

pub(super) fn tight() -> NdfOptions {
    NdfOptions {
        rtol: 1e-9,
        atol: 1e-11,
        ..NdfOptions::default()
    }
}

#[test]
fn second_order_form_matches_the_first_order_form_with_a_configuration_dependent_mass() {
    // forced at t = 1.5 (a breakpoint), damped: both forms at tight tolerance agree to the
    // tolerance, whichever iteration matrix the second-order form is given
    let t = t_out();
    let first = run_first(&mut bead(0.3, 2.0, true), &t, &[1.5], &tight());
    for exact in [true, false] {
        let (second, stats) = run_second(&mut bead(0.3, 2.0, exact), &t, &[1.5], &tight());
        assert_eq!(second.len(), t.len());
        let err = first
            .iter()
            .zip(&second)
            .map(|(a, b)| (a - b).amax())
            .fold(0.0, f64::max);
        assert!(err < 1e-6, "exact parts {exact}: max |Δy| = {err:e}");
        assert!(stats.steps > 0 && stats.newton_iterations >= stats.steps);
    }
}

#[test]
fn mass_renewed_at_every_attempt_gives_the_same_solution_with_fewer_newton_failures() {
    // M(q) = 1 + q² swings between 1 and 2.4 every half period; with D = K = 0 in the iteration
    // matrix (exact_parts false) M is all that keeps Newton contracting: renewed at every attempt,
    // Newton fails less often than with M renewed only when slow (measured 0 against 3), and the
    // solution is the same up to the tolerance
    let t = t_out();
    let first = run_first(&mut bead(0.3, 2.0, true), &t, &[1.5], &tight());
    let mut failures = Vec::new();
    for renewal in [MassRenewal::WhenSlow, MassRenewal::EveryAttempt] {
        let opts = NdfOptions {
            rtol: 1e-3,
            atol: 1e-6,
            mass_renewal: renewal,
            ..NdfOptions::default()
        };
        let (second, stats) = run_second(&mut bead(0.3, 2.0, false), &t, &[1.5], &opts);
        let err = first
            .iter()
            .zip(&second)
            .map(|(a, b)| (a - b).amax())
            .fold(0.0, f64::max);
        eprintln!("{renewal:?}: max |Δy| = {err:e}, {stats:?}");
        // rtol 1e-3 over 4 periods: a global error of a few 1e-2 on |y| ≈ 1–4
        assert!(err < 0.05, "{renewal:?}: max |Δy| = {err:e}");
        assert!(stats.newton_failures <= stats.failed_steps);
        failures.push(stats.newton_failures);
    }
    assert!(
        failures[1] < failures[0],
        "Newton failures, renewed when slow and at every attempt: {failures:?}"
    );
}

#[test]
fn undamped_bead_conserves_energy() {
    let t = t_out();
    let mut sys = bead(0.0, 0.0, true);
    let e0 = sys.energy(&DVector::from_vec(vec![1.2, 0.0]));
    let (ys, _) = run_second(&mut sys, &t, &[], &tight());
    let drift = ys
        .iter()
        .map(|y| (sys.energy(y) - e0).abs() / e0)
        .fold(0.0, f64::max);
    assert!(drift < 1e-6, "relative energy drift {drift:e}");
    // and the motion is not trivial: q swings through zero to about −1.2
    let qmin = ys.iter().map(|y| y[0]).fold(f64::INFINITY, f64::min);
    assert!(qmin < -1.15, "q_min = {qmin}");
}

/// Largest error against the damped cosine of `q̈ + 0.4 q̇ + 4 q = 0` from `q = 1e-4` (small
/// amplitude, `M ≈ 1`: the `q q̇²` and `q²` terms are below 1e-8 relative), relative to the
/// amplitude, for both forms.
fn oscillator_errors(rtol: f64) -> (f64, f64) {
    let t = t_out();
    let opts = NdfOptions {
        rtol,
        atol: rtol * 1e-6,
        ..NdfOptions::default()
    };
    let (zeta_w, wd) = (0.2, (4.0f64 - 0.04).sqrt());
    let exact =
        |ti: f64| 1e-4 * (-zeta_w * ti).exp() * ((wd * ti).cos() + zeta_w / wd * (wd * ti).sin());
    let err = |ys: &[DVector<f64>]| {
        t.iter()
            .zip(ys)
            .map(|(ti, y)| (y[0] - exact(*ti)).abs() / 1e-4)
            .fold(0.0, f64::max)
    };
    let mut second = Vec::new();
    integrate_ndf_second_order(
        &mut bead(0.4, 0.0, true),
        0.0,
        &DVector::from_element(1, 1e-4),
        &DVector::from_element(1, 0.0),
        &t,
        &[],
        &opts,
        &mut |_, y| {
            second.push(y.clone());
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    let mut first = Vec::new();
    integrate_ndf(
        &mut bead(0.4, 0.0, true),
        0.0,
        &DVector::from_vec(vec![1e-4, 0.0]),
        &t,
        &[],
        &opts,
        &mut |_, y| {
            first.push(y.clone());
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    (err(&second), err(&first))
}

#[test]
fn linear_oscillator_follows_the_closed_form_as_closely_as_the_first_order_form() {
    let (e6, f6) = oscillator_errors(1e-6);
    let (e9, f9) = oscillator_errors(1e-9);
    println!("relative errors: rtol 1e-6: {e6:e} (first-order form {f6:e}); 1e-9: {e9:e} ({f9:e})");
    // the error shrinks with the tolerance (at least 100× for 1000×) ...
    assert!(e9 < 1e-2 * e6 && e9 < 1e-5, "{e6:e} → {e9:e}");
    // ... and is that of the first-order form: the same discrete equations
    assert!(
        e6 < 2.0 * f6 && e9 < 2.0 * f9,
        "{e6:e} vs {f6:e}, {e9:e} vs {f9:e}"
    );
}

#[test]
fn bad_initial_state_is_an_error_naming_it() {
    let err = integrate_ndf_second_order(
        &mut bead(0.0, 0.0, true),
        0.0,
        &DVector::from_element(2, 0.0),
        &DVector::from_element(1, 0.0),
        &[0.0, 1.0],
        &[],
        &NdfOptions::default(),
        &mut |_, _| ControlFlow::Continue(()),
    )
    .unwrap_err();
    assert!(
        matches!(err.error, OdeError::Invalid { field: "y0", .. }),
        "{err}"
    );
    // the generalized-α method checks the same way (it used to check q̇0 only)
    let err = integrate_generalized_alpha(
        &mut bead(0.0, 0.0, true),
        0.0,
        &DVector::from_element(2, 0.0),
        &DVector::from_element(1, 0.0),
        &[0.0, 1.0],
        &[],
        &GeneralizedAlphaOptions::default(),
        &mut |_, _| ControlFlow::Continue(()),
    )
    .unwrap_err();
    assert!(
        matches!(err.error, OdeError::Invalid { field: "y0", .. }),
        "{err}"
    );
}
