//! Simulated dynamics against invariants and closed forms (gvs-spec §9.4, §10.5): the inverse-dynamics
//! identity, energy conservation without damping (gravity on), monotone energy decay with damping,
//! convergence of damped motion to the statics solution, and free-vibration periods against the
//! linearized eigenproblem and beam theory.

mod common;

use common::clamped_rod_10_5;
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::inputs::Signal;
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::SectionProps;
use gvs::solve::dynamics::{
    fixed_step_in_second_order, simulate, InitialState, IntegratorOptions, Method, OdeJacobian,
};
use gvs::solve::ode::{FixedStepOptions, NdfOptions};
use gvs::solve::statics::{solve_statics, StaticsOptions};
use gvs::strain::{LinearBasis, SigmoidBend, StrainParam};
use nalgebra::DVector;
use std::f64::consts::PI;

fn arm(damping: f64, friction: f64) -> Model<LinearBasis> {
    common::iva_arm(damping, friction)
}

fn gravity() -> Loads {
    Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    }
}

fn ndf(rtol: f64, atol: f64) -> IntegratorOptions {
    IntegratorOptions {
        method: Method::Ndf(NdfOptions {
            rtol,
            atol,
            ..NdfOptions::default()
        }),
        jacobian: OdeJacobian::Structured,
    }
}

