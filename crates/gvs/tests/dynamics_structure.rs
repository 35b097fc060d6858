//! Structure of the equations of motion (gvs-spec §9.4, §10.5): M symmetric positive definite,
//! `Ṁ − 2C` skew-symmetric, the Coriolis matrix consistent with the force path, `J̇ q̇` against finite
//! differences, and linearized natural frequencies against beam theory.

use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::{DivisionGeometry, Material, Rod, SectionProps};
use gvs::strain::{DivisionBasis, FemDegree, LinearBasis, SigmoidBend, StrainParam};
mod common;

use common::{clamped_rod_10_5, iva_tendon, pseudo_random};
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use std::f64::consts::PI;

fn material(damping: f64) -> Material {
    Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping,
    }
}

fn linear_model(order: MagnusOrder, damping: f64) -> Model<LinearBasis> {
    let rod = Rod::tapered(material(damping), 0.25, 0.0125, 0.005);
    let disc = Discretization::new(&rod, &[Quadrature::Gauss { n: 10 }], order, &[]).unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [1, 3, 2, 1, 1, 2],
        }],
    )
    .unwrap();
    Model::new(rod, disc, b, vec![iva_tendon(0.5)]).unwrap()
}

fn sigmoid_model() -> Model<SigmoidBend> {
    let rod = Rod::tapered(material(0.0), 0.8, 0.015, 0.015);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 16 }], MagnusOrder::Z4, &[]).unwrap();
    let p = SigmoidBend::new(&disc);
    Model::new(rod, disc, p, vec![]).unwrap()
}

fn check_mass_spd_and_skew<P: StrainParam>(m: &Model<P>, q: &DVector<f64>, qd: &DVector<f64>) {
    let mut ws = m.workspace();
    let mass = m.mass_matrix(q, &mut ws);
    let asym = (&mass - mass.transpose()).amax() / mass.amax();
    assert!(asym < 1e-14, "M asymmetry {asym:e}");
    let eig = SymmetricEigen::new(mass.clone()).eigenvalues;
    assert!(eig.min() > 0.0, "M not positive definite: {eig}");
    // Ṁ by central differences along q̇
    let e = 1e-6;
    let mp = m.mass_matrix(&(q + qd * e), &mut ws);
    let mm = m.mass_matrix(&(q - qd * e), &mut ws);
    let mdot = (mp - mm) / (2.0 * e);
    let c = m.coriolis_matrix(q, qd, &mut ws);
    let n = &mdot - &c * 2.0;
    let sym = (&n + n.transpose()).amax() / mdot.amax().max(c.amax());
    assert!(sym < 1e-7, "Ṁ − 2C is not skew-symmetric: {sym:e}");
}

#[test]
fn mass_matrix_is_spd_and_mdot_minus_2c_is_skew_for_linear_basis() {
    for order in [MagnusOrder::Z4, MagnusOrder::Z2] {
        let m = linear_model(order, 0.0);
        let q = pseudo_random(m.n_dof(), 11, 0.5);
        let qd = pseudo_random(m.n_dof(), 12, 2.0);
        check_mass_spd_and_skew(&m, &q, &qd);
    }
}

/// Two divisions of FEM-like bases (all six components; linear elements, then quadratic), whose
/// mass matrix is assembled on each function's support, with the tendon of [`linear_model`]
/// across both.
fn fem_model() -> Model<LinearBasis> {
    let division = |length, radius_start, radius_end| DivisionGeometry {
        length,
        radius_start,
        radius_end,
        material: None,
        section: None,
    };
    let rod = Rod {
        material: material(0.0),
        divisions: vec![division(0.12, 0.0125, 0.009), division(0.13, 0.009, 0.005)],
    };
    let quadrature = |elements| Quadrature::Elements {
        elements,
        gauss_per_element: 3,
    };
    let disc =
        Discretization::new(&rod, &[quadrature(3), quadrature(2)], MagnusOrder::Z4, &[]).unwrap();
    let fem = |elements, degree| DivisionBasis::Fem {
        modes: [true; 6],
        elements,
        degree,
    };
    let b = LinearBasis::per_division(
        &disc,
        &[fem(3, FemDegree::Linear), fem(2, FemDegree::Quadratic)],
    )
    .unwrap();
    Model::new(rod, disc, b, vec![iva_tendon(0.5)]).unwrap()
}

