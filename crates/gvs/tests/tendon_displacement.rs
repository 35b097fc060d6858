//! Tendons driven by their displacement ([`gvs::solve::tendon_drive`]) against closed forms and
//! against tension-driven statics: the tension a straight tendon needs to be wound in by `δ`, an
//! antagonistic pair held, co-contracting or going slack, and a round trip through the tensions
//! on a 3-D arm with friction, helical routing and gravity. Expected values are formulas written
//! here or the tension-driven solver's, never the drive's own.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::{DivisionGeometry, Material, Rod, SectionProps};
use gvs::solve::never_stop;
use gvs::solve::statics::{solve_statics, StaticsError, StaticsOptions};
use gvs::solve::tendon_drive::{solve_driven, solve_driven_within, Drive};
use gvs::strain::{DivisionBasis, LinearBasis};
mod common;

const R: f64 = 0.01;
/// The driven span's length: the first division.
const XE: f64 = 0.1;

fn material() -> Material {
    Material {
        youngs_modulus: 1e6,
        poisson_ratio: 0.5,
        density: 1000.0,
        damping: 0.0,
    }
}

/// A uniform rod of radius `R` in two divisions, `[0, XE]` and `[XE, 0.25]`, all six strains on
/// Legendre polynomials of order 2, with `tendons`.
fn two_division_rod(tendons: Vec<Tendon>) -> Model<LinearBasis> {
    let rod = Rod {
        material: material(),
        divisions: [XE, 0.15]
            .iter()
            .map(|&length| DivisionGeometry {
                length,
                radius_start: R,
                radius_end: R,
                material: None,
                section: None,
            })
            .collect(),
    };
    let quad = vec![Quadrature::Gauss { n: 8 }; 2];
    let disc = Discretization::new(&rod, &quad, MagnusOrder::Z4, &[]).unwrap();
    let basis = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [2; 6],
    };
    let b = LinearBasis::per_division(&disc, &[basis.clone(), basis]).unwrap();
    Model::new(rod, disc, b, tendons).unwrap()
}

/// A frictionless tendon at the constant offset `[0, d]` over the first division.
fn straight_tendon(d: f64) -> Tendon {
    Tendon {
        offset_start: [0.0, d],
        offset_end: [0.0, d],
        x_start: 0.0,
        x_end: XE,
        friction: 0.0,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    }
}

/// `1/EA` and `d²/EI` of the rod's section.
fn compliances(d: f64) -> (f64, f64) {
    let s = SectionProps::circular(&material(), R);
    (1.0 / s.es[3], d * d / s.es[1])
}

fn drive(m: &Model<LinearBasis>, drives: &[Drive]) -> gvs::solve::tendon_drive::DrivenSolution {
    solve_driven(
        m,
        &StaticsOptions::default(),
        drives,
        &Loads::default(),
        &never_stop,
    )
    .unwrap()
}

/// A tendon at the constant offset `d` under the tension `u` bends its span uniformly, `κ = u d/EI`,
/// and compresses it, `ε = u/EA`, so its length is `X_e (1 + u (1/EA + d²/EI))` at any curvature
/// (`tendon_lengths.rs`). Wound in by `δ` it needs `u = −δ / (X_e (1/EA + d²/EI))`; paid out, it
/// is slack and the rod straight.
#[test]
fn a_tendon_wound_in_by_delta_pulls_delta_over_its_compliance() {
    let d = 0.005;
    let m = two_division_rod(vec![straight_tendon(d)]);
    let (a, b) = compliances(d);
    // up to a tip turn of 0.5 rad over the span
    for delta in [1e-5, 1e-3, 5e-3] {
        let sol = drive(&m, &[Drive::Displacement(delta)]);
        let exact = -delta / (XE * (a + b));
        assert!(
            ((sol.u[0] - exact) / exact).abs() < 1e-8,
            "δ = {delta}: u = {} vs {exact}",
            sol.u[0]
        );
        assert!(!sol.slack[0]);
        let length = m.tendon_lengths(&sol.statics.q, &mut m.workspace())[0];
        assert!(
            (length - (XE - delta)).abs() <= 1e-9 * 0.25,
            "δ = {delta}: ℓ = {length}"
        );
        // Newton on the tensions: the tendon's length is affine in u here, so one update lands
        assert!(
            sol.drive_iterations <= 2,
            "{} updates",
            sol.drive_iterations
        );
    }
    // paid out: slack, the rod straight
    let sol = drive(&m, &[Drive::Displacement(-1e-3)]);
    assert_eq!(sol.u[0], 0.0);
    assert!(sol.slack[0]);
    assert!(sol.statics.q.amax() < 1e-12, "q = {}", sol.statics.q);
    // held at its rest length on the unloaded rod: at its length without tension, taut, not slack
    let sol = drive(&m, &[Drive::Displacement(0.0)]);
    assert_eq!(sol.u[0], 0.0);
    assert!(!sol.slack[0]);
    // a tension limit below the 1.77 N that 5 mm needs: refused at the limit, in a few updates
    let e = solve_driven_within(
        &m,
        &StaticsOptions::default(),
        &[Drive::Displacement(5e-3)],
        &Loads::default(),
        &[1.0],
        &never_stop,
    )
    .unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("tendon 0 needs more than its tension limit |u| = 1.0000 N"),
        "{text}"
    );
    assert!(
        matches!(e, StaticsError::DriveNotReached { iterations, .. } if iterations <= 2),
        "{e:?}"
    );
}

