//! The smoothed friction angle in the engine (issue 8, `actuation::smoothed_turning_angle`): on the
//! IV-A arm at u = −3 N the tendon path's curvature changes sign near X ≈ 0.09 m (gravity bends the
//! arm down, the tendon up), which is where the exact turning angle has its kink. There the analytic
//! statics Jacobian — with `∂α/∂q` through the smoothed angles — must still match central finite
//! differences, with the smoothing active on several points (κ_ε up to 5 rad/m).

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::{Material, Rod};
use gvs::solve::statics::{solve_statics, StaticsOptions};
use gvs::strain::{DivisionBasis, LinearBasis};
use nalgebra::{DMatrix, DVector};

/// The IV-A arm (gvs-spec §10.4): L = 0.25 m, taper 12.5 → 5 mm, gravity −z, Legendre order 10 in
/// bend-y, elongation and shear-z (33 DOF), 100 Gauss points, Z4, tendon (0, 0.01) → (0, 0.003) m.
fn arm(friction_smoothing: f64) -> Model<LinearBasis> {
    let material = Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping: 1e4,
    };
    let rod = Rod::tapered(material, 0.25, 0.0125, 0.005);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 100 }], MagnusOrder::Z4, &[]).unwrap();
    let basis = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [false, true, false, true, false, true],
            orders: [0, 10, 0, 10, 0, 10],
        }],
    )
    .unwrap();
    let tendon = Tendon {
        offset_start: [0.0, 0.01],
        offset_end: [0.0, 0.003],
        x_start: 0.0,
        x_end: 0.25,
        friction: 0.88,
        friction_smoothing,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    };
    Model::new(rod, disc, basis, vec![tendon]).unwrap()
}

fn gravity() -> Loads {
    Loads {
        gravity: [0.0, 0.0, -9.81],
        point: vec![],
        distributed: vec![],
    }
}

fn residual(m: &Model<LinearBasis>, q: &DVector<f64>, u: &[f64]) -> DVector<f64> {
    let pl = m.prepare_loads(&gravity()).unwrap();
    let mut ws = m.workspace();
    let mut r = DVector::zeros(m.n_dof());
    m.statics_residual(q, u, &pl, &mut ws, &mut r);
    r
}

/// ‖analytic − central differences‖_F / ‖central differences‖_F of `∂R/∂q` at `q`.
fn jacobian_error(m: &Model<LinearBasis>, q: &DVector<f64>, u: &[f64]) -> f64 {
    let n = m.n_dof();
    let pl = m.prepare_loads(&gravity()).unwrap();
    let mut ws = m.workspace();
    let mut an = DMatrix::zeros(n, n);
    m.statics_jacobian(q, u, &pl, &mut ws, &mut an);
    let mut fd = DMatrix::zeros(n, n);
    for j in 0..n {
        let h = 1e-6 * (1.0 + q[j].abs());
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        fd.set_column(
            j,
            &((residual(m, &qp, u) - residual(m, &qm, u)) / (2.0 * h)),
        );
    }
    (&an - &fd).norm() / fd.norm()
}

#[test]
fn statics_jacobian_matches_finite_differences_where_the_tendon_curvature_changes_sign() {
    let u = [-3.0];
    let exact = arm(0.0);
    let q = solve_statics(&exact, &u, &gravity(), None, &StaticsOptions::default())
        .unwrap()
        .q;
    let r0 = residual(&exact, &q, &u);
    for kappa_eps in [DEFAULT_FRICTION_SMOOTHING, 0.3, 1.0, 5.0] {
        let m = arm(kappa_eps);
        // the smoothing is active at this configuration: it changes the residual
        let dr = (residual(&m, &q, &u) - &r0).amax();
        assert!(dr > 1e-9, "κ_ε = {kappa_eps}: residual unchanged ({dr:e})");
        // and at configurations that move the zero of the curvature across the points
        for scale in [1.0, 0.97, 1.03] {
            let qs = &q * scale;
            let err = jacobian_error(&m, &qs, &u);
            assert!(
                err < 1e-6,
                "κ_ε = {kappa_eps}, q = {scale} q*: statics Jacobian vs central differences {err:e}"
            );
        }
    }
}

#[test]
fn smoothing_converges_to_the_exact_rule_and_stays_within_anchor_accuracy() {
    // the equilibrium depends continuously on κ_ε and tends to the exact tangent rule; at the
    // default and at the IV-A preset's 0.3 rad/m it stays within 0.005 % L of it (the tangent rule's
    // own accuracy against the continuum, gvs-spec §7.7) at the tensions where the curvature changes
    // sign
    let tip = |kappa_eps: f64, u: f64| {
        let m = arm(kappa_eps);
        let s = solve_statics(&m, &[u], &gravity(), None, &StaticsOptions::default()).unwrap();
        let mut ws = m.workspace();
        m.forward(&s.q, &mut ws, false);
        ws.g[m.disc.n_points() - 1].pos
    };
    for u in [-1.0, -2.0, -3.0, -4.0, -6.0] {
        let exact = tip(0.0, u);
        for kappa_eps in [DEFAULT_FRICTION_SMOOTHING, 0.3] {
            let moved = (tip(kappa_eps, u) - exact).norm();
            assert!(
                moved < 5e-5 * 0.25,
                "u = {u}: κ_ε = {kappa_eps} moves the tip by {moved:e} m"
            );
        }
        let tiny = (tip(1e-3, u) - exact).norm();
        assert!(
            tiny < 1e-9,
            "u = {u}: κ_ε = 1e-3 moves the tip by {tiny:e} m"
        );
    }
}