#[test]
fn fem_mass_matrix_is_its_definition_spd_and_mdot_minus_2c_is_skew() {
    // M = Σ_i W_i J_iᵀ Ms_i J_i (gvs-spec §7.8) from the point Jacobians (themselves checked against
    // finite differences) and the section inertia, against the support-limited assembly
    let m = fem_model();
    let n = m.n_dof();
    let q = pseudo_random(n, 21, 0.5);
    let qd = pseudo_random(n, 22, 2.0);
    let mut ws = m.workspace();
    m.forward(&q, &mut ws, true);
    let mut by_definition = DMatrix::<f64>::zeros(n, n);
    for (i, p) in m.disc.points.iter().enumerate() {
        let j = ws.jac.columns(i * n, n).into_owned();
        let ms = nalgebra::Matrix6::from_diagonal(&m.section(i).ms);
        by_definition += j.transpose() * ms * j * p.weight;
    }
    let mass = m.mass_matrix(&q, &mut ws);
    let err = (&mass - &by_definition).amax() / by_definition.amax();
    assert!(err < 1e-12, "M against Σ W Jᵀ Ms J: {err:e}");
    check_mass_spd_and_skew(&m, &q, &qd);
}

#[test]
fn mass_matrix_is_spd_and_mdot_minus_2c_is_skew_for_nonlinear_basis() {
    let m = sigmoid_model();
    check_mass_spd_and_skew(
        &m,
        &DVector::from_vec(vec![1.2, 7.0, 0.4]),
        &DVector::from_vec(vec![0.8, -4.0, 0.3]),
    );
}

fn check_coriolis_force_consistency<P: StrainParam>(
    m: &Model<P>,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) {
    // with no damping: τ(q, q̇) − τ(q, 0) = −C(q, q̇) q̇
    let n = m.n_dof();
    let mut ws = m.workspace();
    let loads = m
        .prepare_loads(&Loads {
            gravity: [0.0, 0.0, -9.81],
            ..Default::default()
        })
        .unwrap();
    let u = vec![-1.0; m.n_actuators()];
    let (mut t1, mut t0) = (DVector::zeros(n), DVector::zeros(n));
    m.dynamic_forces(q, qd, &u, &loads, &mut ws, &mut t1);
    m.dynamic_forces(q, &DVector::zeros(n), &u, &loads, &mut ws, &mut t0);
    let cqd = m.coriolis_matrix(q, qd, &mut ws) * qd;
    let err = (&t0 - &t1 - &cqd).amax() / cqd.amax();
    assert!(
        err < 1e-10,
        "C q̇ from the force path vs the matrix: {err:e}"
    );
}

#[test]
fn coriolis_matrix_agrees_with_force_path() {
    let m = linear_model(MagnusOrder::Z4, 0.0);
    check_coriolis_force_consistency(
        &m,
        &pseudo_random(m.n_dof(), 21, 0.5),
        &pseudo_random(m.n_dof(), 22, 2.0),
    );
    let m = sigmoid_model();
    check_coriolis_force_consistency(
        &m,
        &DVector::from_vec(vec![1.2, 7.0, 0.4]),
        &DVector::from_vec(vec![0.8, -4.0, 0.3]),
    );
}

/// `ε(q, q̇, q̈) = M q̈ − τ` of the recursive path against the assembled `M` and the force path,
/// with damping, friction, tendons and gravity.
fn check_dynamics_residual<P: StrainParam>(
    m: &Model<P>,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    qdd: &DVector<f64>,
) {
    let n = m.n_dof();
    let mut ws = m.workspace();
    let loads = m
        .prepare_loads(&Loads {
            gravity: [0.0, 0.0, -9.81],
            ..Default::default()
        })
        .unwrap();
    let u = vec![-1.5; m.n_actuators()];
    let mut tau = DVector::zeros(n);
    m.dynamic_forces(q, qd, &u, &loads, &mut ws, &mut tau);
    let expected = &ws.mass * qdd - &tau;
    let mut eps = DVector::from_element(n, f64::NAN);
    m.dynamics_residual(q, qd, qdd, &u, &loads, &mut ws, &mut eps);
    let err = (&eps - &expected).amax() / expected.amax();
    assert!(err < 1e-11, "M q̈ − τ recursive vs assembled: {err:e}");
}

