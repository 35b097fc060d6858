//! Tests of [`super::drive`]'s tension law and its stiffness against finite differences of the
//! statics residual with the tensions following `q`.

use super::drive::TendonSprings;
use crate::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use crate::discretize::{Discretization, MagnusOrder, Quadrature};
use crate::loads::Loads;
use crate::model::Model;
use crate::rod::{DivisionGeometry, Material, Rod};
use crate::strain::{DivisionBasis, LinearBasis};
use nalgebra::{DMatrix, DVector};

/// A 0.25 m rod of radius 1 cm, bending and stretching on Legendre order 2, with two elastic
/// tendons: a straight frictionless one (EA 300 N) and an oblique one with friction (`B ≠ ∇ℓ`,
/// EA `ea1`).
fn rod_with_tendons(ea1: Option<f64>) -> Model<LinearBasis> {
    let rod = Rod {
        material: Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.5,
            density: 1000.0,
            damping: 0.0,
        },
        divisions: vec![DivisionGeometry {
            length: 0.25,
            radius_start: 0.01,
            radius_end: 0.01,
            material: None,
            section: None,
        }],
    };
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 8 }], MagnusOrder::Z4, &[]).unwrap();
    let basis = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [2; 6],
    };
    let b = LinearBasis::per_division(&disc, &[basis]).unwrap();
    let tendon = |start: [f64; 2], end: [f64; 2], friction: f64, ea: Option<f64>| Tendon {
        offset_start: start,
        offset_end: end,
        x_start: 0.0,
        x_end: 0.25,
        friction,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: ea,
    };
    let tendons = vec![
        tendon([0.0, 0.008], [0.0, 0.008], 0.0, Some(300.0)),
        tendon([0.006, 0.0], [0.002, -0.004], 0.3, ea1),
    ];
    Model::new(rod, disc, b, tendons).unwrap()
}

/// The tensions at `q` of the displacements `delta` (both driven).
fn tensions(
    springs: &mut TendonSprings,
    m: &Model<LinearBasis>,
    q: &DVector<f64>,
    delta: &[f64],
) -> Vec<f64> {
    let mut u = delta.to_vec();
    springs.tensions(m, q, &mut m.workspace(), &mut u);
    u
}

#[test]
fn tension_law_pulls_by_the_stretch_and_goes_slack_when_the_path_is_short() {
    let m = rod_with_tendons(Some(500.0));
    let mut springs = TendonSprings::new(&m, &[true, true]).unwrap().unwrap();
    let rest = m.tendon_rest_lengths();
    let c = m.tendon_compliances();
    // the straight rod: the path is the rest length; wound in by δ, the thread is stretched by δ
    let q = DVector::zeros(m.n_dof());
    let u = tensions(&mut springs, &m, &q, &[1e-3, -1e-3]);
    assert!(
        (u[0] - (-1e-3 / c[0])).abs() < 1e-9 * u[0].abs(),
        "u = {u:?}"
    );
    assert_eq!(u[1], 0.0, "paid out: slack");
    assert!((c[0] - rest[0] / 300.0).abs() < 1e-15 && (c[1] - rest[1] / 500.0).abs() < 1e-15);
    // only tension-driven actuators: nothing to do; an inextensible driven tendon: refused
    assert!(TendonSprings::new(&m, &[false, false]).unwrap().is_none());
    let rigid = rod_with_tendons(None);
    let e = TendonSprings::new(&rigid, &[false, true])
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("tendons[1].axial_stiffness"), "{e}");
}

