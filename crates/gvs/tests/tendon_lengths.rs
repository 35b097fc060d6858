//! Tendon lengths and spans against closed forms (gvs-spec §7.6): the routed length of a tendon on
//! the straight rod (oblique and helical), its shortening under its own tension, the exact load of
//! a tendon whose span ends inside a division, and `∂ℓ/∂q` against central differences and the
//! frictionless actuation matrix. Expected values are formulas written here.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::model::Model;
use gvs::rod::{DivisionGeometry, Material, Rod, SectionProps};
use gvs::solve::statics::{solve_statics, StaticsOptions};
use gvs::strain::{DivisionBasis, LinearBasis};
use nalgebra::{DVector, Rotation3};
use std::f64::consts::PI;
mod common;

const E: f64 = 1e6;
const R: f64 = 0.01;

fn material() -> Material {
    Material {
        youngs_modulus: E,
        poisson_ratio: 0.5,
        density: 1000.0,
        damping: 0.0,
    }
}

/// A uniform rod of radius `R` made of divisions of the given lengths, each with all six strains
/// on Legendre polynomials of order `order` and `gauss` Gauss points.
fn rod_model(
    divisions: &[f64],
    order: usize,
    gauss: usize,
    tendons: Vec<Tendon>,
) -> Model<LinearBasis> {
    let rod = Rod {
        material: material(),
        divisions: divisions
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
    let quad = vec![Quadrature::Gauss { n: gauss }; divisions.len()];
    let disc = Discretization::new(&rod, &quad, MagnusOrder::Z4, &[]).unwrap();
    let basis = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [order; 6],
    };
    let b = LinearBasis::per_division(&disc, &vec![basis; divisions.len()]).unwrap();
    Model::new(rod, disc, b, tendons).unwrap()
}

/// [`rod_model`]'s parts before the model: the rod, its points and basis.
fn rod_parts(length: f64, gauss: usize) -> (Rod, Discretization, LinearBasis) {
    let rod = Rod::tapered(material(), length, R, R);
    let disc = Discretization::new(
        &rod,
        &[Quadrature::Gauss { n: gauss }],
        MagnusOrder::Z4,
        &[],
    )
    .unwrap();
    let basis = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [1; 6],
    };
    let b = LinearBasis::per_division(&disc, &[basis]).unwrap();
    (rod, disc, b)
}

/// A frictionless tendon from offset `d0` to `d1` (`[d_y, d_z]`) over `[xs, xe]`.
fn tendon(d0: [f64; 2], d1: [f64; 2], xs: f64, xe: f64) -> Tendon {
    Tendon {
        offset_start: d0,
        offset_end: d1,
        x_start: xs,
        x_end: xe,
        friction: 0.0,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    }
}

/// The equilibrium of `m` under tensions `u`, no external loads.
fn equilibrium(m: &Model<LinearBasis>, u: &[f64]) -> DVector<f64> {
    let loads = gvs::loads::Loads::default();
    solve_statics(m, u, &loads, None, &StaticsOptions::default())
        .unwrap()
        .q
}

/// The tip's rotation about the world y axis \[rad\].
fn tip_turn_y(m: &Model<LinearBasis>, q: &DVector<f64>) -> f64 {
    let mut ws = m.workspace();
    m.forward(q, &mut ws, false);
    let rot = Rotation3::from_matrix_unchecked(m.tip_pose(&ws).rot);
    rot.scaled_axis()[1]
}

