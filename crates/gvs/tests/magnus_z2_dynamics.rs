//! The velocity-level kinematics and the Coriolis terms with the second-order (midpoint) Magnus
//! step `Ω = h ξ(X + h/2)`, `Z = h Ψ_q,Z`, `Ż = h Ψ̇_q,Z` (gvs-spec §5.3, §6, §7.2), on a 3-D linear
//! model and on the nonlinear sigmoid parameterization: `η_i = J_i q̇` and `J̇ˢ_i q̇` against finite
//! differences of `J_i`, the Coriolis matrix against the force path, `Ṁ − 2C` skew, and the Coriolis
//! force against the Christoffel form of the mass matrix,
//! `C(q, q̇) q̇ = Ṁ q̇ − ½ ∇_q (q̇ᵀ M q̇)` (for Z2 and Z4).

use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::model::Model;
use gvs::rod::{Material, Rod};
use gvs::strain::{DivisionBasis, LinearBasis, SigmoidBend, StrainParam};
use nalgebra::{DMatrix, DVector};
mod common;

use common::pseudo_random;

fn material() -> Material {
    Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping: 0.0,
    }
}

/// IV-A tapered rod, all six modes (Legendre [1, 3, 2, 1, 1, 2], 16 coordinates), 10 Gauss points.
fn linear_model(order: MagnusOrder) -> Model<LinearBasis> {
    let rod = Rod::tapered(material(), 0.25, 0.0125, 0.005);
    let disc = Discretization::new(&rod, &[Quadrature::Gauss { n: 10 }], order, &[]).unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [1, 3, 2, 1, 1, 2],
        }],
    )
    .unwrap();
    Model::new(rod, disc, b, vec![]).unwrap()
}

/// The IV-B beam with the bending-y sigmoid `Ψ₂ = q₁/ℓ σ(−q₂(X̄ − q₃))`, 16 Gauss points.
fn sigmoid_model(order: MagnusOrder) -> Model<SigmoidBend> {
    let rod = Rod::tapered(material(), 0.8, 0.015, 0.015);
    let disc = Discretization::new(&rod, &[Quadrature::Gauss { n: 16 }], order, &[]).unwrap();
    let p = SigmoidBend::new(&disc);
    Model::new(rod, disc, p, vec![]).unwrap()
}

fn sigmoid_state() -> (DVector<f64>, DVector<f64>) {
    (
        DVector::from_vec(vec![1.2, 7.0, 0.4]),
        DVector::from_vec(vec![0.8, -4.0, 0.3]),
    )
}

