//! Static stability of equilibria (`gvs::solve::stability`), against a closed form and on the case
//! that made it necessary: a full-load step from the straight rod converging onto an equilibrium
//! the rod cannot rest on.

mod common;

use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::{Material, Rod, SectionProps};
use gvs::solve::stability::divergence_at;
use gvs::solve::statics::{solve_statics, StaticsOptions};
use gvs::strain::{LinearBasis, StrainParam};

fn rod(e: f64, rho: f64, l: f64, r: f64) -> Rod {
    let mat = Material {
        youngs_modulus: e,
        poisson_ratio: 0.5,
        density: rho,
        damping: 0.0,
    };
    Rod::tapered(mat, l, r, r)
}

fn model(rod: Rod, gauss: usize, modes: [bool; 6], order: usize) -> Model<LinearBasis> {
    common::legendre_model(rod, gauss, modes, order)
}

fn gravity(g: [f64; 3]) -> Loads {
    Loads {
        gravity: g,
        ..Loads::default()
    }
}

/// Greenhill (1881): a column clamped at its foot and free at its top, standing under its own
/// weight `w` per length, buckles when `w L³ / EI` exceeds 7.8373 (the first zero of the Bessel
/// function J₋₁/₃ of `(2/3)√(w L³/EI)`). Below, the straight compressed column is stable; above,
/// it diverges. The rod stands along +x with gravity along −x; bending, elongation and shear in
/// the x–z plane (Legendre order 6, 12 Gauss points).
#[test]
fn greenhill_column_standing_under_its_own_weight_diverges_above_7_837_ei_over_l3() {
    let (e, l, r, g): (f64, f64, f64, f64) = (1e6, 1.0, 0.01, 9.81);
    let s = SectionProps::circular(
        &Material {
            youngs_modulus: e,
            poisson_ratio: 0.5,
            density: 1.0,
            damping: 0.0,
        },
        r,
    );
    let ei = s.es[1];
    // the density at which w L³/EI = 7.8373, w = ρ g A
    let rho_c = 7.8373 * ei / (g * s.area * l.powi(3));
    // one full-load step from the straight rod: it stays straight (the bending residual is zero
    // there by symmetry), the equilibrium whose stability is judged
    let one_step = StaticsOptions {
        min_increment: 1.0,
        ..StaticsOptions::default()
    };
    let planar = [false, true, false, true, false, true];
    for (factor, diverges) in [(0.9, false), (0.97, false), (1.03, true), (1.1, true)] {
        let m = model(rod(e, factor * rho_c, l, r), 12, planar, 6);
        let loads = gravity([-g, 0.0, 0.0]);
        let sol = solve_statics(&m, &[], &loads, None, &one_step).unwrap();
        let mut ws = m.workspace();
        m.forward(&sol.q, &mut ws, false);
        let tip = ws.g.last().unwrap().pos;
        assert!(
            tip[2].abs() < 1e-12,
            "factor {factor}: the column bent: {tip:?}"
        );
        let prepared = m.prepare_loads(&loads).unwrap();
        let w2 = divergence_at(&m, &sol.q, &[], &prepared, &mut m.workspace());
        assert_eq!(
            w2.is_some(),
            diverges,
            "w L³/EI = {:.3}: {w2:?}",
            7.8373 * factor
        );
        // the solver reports the same verdict
        assert_eq!(sol.divergence.is_some(), diverges);
        if let Some(w2) = w2 {
            assert!(w2 < 0.0);
        }
    }
}

/// Past Greenhill's load the straight column diverges, and the continuation from the straight rod
/// follows the straight branch through the bifurcation; the solver then displaces the column along
/// its divergent mode and finds the buckled equilibrium beside it, stable, bent to one side.
#[test]
fn greenhill_column_past_its_critical_weight_settles_buckled_to_one_side() {
    let tip = greenhill_buckled(1.3);
    // bent sideways (in z, the plane of the basis), not by a hair, and still standing
    assert!(tip[2].abs() > 0.5 && tip[0] > 0.0, "tip {tip:?}");
    // far past it the column cannot stand at all: it falls over and hangs below its clamp
    let tip = greenhill_buckled(6.5);
    assert!(tip[0] < -0.5, "tip {tip:?}");
}

