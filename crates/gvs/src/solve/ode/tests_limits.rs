//! Tests of the integrators' limits: the accepted tolerance ranges, the tolerances named by a
//! step-size failure, and a stop request polled before every step attempt.

use super::tests::{ndf, sys};
use super::*;
use nalgebra::{DMatrix, DVector};

/// `q̈ = a(q)` with unit mass (`a` from a closure), counting the polls of
/// [`MechanicalSystem::stop_requested`] and asking to stop after `stop_after` of them.
struct Unit<A: Fn(f64) -> f64, D: Fn(f64) -> f64> {
    /// The acceleration `a(q)`.
    a: A,
    /// `da/dq`.
    da: D,
    polls: usize,
    stop_after: usize,
}

impl<A: Fn(f64) -> f64, D: Fn(f64) -> f64> Unit<A, D> {
    fn poll(&mut self) -> Option<String> {
        self.polls += 1;
        (self.polls > self.stop_after).then(|| "stop asked".to_string())
    }
}

impl<A: Fn(f64) -> f64, D: Fn(f64) -> f64> MechanicalSystem for Unit<A, D> {
    fn dim(&self) -> usize {
        1
    }
    fn residual(
        &mut self,
        _t: f64,
        q: &DVector<f64>,
        _qd: &DVector<f64>,
        qdd: &DVector<f64>,
        eps: &mut DVector<f64>,
    ) -> Result<(), RhsError> {
        eps[0] = qdd[0] - (self.a)(q[0]);
        Ok(())
    }
    fn accelerations(
        &mut self,
        _t: f64,
        q: &DVector<f64>,
        _qd: &DVector<f64>,
        qdd: &mut DVector<f64>,
    ) -> Result<(), RhsError> {
        qdd[0] = (self.a)(q[0]);
        Ok(())
    }
    fn mass(&mut self, _t: f64, _q: &DVector<f64>, m: &mut DMatrix<f64>) -> Result<(), RhsError> {
        m[(0, 0)] = 1.0;
        Ok(())
    }
    fn iteration_parts(
        &mut self,
        _t: f64,
        q: &DVector<f64>,
        _qd: &DVector<f64>,
        m: &mut DMatrix<f64>,
        d: &mut DMatrix<f64>,
        k: &mut DMatrix<f64>,
    ) -> Result<(), RhsError> {
        m[(0, 0)] = 1.0;
        d[(0, 0)] = 0.0;
        k[(0, 0)] = -(self.da)(q[0]);
        Ok(())
    }
    fn stop_requested(&mut self) -> Option<String> {
        self.poll()
    }
}

/// The same system in first-order form `y = [q; q̇]`.
impl<A: Fn(f64) -> f64, D: Fn(f64) -> f64> OdeSystem for Unit<A, D> {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) -> Result<(), RhsError> {
        dy[0] = y[1];
        dy[1] = (self.a)(y[0]);
        Ok(())
    }
    fn stop_requested(&mut self) -> Option<String> {
        self.poll()
    }
}

/// The unit oscillator `q̈ = −(2π)² q` (period 1 s).
fn oscillator(stop_after: usize) -> Unit<impl Fn(f64) -> f64, impl Fn(f64) -> f64> {
    let w2 = (2.0 * std::f64::consts::PI).powi(2);
    Unit {
        a: move |q| -w2 * q,
        da: move |_| -w2,
        polls: 0,
        stop_after,
    }
}