#[test]
fn recursive_dynamics_residual_equals_mass_times_acceleration_minus_forces() {
    let m = linear_model(MagnusOrder::Z4, 2e4);
    check_dynamics_residual(
        &m,
        &pseudo_random(m.n_dof(), 31, 0.5),
        &pseudo_random(m.n_dof(), 32, 2.0),
        &pseudo_random(m.n_dof(), 33, 50.0),
    );
    let m = linear_model(MagnusOrder::Z2, 2e4);
    check_dynamics_residual(
        &m,
        &pseudo_random(m.n_dof(), 34, 0.5),
        &pseudo_random(m.n_dof(), 35, 2.0),
        &pseudo_random(m.n_dof(), 36, 50.0),
    );
    let m = sigmoid_model();
    check_dynamics_residual(
        &m,
        &DVector::from_vec(vec![1.2, 7.0, 0.4]),
        &DVector::from_vec(vec![0.8, -4.0, 0.3]),
        &DVector::from_vec(vec![-3.0, 20.0, 1.0]),
    );
}

/// At an equilibrium at rest the iteration matrix `M + c_v D + c_q K_T` is the exact derivative of
/// `q̈ ↦ ε(q_e + c_q q̈, c_v q̈, q̈)` at `q̈ = 0` (central differences).
#[test]
fn iteration_matrix_is_exact_at_an_equilibrium_at_rest() {
    use gvs::solve::statics::{StaticsOptions, StaticsSolver};
    let m = linear_model(MagnusOrder::Z4, 2e4);
    let n = m.n_dof();
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Default::default()
    };
    let u = [-1.5];
    let qe = StaticsSolver::new(&m, StaticsOptions::default())
        .solve(&u, &loads, None)
        .unwrap()
        .q;
    let pl = m.prepare_loads(&loads).unwrap();
    let mut ws = m.workspace();
    let (mut mm, mut dd, mut kk) = (
        nalgebra::DMatrix::zeros(n, n),
        nalgebra::DMatrix::zeros(n, n),
        nalgebra::DMatrix::zeros(n, n),
    );
    m.iteration_parts(&qe, &u, &pl, &mut ws, &mut mm, &mut dd, &mut kk);
    let (cv, cq) = (0.61 * 1e-3, 0.31 * 1e-6);
    let s = &mm + &dd * cv + &kk * cq;
    let mut fd = nalgebra::DMatrix::zeros(n, n);
    let (mut ep, mut em) = (DVector::zeros(n), DVector::zeros(n));
    for j in 0..n {
        let e = 1e-3;
        let mut a = DVector::zeros(n);
        a[j] = e;
        m.dynamics_residual(&(&qe + &a * cq), &(&a * cv), &a, &u, &pl, &mut ws, &mut ep);
        a[j] = -e;
        m.dynamics_residual(&(&qe + &a * cq), &(&a * cv), &a, &u, &pl, &mut ws, &mut em);
        fd.set_column(j, &((&ep - &em) / (2.0 * e)));
    }
    let err = (&s - &fd).amax() / fd.amax();
    assert!(
        err < 1e-6,
        "iteration matrix vs central differences: {err:e}"
    );
}

fn check_velocity_recursions<P: StrainParam>(m: &Model<P>, q: &DVector<f64>, qd: &DVector<f64>) {
    // η_i = J_i q̇ and ζ_i = J̇_i q̇ with J̇ from central differences of J along q̇
    let n = m.n_dof();
    let mut ws = m.workspace();
    m.forward(q, &mut ws, true);
    m.velocities(q, qd, &mut ws);
    let eta = ws.eta.clone();
    let jac = ws.jac.clone();
    let e = 1e-6;
    let mut wp = m.workspace();
    let mut wm = m.workspace();
    m.forward(&(q + qd * e), &mut wp, true);
    m.forward(&(q - qd * e), &mut wm, true);
    // ζ_i = J̇ˢ_i q̇ = J̇_i q̇ since ad_η η = 0 (gvs-spec §6)
    let mut worst: f64 = 0.0;
    for i in 0..m.disc.n_points() {
        let ji = jac.columns(i * n, n);
        let eta_fd = ji * qd;
        worst = worst.max((eta_fd - eta[i]).amax());
        let jdot = (wp.jac.columns(i * n, n) - wm.jac.columns(i * n, n)) / (2.0 * e);
        let zeta_fd = jdot * qd;
        let zeta = m.point_acceleration_bias(&ws, i);
        worst = worst.max((zeta_fd - zeta).amax() / (1.0 + zeta.amax()));
    }
    assert!(
        worst < 1e-7,
        "velocity recursions vs finite differences: {worst:e}"
    );
}

