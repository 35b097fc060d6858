//! Modes with tendons held at their lengths ([`gvs::model::Model::held_modes`]) against the stiff
//! tendon they idealize: a tendon spring of stiffness `κ` adds `κ B_H G_Hᵀ` to `K_T` (its tension
//! change `−κ δℓ` along `B_H`), and as `κ → ∞` the lowest `n − m` modes of the spring-held rod
//! tend to the held modes (error `O(1/κ)`). Checked on the 3-D IV-A arm at a displacement-driven
//! equilibrium under gravity, frictionless (symmetric) and with capstan friction (non-symmetric),
//! and against Rayleigh's interlacing theorem.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::solve::never_stop;
use gvs::solve::statics::StaticsOptions;
use gvs::solve::tendon_drive::{solve_driven, Drive};
use gvs::strain::LinearBasis;
use nalgebra::{DMatrix, DVector};
mod common;

fn arm(friction: f64) -> Model<LinearBasis> {
    arm_with(friction, None)
}

/// [`arm`] with tendon 0's axial stiffness `ea0`.
fn arm_with(friction: f64, ea0: Option<f64>) -> Model<LinearBasis> {
    let tendon = |d0: [f64; 2], d1: [f64; 2]| Tendon {
        offset_start: d0,
        offset_end: d1,
        x_start: 0.0,
        x_end: 0.25,
        friction,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    };
    let tendons = vec![
        Tendon {
            axial_stiffness: ea0,
            ..tendon([0.0, 0.01], [0.0, 0.003])
        },
        tendon([0.008, 0.0], [0.003, 0.0]),
        tendon([0.0, -0.01], [0.0, -0.003]),
    ];
    common::iva_rod_3d(0.0, 10, &[], tendons)
}

/// The equilibrium with tendons 0 and 1 wound in and tendon 2 by tension, its held tendons (the
/// taut displacement-driven ones), and the held modes' `ω²`.
struct Case {
    model: Model<LinearBasis>,
    q: DVector<f64>,
    u: Vec<f64>,
    held: Vec<usize>,
    loads: Loads,
}

fn case(friction: f64) -> Case {
    case_with(arm(friction))
}

fn case_with(model: Model<LinearBasis>) -> Case {
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    };
    let drives = [
        Drive::Displacement(0.004),
        Drive::Displacement(0.006),
        Drive::Tension(-0.5),
    ];
    let sol = solve_driven(
        &model,
        &StaticsOptions::default(),
        &drives,
        &loads,
        &never_stop,
    )
    .unwrap();
    assert_eq!(sol.slack, [false, false, false], "u = {:?}", sol.u);
    Case {
        model,
        q: sol.statics.q,
        u: sol.u,
        held: vec![0, 1],
        loads,
    }
}

/// `ω²` of `M⁻¹ (K_T + κ B_H G_Hᵀ)` by nalgebra's general eigenvalues, ascending by real part.
fn spring_held(c: &Case, kappa: f64) -> Vec<f64> {
    spring_held_each(c, &vec![kappa; c.held.len()])
}

/// [`spring_held`] with the stiffness `kappa[i]` on held tendon `i`.
fn spring_held_each(c: &Case, kappa: &[f64]) -> Vec<f64> {
    let m = &c.model;
    let n = m.n_dof();
    let mut ws = m.workspace();
    let loads = m.prepare_loads(&c.loads).unwrap();
    let mut k = DMatrix::zeros(n, n);
    m.statics_jacobian(&c.q, &c.u, &loads, &mut ws, &mut k);
    k.neg_mut();
    let b = m.actuation_matrix(&c.q, &mut ws);
    let g = m.tendon_length_jacobian(&c.q, &mut ws);
    for (&h, &kappa) in c.held.iter().zip(kappa) {
        k += b.column(h) * g.column(h).transpose() * kappa;
    }
    let mass = m.mass_matrix(&c.q, &mut ws);
    let a = mass.lu().solve(&k).unwrap();
    let mut w2: Vec<f64> = a.complex_eigenvalues().iter().map(|z| z.re).collect();
    w2.sort_by(f64::total_cmp);
    w2
}

fn held(c: &Case) -> Vec<gvs::dynamics::Mode> {
    let m = &c.model;
    let loads = m.prepare_loads(&c.loads).unwrap();
    m.held_modes(&c.q, &c.u, &loads, &c.held, &mut m.workspace())
        .unwrap()
}