/// Every adaptive integrator (and the fixed step, `tol` unused) on `sys` from `q = 1` at rest, with
/// `rtol`, `atol`; each result with the output times delivered.
#[allow(clippy::type_complexity)]
fn every_integrator<A: Fn(f64) -> f64, D: Fn(f64) -> f64>(
    make: &dyn Fn() -> Unit<A, D>,
    t_out: &[f64],
    rtol: f64,
    atol: f64,
) -> Vec<(&'static str, Vec<f64>, Result<OdeStats, OdeFailure>, usize)> {
    let q0 = DVector::from_element(1, 1.0);
    let qd0 = DVector::zeros(1);
    let y0 = DVector::from_vec(vec![1.0, 0.0]);
    let ndf_opts = NdfOptions {
        rtol,
        atol,
        ..Default::default()
    };
    let mut results = vec![];
    let mut run = |name: &'static str,
                   f: &mut dyn FnMut(
        &mut Unit<A, D>,
        &mut Output<'_>,
    ) -> Result<OdeStats, OdeFailure>| {
        let mut s = make();
        let mut delivered = vec![];
        let r = f(&mut s, &mut |t, _| {
            delivered.push(t);
            std::ops::ControlFlow::Continue(())
        });
        results.push((name, delivered, r, s.polls));
    };
    run("ndf", &mut |s, out| {
        integrate_ndf(s, 0.0, &y0, t_out, &[], &ndf_opts, out)
    });
    run("ndf second order", &mut |s, out| {
        integrate_ndf_second_order(s, 0.0, &q0, &qd0, t_out, &[], &ndf_opts, out)
    });
    run("sdirk", &mut |s, out| {
        let o = SdirkOptions {
            rtol,
            atol,
            ..Default::default()
        };
        integrate_sdirk(s, 0.0, &q0, &qd0, t_out, &[], &o, out)
    });
    run("galpha", &mut |s, out| {
        let o = GeneralizedAlphaOptions {
            rtol,
            atol,
            ..Default::default()
        };
        integrate_generalized_alpha(s, 0.0, &q0, &qd0, t_out, &[], &o, out)
    });
    run("fixed", &mut |s, out| {
        integrate_fixed(s, 0.0, &y0, t_out, &[], &FixedStepOptions::default(), out)
    });
    results
}

#[test]
fn a_stop_request_ends_every_integrator_at_the_next_attempt_between_output_times() {
    // one output at t = 0 and the next 1000 periods away: only the per-attempt poll can stop it
    let t_out = [0.0, 1000.0];
    for (name, delivered, r, polls) in every_integrator(&|| oscillator(20), &t_out, 1e-6, 1e-9) {
        let e = r.expect_err(name).error;
        assert!(
            matches!(&e, OdeError::Stopped { reason, .. } if reason == "stop asked"),
            "{name}: {e}"
        );
        // stopped at the 21st poll, i.e. within 21 attempts, far before the next output
        assert_eq!(polls, 21, "{name}");
        let t = e.t_reached().unwrap();
        assert!(t > 0.0 && t < 1.0, "{name}: stopped at t = {t}");
        assert_eq!(delivered, vec![0.0], "{name}");
    }
    // without a request the same runs reach the end
    let t_out = [0.0, 0.5];
    for (name, delivered, r, _) in every_integrator(&|| oscillator(usize::MAX), &t_out, 1e-6, 1e-9)
    {
        r.expect(name);
        assert_eq!(delivered, t_out, "{name}");
    }
}

