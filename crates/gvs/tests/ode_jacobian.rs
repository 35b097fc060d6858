//! The structured ODE Jacobian `Model::ode_jacobian_approx` (gvs-spec §9.3) against central
//! differences of the right-hand side it approximates, `f(q, q̇) = [q̇; M(q)⁻¹ τ(q, q̇)]` with
//! `τ = R(q) − D q̇ − C(q, q̇) q̇` (linear basis: `D` constant), i.e. `Model::accelerations`.
//!
//! The approximation is `[0 I; M⁻¹ ∂R/∂q  −M⁻¹ D]`. Differentiating `M q̈ = τ` exactly,
//!
//! ```text
//!   ∂q̈/∂q  = M⁻¹ (∂R/∂q − ∂(C q̇)/∂q − (∂M/∂q) q̈),     ∂q̈/∂q̇ = M⁻¹ (−D − ∂(C q̇)/∂q̇),
//! ```
//!
//! so what it neglects is `−M⁻¹ (∂(Cq̇)/∂q + (∂M/∂q) q̈)` and `−M⁻¹ ∂(Cq̇)/∂q̇`: zero at rest in an
//! equilibrium (`q̇ = 0`, `q̈ = 0`; `C q̇` is quadratic in `q̇`), where it is exact.
//!
//! The full linearization `Model::linearize` (`A = ∂f/∂x`, `B = ∂f/∂u`) keeps those terms: it is
//! checked here in motion against the same differences, in the tensions, on a nonlinear strain
//! parameterization, at rest against the approximation, and on a Kelvin–Voigt rod against the
//! poles its undamped modes imply.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::loads::{Frame, Loads, PointWrench};
use gvs::model::{Model, PreparedLoads};
use gvs::solve::statics::{solve_statics, StaticsOptions};
use gvs::strain::{LinearBasis, SigmoidBend, StrainParam};
use nalgebra::{Complex, DMatrix, DVector};
mod common;

use common::pseudo_random;

const U: [f64; 2] = [-1.5, -0.8];

/// IV-A tapered rod with damping (η = 1e4 Pa·s), all six modes (Legendre [1, 2, 2, 1, 1, 1], 14
/// coordinates), a planar tendon with friction and an off-plane one.
fn model() -> Model<LinearBasis> {
    let tendons = vec![
        Tendon {
            offset_start: [0.0, 0.01],
            offset_end: [0.0, 0.003],
            x_start: 0.0,
            x_end: 0.25,
            friction: 0.5,
            friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
            turns: 0.0,
            path: Vec::new(),
            axial_stiffness: None,
        },
        Tendon {
            offset_start: [0.006, -0.002],
            offset_end: [-0.002, 0.003],
            x_start: 0.0,
            x_end: 0.25,
            friction: 0.0,
            friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
            turns: 0.0,
            path: Vec::new(),
            axial_stiffness: None,
        },
    ];
    common::iva_rod_3d(1e4, 10, &[], tendons)
}

/// Gravity oblique to the rod and a world-fixed tip force.
fn loads() -> Loads {
    Loads {
        gravity: [2.0, -3.0, -9.81],
        point: vec![PointWrench {
            x: 0.25,
            wrench: [0.0, 0.0, 0.0, 0.0, 0.05, -0.02],
            frame: Frame::Global,
        }],
        distributed: vec![],
    }
}

fn approx(m: &Model<LinearBasis>, q: &DVector<f64>, pl: &PreparedLoads) -> DMatrix<f64> {
    let n = m.n_dof();
    let mut ws = m.workspace();
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    m.ode_jacobian_approx(q, &U, pl, &mut ws, &mut a).unwrap();
    a
}

/// `f(q, q̇, u) = [q̇; M⁻¹ τ]`.
fn rhs<P: StrainParam>(
    m: &Model<P>,
    pl: &PreparedLoads,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    u: &[f64],
) -> DVector<f64> {
    let n = m.n_dof();
    let mut ws = m.workspace();
    let mut qdd = DVector::zeros(n);
    m.accelerations(q, qd, u, pl, &mut ws, &mut qdd).unwrap();
    let mut f = DVector::zeros(2 * n);
    f.rows_mut(0, n).copy_from(qd);
    f.rows_mut(n, n).copy_from(&qdd);
    f
}

