//! Tests of `solve::statics`.

use super::*;
use crate::discretize::{Discretization, MagnusOrder, Quadrature};
use crate::rod::{Material, Rod};
use crate::strain::{DivisionBasis, LinearBasis};

/// A uniform 0.5 m rod, r = 5 mm, E = 1e6 Pa, bending about y with a quadratic Legendre basis.
fn rod_model() -> Model<LinearBasis> {
    let mat = Material {
        youngs_modulus: 1e6,
        poisson_ratio: 0.5,
        density: 1000.0,
        damping: 0.0,
    };
    let rod = Rod::tapered(mat, 0.5, 0.005, 0.005);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 5 }], MagnusOrder::Z4, &[]).unwrap();
    let mut modes = [false; 6];
    modes[1] = true;
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes,
            orders: [0, 2, 0, 0, 0, 0],
        }],
    )
    .unwrap();
    Model::new(rod, disc, b, vec![]).unwrap()
}

fn gravity() -> Loads {
    Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    }
}

fn rejected(options: StaticsOptions) -> String {
    options.validate().unwrap_err().to_string()
}

#[test]
fn ramp_steps_above_the_limit_are_rejected_with_the_limit() {
    let ok = StaticsOptions {
        ramp_steps: MAX_RAMP_STEPS,
        ..StaticsOptions::default()
    };
    assert!(ok.validate().is_ok());
    let e = rejected(StaticsOptions {
        ramp_steps: 1_000_000_000,
        ..StaticsOptions::default()
    });
    assert!(
        e.contains("solver.ramp_steps") && e.contains("1000000000") && e.contains("[1, 10000]"),
        "{e}"
    );
    let e = rejected(StaticsOptions {
        ramp_steps: 0,
        ..StaticsOptions::default()
    });
    assert!(
        e.contains("solver.ramp_steps") && e.contains("[1, 10000]"),
        "{e}"
    );
}

#[test]
fn max_iterations_above_the_limit_are_rejected_with_the_limit() {
    let e = rejected(StaticsOptions {
        max_iterations: MAX_ITERATIONS + 1,
        ..StaticsOptions::default()
    });
    assert!(
        e.contains("solver.max_iterations") && e.contains("10001") && e.contains("[1, 10000]"),
        "{e}"
    );
}

#[test]
fn min_increment_below_the_floor_is_rejected_with_the_floor() {
    let ok = StaticsOptions {
        min_increment: MIN_INCREMENT_FLOOR,
        ..StaticsOptions::default()
    };
    assert!(ok.validate().is_ok());
    let e = rejected(StaticsOptions {
        min_increment: 1e-9,
        ..StaticsOptions::default()
    });
    assert!(
        e.contains("solver.min_increment") && e.contains("1e-9") && e.contains("[1e-6, 1]"),
        "{e}"
    );
}

#[test]
fn tolerances_below_the_round_off_or_absurdly_loose_are_rejected_with_the_range() {
    for (ftol, xtol) in [(MIN_FTOL, MIN_XTOL), (MAX_FTOL, MAX_XTOL)] {
        let ok = StaticsOptions {
            ftol,
            xtol,
            ..StaticsOptions::default()
        };
        assert!(ok.validate().is_ok(), "ftol {ftol}, xtol {xtol}");
    }
    for ftol in [1e-30, 1e-15, 0.0, 0.1, f64::NAN] {
        let e = rejected(StaticsOptions {
            ftol,
            ..StaticsOptions::default()
        });
        assert!(
            e.contains("solver.ftol") && e.contains("[1e-14, 1e-3]") && e.contains("round-off"),
            "{e}"
        );
    }
    for xtol in [1e-300, 0.0, f64::INFINITY, 0.01, 1e300] {
        let e = rejected(StaticsOptions {
            xtol,
            ..StaticsOptions::default()
        });
        assert!(
            e.contains("solver.xtol")
                && e.contains("[2.220446049250313e-16 (the machine epsilon), 1e-3]"),
            "{e}"
        );
    }
}

#[test]
fn a_solve_stops_at_its_stage_cap_with_iterations_and_residual() {
    // 10 ramp stages, capped at 3: stops at λ = 3/10 having solved 3 stages
    let model = rod_model();
    let options = StaticsOptions {
        ramp_steps: 10,
        ..StaticsOptions::default()
    };
    let mut solver = StaticsSolver::new(&model, options.clone());
    let e = solver
        .solve_within(&[], &gravity(), None, 3, MAX_TOTAL_ITERATIONS, &never_stop)
        .unwrap_err();
    match &e {
        StaticsError::NotConverged {
            load_factor,
            iterations,
            residual_norm,
            reason,
            ..
        } => {
            assert!((load_factor - 0.3).abs() < 1e-12, "{e}");
            assert!(*iterations >= 3, "{e}");
            assert!(residual_norm.is_finite(), "{e}");
            assert!(
                reason.contains("3 load stages") && reason.contains("3 stages"),
                "{e}"
            );
        }
        other => panic!("expected NotConverged, got {other}"),
    }
    // the same solve within the default caps converges
    assert!(StaticsSolver::new(&model, options)
        .solve(&[], &gravity(), None)
        .is_ok());
}