/// Greenhill's column of `factor` times its critical weight, solved from the straight rod: it
/// buckled onto a stable equilibrium of lower potential than the straight column's. Its tip.
fn greenhill_buckled(factor: f64) -> [f64; 3] {
    let (e, l, r, g): (f64, f64, f64, f64) = (1e6, 1.0, 0.01, 9.81);
    let ei = e * std::f64::consts::PI * r.powi(4) / 4.0;
    let area = std::f64::consts::PI * r * r;
    let rho = factor * 7.8373 * ei / (g * area * l.powi(3));
    let m = model(
        rod(e, rho, l, r),
        12,
        [false, true, false, true, false, true],
        6,
    );
    let loads = gravity([-g, 0.0, 0.0]);
    let sol = solve_statics(&m, &[], &loads, None, &StaticsOptions::default()).unwrap();
    assert_eq!(sol.divergence, None);
    let w2 = sol.buckled.expect("the straight column buckled");
    assert!(w2 < 0.0);
    let mut ws = m.workspace();
    m.forward(&sol.q, &mut ws, false);
    let tip = ws.g.last().unwrap().pos;
    let prepared = m.prepare_loads(&loads).unwrap();
    assert_eq!(
        divergence_at(&m, &sol.q, &[], &prepared, &mut m.workspace()),
        None
    );
    // gravity is conservative: the rod came down the potential, below the straight column's
    let zero = nalgebra::DVector::zeros(m.n_dof());
    let potential = |q: &nalgebra::DVector<f64>| {
        let e = m.energy(q, &zero, &[-g, 0.0, 0.0], &mut m.workspace());
        e.elastic + e.gravitational
    };
    let straight = m.param.rest_coordinates();
    let (v_buckled, v_straight) = (potential(&sol.q), potential(&straight));
    assert!(v_buckled < v_straight, "{v_buckled} against {v_straight}");
    eprintln!(
        "{factor}×: tip {tip:?}, V {v_buckled} < {v_straight}, descent {} steps",
        sol.descent_steps
    );
    [tip[0] / l, tip[1] / l, tip[2] / l]
}

/// A soft cantilever (1 m, r = 1 cm, E = 3.3e5 Pa, 1000 kg/m³) held horizontal under gravity droops
/// to nearly vertical. One full-load dogleg step from the straight rod converges instead onto an
/// equilibrium curled up above the clamp (tip 0.16 m above it), which diverges; the solver then
/// follows the equilibria from the straight rod and lands on the hanging one, which is stable.
#[test]
fn a_soft_cantilever_under_gravity_hangs_down_rather_than_curls_up() {
    let m = model(rod(3.3e5, 1000.0, 1.0, 0.01), 5, [true; 6], 3);
    let loads = gravity([0.0, 0.0, -9.81]);
    let tip_z = |q: &nalgebra::DVector<f64>| {
        let mut ws = m.workspace();
        m.forward(q, &mut ws, false);
        ws.g.last().unwrap().pos[2]
    };
    // no continuation allowed: the full-load step's equilibrium, curled up and divergent
    let one_step = StaticsOptions {
        min_increment: 1.0,
        ..StaticsOptions::default()
    };
    let curled = solve_statics(&m, &[], &loads, None, &one_step).unwrap();
    assert!(tip_z(&curled.q) > 0.1, "tip z {}", tip_z(&curled.q));
    let w2 = curled.divergence.expect("the curled equilibrium diverges");
    assert!(w2 < -1e3, "ω² = {w2}");
    // the default solve: the hanging equilibrium, stable, reached by continuation after the
    // unstable one
    let sol = solve_statics(&m, &[], &loads, None, &StaticsOptions::default()).unwrap();
    assert!(tip_z(&sol.q) < -0.9, "tip z {}", tip_z(&sol.q));
    assert_eq!(sol.divergence, None);
    assert_eq!(sol.unstable_start, Some(w2));
    assert!(sol.continuation.is_some());
    // with the check turned off (`solver.check_stability = false`), the full-load step's curled
    // equilibrium is returned as it is, unjudged
    let unchecked = StaticsOptions {
        check_stability: false,
        ..StaticsOptions::default()
    };
    let sol = solve_statics(&m, &[], &loads, None, &unchecked).unwrap();
    assert!(tip_z(&sol.q) > 0.1, "tip z {}", tip_z(&sol.q));
    assert_eq!((sol.divergence, sol.continuation.is_none()), (None, true));
    // the same solve checked (no continuation) judged the curled equilibrium with one evaluation
    // of ∂R/∂q more (the last dogleg Jacobian's screen did not pass it): counted in its work
    let unchecked_one_step = StaticsOptions {
        check_stability: false,
        ..one_step
    };
    let same = solve_statics(&m, &[], &loads, None, &unchecked_one_step).unwrap();
    assert_eq!(same.q, curled.q);
    assert_eq!(
        curled.jacobian_evaluations,
        same.jacobian_evaluations + 1,
        "checked {} against unchecked {}",
        curled.jacobian_evaluations,
        same.jacobian_evaluations
    );
}