fn samples(t_end: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

#[test]
fn inverse_dynamics_identity_holds() {
    // ID(q, q̇, q̈) + τ(q, q̇) = M q̈ − K q for a model without tendons or damping (spec §7.8)
    let m = arm(0.0, 0.0);
    let n = m.n_dof();
    let q = DVector::from_fn(n, |i, _| 0.3 * ((i as f64) * 0.7).sin());
    let qd = DVector::from_fn(n, |i, _| 1.5 * ((i as f64) * 1.3).cos());
    let qdd = DVector::from_fn(n, |i, _| 4.0 * ((i as f64) * 0.4 + 1.0).sin());
    let loads = m.prepare_loads(&gravity()).unwrap();
    let mut ws = m.workspace();
    let id = m.inverse_dynamics(&q, &qd, &qdd, &loads, &mut ws);
    let mut tau = DVector::zeros(n);
    m.dynamic_forces(&q, &qd, &[0.0], &loads, &mut ws, &mut tau);
    let mass = m.mass_matrix(&q, &mut ws);
    let rhs = &mass * &qdd - m.stiffness().unwrap() * &q;
    let err = (&id + &tau - &rhs).amax() / rhs.amax();
    assert!(err < 1e-12, "ID + τ − (M q̈ − K q): {err:e}");
}

#[test]
fn energy_is_conserved_without_damping_and_actuation() {
    // released straight under gravity: kinetic, elastic and gravitational energy are exchanged, the
    // total stays constant up to the integrator's tolerance
    let m = arm(0.0, 0.0);
    let t = samples(0.5, 50);
    let sim = simulate(
        &m,
        &Signal::constant(&[0.0]),
        &gravity(),
        None,
        &InitialState::Rest,
        &t,
        &ndf(1e-9, 1e-12),
    )
    .unwrap();
    assert!(sim.error.is_none(), "{:?}", sim.error);
    let mut ws = m.workspace();
    let e: Vec<_> = sim
        .trajectory
        .q
        .iter()
        .zip(&sim.trajectory.qd)
        .map(|(q, qd)| m.energy(q, qd, &[0.0, 0.0, -9.81], &mut ws))
        .collect();
    let exchanged = e.iter().map(|x| x.kinetic).fold(0.0, f64::max);
    assert!(
        exchanged > 1e-4,
        "the rod moves: max kinetic energy {exchanged:e} J"
    );
    let drift = e
        .iter()
        .map(|x| (x.total() - e[0].total()).abs())
        .fold(0.0, f64::max);
    assert!(
        drift < 1e-6 * exchanged,
        "energy drift {drift:e} J vs {exchanged:e} J exchanged"
    );
}

#[test]
fn energy_decays_monotonically_with_damping() {
    let m = arm(1e4, 0.0);
    let t = samples(0.5, 100);
    let sim = simulate(
        &m,
        &Signal::constant(&[0.0]),
        &gravity(),
        None,
        &InitialState::Rest,
        &t,
        &ndf(1e-6, 1e-9),
    )
    .unwrap();
    assert!(sim.error.is_none());
    let mut ws = m.workspace();
    let e: Vec<f64> = sim
        .trajectory
        .q
        .iter()
        .zip(&sim.trajectory.qd)
        .map(|(q, qd)| m.energy(q, qd, &[0.0, 0.0, -9.81], &mut ws).total())
        .collect();
    for k in 1..e.len() {
        assert!(
            e[k] <= e[k - 1] + 1e-12,
            "energy rises at t = {}: {} -> {}",
            t[k],
            e[k - 1],
            e[k]
        );
    }
    assert!(e[0] - e.last().unwrap() > 1e-4, "energy is dissipated");
}

#[test]
fn damped_dynamics_settle_at_the_statics_solution() {
    // constant tension with friction and gravity, from straight at rest
    let m = arm(1e4, 0.88);
    let u = [-2.0];
    // the slowest mode decays at ≈ 3 /s (friction weakens the effective damping): 5 s is ~15 time constants
    let sim = simulate(
        &m,
        &Signal::constant(&u),
        &gravity(),
        None,
        &InitialState::Rest,
        &samples(5.0, 10),
        &ndf(1e-6, 1e-9),
    )
    .unwrap();
    assert!(sim.error.is_none());
    let q_static = solve_statics(&m, &u, &gravity(), None, &StaticsOptions::default())
        .unwrap()
        .q;
    let q_end = sim.trajectory.q.last().unwrap();
    let err = (q_end - &q_static).amax() / q_static.amax();
    assert!(err < 1e-4, "q(5 s) vs statics: relative {err:e}");
    // a release test: from that equilibrium, dropping the tension returns to the gravity-only state
    let sim = simulate(
        &m,
        &Signal::constant(&[0.0]),
        &gravity(),
        None,
        &InitialState::Equilibrium {
            u: u.to_vec(),
            loads: gravity(),
        },
        &samples(5.0, 10),
        &ndf(1e-6, 1e-9),
    )
    .unwrap();
    assert!(
        (&sim.trajectory.q[0] - &q_static).amax() < 1e-9,
        "starts at the equilibrium"
    );
    let q0 = solve_statics(&m, &[0.0], &gravity(), None, &StaticsOptions::default())
        .unwrap()
        .q;
    assert!((sim.trajectory.q.last().unwrap() - &q0).amax() / q0.amax() < 1e-4);
}

#[test]
fn fixed_step_method_tracks_the_adaptive_solution() {
    let m = arm(1e4, 0.0);
    let t = samples(0.3, 30);
    let opts = IntegratorOptions {
        method: Method::Fixed(FixedStepOptions {
            h: 1e-3,
            ..FixedStepOptions::default()
        }),
        jacobian: OdeJacobian::Structured,
    };
    let fixed = simulate(
        &m,
        &Signal::constant(&[-1.0]),
        &gravity(),
        None,
        &InitialState::Rest,
        &t,
        &opts,
    )
    .unwrap();
    let adaptive = simulate(
        &m,
        &Signal::constant(&[-1.0]),
        &gravity(),
        None,
        &InitialState::Rest,
        &t,
        &ndf(1e-8, 1e-11),
    )
    .unwrap();
    let dz = fixed
        .trajectory
        .tip
        .iter()
        .zip(&adaptive.trajectory.tip)
        .map(|(a, b)| (a.pos - b.pos).norm())
        .fold(0.0, f64::max);
    // BDF2 with h = 1 ms on a motion with a ~0.05 s time scale: O(h²) ≈ 1e-4 relative of 0.1 m
    assert!(dz < 2e-4, "max tip distance fixed vs adaptive {dz:e} m");
}

/// Runs `m` from `initial` for 0.1 s with the fixed step `h = 2 ms` in the form `second_order`
/// asks for; the trajectory's `q`.
fn fixed_run<P: StrainParam>(
    m: &Model<P>,
    initial: &InitialState,
    second_order: bool,
) -> Vec<DVector<f64>> {
    let opts = IntegratorOptions {
        method: Method::Fixed(FixedStepOptions {
            h: 2e-3,
            second_order,
            ..FixedStepOptions::default()
        }),
        jacobian: OdeJacobian::Structured,
    };
    let u = vec![0.0; m.n_actuators()];
    let sim = simulate(
        m,
        &Signal::constant(&u),
        &gravity(),
        None,
        initial,
        &samples(0.1, 10),
        &opts,
    )
    .unwrap();
    assert!(sim.error.is_none(), "{:?}", sim.error);
    sim.trajectory.q
}

#[test]
fn a_nonlinear_strain_parameterization_runs_the_fixed_step_in_first_order_form() {
    // a decoder's reduced model jumped to a spurious root in the second-order form: the driver
    // keeps the first-order form for any nonlinear parameterization, whatever the options say
    let rod = common::iva_rod(1e4);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 12 }], MagnusOrder::Z4, &[]).unwrap();
    let p = SigmoidBend::new(&disc);
    let sigmoid = Model::new(rod, disc, p, vec![]).unwrap();
    let given = InitialState::Given {
        q: DVector::from_vec(vec![1.2, 7.0, 0.4]),
        qd: DVector::zeros(3),
    };
    assert!(!fixed_step_in_second_order(
        &sigmoid,
        &FixedStepOptions::default()
    ));
    let (asked_second, first) = (
        fixed_run(&sigmoid, &given, true),
        fixed_run(&sigmoid, &given, false),
    );
    assert!(
        (&first[10] - &first[0]).amax() > 1e-3,
        "the rod does not move: the test is vacuous"
    );
    for (a, b) in asked_second.iter().zip(&first) {
        assert_eq!(a, b, "the same form, the same iterates");
    }
    // a linear basis does run the two forms (the same discrete solution, reached otherwise)
    let linear = arm(1e4, 0.0);
    assert!(fixed_step_in_second_order(
        &linear,
        &FixedStepOptions::default()
    ));
    let (second, first) = (
        fixed_run(&linear, &InitialState::Rest, true),
        fixed_run(&linear, &InitialState::Rest, false),
    );
    let differ = second.iter().zip(&first).any(|(a, b)| a != b);
    assert!(
        differ,
        "the two forms gave identical iterates on a linear basis"
    );
}