#[test]
fn a_stop_request_ends_the_ramp_before_the_next_stage() {
    // a 10-stage ramp whose stop check answers on its 5th poll: 4 stages solved, λ = 0.4
    let model = rod_model();
    let options = StaticsOptions {
        ramp_steps: 10,
        ..StaticsOptions::default()
    };
    let polls = std::cell::Cell::new(0);
    let stop = || {
        polls.set(polls.get() + 1);
        (polls.get() == 5).then(|| "interrupted by SIGINT".to_string())
    };
    let e = StaticsSolver::new(&model, options.clone())
        .solve_interruptible(&[], &gravity(), None, &stop)
        .unwrap_err();
    match &e {
        StaticsError::Stopped {
            load_factor,
            reason,
        } => {
            assert!((load_factor - 0.4).abs() < 1e-12, "{e}");
            assert_eq!(reason, "interrupted by SIGINT");
        }
        other => panic!("expected Stopped, got {other}"),
    }
    assert_eq!(polls.get(), 5);
    // a check that never answers leaves the solve as it was: the same q as `solve`
    let a = StaticsSolver::new(&model, options.clone())
        .solve_interruptible(&[], &gravity(), None, &|| None)
        .unwrap();
    let b = StaticsSolver::new(&model, options)
        .solve(&[], &gravity(), None)
        .unwrap();
    assert_eq!(a.q, b.q);
}

#[test]
fn a_stop_request_ends_the_continuation_before_its_next_step() {
    let model = rod_model();
    let mut ws = model.workspace();
    let e = continuation::follow_statics(
        &model,
        &mut ws,
        &[],
        &gravity(),
        &DoglegOptions::default(),
        &|| Some("interrupted by SIGTERM".into()),
    )
    .unwrap_err();
    match &e {
        continuation::ContinuationError::Stopped {
            why: continuation::Stop::Requested(reason),
            steps: 0,
            ..
        } => assert_eq!(reason, "interrupted by SIGTERM"),
        other => panic!("expected a requested stop before the first step, got {other}"),
    }
}

#[test]
fn a_solve_stops_at_its_iteration_cap() {
    let model = rod_model();
    let options = StaticsOptions {
        ramp_steps: 10,
        ..StaticsOptions::default()
    };
    let e = StaticsSolver::new(&model, options)
        .solve_within(&[], &gravity(), None, MAX_LOAD_STAGES, 1, &never_stop)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("did not converge") && e.contains("stages, 1 iterations)"),
        "{e}"
    );
}

/// The rod of [`rod_model`] bending about y with Legendre polynomials up to `order`
/// (`order + 1` coordinates).
fn bending_model(order: usize) -> Model<LinearBasis> {
    let m = rod_model();
    let mut modes = [false; 6];
    modes[1] = true;
    let b = LinearBasis::per_division(
        &m.disc,
        &[DivisionBasis::Legendre {
            modes,
            orders: [0, order, 0, 0, 0, 0],
        }],
    )
    .unwrap();
    Model::new(m.rod, m.disc, b, vec![]).unwrap()
}

#[test]
fn forward_differences_reach_the_analytic_jacobians_equilibrium() {
    // the Jacobian only steers the iteration: every choice must converge to the same q (to the
    // residual test) in about as many iterations as the analytic Jacobian
    let m = bending_model(0);
    assert_eq!(m.n_dof(), 1);
    // a tenth of gravity: a moderate sag that the dogleg takes in a few steps
    let light = Loads {
        gravity: [0.0, 0.0, -0.981],
        ..Loads::default()
    };
    let solve = |jacobian| {
        let options = StaticsOptions {
            jacobian,
            ..StaticsOptions::default()
        };
        StaticsSolver::new(&m, options)
            .solve(&[], &light, None)
            .unwrap()
    };
    let analytic = solve(StaticsJacobian::Analytic);
    let auto = solve(StaticsJacobian::Auto);
    let differences = solve(StaticsJacobian::Differences);
    assert!(analytic.q[0].abs() > 0.1, "the rod sags: {}", analytic.q[0]);
    for s in [&auto, &differences] {
        assert!(
            (s.q[0] - analytic.q[0]).abs() <= 1e-9 * analytic.q[0].abs(),
            "{} vs {}",
            s.q[0],
            analytic.q[0]
        );
        assert!(s.iterations <= analytic.iterations + 1);
        // one residual at the start and per trial step, and (differences) one per Jacobian (the
        // sag is stable by the last Jacobian's screen: no stability check's Jacobian, which would
        // cost no residual)
        assert_eq!(
            s.residual_evaluations,
            1 + s.iterations + s.jacobian_evaluations
        );
    }
    assert_eq!(analytic.residual_evaluations, 1 + analytic.iterations);
    // auto is differences at one coordinate, analytic above DIFFERENCE_MAX_DOF
    assert_eq!(auto.residual_evaluations, differences.residual_evaluations);
    let two = bending_model(DIFFERENCE_MAX_DOF);
    assert_eq!(two.n_dof(), DIFFERENCE_MAX_DOF + 1);
    let a = StaticsSolver::new(&two, StaticsOptions::default())
        .solve(&[], &gravity(), None)
        .unwrap();
    let b = StaticsSolver::new(
        &two,
        StaticsOptions {
            jacobian: StaticsJacobian::Analytic,
            ..StaticsOptions::default()
        },
    )
    .solve(&[], &gravity(), None)
    .unwrap();
    assert_eq!(a.q, b.q);
    assert_eq!(a.residual_evaluations, b.residual_evaluations);
}