#[test]
fn tolerances_outside_their_range_are_refused_by_every_adaptive_method() {
    let t_out = [0.0, 0.01];
    let bad = [
        (1e-13, 1e-6, "rtol", "[1e-12, 1)"),
        (1e-30, 1e-6, "rtol", "[1e-12, 1)"),
        (0.0, 1e-6, "rtol", "[1e-12, 1)"),
        (1.0, 1e-6, "rtol", "[1e-12, 1)"),
        (f64::NAN, 1e-6, "rtol", "[1e-12, 1)"),
        (1e-3, 0.0, "atol", "a finite number > 0"),
        (1e-3, -1e-6, "atol", "a finite number > 0"),
        (1e-3, f64::INFINITY, "atol", "a finite number > 0"),
        (1e-3, f64::NAN, "atol", "a finite number > 0"),
    ];
    for (rtol, atol, field, range) in bad {
        for (name, delivered, r, _) in
            every_integrator(&|| oscillator(usize::MAX), &t_out, rtol, atol)
        {
            if name == "fixed" {
                continue; // no tolerances
            }
            let e = r.expect_err(name).error;
            assert!(
                matches!(&e, OdeError::Invalid { field: f, message } if *f == field && message.contains(range)),
                "{name}, rtol {rtol}, atol {atol}: expected `{field}` with {range}, got {e}"
            );
            assert!(delivered.is_empty(), "{name}: nothing is integrated");
        }
    }
    // per-component tolerances: the entry is named
    let mut s = oscillator(usize::MAX);
    let (_, r) = ndf(
        &mut s,
        &[1.0, 0.0],
        &t_out,
        &[],
        &NdfOptions {
            atol_components: Some(vec![1e-6, -1e-20]),
            ..Default::default()
        },
    );
    let e = r.unwrap_err().to_string();
    assert!(
        e.contains("atol_components") && e.contains("entry 1") && e.contains("-1e-20"),
        "{e}"
    );
    // the ends of the ranges are accepted
    for (name, _, r, _) in every_integrator(&|| oscillator(usize::MAX), &t_out, MIN_RTOL, 1e-14) {
        r.expect(name);
    }
    for (name, _, r, _) in every_integrator(&|| oscillator(usize::MAX), &t_out, 0.9, 1.0) {
        r.expect(name);
    }
}

#[test]
fn a_step_size_failure_names_the_tolerances_in_use() {
    // y' = y², y(0) = 1 blows up at t = 1: the NDF's steps shrink to the time resolution there
    let mut s = sys(1, |_t, y: &DVector<f64>, dy: &mut DVector<f64>| {
        dy[0] = y[0] * y[0]
    });
    let o = NdfOptions {
        rtol: 1e-6,
        atol: 1e-9,
        ..Default::default()
    };
    let (_, r) = ndf(&mut s, &[1.0], &[0.0, 2.0], &[], &o);
    let e = r.unwrap_err();
    assert!(
        matches!(e, OdeError::StepSizeUnderflow { rtol, atol, .. } if rtol == 1e-6 && atol == 1e-9),
        "{e}"
    );
    let msg = e.to_string();
    assert!(
        msg.contains("rtol = 1e-6") && msg.contains("atol = 1e-9"),
        "{msg}"
    );
    // q̈ = 6q² from q = 1 at rest blows up too (near t = 1.214): every method's steps shrink to
    // the resolution likewise
    for (name, _, r, _) in every_integrator(
        &|| Unit {
            a: |q: f64| 6.0 * q * q,
            da: |q: f64| 12.0 * q,
            polls: 0,
            stop_after: usize::MAX,
        },
        &[0.0, 2.0],
        1e-5,
        1e-8,
    ) {
        if name == "fixed" {
            continue;
        }
        let e = r.expect_err(name).error;
        assert!(
            matches!(e, OdeError::StepSizeUnderflow { .. }),
            "{name}: {e}"
        );
        let msg = e.to_string();
        assert!(
            msg.contains("rtol = 1e-5") && msg.contains("atol = 1e-8"),
            "{name}: {msg}"
        );
    }
}

#[test]
fn a_newton_failure_of_an_adaptive_method_names_its_tolerances() {
    let e = OdeError::NewtonFailure {
        t: 0.5,
        tolerances: Some((1e-12, 1e-14)),
    };
    let msg = e.to_string();
    assert!(
        msg.contains("t = 0.5") && msg.contains("rtol = 1e-12") && msg.contains("atol = 1e-14"),
        "{msg}"
    );
    assert_eq!(e.t_reached(), Some(0.5));
    let fixed = OdeError::NewtonFailure {
        t: 0.5,
        tolerances: None,
    };
    assert!(!fixed.to_string().contains("rtol"), "{fixed}");
}