/// On the straight rod a tendon is a straight line from `(0, d0)` to `(L, d1)`, of length
/// `√(L² + ‖d1 − d0‖²)`, and a helix of radius ρ and n turns has `√(L² + (2πnρ)²)`: the rest
/// lengths, and the lengths at `q = 0`.
#[test]
fn tendon_on_the_straight_rod_is_as_long_as_its_line_or_helix() {
    let l = 0.25;
    let oblique = tendon([0.0, 0.008], [0.003, -0.002], 0.0, l);
    let rho = 0.006;
    let helix = Tendon {
        turns: 1.5,
        ..tendon([rho, 0.0], [rho, 0.0], 0.0, l)
    };
    let m = rod_model(&[0.1, 0.15], 3, 12, vec![oblique, helix]);
    let exact = [
        (l * l + 0.003f64.powi(2) + 0.01f64.powi(2)).sqrt(),
        (l * l + (2.0 * PI * 1.5 * rho).powi(2)).sqrt(),
    ];
    let rest = m.tendon_rest_lengths();
    let at_zero = m.tendon_lengths(&DVector::zeros(m.n_dof()), &mut m.workspace());
    for k in 0..2 {
        // the oblique line has a constant speed: exact; the helix's speed is constant too
        assert!(
            (rest[k] - exact[k]).abs() < 1e-14 && (at_zero[k] - exact[k]).abs() < 1e-14,
            "tendon {k}: rest {} and at q = 0 {} vs {}",
            rest[k],
            at_zero[k],
            exact[k]
        );
    }
    assert!(exact[1] > l + 1e-3, "the helix is longer than the rod");
}

/// A tendon at the constant offset `d` pulled by `t = −u` on the first division only: its span
/// has the uniform curvature `κ = u d/EI` and stretch `ε = u/EA` (gvs-spec §10.3.6), so its length
/// is `X_e (1 + u/EA + κ d) = X_e (1 + u (1/EA + d²/EI))`, shorter by the tendon's compliance
/// times the pull; the distal division stays straight.
#[test]
fn pulled_tendon_shortens_by_its_compliance_x_e_over_ea_plus_d2_over_ei() {
    let (d, xe, u) = (0.005, 0.1, -0.4);
    let m = rod_model(&[xe, 0.15], 2, 8, vec![tendon([0.0, d], [0.0, d], 0.0, xe)]);
    let q = equilibrium(&m, &[u]);
    let s = SectionProps::circular(&material(), R);
    let (ea, ei) = (s.es[3], s.es[1]);
    let exact = xe * (1.0 + u * (1.0 / ea + d * d / ei));
    let length = m.tendon_lengths(&q, &mut m.workspace())[0];
    assert!(
        (length - exact).abs() < 1e-13,
        "ℓ = {length} vs {exact} (shortened by {:e} m)",
        xe - exact
    );
    assert!(
        xe - exact > 1e-4,
        "a visible shortening: {:e} m",
        xe - exact
    );
}

/// A tendon whose span ends inside a division applies its moment over exactly its span: the tip
/// turns by `∫ κ = u d (X_e − X_s)/EI`. With the points' quadrature weights it applied the
/// moment over the points inside the span (4 % off on this rod); its points now share the span
/// exactly (`Σ w = X_e − X_s`), as a span of whole divisions keeps the quadrature weights.
#[test]
fn a_tendon_ending_inside_a_division_turns_the_tip_by_u_d_span_over_ei() {
    let (d, u) = (0.005, -0.2);
    let ei = SectionProps::circular(&material(), R).es[1];
    for (xs, xe) in [(0.0, 0.1), (0.06, 0.19), (0.13, 0.25)] {
        let m = rod_model(&[0.25], 10, 33, vec![tendon([0.0, d], [0.0, d], xs, xe)]);
        let w: f64 = m.tendon_weights(0).iter().sum();
        assert!((w - (xe - xs)).abs() < 1e-15, "[{xs}, {xe}]: Σ w = {w}");
        let q = equilibrium(&m, &[u]);
        let (turn, exact) = (tip_turn_y(&m, &q), u * d * (xe - xs) / ei);
        // the Legendre basis rings about the jump: the turn, its mean, is held to ~1e-6
        assert!(
            ((turn - exact) / exact).abs() < 1e-5,
            "[{xs}, {xe}]: tip turned {turn} rad vs {exact}"
        );
        // the span's length at rest, exactly
        let rest = m.tendon_rest_lengths()[0];
        assert!((rest - (xe - xs)).abs() < 1e-15, "rest length {rest}");
    }
    // whole divisions keep the quadrature weights, bit for bit
    let m = rod_model(
        &[0.1, 0.15],
        10,
        33,
        vec![tendon([0.0, d], [0.0, d], 0.0, 0.1)],
    );
    let weights: Vec<f64> = (m.tendon_points(0).iter())
        .map(|&i| m.disc.points[i].weight)
        .collect();
    assert_eq!(m.tendon_weights(0), &weights[..]);
}