/// Beck's column (1952): a cantilever under a compressive *follower* force `P` at its tip keeps its
/// straight equilibrium, and its undamped vibration turns into flutter — two frequencies merge into
/// a complex pair of `ω²` — at `P L²/EI = 20.05`, not at Euler's `π²/4` of a dead force. Below,
/// the follower force raises the first frequency (the symmetric part of `K_T`, which `modes` used
/// to take, lowers it: 21 % low at `P = 5 EI/L²`). The modes of the non-symmetric `M⁻¹ K_T`
/// (`Model::linearized_modes`) against that closed form, planar (bending, elongation, shear;
/// Legendre order 8, 24 Gauss points), and against the unloaded column.
#[test]
fn becks_column_under_a_follower_force_flutters_above_20_05_ei_over_l2() {
    use gvs::loads::{Frame, PointWrench};
    let (e, l, r): (f64, f64, f64) = (1e6, 1.0, 0.01);
    let m = model(
        rod(e, 1000.0, l, r),
        24,
        [false, true, false, true, false, true],
        8,
    );
    let ei = e * std::f64::consts::PI * r.powi(4) / 4.0;
    let follower = |p: f64| Loads {
        point: vec![PointWrench {
            x: l,
            wrench: [0.0, 0.0, 0.0, -p, 0.0, 0.0],
            frame: Frame::Local,
        }],
        ..Loads::default()
    };
    let lowest = |p: f64| {
        let loads = follower(p);
        let sol = solve_statics(&m, &[], &loads, None, &StaticsOptions::default()).unwrap();
        let prepared = m.prepare_loads(&loads).unwrap();
        let modes = m
            .linearized_modes(&sol.q, &[], &prepared, &mut m.workspace())
            .unwrap();
        (modes[0].omega_squared, modes[0].omega_squared_imag)
    };
    let (w0, i0) = lowest(0.0);
    assert_eq!(i0, 0.0);
    // below the flutter load: real, and raised by the follower force
    let (w5, i5) = lowest(5.0 * ei / (l * l));
    assert_eq!(i5, 0.0);
    assert!(
        w5 > 1.3 * w0,
        "ω² {w5} at P = 5 EI/L² against {w0} unloaded"
    );
    let (w18, i18) = lowest(18.0 * ei / (l * l));
    assert!(
        i18 == 0.0 && w18 > 0.0,
        "P = 18 EI/L²: ω² = {w18} + {i18} i"
    );
    // above it: a complex pair
    let (_, i22) = lowest(22.0 * ei / (l * l));
    assert!(i22 != 0.0, "P = 22 EI/L²: no complex ω²");
    // whose two shapes (the real and imaginary parts of its eigenvector, each with φᵀMφ = 1)
    // differ and span a plane that M⁻¹K_T maps into itself: the plane of the flutter motion
    let loads = follower(22.0 * ei / (l * l));
    let sol = solve_statics(&m, &[], &loads, None, &StaticsOptions::default()).unwrap();
    let prepared = m.prepare_loads(&loads).unwrap();
    let mut ws = m.workspace();
    let modes = m.linearized_modes(&sol.q, &[], &prepared, &mut ws).unwrap();
    let (a, b) = (&modes[0].shape, &modes[1].shape);
    assert_eq!(modes[0].omega_squared_imag, -modes[1].omega_squared_imag);
    let n = m.n_dof();
    let mut jac = nalgebra::DMatrix::zeros(n, n);
    m.statics_jacobian(&sol.q, &[], &prepared, &mut ws, &mut jac);
    let mass = m.mass_matrix(&sol.q, &mut ws);
    for phi in [a, b] {
        assert!((phi.dot(&(&mass * phi)) - 1.0).abs() < 1e-8);
    }
    let basis = nalgebra::DMatrix::from_columns(&[a.clone(), b.clone()]);
    let gram = basis.transpose() * &basis;
    assert!(
        gram.determinant() > 1e-6 * gram[(0, 0)] * gram[(1, 1)],
        "the pair's shapes are parallel"
    );
    for phi in [a, b] {
        let image = mass.clone().lu().solve(&(-&jac * phi)).unwrap(); // M⁻¹ K_T φ
        let coef = gram
            .clone()
            .lu()
            .solve(&(basis.transpose() * &image))
            .unwrap();
        let rest = &image - &basis * coef;
        // (the pair is near its flutter onset, where its two vectors merge: ill-conditioned)
        assert!(
            rest.norm() < 1e-4 * image.norm(),
            "{} of {}",
            rest.norm(),
            image.norm()
        );
    }
}