#[test]
fn velocity_and_jdot_recursions_match_finite_differences() {
    let m = linear_model(MagnusOrder::Z4, 0.0);
    check_velocity_recursions(
        &m,
        &pseudo_random(m.n_dof(), 31, 0.5),
        &pseudo_random(m.n_dof(), 32, 2.0),
    );
    let m = sigmoid_model();
    check_velocity_recursions(
        &m,
        &DVector::from_vec(vec![1.2, 7.0, 0.4]),
        &DVector::from_vec(vec![0.8, -4.0, 0.3]),
    );
}

/// Natural frequencies [Hz] from det(K − ω² M) = 0 at q = 0.
fn frequencies(m: &Model<LinearBasis>) -> Vec<f64> {
    let loads = m.prepare_loads(&Loads::default()).unwrap();
    let mut ws = m.workspace();
    let modes = m
        .linearized_modes(&DVector::zeros(m.n_dof()), &[], &loads, &mut ws)
        .unwrap();
    modes.iter().map(|md| md.frequency_hz).collect()
}

#[test]
fn linearized_frequencies_of_clamped_rod_match_beam_theory() {
    // gvs-spec §10.5: L = 0.5, r = 5 mm, E = 1e6, ρ = 1000, Legendre orders [2,6,6,2,2,2], N = 12
    let (m, mat) = clamped_rod_10_5();
    let (l, r, e, rho) = (0.5, 0.005, mat.youngs_modulus, mat.density);
    let f = frequencies(&m);
    let s = SectionProps::circular(&mat, r);
    let eb = |beta_l: f64| beta_l * beta_l / (2.0 * PI * l * l) * (s.es[1] / (rho * s.area)).sqrt();
    let (f1, f2) = (eb(1.875_104_068_711_96), eb(4.694_091_132_974_17));
    let g = e / (2.0 * (1.0 + mat.poisson_ratio));
    let torsion = (g / rho).sqrt() / (4.0 * l);
    let axial = (e / rho).sqrt() / (4.0 * l);
    // first two bending modes, each doubly degenerate (y and z), within 1 % of Euler–Bernoulli
    for (k, fe) in [(0, f1), (2, f2)] {
        for j in [k, k + 1] {
            assert!(
                ((f[j] - fe) / fe).abs() < 0.01,
                "bending f[{j}] = {} vs EB {fe}",
                f[j]
            );
        }
    }
    assert!(
        (f[0] - 0.176917).abs() < 1e-5 && (f[2] - 1.10726).abs() < 1e-4,
        "{:?}",
        &f[..4]
    );
    // torsion and axial fundamental modes against their closed forms
    let near = |target: f64| {
        f.iter()
            .map(|x| ((x - target) / target).abs())
            .fold(f64::MAX, f64::min)
    };
    // the order-2 polynomial's Ritz error, measured 6.8e-5 for both: a mode within 1e-3 is theirs
    // (the nearest others lie 12–22 % off), and G is written out here (not the code's)
    assert!(
        near(torsion) < 1e-3,
        "no mode within 1e-3 of torsion {torsion} Hz: {f:?}"
    );
    assert!(
        near(axial) < 1e-3,
        "no mode within 1e-3 of axial {axial} Hz: {f:?}"
    );
}

/// The merged pass of the second-order NDF's first residual of an attempt gives the residual of
/// [`Model::dynamics_residual`] and the mass matrix of [`Model::mass_matrix`] exactly.
#[test]
fn residual_and_mass_from_one_pass_equal_the_separate_evaluations() {
    let m = linear_model(MagnusOrder::Z4, 2e4);
    let n = m.n_dof();
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Default::default()
    };
    let pl = m.prepare_loads(&loads).unwrap();
    let q = pseudo_random(n, 3, 0.8);
    let qd = pseudo_random(n, 4, 2.0);
    let qdd = pseudo_random(n, 5, 20.0);
    let u = [-1.5];
    let mut ws = m.workspace();
    let (mut e1, mut e2) = (DVector::zeros(n), DVector::zeros(n));
    m.dynamics_residual(&q, &qd, &qdd, &u, &pl, &mut ws, &mut e1);
    let mass = m.mass_matrix(&q, &mut ws);
    let mut ws2 = m.workspace();
    m.dynamics_residual_and_mass(&q, &qd, &qdd, &u, &pl, &mut ws2, &mut e2);
    assert!(e1.amax() > 0.0 && mass.amax() > 0.0);
    assert!((&e1 - &e2).amax() <= 1e-12 * e1.amax(), "residuals differ");
    assert!(
        (&mass - &ws2.mass).amax() <= 1e-12 * mass.amax(),
        "masses differ"
    );
}