/// Central differences of `f` in the `2n` state coordinates (step `h (1 + |y_j|)`).
fn fd_jacobian<P: StrainParam>(
    m: &Model<P>,
    pl: &PreparedLoads,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    u: &[f64],
) -> DMatrix<f64> {
    let n = m.n_dof();
    let mut jf = DMatrix::zeros(2 * n, 2 * n);
    for j in 0..2 * n {
        let (mut qp, mut qdp) = (q.clone(), qd.clone());
        let (mut qm, mut qdm) = (q.clone(), qd.clone());
        let h;
        if j < n {
            h = 1e-6 * (1.0 + q[j].abs());
            qp[j] += h;
            qm[j] -= h;
        } else {
            h = 1e-6 * (1.0 + qd[j - n].abs());
            qdp[j - n] += h;
            qdm[j - n] -= h;
        }
        let col = (rhs(m, pl, &qp, &qdp, u) - rhs(m, pl, &qm, &qdm, u)) / (2.0 * h);
        jf.set_column(j, &col);
    }
    jf
}

/// At the static equilibrium under the tensions `U`, gravity and the tip force, at rest, the
/// approximation is the exact Jacobian: `‖J_approx − J_FD‖_F ≤ 1e-6 ‖J_FD‖_F`.
#[test]
fn ode_jacobian_approx_is_exact_at_an_equilibrium_at_rest() {
    let m = model();
    let n = m.n_dof();
    let tight = StaticsOptions {
        ftol: 1e-13,
        ..StaticsOptions::default()
    };
    let qe = solve_statics(&m, &U, &loads(), None, &tight).unwrap().q;
    let pl = m.prepare_loads(&loads()).unwrap();
    let zero = DVector::zeros(n);
    // at rest at the equilibrium the accelerations vanish (to the statics tolerance)
    assert!(rhs(&m, &pl, &qe, &zero, &U).amax() < 1e-6);
    let a = approx(&m, &qe, &pl);
    let fd = fd_jacobian(&m, &pl, &qe, &zero, &U);
    let err = (&a - &fd).norm() / fd.norm();
    assert!(err < 1e-6, "approximate vs FD Jacobian at rest: {err:e}");
}

/// In motion (random `q`, `q̇`, hence `q̈ ≠ 0`) the difference to the exact Jacobian is the
/// neglected part and nothing else: `J_FD − J_approx = [0 0; −M⁻¹(∂(Cq̇)/∂q + (∂M/∂q) q̈)
/// −M⁻¹ ∂(Cq̇)/∂q̇]`, with `∂M/∂q` and `∂(Cq̇)/∂(q, q̇)` by central differences of
/// `Model::mass_matrix` and `Model::coriolis_force` (`Cq̇` is quadratic in `q̇`: its difference in
/// `q̇` is exact).
#[test]
fn ode_jacobian_approx_neglects_only_the_inertial_terms_in_motion() {
    let m = model();
    let n = m.n_dof();
    let q = pseudo_random(n, 51, 0.5);
    let qd = pseudo_random(n, 52, 3.0);
    let pl = m.prepare_loads(&loads()).unwrap();
    let a = approx(&m, &q, &pl);
    let fd = fd_jacobian(&m, &pl, &q, &qd, &U);
    let qdd = rhs(&m, &pl, &q, &qd, &U).rows(n, n).into_owned();

    let mut ws = m.workspace();
    let mass = m.mass_matrix(&q, &mut ws);
    let mut neglected = DMatrix::zeros(n, 2 * n);
    for j in 0..2 * n {
        let (mut qp, mut qdp) = (q.clone(), qd.clone());
        let (mut qm, mut qdm) = (q.clone(), qd.clone());
        let col = if j < n {
            let h = 1e-6 * (1.0 + q[j].abs());
            qp[j] += h;
            qm[j] -= h;
            let dm_qdd = (m.mass_matrix(&qp, &mut ws) - m.mass_matrix(&qm, &mut ws)) * &qdd;
            let dcqd = m.coriolis_force(&qp, &qd, &mut ws) - m.coriolis_force(&qm, &qd, &mut ws);
            (dm_qdd + dcqd) / (2.0 * h)
        } else {
            let h = 1e-6 * (1.0 + qd[j - n].abs());
            qdp[j - n] += h;
            qdm[j - n] -= h;
            (m.coriolis_force(&q, &qdp, &mut ws) - m.coriolis_force(&q, &qdm, &mut ws)) / (2.0 * h)
        };
        neglected.set_column(j, &(-col));
    }
    let chol = mass.cholesky().expect("M is SPD");
    let neglected = chol.solve(&neglected);
    let mut expected = a.clone();
    {
        let mut lower = expected.view_mut((n, 0), (n, 2 * n));
        lower += &neglected;
    }

    let share = (&fd - &a).norm() / fd.norm();
    let err = (&expected - &fd).norm() / fd.norm();
    // the neglected terms are a visible part of the Jacobian in this state ...
    assert!(
        share > 1e-3,
        "neglected share {share:e}: the test is vacuous"
    );
    // ... and exactly what is missing
    assert!(
        err < 1e-6,
        "J_FD vs J_approx + neglected: {err:e} (J_FD − J_approx alone: {share:e})"
    );
}

