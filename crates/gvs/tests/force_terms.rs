//! The generalized forces one by one (`Model::elastic_force`, `external_force`, `actuation_matrix`,
//! `damping_force`, `coriolis_force`) add up to what the solvers assemble together: the statics
//! residual `R = −K₁ + F + Bu` and the dynamics forces `τ = R − D₁ − C q̇`; and each agrees with an
//! independent quantity (the linear stiffness `K`, the Coriolis matrix).

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::loads::{Frame, Loads, PointWrench};
use gvs::model::Model;
use gvs::rod::{Material, Rod};
use gvs::strain::{DivisionBasis, LinearBasis, SigmoidBend, StrainParam};
mod common;

use common::pseudo_random;
use nalgebra::DVector;

/// A tapered damped rod with two tendons (one with friction), Legendre basis.
fn tendon_model() -> Model<LinearBasis> {
    let mat = Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping: 0.02,
    };
    let rod = Rod::tapered(mat, 0.25, 0.0125, 0.005);
    let disc = Discretization::new(
        &rod,
        &[Quadrature::Gauss { n: 10 }],
        MagnusOrder::Z4,
        &[0.2],
    )
    .unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [1, 3, 2, 1, 1, 2],
        }],
    )
    .unwrap();
    let tendon = |offset: [f64; 2], friction: f64| Tendon {
        offset_start: offset,
        offset_end: [offset[0] * 0.3, offset[1] * 0.3],
        x_start: 0.0,
        x_end: 0.25,
        friction,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    };
    Model::new(
        rod,
        disc,
        b,
        vec![tendon([0.0, 0.01], 0.5), tendon([0.01, 0.0], 0.0)],
    )
    .unwrap()
}

/// Gravity, a follower wrench at X = 0.2 and a world-fixed one at the tip.
fn loads() -> Loads {
    Loads {
        gravity: [0.0, 0.0, -9.81],
        point: vec![
            PointWrench {
                x: 0.2,
                wrench: [0.001, 0.0, 0.002, 0.0, 0.05, 0.0],
                frame: Frame::Local,
            },
            PointWrench {
                x: 0.25,
                wrench: [0.0, 0.0, 0.0, 0.02, 0.0, -0.03],
                frame: Frame::Global,
            },
        ],
        distributed: vec![],
    }
}

fn max_abs_diff(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax()
}

/// `R = −K₁ + F + Bu` and `τ = R − D₁ − C q̇` from the separate terms, to round-off of the largest.
fn check_sums<P: StrainParam>(m: &Model<P>, loads: &Loads, q: &DVector<f64>, qd: &DVector<f64>) {
    let n = m.n_dof();
    let u: Vec<f64> = (0..m.n_actuators()).map(|k| -2.0 - k as f64).collect();
    let prepared = m.prepare_loads(loads).unwrap();
    let mut ws = m.workspace();
    let k1 = m.elastic_force(q, &mut ws);
    let f = m.external_force(q, &prepared, &mut ws);
    let b = m.actuation_matrix(q, &mut ws);
    let d1 = m.damping_force(q, qd, &mut ws);
    let cqd = m.coriolis_force(q, qd, &mut ws);
    let bu = &b * DVector::from_column_slice(&u);
    let scale = [k1.amax(), f.amax(), bu.amax(), d1.amax(), cqd.amax()]
        .into_iter()
        .fold(1e-300, f64::max);

    let mut r = DVector::zeros(n);
    m.statics_residual(q, &u, &prepared, &mut ws, &mut r);
    let sum = -&k1 + &f + &bu;
    let err = max_abs_diff(&r, &sum) / scale;
    assert!(err < 1e-12, "R ≠ −K₁ + F + Bu by {err:e} (relative)");

    let mut tau = DVector::zeros(n);
    m.dynamic_forces(q, qd, &u, &prepared, &mut ws, &mut tau);
    let sum = -&k1 - &d1 + &f + &bu - &cqd;
    let err = max_abs_diff(&tau, &sum) / scale;
    assert!(
        err < 1e-12,
        "τ ≠ −K₁ − D₁ + F + Bu − Cq̇ by {err:e} (relative)"
    );

    // C q̇ from the Coriolis matrix (another assembly, spec §7.2)
    let c = m.coriolis_matrix(q, qd, &mut ws);
    let err = max_abs_diff(&(c * qd), &cqd) / cqd.amax().max(1e-300);
    assert!(
        err < 1e-10,
        "C(q, q̇) q̇ ≠ coriolis_force by {err:e} (relative)"
    );
}

#[test]
fn linear_model_terms_add_up_to_the_residual_and_the_dynamics_forces() {
    let m = tendon_model();
    let n = m.n_dof();
    let q = pseudo_random(n, 3, 2.0);
    let qd = pseudo_random(n, 4, 5.0);
    check_sums(&m, &loads(), &q, &qd);
}

#[test]
fn nonlinear_parameterization_terms_add_up_to_the_residual_and_the_dynamics_forces() {
    let mat = Material {
        youngs_modulus: 1e6,
        poisson_ratio: 0.5,
        density: 1000.0,
        damping: 0.01,
    };
    let rod = Rod::tapered(mat, 0.8, 0.015, 0.015);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 16 }], MagnusOrder::Z4, &[]).unwrap();
    let p = SigmoidBend::new(&disc);
    let m = Model::new(rod, disc, p, vec![]).unwrap();
    let n = m.n_dof();
    let q = pseudo_random(n, 5, 1.0);
    let qd = pseudo_random(n, 6, 2.0);
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    };
    check_sums(&m, &loads, &q, &qd);
}

#[test]
fn elastic_force_of_a_linear_basis_is_k_q_and_its_stiffness_k() {
    let m = tendon_model();
    let k = m
        .stiffness()
        .expect("a linear basis has a constant K")
        .clone();
    let q = pseudo_random(m.n_dof(), 7, 1.5);
    let mut ws = m.workspace();
    let k1 = m.elastic_force(&q, &mut ws);
    let kq = &k * &q;
    assert!(max_abs_diff(&k1, &kq) < 1e-12 * kq.amax(), "K₁(q) ≠ K q");
    let kt = m.elastic_stiffness(&q, &mut ws);
    assert!((&kt - &k).amax() < 1e-12 * k.amax(), "∂K₁/∂q ≠ K");
}

#[test]
fn actuation_force_is_the_residuals_change_with_the_tension() {
    // B(q) u is linear in u: the residual's change from u = 0 to u is B u, for any u
    let m = tendon_model();
    let q = pseudo_random(m.n_dof(), 8, 1.0);
    let no_loads = m.prepare_loads(&Loads::default()).unwrap();
    let mut ws = m.workspace();
    let b = m.actuation_matrix(&q, &mut ws);
    let (mut r0, mut r1) = (DVector::zeros(m.n_dof()), DVector::zeros(m.n_dof()));
    m.statics_residual(&q, &[0.0, 0.0], &no_loads, &mut ws, &mut r0);
    let u = [-7.0, 3.0];
    m.statics_residual(&q, &u, &no_loads, &mut ws, &mut r1);
    let bu = &b * DVector::from_column_slice(&u);
    // the difference of two residuals loses ε·‖K₁‖ to cancellation
    let tol = 1e-13 * (r0.amax() + bu.amax());
    assert!(max_abs_diff(&(r1 - r0), &bu) < tol);
}