/// Worst error over the points of `η_i = J_i q̇` and of `J̇ˢ_i q̇ = J̇_i q̇` (`ad_η η = 0`, spec §6)
/// with `J̇_i` the central difference of `J_i` along `q̇`, relative to `1 + |J̇ q̇|`.
fn velocity_recursion_error<P: StrainParam>(
    m: &Model<P>,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> f64 {
    let n = m.n_dof();
    let mut ws = m.workspace();
    m.forward(q, &mut ws, true);
    m.velocities(q, qd, &mut ws);
    let e = 1e-6;
    let (mut wp, mut wm) = (m.workspace(), m.workspace());
    m.forward(&(q + qd * e), &mut wp, true);
    m.forward(&(q - qd * e), &mut wm, true);
    let mut worst: f64 = 0.0;
    for i in 0..m.disc.n_points() {
        let eta = ws.jac.columns(i * n, n) * qd;
        worst = worst.max((eta - ws.eta[i]).amax());
        let jdot = (wp.jac.columns(i * n, n) - wm.jac.columns(i * n, n)) / (2.0 * e);
        let zeta_fd = jdot * qd;
        let zeta = m.point_acceleration_bias(&ws, i);
        worst = worst.max((zeta_fd - zeta).amax() / (1.0 + zeta.amax()));
    }
    worst
}

/// `η_i = J_i q̇`, `J̇ˢ_i q̇ = (d/dt J_i) q̇` with the Z2 step on a 3-D state (spec §6).
#[test]
fn jdot_qdot_matches_finite_differences_with_z2_linear_3d() {
    let m = linear_model(MagnusOrder::Z2);
    let q = pseudo_random(m.n_dof(), 41, 0.6);
    let qd = pseudo_random(m.n_dof(), 42, 2.0);
    let err = velocity_recursion_error(&m, &q, &qd);
    assert!(err < 1e-7, "Z2 velocity recursions vs FD: {err:e}");
}

/// As above for the sigmoid, where the Z2 step's `Ż q̇ = h Ψ̇_q,Z q̇` carries paper eq. 17.
#[test]
fn jdot_qdot_matches_finite_differences_with_z2_nonlinear_sigmoid() {
    let m = sigmoid_model(MagnusOrder::Z2);
    let (q, qd) = sigmoid_state();
    let err = velocity_recursion_error(&m, &q, &qd);
    assert!(err < 1e-7, "Z2 sigmoid velocity recursions vs FD: {err:e}");
}

/// `C(q, q̇) q̇` from the Coriolis matrix (its own `J̇ˢ` and `Ż` recursion) against the force path
/// (`coriolis_force`, the inverse dynamics at `q̈ = 0`), Z2, linear 3-D and sigmoid.
#[test]
fn coriolis_matrix_agrees_with_force_path_with_z2() {
    fn check<P: StrainParam>(m: &Model<P>, q: &DVector<f64>, qd: &DVector<f64>) -> f64 {
        let mut ws = m.workspace();
        let cqd = m.coriolis_force(q, qd, &mut ws);
        let c = m.coriolis_matrix(q, qd, &mut ws);
        (c * qd - &cqd).amax() / cqd.amax()
    }
    let m = linear_model(MagnusOrder::Z2);
    let q = pseudo_random(m.n_dof(), 43, 0.6);
    let qd = pseudo_random(m.n_dof(), 44, 2.0);
    let err = check(&m, &q, &qd);
    assert!(err < 1e-10, "Z2 linear: C q̇ matrix vs force path {err:e}");
    let m = sigmoid_model(MagnusOrder::Z2);
    let (q, qd) = sigmoid_state();
    let err = check(&m, &q, &qd);
    assert!(err < 1e-10, "Z2 sigmoid: C q̇ matrix vs force path {err:e}");
}

/// `Ṁ − 2C` skew-symmetric for the sigmoid with Z2 (the linear Z2 case is in dynamics_structure).
#[test]
fn mdot_minus_2c_is_skew_with_z2_nonlinear_sigmoid() {
    let m = sigmoid_model(MagnusOrder::Z2);
    let (q, qd) = sigmoid_state();
    let mut ws = m.workspace();
    let e = 1e-6;
    let mdot = (m.mass_matrix(&(&q + &qd * e), &mut ws) - m.mass_matrix(&(&q - &qd * e), &mut ws))
        / (2.0 * e);
    let c = m.coriolis_matrix(&q, &qd, &mut ws);
    let n = &mdot - &c * 2.0;
    let sym = (&n + n.transpose()).amax() / mdot.amax().max(c.amax());
    assert!(sym < 1e-7, "Ṁ − 2C not skew with Z2: {sym:e}");
}

/// Relative error of `coriolis_force` against `Ṁ q̇ − ½ ∇_q(q̇ᵀ M q̇)`, with `Ṁ` and the gradient by
/// central differences (step 1e-6) of `mass_matrix` alone.
fn christoffel_error<P: StrainParam>(m: &Model<P>, q: &DVector<f64>, qd: &DVector<f64>) -> f64 {
    let n = m.n_dof();
    let mut ws = m.workspace();
    let h = 1e-6;
    let mut mass = |x: &DVector<f64>| -> DMatrix<f64> { m.mass_matrix(x, &mut ws) };
    let mdot = (mass(&(q + qd * h)) - mass(&(q - qd * h))) / (2.0 * h);
    let grad = DVector::from_fn(n, |j, _| {
        let mut qp = q.clone();
        qp[j] += h;
        let mut qm = q.clone();
        qm[j] -= h;
        (qd.dot(&(mass(&qp) * qd)) - qd.dot(&(mass(&qm) * qd))) / (2.0 * h)
    });
    let expected = mdot * qd - grad * 0.5;
    let cqd = m.coriolis_force(q, qd, &mut m.workspace());
    (cqd - &expected).amax() / expected.amax()
}

/// `C(q, q̇) q̇ = Ṁ q̇ − ½ ∇_q(q̇ᵀ M q̇)` (Lagrange's equations with `T = ½ q̇ᵀ M(q) q̇`: the
/// Christoffel symbols of `M`; gvs-spec §7.2, §9.4) — a check of the whole Coriolis force path that
/// uses neither `J̇` nor the Coriolis matrix, for Z2 and Z4, linear 3-D and sigmoid.
#[test]
fn coriolis_force_equals_christoffel_form_of_mass_matrix_z2_and_z4() {
    for order in [MagnusOrder::Z2, MagnusOrder::Z4] {
        let m = linear_model(order);
        let q = pseudo_random(m.n_dof(), 45, 0.6);
        let qd = pseudo_random(m.n_dof(), 46, 2.0);
        let err = christoffel_error(&m, &q, &qd);
        assert!(err < 1e-7, "{order:?} linear 3-D: {err:e}");
        let m = sigmoid_model(order);
        let (q, qd) = sigmoid_state();
        let err = christoffel_error(&m, &q, &qd);
        assert!(err < 1e-7, "{order:?} sigmoid: {err:e}");
    }
}