/// In the same moving state as above, where the approximation misses a visible share, the full
/// linearization `A` equals central differences of `f` (`‖A − J_FD‖_F ≤ 1e-6 ‖J_FD‖_F`, 1000×
/// below that share), and `ẋ` is `f` itself.
#[test]
fn linearization_matches_differences_of_the_right_hand_side_in_motion() {
    let m = model();
    let n = m.n_dof();
    let q = pseudo_random(n, 51, 0.5);
    let qd = pseudo_random(n, 52, 3.0);
    let pl = m.prepare_loads(&loads()).unwrap();
    let mut ws = m.workspace();
    let lin = m.linearize(&q, &qd, &U, &pl, &mut ws).unwrap();
    let fd = fd_jacobian(&m, &pl, &q, &qd, &U);
    let share = (&fd - approx(&m, &q, &pl)).norm() / fd.norm();
    let err = (&lin.a - &fd).norm() / fd.norm();
    assert!(
        share > 1e-3,
        "approximation's miss {share:e}: the state is too quiet to tell"
    );
    assert!(
        err < 1e-6,
        "A vs FD: {err:e} (the approximation misses {share:e})"
    );
    let f = rhs(&m, &pl, &q, &qd, &U);
    assert!(
        (&lin.xdot - &f).amax() <= 1e-12 * f.amax(),
        "ẋ is not f(x, u)"
    );
    // the top blocks are exactly [0 I]
    for i in 0..n {
        for j in 0..2 * n {
            assert_eq!(lin.a[(i, j)], if j == n + i { 1.0 } else { 0.0 });
        }
    }
}

/// `B = ∂f/∂u` against central differences in each tension (friction on tendon 1, so the
/// capstan's decay of the tension is in it), in motion: ≤ 1e-7 relative per column; the top
/// half is zero.
#[test]
fn linearization_input_matrix_matches_differences_in_the_tensions() {
    let m = model();
    let n = m.n_dof();
    let q = pseudo_random(n, 53, 0.5);
    let qd = pseudo_random(n, 54, 2.0);
    let pl = m.prepare_loads(&loads()).unwrap();
    let mut ws = m.workspace();
    let lin = m.linearize(&q, &qd, &U, &pl, &mut ws).unwrap();
    assert_eq!(lin.b.shape(), (2 * n, 2));
    for k in 0..2 {
        let (mut up, mut um) = (U, U);
        let h = 1e-4;
        up[k] += h;
        um[k] -= h;
        let col = (rhs(&m, &pl, &q, &qd, &up) - rhs(&m, &pl, &q, &qd, &um)) / (2.0 * h);
        let err = (lin.b.column(k) - &col).norm() / col.norm();
        assert!(col.norm() > 0.0 && err < 1e-7, "B column {k}: {err:e}");
        assert!(lin.b.column(k).rows(0, n).iter().all(|v| *v == 0.0));
    }
}

/// At the equilibrium at rest the inertial terms vanish and `A` is the analytic approximation
/// to rounding (no differences are taken), with `ẋ ≈ 0`.
#[test]
fn linearization_at_an_equilibrium_at_rest_is_analytic() {
    let m = model();
    let n = m.n_dof();
    let tight = StaticsOptions {
        ftol: 1e-13,
        ..StaticsOptions::default()
    };
    let qe = solve_statics(&m, &U, &loads(), None, &tight).unwrap().q;
    let pl = m.prepare_loads(&loads()).unwrap();
    let mut ws = m.workspace();
    let lin = m
        .linearize(&qe, &DVector::zeros(n), &U, &pl, &mut ws)
        .unwrap();
    assert!(lin.xdot.amax() < 1e-6, "not at rest: {:e}", lin.xdot.amax());
    let a = approx(&m, &qe, &pl);
    let err = (&lin.a - &a).norm() / a.norm();
    assert!(
        err < 1e-9,
        "A vs the analytic approximation at rest: {err:e}"
    );
    // about the equilibrium with q̈ = 0 held: the approximation itself, to rounding, and the same
    // ẋ (the residual's acceleration) and B
    let eq = m.linearize_equilibrium(&qe, &U, &pl, &mut ws).unwrap();
    let err = (&eq.a - &a).norm() / a.norm();
    assert!(
        err < 1e-13,
        "A at the equilibrium vs the approximation: {err:e}"
    );
    assert_eq!(eq.xdot, lin.xdot);
    assert_eq!(eq.b, lin.b);
}