/// An elastic thread (axial stiffness `EA_t`) stretches by `c_t |u|`, `c_t = X_e / EA_t`
/// ([`Model::tendon_compliances`]): wound in by `δ`, the path is `X_e − δ + c_t |u|` long, so the
/// tendon pulls `u = −δ / (X_e (1/EA + d²/EI) + c_t)`, the rod and the thread springs in series;
/// paid out it is slack, as the inextensible one.
#[test]
fn an_elastic_tendon_wound_in_pulls_through_rod_and_thread_in_series() {
    let d = 0.005;
    let ea_t = 150.0;
    let m = two_division_rod(vec![Tendon {
        axial_stiffness: Some(ea_t),
        ..straight_tendon(d)
    }]);
    let (a, b) = compliances(d);
    let c_t = XE / ea_t;
    assert!((m.tendon_compliances()[0] - c_t).abs() < 1e-15);
    // the thread is as compliant as the rod here: a quarter to three quarters of δ is stretch
    assert!(c_t > 0.3 * XE * (a + b) && c_t < 3.0 * XE * (a + b));
    for delta in [1e-4, 3e-3] {
        let sol = drive(&m, &[Drive::Displacement(delta)]);
        let exact = -delta / (XE * (a + b) + c_t);
        assert!(
            ((sol.u[0] - exact) / exact).abs() < 1e-8,
            "δ = {delta}: u = {} vs {exact}",
            sol.u[0]
        );
        let length = m.tendon_lengths(&sol.statics.q, &mut m.workspace())[0];
        let stretched = XE - delta - c_t * sol.u[0];
        assert!(
            (length - stretched).abs() <= 1e-9 * 0.25,
            "δ = {delta}: ℓ = {length} vs {stretched}"
        );
    }
    let sol = drive(&m, &[Drive::Displacement(-1e-3)]);
    assert_eq!(sol.u[0], 0.0);
    assert!(sol.slack[0]);
}

/// Two tendons at `±d` over the same span: `ℓ_0,1 = X_e (1 + a (u₀ + u₁) ± b (u₀ − u₁))` with
/// `a = 1/EA`, `b = d²/EI`. Winding in tendon 0 by `δ₀` while tendon 1 is held (`δ₁ = 0`) makes
/// tendon 1 pull too (its path lengthens where `b > a`: co-contraction); paid out by more than its
/// path lengthens it goes slack, and tendon 0 pulls alone.
#[test]
fn an_antagonistic_pair_held_co_contracts_and_paid_out_goes_slack() {
    let d = 0.008;
    let m = two_division_rod(vec![straight_tendon(d), straight_tendon(-d)]);
    let (a, b) = compliances(d);
    assert!(
        b > a * 2.0,
        "a case where holding the antagonist makes it pull"
    );
    let delta0 = 2e-3;
    // both taut: a s + b t = −δ₀/X_e, a s − b t = −δ₁/X_e, s = u₀ + u₁, t = u₀ − u₁
    let taut = |delta1: f64| {
        let s = -(delta0 + delta1) / (2.0 * a * XE);
        let t = -(delta0 - delta1) / (2.0 * b * XE);
        [(s + t) / 2.0, (s - t) / 2.0]
    };
    // tendon 1's path lengthens by δ₀ (b − a)/(a + b) while tendon 0 pulls alone
    let lengthens = delta0 * (b - a) / (a + b);
    for delta1 in [0.0, -0.5 * lengthens] {
        let exact = taut(delta1);
        assert!(exact[0] < 0.0 && exact[1] < 0.0, "both pull: {exact:?}");
        let sol = drive(
            &m,
            &[Drive::Displacement(delta0), Drive::Displacement(delta1)],
        );
        for k in 0..2 {
            assert!(
                ((sol.u[k] - exact[k]) / exact[k]).abs() < 1e-8,
                "δ₁ = {delta1}: u = {:?} vs {exact:?}",
                sol.u
            );
        }
        assert_eq!(sol.slack, [false, false]);
    }
    let sol = drive(
        &m,
        &[
            Drive::Displacement(delta0),
            Drive::Displacement(-1.5 * lengthens),
        ],
    );
    let alone = -delta0 / (XE * (a + b));
    assert!(((sol.u[0] - alone) / alone).abs() < 1e-8, "u = {:?}", sol.u);
    assert_eq!(sol.u[1], 0.0);
    assert_eq!(sol.slack, [false, true]);
    let lengths = m.tendon_lengths(&sol.statics.q, &mut m.workspace());
    assert!(
        ((lengths[1] - XE) - lengthens).abs() < 1e-10,
        "the slack tendon's path: {} vs {lengthens}",
        lengths[1] - XE
    );
    // a tension drive and a displacement drive together: tendon 1 given the tension found above
    let held = taut(0.0);
    let sol = drive(&m, &[Drive::Displacement(delta0), Drive::Tension(held[1])]);
    assert!(
        ((sol.u[0] - held[0]) / held[0]).abs() < 1e-8,
        "u = {:?}",
        sol.u
    );
    assert_eq!(sol.u[1], held[1]);
}