/// `∂ℓ/∂q` against central differences of the lengths on a 3-D state, for a frictionless, a
/// frictional and a mid-division tendon; for the frictionless ones it is their column of the
/// actuation matrix `B` (the tension's virtual work), for the frictional one it is not.
#[test]
fn tendon_length_jacobian_is_the_gradient_and_the_frictionless_actuation_column() {
    let skew = tendon([0.006, -0.002], [-0.002, 0.003], 0.0, 0.25);
    let rough = Tendon {
        friction: 0.5,
        ..tendon([0.0, 0.008], [0.0, 0.004], 0.0, 0.25)
    };
    let short = tendon([-0.004, 0.0], [-0.003, 0.002], 0.04, 0.17);
    let m = rod_model(&[0.1, 0.15], 2, 10, vec![skew, rough, short]);
    let q = common::pseudo_random(m.n_dof(), 23, 0.6);
    let mut ws = m.workspace();
    let jac = m.tendon_length_jacobian(&q, &mut ws);
    let h = 1e-6;
    for j in 0..m.n_dof() {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        let (lp, lm) = (
            m.tendon_lengths(&qp, &mut ws),
            m.tendon_lengths(&qm, &mut ws),
        );
        for k in 0..3 {
            let fd = (lp[k] - lm[k]) / (2.0 * h);
            assert!(
                (jac[(j, k)] - fd).abs() < 1e-9 * jac.column(k).amax(),
                "∂ℓ_{k}/∂q_{j}: {} vs {fd}",
                jac[(j, k)]
            );
        }
    }
    let b = m.actuation_matrix(&q, &mut ws);
    for k in [0, 2] {
        let err = (b.column(k) - jac.column(k)).amax() / jac.column(k).amax();
        assert!(err < 1e-13, "B_{k} vs ∇ℓ_{k}: {err:e}");
    }
    let err = (b.column(1) - jac.column(1)).amax() / jac.column(1).amax();
    assert!(err > 1e-3, "friction makes B_1 differ from ∇ℓ_1: {err:e}");
}

/// A span between two computational points holds none: the tendon would act on nothing, its
/// length would be 0. It is refused, naming the field and the points around it.
#[test]
fn a_tendon_span_between_two_points_is_refused_naming_them() {
    let (rod, disc, basis) = rod_parts(0.25, 10);
    let e = Model::new(
        rod,
        disc,
        basis,
        vec![tendon([0.0, 0.005], [0.0, 0.005], 0.1001, 0.1002)],
    )
    .err()
    .expect("refused")
    .to_string();
    assert!(
        e.contains("tendons[0].x_end")
            && e.contains(
                "[0.1001, 0.1002] m lies between the points at X = 0.070826 and 0.106391 m"
            )
            && e.contains("act on nothing"),
        "{e}"
    );
    // the same span with a point inside is accepted, and its length is the span's
    let (rod, disc, basis) = rod_parts(0.25, 10);
    let x = disc.points[5].x;
    let m = Model::new(
        rod,
        disc,
        basis,
        vec![tendon([0.0, 0.005], [0.0, 0.005], x - 1e-4, x + 1e-4)],
    )
    .unwrap();
    assert!((m.tendon_rest_lengths()[0] - 2e-4).abs() < 1e-15);
}