/// Free vibration of a uniform clamped rod (spec §10.5) started in a single eigenmode; the period is
/// measured from the upward zero crossings of the modal coordinate.
#[test]
fn free_vibration_periods_match_eigenproblem_and_beam_theory() {
    let (m, mat) = clamped_rod_10_5();
    let (l, r, e, rho) = (0.5, 0.005, mat.youngs_modulus, mat.density);
    let n = m.n_dof();
    let mut ws = m.workspace();
    let mass = m.mass_matrix(&DVector::zeros(n), &mut ws);
    let modes = m
        .linearized_modes(
            &DVector::zeros(n),
            &[],
            &m.prepare_loads(&Loads::default()).unwrap(),
            &mut ws,
        )
        .unwrap();
    let s = SectionProps::circular(&mat, r);
    let eb = |beta_l: f64| beta_l * beta_l / (2.0 * PI * l * l) * (s.es[1] / (rho * s.area)).sqrt();
    let (f_eb, f_eb2) = (eb(1.875_104_068_711_96), eb(4.694_091_132_974_17));
    let f_torsion = (mat.shear_modulus() / rho).sqrt() / (4.0 * l);
    let f_axial = (e / rho).sqrt() / (4.0 * l);
    // first two bending modes (Euler–Bernoulli), torsion and axial fundamentals, each within 1 % of
    // its closed form
    for (target, tol_theory) in [
        (f_eb, 0.01),
        (f_eb2, 0.01),
        (f_torsion, 0.01),
        (f_axial, 0.01),
    ] {
        // the eigenmode nearest the target frequency
        let nearest = modes
            .iter()
            .min_by(|a, b| {
                (a.frequency_hz - target)
                    .abs()
                    .total_cmp(&(b.frequency_hz - target).abs())
            })
            .unwrap();
        let f_eig = nearest.frequency_hz;
        let mode = nearest.shape.clone();
        let q0 = &mode * (1e-3 / mode.amax());
        let period = 1.0 / f_eig;
        let t = samples(2.5 * period, 500);
        let sim = simulate(
            &m,
            &Signal::constant(&[]),
            &Loads::default(),
            None,
            &InitialState::Given {
                q: q0.clone(),
                qd: DVector::zeros(n),
            },
            &t,
            // atol = 1e-4 of the 1e-3 amplitude: tighter values only make the integrator resolve the
            // undamped high-frequency shear modes that the geometric nonlinearity excites at tiny levels
            &ndf(1e-6, 1e-7),
        )
        .unwrap();
        assert!(sim.error.is_none());
        // modal amplitude a(t) = modeᵀ M q(t) / modeᵀ M mode; crossings of a from − to + by linear interpolation
        let mm = &mass * &mode;
        let norm = mode.dot(&mm);
        let amp: Vec<f64> = sim.trajectory.q.iter().map(|q| q.dot(&mm) / norm).collect();
        let mut crossings = vec![];
        for j in 1..amp.len() {
            if amp[j - 1] < 0.0 && amp[j] >= 0.0 {
                crossings
                    .push(t[j - 1] + (t[j] - t[j - 1]) * (-amp[j - 1]) / (amp[j] - amp[j - 1]));
            }
        }
        assert!(
            crossings.len() >= 2,
            "need two upward crossings, got {crossings:?}"
        );
        let measured = 1.0 / (crossings[1] - crossings[0]);
        assert!(
            ((measured - f_eig) / f_eig).abs() < 1e-3,
            "simulated {measured} Hz vs eigenproblem {f_eig} Hz"
        );
        assert!(
            ((measured - target) / target).abs() < tol_theory,
            "simulated {measured} Hz vs theory {target} Hz"
        );
    }
}