/// `K_T + B_D C⁻¹ ∇ℓ_Dᵀ` against central differences of `−R(q, u(q))` at a bent `q`, the tensions
/// following `q` by the law; both tendons taut, one with friction.
#[test]
fn spring_stiffness_matches_finite_differences_of_the_residual() {
    let m = rod_with_tendons(Some(500.0));
    let n = m.n_dof();
    let mut springs = TendonSprings::new(&m, &[true, true]).unwrap().unwrap();
    let loads = m.prepare_loads(&Loads::default()).unwrap();
    let mut ws = m.workspace();
    let q = DVector::from_fn(n, |i, _| {
        0.3 * ((i as f64) * 1.7).sin() * if i % 6 < 3 { 1.0 } else { 0.01 }
    });
    let delta = [4e-3, 3e-3];
    let u = tensions(&mut springs, &m, &q, &delta);
    assert!(u[0] < 0.0 && u[1] < 0.0, "both taut: {u:?}");
    let mut k = DMatrix::zeros(n, n);
    m.statics_jacobian(&q, &u, &loads, &mut ws, &mut k);
    k.neg_mut();
    assert!(springs.evaluate(&m, &q, &u, &mut ws));
    let kt = k.clone();
    springs.add_stiffness(&u, &mut k);
    let residual =
        |springs: &mut TendonSprings, x: &DVector<f64>, ws: &mut crate::model::Workspace| {
            let u = tensions(springs, &m, x, &delta);
            let mut r = DVector::zeros(n);
            m.statics_residual(x, &u, &loads, ws, &mut r);
            r
        };
    let h = 1e-6;
    let mut fd = DMatrix::zeros(n, n);
    for j in 0..n {
        let mut a = q.clone();
        a[j] += h;
        let mut b = q.clone();
        b[j] -= h;
        let col = -(residual(&mut springs, &a, &mut ws) - residual(&mut springs, &b, &mut ws))
            / (2.0 * h);
        fd.set_column(j, &col);
    }
    let err = (&k - &fd).amax() / fd.amax();
    assert!(err < 1e-6, "relative error {err:e}");
    // and the springs' share is not negligible: without it the difference is large
    let without = (&kt - &fd).amax() / fd.amax();
    assert!(without > 1e-3, "the springs change K by only {without:e}");
}

/// The first-order Jacobian's lower-left block `M⁻¹ ∂τ/∂q` with the springs' share against
/// central differences of the accelerations `M⁻¹ τ(q, 0, u(q))` at the driven equilibrium (where
/// `τ = 0`, so `∂M⁻¹/∂q τ` vanishes and the block is exact).
#[test]
fn first_order_jacobian_matches_finite_differences_of_the_accelerations() {
    use crate::solve::tendon_drive::{solve_driven, Drive};
    let m = rod_with_tendons(Some(500.0));
    let n = m.n_dof();
    let delta = [4e-3, 3e-3];
    let loads = Loads::default();
    let eq = solve_driven(
        &m,
        &Default::default(),
        &[Drive::Displacement(delta[0]), Drive::Displacement(delta[1])],
        &loads,
        &crate::solve::never_stop,
    )
    .unwrap();
    let q = eq.statics.q;
    let mut springs = TendonSprings::new(&m, &[true, true]).unwrap().unwrap();
    let prepared = m.prepare_loads(&loads).unwrap();
    let mut ws = m.workspace();
    let u = tensions(&mut springs, &m, &q, &delta);
    assert!(u[0] < 0.0 && u[1] < 0.0, "both taut: {u:?}");
    assert!(springs.evaluate(&m, &q, &u, &mut ws));
    let mut jac = DMatrix::zeros(2 * n, 2 * n);
    m.ode_jacobian_approx(&q, &u, &prepared, &mut ws, &mut jac)
        .unwrap();
    let without = jac.view((n, 0), (n, n)).clone_owned();
    springs.add_to_first_order(&u, &ws.mass, &mut jac);
    let block = jac.view((n, 0), (n, n)).clone_owned();
    let qd = DVector::zeros(n);
    let mut acc = |x: &DVector<f64>| {
        let u = tensions(&mut springs, &m, x, &delta);
        let mut a = DVector::zeros(n);
        m.accelerations(x, &qd, &u, &prepared, &mut ws, &mut a)
            .unwrap();
        a
    };
    let h = 1e-6;
    let mut fd = DMatrix::zeros(n, n);
    for j in 0..n {
        let mut a = q.clone();
        a[j] += h;
        let mut b = q.clone();
        b[j] -= h;
        fd.set_column(j, &((acc(&a) - acc(&b)) / (2.0 * h)));
    }
    let err = (&block - &fd).amax() / fd.amax();
    assert!(err < 1e-5, "relative error {err:e}");
    let off = (&without - &fd).amax() / fd.amax();
    assert!(off > 1e-3, "the springs change the block by only {off:e}");
}