/// The 3-D IV-A arm with three frictional tendons (oblique, helical, offset) under gravity: the
/// lengths of a tension-driven equilibrium, asked for as displacements, give back its tensions
/// and its `q`; a third tendon paid out 1 mm past its free path goes slack (the free solution),
/// wound in 1 mm more it pulls.
#[test]
fn displacements_of_a_tension_driven_equilibrium_give_back_its_tensions() {
    let tendon = |d0: [f64; 2], d1: [f64; 2], turns: f64| Tendon {
        offset_start: d0,
        offset_end: d1,
        x_start: 0.0,
        x_end: 0.25,
        friction: 0.88,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns,
        path: Vec::new(),
        axial_stiffness: None,
    };
    let tendons = vec![
        tendon([0.0, 0.01], [0.0, 0.003], 0.0),
        tendon([0.008, 0.0], [0.003, 0.0], 0.25),
        tendon([-0.006, -0.006], [-0.002, -0.002], 0.0),
    ];
    let m = common::iva_rod_3d(0.0, 10, &[], tendons);
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    };
    let options = StaticsOptions::default();
    let u0 = [-1.5, -0.6, -0.3];
    let reference = solve_statics(&m, &u0, &loads, None, &options).unwrap();
    let rest = m.tendon_rest_lengths();
    let lengths = m.tendon_lengths(&reference.q, &mut m.workspace());
    let delta: Vec<f64> = (0..3).map(|k| rest[k] - lengths[k]).collect();
    assert!(delta[0] > 1e-3, "a visible winding: {delta:?}");
    let drives = [
        Drive::Displacement(delta[0]),
        Drive::Displacement(delta[1]),
        Drive::Tension(u0[2]),
    ];
    let sol = solve_driven(&m, &options, &drives, &loads, &never_stop).unwrap();
    for k in 0..3 {
        assert!(
            (sol.u[k] - u0[k]).abs() < 1e-6 * u0[k].abs(),
            "u = {:?} vs {u0:?}",
            sol.u
        );
    }
    assert!((&sol.statics.q - &reference.q).amax() < 1e-7 * reference.q.amax());
    // Newton's quadratic convergence: a wrong ∂ℓ/∂u would take many more
    assert!(
        sol.drive_iterations <= 6,
        "{} updates",
        sol.drive_iterations
    );
    // with tendon 2 free (u₂ = 0) its path has some length ℓ₂; paid out 1 mm past it, tendon 2 is
    // slack and the solution is the free one's; wound in 1 mm short of it, tendon 2 pulls
    let free = [drives[0], drives[1], Drive::Tension(0.0)];
    let free = solve_driven(&m, &options, &free, &loads, &never_stop).unwrap();
    let free_path = m.tendon_lengths(&free.statics.q, &mut m.workspace())[2];
    let check = solve_statics(&m, &free.u, &loads, None, &options).unwrap();
    let lengths = m.tendon_lengths(&check.q, &mut m.workspace());
    for k in 0..2 {
        assert!(
            (rest[k] - lengths[k] - delta[k]).abs() < 1e-8,
            "tendon {k} wound in by {} vs {}",
            rest[k] - lengths[k],
            delta[k]
        );
    }
    for (change, slack) in [(-1e-3, true), (1e-3, false)] {
        let drives = [
            drives[0],
            drives[1],
            Drive::Displacement(rest[2] - free_path + change),
        ];
        let sol = solve_driven(&m, &options, &drives, &loads, &never_stop).unwrap();
        assert_eq!(sol.slack, [false, false, slack], "u = {:?}", sol.u);
        if slack {
            assert_eq!(sol.u[2], 0.0);
            assert!((&sol.statics.q - &free.statics.q).amax() < 1e-9);
        } else {
            assert!(sol.u[2] < 0.0, "u = {:?}", sol.u);
        }
    }
}

/// A displacement of the tendon's whole rest length, or not finite, is refused naming the drive.
#[test]
fn impossible_displacements_are_refused_naming_the_drive() {
    let m = two_division_rod(vec![straight_tendon(0.005)]);
    for delta in [XE, -2.0 * XE, f64::NAN] {
        let e = solve_driven(
            &m,
            &StaticsOptions::default(),
            &[Drive::Displacement(delta)],
            &Loads::default(),
            &never_stop,
        )
        .unwrap_err();
        assert!(matches!(e, StaticsError::Model(_)), "{e}");
        assert!(e.to_string().contains("drives[0]"), "{e}");
    }
    let e = solve_driven(
        &m,
        &StaticsOptions::default(),
        &[],
        &Loads::default(),
        &never_stop,
    )
    .unwrap_err();
    assert!(matches!(e, StaticsError::ActuatorCount { .. }), "{e}");
}