fn check_against_springs(friction: f64) {
    let c = case(friction);
    let modes = held(&c);
    let n = c.model.n_dof();
    assert_eq!(modes.len(), n - c.held.len());
    // κ scaled to the stiffness: ‖K_T‖ ≈ 1e2 … 1e3 here; κ ‖G‖² ≈ 1e7 ‖K_T‖
    let springs = spring_held(&c, 1e9);
    for (j, mode) in modes.iter().take(6).enumerate() {
        let rel = (mode.omega_squared - springs[j]).abs() / springs[j].abs();
        assert!(
            rel < 1e-4,
            "friction {friction}, mode {j}: held ω² = {} vs spring-held {} ({rel:e})",
            mode.omega_squared,
            springs[j]
        );
        assert!(mode.omega_squared > 0.0, "stable: {}", mode.omega_squared);
        // the shape keeps the held lengths and is mass-normalized
        let mut ws = c.model.workspace();
        let g = c.model.tendon_length_jacobian(&c.q, &mut ws);
        let mass = c.model.mass_matrix(&c.q, &mut ws);
        for &h in &c.held {
            let along = g.column(h).dot(&mode.shape);
            assert!(
                along.abs() < 1e-10 * g.column(h).norm() * mode.shape.norm(),
                "δℓ_{h} = {along}"
            );
        }
        assert!((mode.shape.dot(&(&mass * &mode.shape)) - 1.0).abs() < 1e-10);
    }
    // a softer spring sits further from the held modes: the limit is approached, not met by luck
    let soft = spring_held(&c, 1e5);
    assert!(
        (modes[0].omega_squared - soft[0]).abs() > (modes[0].omega_squared - springs[0]).abs(),
        "held {} vs soft {} vs stiff {}",
        modes[0].omega_squared,
        soft[0],
        springs[0]
    );
}

#[test]
fn held_tendons_are_the_limit_of_stiff_tendon_springs_without_friction() {
    check_against_springs(0.0);
}

#[test]
fn held_tendons_are_the_limit_of_stiff_tendon_springs_with_friction() {
    check_against_springs(0.88);
}

/// Frictionless: each held `ω²_j` lies between the free rod's `ω²_j` and `ω²_{j+m}` (Rayleigh),
/// and holding changes the first frequency (the constraint is felt).
#[test]
fn held_frequencies_interlace_with_the_free_ones() {
    let c = case(0.0);
    let m = &c.model;
    let loads = m.prepare_loads(&c.loads).unwrap();
    let free = m
        .linearized_modes(&c.q, &c.u, &loads, &mut m.workspace())
        .unwrap();
    let modes = held(&c);
    let k = c.held.len();
    for (j, mode) in modes.iter().enumerate() {
        let (lo, hi) = (free[j].omega_squared, free[j + k].omega_squared);
        let tol = 1e-9 * hi.abs();
        assert!(
            mode.omega_squared >= lo - tol && mode.omega_squared <= hi + tol,
            "mode {j}: {} outside [{lo}, {hi}]",
            mode.omega_squared
        );
    }
    assert!(modes[0].omega_squared > free[0].omega_squared * (1.0 + 1e-3));
}

/// A tendon held twice is a dependent constraint: refused by name, not a silently wrong count of
/// modes.
#[test]
fn dependent_held_tendons_are_refused() {
    let c = case(0.0);
    let m = &c.model;
    let loads = m.prepare_loads(&c.loads).unwrap();
    let e = m
        .held_modes(&c.q, &c.u, &loads, &[0, 0], &mut m.workspace())
        .unwrap_err();
    assert!(
        matches!(
            e,
            gvs::dynamics::DynamicsError::DependentConstraints {
                rank: 1,
                count: 2,
                ..
            }
        ),
        "{e}"
    );
}

/// An elastic held tendon (EA = 30 N: stiffness `1/c = EA/ℓ_rest` ≈ 120 N/m) is the spring it
/// is, not a constraint: with tendon 0 elastic and tendon 1 inextensible, the held modes are
/// `n − 1` and match the spring-held rod with `κ₀ = 1/c₀` and a stiff `κ₁`, with friction too.
#[test]
fn an_elastic_held_tendon_is_its_own_spring() {
    for friction in [0.0, 0.88] {
        let c = case_with(arm_with(friction, Some(30.0)));
        let modes = held(&c);
        let n = c.model.n_dof();
        assert_eq!(
            modes.len(),
            n - 1,
            "only the inextensible tendon constrains"
        );
        let c0 = c.model.tendon_compliances()[0];
        assert!((c0 - c.model.tendon_rest_lengths()[0] / 30.0).abs() < 1e-15);
        let springs = spring_held_each(&c, &[1.0 / c0, 1e9]);
        let rigid = spring_held(&c, 1e9);
        for (j, mode) in modes.iter().take(6).enumerate() {
            let rel = (mode.omega_squared - springs[j]).abs() / springs[j].abs();
            assert!(
                rel < 1e-4,
                "friction {friction}, mode {j}: held ω² = {} vs spring-held {} ({rel:e})",
                mode.omega_squared,
                springs[j]
            );
        }
        // the thread's give is felt: the first mode sits well below the inextensible one's
        assert!(
            modes[0].omega_squared < rigid[0] * 0.99,
            "friction {friction}: {} vs {}",
            modes[0].omega_squared,
            rigid[0]
        );
    }
}