/// On a nonlinear strain parameterization (a sigmoid bend, the decoder-like path of the reduced
/// models) under gravity, moving and momentarily still: `A` against central differences of `f`,
/// ≤ 1e-6.
#[test]
fn linearization_of_a_nonlinear_parameterization_matches_differences() {
    let rod = common::iva_rod(1e4);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 12 }], MagnusOrder::Z4, &[]).unwrap();
    let p = SigmoidBend::new(&disc);
    let m = Model::new(rod, disc, p, vec![]).unwrap();
    // amplitude 1.2, steepness 7, centre 0.4: M's condition number ~1e6 (a flat sigmoid, amplitude
    // near 0, makes M nearly singular, 1e13, and differences of f meaningless)
    let q = DVector::from_vec(vec![1.2, 7.0, 0.4]);
    let pl = m.prepare_loads(&loads()).unwrap();
    let mut ws = m.workspace();
    // moving, and momentarily still (q̇ = 0, q̈ ≠ 0: ∂ε/∂q̇ is then the damping matrix D(q))
    for qd in [DVector::from_vec(vec![0.8, -4.0, 0.3]), DVector::zeros(3)] {
        let lin = m.linearize(&q, &qd, &[], &pl, &mut ws).unwrap();
        let fd = fd_jacobian(&m, &pl, &q, &qd, &[]);
        let err = (&lin.a - &fd).norm() / fd.norm();
        assert!(
            err < 1e-6,
            "A vs FD on the sigmoid bend at q̇ = {qd:?}: {err:e}"
        );
        assert!(
            lin.xdot.rows(3, 3).amax() > 1.0,
            "not a still state: the test is vacuous"
        );
        assert_eq!(lin.b.ncols(), 0);
    }
}

/// A straight Kelvin–Voigt rod (ν = ½: `Ds = t_d Es` in every component, `t_d = 3η/E`) without
/// loads: `D = t_d K`, so each undamped mode `(ω, φ)` of `Model::linearized_modes` (a symmetric
/// eigenproblem, another path) gives the poles `λ² + t_d ω² λ + ω² = 0` with eigenvectors
/// `[φ; λφ]`: `‖A v − λ v‖ ≤ 1e-8 ‖λ v‖` for the six lowest modes, under- and overdamped.
#[test]
fn linearization_of_a_kelvin_voigt_rod_has_the_poles_of_its_modes() {
    let eta = 1e3;
    let m = common::iva_rod_3d(eta, 10, &[], vec![]);
    let n = m.n_dof();
    let t_d = 3.0 * eta / 0.617e6;
    assert!((m.damping_time() - t_d).abs() < 1e-12 * t_d);
    let pl = m.prepare_loads(&Loads::default()).unwrap();
    let mut ws = m.workspace();
    let zero = DVector::zeros(n);
    let lin = m.linearize(&zero, &zero, &[], &pl, &mut ws).unwrap();
    let modes = m.linearized_modes(&zero, &[], &pl, &mut ws).unwrap();
    let a = lin.a.map(|v| Complex::new(v, 0.0));
    let mut kinds = (0, 0);
    for mode in &modes {
        let w2 = mode.omega_squared;
        let disc = Complex::new((t_d * w2).powi(2) - 4.0 * w2, 0.0).sqrt();
        if disc.re > 0.0 {
            kinds.1 += 1;
        } else {
            kinds.0 += 1;
        }
        for sign in [1.0, -1.0] {
            let lambda = (Complex::new(-t_d * w2, 0.0) + disc * sign) / 2.0;
            let mut v = DVector::from_element(2 * n, Complex::new(0.0, 0.0));
            for i in 0..n {
                v[i] = Complex::new(mode.shape[i], 0.0);
                v[n + i] = lambda * mode.shape[i];
            }
            let lv = v.map(|c| c * lambda);
            let res = (&a * &v - &lv).norm() / lv.norm();
            assert!(
                res < 1e-8,
                "mode at ω² = {w2:e}, λ = {lambda}: residual {res:e}"
            );
        }
    }
    assert!(
        kinds.0 > 0 && kinds.1 > 0,
        "under/overdamped modes {kinds:?}: both kinds wanted"
    );
}