#[test]
fn streaming_sink_sees_the_same_samples_and_can_stop_the_run() {
    use gvs::solve::dynamics::simulate_streaming;
    use gvs::solve::ode::OdeError;
    use std::ops::ControlFlow;
    let m = arm(1e4, 0.0);
    let u = Signal::constant(&[-2.0]);
    let t_out = samples(1.0, 20);
    let full = simulate(
        &m,
        &u,
        &gravity(),
        None,
        &InitialState::Rest,
        &t_out,
        &ndf(1e-6, 1e-9),
    )
    .unwrap();
    assert_eq!(full.trajectory.t.len(), t_out.len());
    // the sink breaks after the 6th sample: the run ends there, reported as Stopped at that time
    let mut seen: Vec<(f64, Vec<f64>)> = vec![];
    let summary = simulate_streaming(
        &m,
        &u,
        &gravity(),
        None,
        &InitialState::Rest,
        &t_out,
        &ndf(1e-6, 1e-9),
        &mut |s| {
            seen.push((s.t, s.q.to_vec()));
            assert_eq!(s.strain.len(), m.disc.n_points());
            if seen.len() == 6 {
                ControlFlow::Break("enough".into())
            } else {
                ControlFlow::Continue(())
            }
        },
    )
    .unwrap();
    assert_eq!(summary.samples, 6);
    assert_eq!(summary.t_last, Some(t_out[5]));
    match summary.error {
        Some(OdeError::Stopped { t, ref reason }) => {
            assert_eq!(t, t_out[5]);
            assert_eq!(reason, "enough");
        }
        ref other => panic!("expected Stopped, got {other:?}"),
    }
    // the work up to the stop is counted: fewer steps than the whole run, but some
    assert!(
        summary.stats.steps > 0 && summary.stats.steps < full.stats.steps,
        "{:?} of {:?}",
        summary.stats,
        full.stats
    );
    assert!(summary.stats.rhs_evals > summary.stats.steps);
    // the samples before the stop are those of the uninterrupted run, bit for bit
    for (k, (t, q)) in seen.iter().enumerate() {
        assert_eq!(*t, full.trajectory.t[k]);
        assert_eq!(q.as_slice(), full.trajectory.q[k].as_slice());
    }
}
