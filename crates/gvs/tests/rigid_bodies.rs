//! Rigid bodies fixed to the rod (`gvs::bodies`): a payload's weight against the gradient of its
//! potential, the statics Jacobian against finite differences, its inertia against the kinetic
//! energy of its centre of mass and its spin, the structure of the equations of motion, and closed
//! forms of a cantilever carrying a tip mass or a tip disc.

use gvs::bodies::RigidBody;
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::inputs::Signal;
use gvs::loads::{Frame, Loads, PointWrench};
use gvs::model::Model;
use gvs::rod::{Material, Rod, SectionProps};
use gvs::solve::dynamics::{simulate, InitialState, IntegratorOptions, Method, OdeJacobian};
use gvs::solve::ode::NdfOptions;
use gvs::solve::statics::{solve_statics, StaticsOptions};
use gvs::strain::{DivisionBasis, LinearBasis, StrainParam};
use nalgebra::{DMatrix, DVector, SymmetricEigen, Vector3};
use std::f64::consts::PI;
mod common;
use common::pseudo_random;

const GRAVITY: [f64; 3] = [3.0, -4.0, -8.0];

/// An off-centre payload at the tip of the IV-A rod (0.0715 kg): 0.02 kg, its centre of mass
/// 1 cm beyond the tip and off the axis, a full inertia tensor.
fn payload(x: f64) -> RigidBody {
    RigidBody {
        x,
        mass: 0.02,
        center: [0.01, 0.004, -0.003],
        inertia: [
            [2e-6, 2e-7, 0.0],
            [2e-7, 1.5e-6, -1e-7],
            [0.0, -1e-7, 1.2e-6],
        ],
    }
}

/// The IV-A rod in 3-D (all six modes, 14 coordinates, 12 Gauss points) with a skew tendon, a
/// payload at the tip and a disc-like body at 0.12 m (an extra point).
fn model_with_bodies(damping: f64) -> Model<LinearBasis> {
    let tendon = common::iva_tendon(0.5);
    common::iva_rod_3d(damping, 12, &[0.12], vec![tendon])
        .with_bodies(vec![
            payload(0.25),
            RigidBody {
                x: 0.12,
                mass: 0.005,
                center: [0.0, -0.002, 0.001],
                inertia: [[4e-7, 0.0, 0.0], [0.0, 2e-7, 0.0], [0.0, 0.0, 2e-7]],
            },
        ])
        .unwrap()
}

fn state(m: &Model<LinearBasis>, seed: u64) -> DVector<f64> {
    pseudo_random(m.n_dof(), seed, 0.6)
}

fn gradient(q: &DVector<f64>, h: f64, mut f: impl FnMut(&DVector<f64>) -> f64) -> DVector<f64> {
    DVector::from_fn(q.len(), |j, _| {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        (f(&qp) - f(&qm)) / (2.0 * h)
    })
}

fn gravity_loads() -> Loads {
    Loads {
        gravity: GRAVITY,
        ..Loads::default()
    }
}

/// `F_g = −∇U_g` with the bodies' potential `−m g·(r_b + R_b c)` in `U_g`: the weights `[c × f; f]`
/// at their points are the gradient of the energy the module doc writes.
#[test]
fn body_weight_is_minus_the_gradient_of_its_potential() {
    let m = model_with_bodies(0.0);
    let q = state(&m, 17);
    let loads = m.prepare_loads(&gravity_loads()).unwrap();
    let mut ws = m.workspace();
    let f_g = m.external_force(&q, &loads, &mut ws);
    let zero = DVector::zeros(m.n_dof());
    let grad = gradient(&q, 1e-5, |x| {
        m.energy(x, &zero, &GRAVITY, &mut ws).gravitational
    });
    let err = (&f_g + &grad).amax() / grad.amax();
    assert!(err < 1e-9, "F_g vs −∇U_g: {err:e}");
    // the bodies matter: without them the force differs by far more than the check's tolerance
    let bare = common::iva_rod_3d(0.0, 12, &[0.12], vec![common::iva_tendon(0.5)]);
    let f_bare = bare.external_force(
        &q,
        &bare.prepare_loads(&gravity_loads()).unwrap(),
        &mut bare.workspace(),
    );
    assert!(
        (&f_g - &f_bare).amax() > 0.1 * f_g.amax(),
        "{f_g} vs {f_bare}"
    );
}

/// `∂R/∂q` with off-centre bodies under gravity, a tendon and a follower tip load against central
/// differences of the residual: the weight's moment `c × f` turns with the section.
#[test]
fn statics_jacobian_with_off_centre_bodies_matches_finite_differences() {
    let m = model_with_bodies(0.0);
    let bare = common::iva_rod_3d(0.0, 12, &[0.12], vec![common::iva_tendon(0.5)]);
    let n = m.n_dof();
    let loads = Loads {
        gravity: GRAVITY,
        point: vec![PointWrench {
            x: 0.25,
            wrench: [0.0, 0.01, 0.0, 0.0, 0.0, 0.05],
            frame: Frame::Local,
        }],
        ..Loads::default()
    };
    let u = [-1.5];
    // ∂R/∂q analytic and by central differences
    let both = |mm: &Model<LinearBasis>, q: &DVector<f64>| {
        let loads = mm.prepare_loads(&loads).unwrap();
        let mut ws = mm.workspace();
        let mut jac = DMatrix::zeros(n, n);
        mm.statics_jacobian(q, &u, &loads, &mut ws, &mut jac);
        let h = 1e-6;
        let mut fd = DMatrix::zeros(n, n);
        let (mut rp, mut rm) = (DVector::zeros(n), DVector::zeros(n));
        for j in 0..n {
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[j] += h;
            qm[j] -= h;
            mm.statics_residual(&qp, &u, &loads, &mut ws, &mut rp);
            mm.statics_residual(&qm, &u, &loads, &mut ws, &mut rm);
            fd.set_column(j, &((&rp - &rm) / (2.0 * h)));
        }
        (jac, fd)
    };
    for seed in [3, 4] {
        let q = state(&m, seed);
        let (jac, fd) = both(&m, &q);
        let err = (&jac - &fd).amax() / fd.amax();
        assert!(err < 1e-7, "seed {seed}: ∂R/∂q against differences {err:e}");
        // the bodies' part alone (the rod's axial entries dominate the whole), against its own size
        let (jac_bare, fd_bare) = both(&bare, &q);
        let (part, fd_part) = (&jac - &jac_bare, &fd - &fd_bare);
        let err = (&part - &fd_part).amax() / fd_part.amax();
        assert!(
            err < 1e-6,
            "seed {seed}: the bodies' ∂R/∂q against differences {err:e}"
        );
    }
}

/// `½ q̇ᵀ (M − M_rod) q̇` is the bodies' kinetic energy `½ m |v_c|² + ½ ωᵀ I_c ω`, with the centre
/// of mass velocity `v_c` and the section's angular velocity `ω` (body axes) taken by central
/// differences of the poses along `q̇`: an independent check of `Mb` and of where it acts.
#[test]
fn body_inertia_gives_the_kinetic_energy_of_its_centre_of_mass_and_spin() {
    let m = model_with_bodies(0.0);
    let bare = common::iva_rod_3d(0.0, 12, &[0.12], vec![common::iva_tendon(0.5)]);
    let (mut ws, mut wb) = (m.workspace(), bare.workspace());
    let q = state(&m, 5);
    let qd = pseudo_random(m.n_dof(), 6, 2.0);
    let dm = m.mass_matrix(&q, &mut ws) - bare.mass_matrix(&q, &mut wb);
    let t_matrix = 0.5 * qd.dot(&(&dm * &qd));
    let h = 1e-6;
    let poses = |x: &DVector<f64>, ws: &mut gvs::model::Workspace| {
        m.forward(x, ws, false);
        m.bodies()
            .map(|b| ws.g[m.disc.point_at(b.x).unwrap()])
            .collect::<Vec<_>>()
    };
    let (pp, pm) = (
        poses(&(&q + &qd * h), &mut ws),
        poses(&(&q - &qd * h), &mut ws),
    );
    let p0 = poses(&q, &mut ws);
    let mut t_bodies = 0.0;
    for (k, b) in m.bodies().enumerate() {
        let c = Vector3::from(b.center);
        let centre = |p: &gvs::lie::Pose| p.pos + p.rot * c;
        let v_c = (centre(&pp[k]) - centre(&pm[k])) / (2.0 * h);
        // Rᵀ Ṙ = ω̃ (body axes)
        let rdot = (pp[k].rot - pm[k].rot) / (2.0 * h);
        let w = p0[k].rot.transpose() * rdot;
        let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        t_bodies +=
            0.5 * b.mass * v_c.norm_squared() + 0.5 * omega.dot(&(b.inertia_matrix() * omega));
    }
    assert!(
        t_bodies > 1e-4,
        "the motion moves the bodies: {t_bodies:e} J"
    );
    let err = ((t_matrix - t_bodies) / t_bodies).abs();
    assert!(
        err < 1e-8,
        "½ q̇ᵀ ΔM q̇ = {t_matrix:e} J against {t_bodies:e} J: {err:e}"
    );
}

/// With bodies: `M` symmetric positive definite, `Ṁ − 2C` skew, `C q̇` of the force path equal to
/// the matrix's, the recursive residual `ε = M q̈ − τ` equal to the assembled one and the inverse
/// dynamics `ID = M q̈ + C q̇ − F` (gvs-spec §7.8, §9.4).
#[test]
fn equations_of_motion_keep_their_structure_with_bodies() {
    let m = model_with_bodies(2e4);
    let n = m.n_dof();
    let q = state(&m, 7);
    let qd = pseudo_random(n, 8, 2.0);
    let qdd = pseudo_random(n, 9, 50.0);
    let mut ws = m.workspace();
    let mass = m.mass_matrix(&q, &mut ws);
    assert!((&mass - mass.transpose()).amax() < 1e-14 * mass.amax());
    assert!(SymmetricEigen::new(mass.clone()).eigenvalues.min() > 0.0);
    let e = 1e-6;
    let mdot = (m.mass_matrix(&(&q + &qd * e), &mut ws) - m.mass_matrix(&(&q - &qd * e), &mut ws))
        / (2.0 * e);
    let c = m.coriolis_matrix(&q, &qd, &mut ws);
    let skew = &mdot - &c * 2.0;
    let sym = (&skew + skew.transpose()).amax() / mdot.amax().max(c.amax());
    assert!(sym < 1e-7, "Ṁ − 2C not skew: {sym:e}");
    let cqd = m.coriolis_force(&q, &qd, &mut ws);
    let err = (&cqd - &c * &qd).amax() / cqd.amax();
    assert!(err < 1e-10, "C q̇ force path vs matrix: {err:e}");

    let loads = m.prepare_loads(&gravity_loads()).unwrap();
    let u = [-1.5];
    let mut tau = DVector::zeros(n);
    m.dynamic_forces(&q, &qd, &u, &loads, &mut ws, &mut tau);
    let expected = &ws.mass * &qdd - &tau;
    let mut eps = DVector::zeros(n);
    m.dynamics_residual(&q, &qd, &qdd, &u, &loads, &mut ws, &mut eps);
    let err = (&eps - &expected).amax() / expected.amax();
    assert!(err < 1e-11, "recursive vs assembled M q̈ − τ: {err:e}");
    let id = m.inverse_dynamics(&q, &qd, &qdd, &loads, &mut ws);
    let f = m.external_force(&q, &loads, &mut ws);
    let expected = &mass * &qdd + &cqd - f;
    let err = (&id - &expected).amax() / expected.amax();
    assert!(err < 1e-11, "ID vs M q̈ + C q̇ − F: {err:e}");
}

/// A slender uniform cantilever (L = 0.5 m, r = 5 mm, E = 1 MPa, ρ = 1000 kg/m³; L/r = 100) with
/// orders [6, 6, 6, 2, 2, 2] and `bodies`.
fn slender(bodies: Vec<RigidBody>) -> (Model<LinearBasis>, Material) {
    slender_of(
        Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.5,
            density: 1000.0,
            damping: 0.0,
        },
        bodies,
    )
}

fn slender_of(mat: Material, bodies: Vec<RigidBody>) -> (Model<LinearBasis>, Material) {
    let rod = Rod::tapered(mat, 0.5, 0.005, 0.005);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 16 }], MagnusOrder::Z4, &[]).unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [6, 6, 6, 2, 2, 2],
        }],
    )
    .unwrap();
    let m = Model::new(rod, disc, b, vec![])
        .unwrap()
        .with_bodies(bodies)
        .unwrap();
    (m, mat)
}

fn frequencies<P: StrainParam>(m: &Model<P>) -> Vec<f64> {
    let loads = m
        .prepare_loads(&Loads {
            gravity: [0.0; 3],
            ..Loads::default()
        })
        .unwrap();
    let modes = m
        .linearized_modes(&DVector::zeros(m.n_dof()), &[], &loads, &mut m.workspace())
        .unwrap();
    modes.iter().map(|md| md.frequency_hz).collect()
}

/// Bisection for a root of `f` in `[a, b]` (a sign change).
fn root(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    assert!(f(a) * f(b) < 0.0);
    for _ in 0..200 {
        let c = 0.5 * (a + b);
        if f(a) * f(c) <= 0.0 {
            b = c;
        } else {
            a = c;
        }
    }
    0.5 * (a + b)
}

/// Euler–Bernoulli cantilever carrying a tip point mass `μ ρAL`: the first bending frequency is
/// `ω = β² √(EI / ρAL⁴)` with `β` the least root of
/// `1 + cos β cosh β + μ β (cos β sinh β − sin β cosh β) = 0` (for `μ = 0`, `β = 1.8751`).
#[test]
fn cantilever_with_a_tip_mass_vibrates_at_the_euler_bernoulli_frequency() {
    let (l, r) = (0.5, 0.005);
    for mu in [0.5, 1.0, 4.0] {
        let (bare, mat) = slender(vec![]);
        let s = SectionProps::circular(&mat, r);
        let rod_mass = mat.density * s.area * l;
        let (m, _) = slender(vec![RigidBody::point_mass(l, mu * rod_mass)]);
        let beta = root(
            |b: f64| 1.0 + b.cos() * b.cosh() + mu * b * (b.cos() * b.sinh() - b.sin() * b.cosh()),
            0.3,
            1.87,
        );
        let f1 = beta * beta / (2.0 * PI) * (s.es[1] / (rod_mass / l * l.powi(4))).sqrt();
        let f = frequencies(&m);
        // the bending pair (y and z) lies first; rotary inertia and shear of an L/r = 100 rod move
        // it by ~1e-4
        for fk in &f[..2] {
            assert!(
                ((fk - f1) / f1).abs() < 1e-3,
                "μ = {mu}: f = {fk} Hz, closed form {f1} Hz"
            );
        }
        assert!(
            f[0] < 0.95 * frequencies(&bare)[0],
            "the mass lowers the frequency"
        );
    }
}

/// Torsion of a shaft carrying a tip disc of inertia `I_d`: `β tan β = ρ J L / I_d` with
/// `ω = β √(G/ρ) / L`. The disc is given as an inertia tensor, and as two point masses `m/2` at
/// `±a` off the axis (`I_d = m a²`, the parallel-axis term of `Mb`); both must give the same mode.
#[test]
fn shaft_with_a_tip_disc_twists_at_the_closed_form_frequency() {
    let (l, r) = (0.5, 0.005);
    let (_, mat) = slender(vec![]);
    let s = SectionProps::circular(&mat, r);
    let j_shaft = s.ms[0] * l; // ρ J L
    let g = mat.youngs_modulus / (2.0 * (1.0 + mat.poisson_ratio));
    for ratio in [1.0, 3.0] {
        let i_d = j_shaft / ratio;
        let beta = root(|b: f64| b * b.tan() - ratio, 1e-3, PI / 2.0 - 1e-9);
        let ft = beta * (g / mat.density).sqrt() / l / (2.0 * PI);
        let disc = RigidBody {
            x: l,
            mass: 0.0,
            center: [0.0; 3],
            inertia: [
                [i_d, 0.0, 0.0],
                [0.0, i_d / 2.0, 0.0],
                [0.0, 0.0, i_d / 2.0],
            ],
        };
        let a = 0.02;
        let half = |sign: f64| RigidBody {
            x: l,
            mass: i_d / (a * a) / 2.0,
            center: [0.0, sign * a, 0.0],
            inertia: [[0.0; 3]; 3],
        };
        for (what, bodies) in [
            ("tensor", vec![disc]),
            ("two masses", vec![half(1.0), half(-1.0)]),
        ] {
            let (m, _) = slender(bodies);
            let f = frequencies(&m);
            let near = f
                .iter()
                .map(|x| ((x - ft) / ft).abs())
                .fold(f64::MAX, f64::min);
            assert!(
                near < 1e-3,
                "{what}, ratio {ratio}: no mode within 1e-3 of {ft} Hz: {f:?}"
            );
        }
    }
}

/// A tip point mass under gravity is the same load as its weight applied as a world-fixed tip
/// force (statics solved to convergence, both ways); on a massless stiff rod (E = 1 GPa, density 0,
/// the payload the only weight) it deflects the tip by `mgL³/3EI + mgL/κGA` (0.33 % of L).
#[test]
fn tip_mass_under_gravity_deflects_like_its_weight_as_a_world_fixed_force() {
    let l = 0.5;
    let mass = 2e-3;
    let g = 9.81;
    let stiff = Material {
        youngs_modulus: 1e9,
        poisson_ratio: 0.5,
        density: 0.0,
        damping: 0.0,
    };
    let tip = |mm: &Model<LinearBasis>, weight: f64| {
        let loads = Loads {
            gravity: [0.0, 0.0, -g],
            point: vec![PointWrench {
                x: l,
                wrench: [0.0, 0.0, 0.0, 0.0, 0.0, -weight],
                frame: Frame::Global,
            }],
            ..Loads::default()
        };
        let sol = solve_statics(mm, &[], &loads, None, &StaticsOptions::default()).unwrap();
        let mut ws = mm.workspace();
        mm.forward(&sol.q, &mut ws, false);
        mm.tip_pose(&ws).pos
    };
    // on the heavy soft rod (large deflection: its own weight folds it), body and force agree
    let (with_mass, _) = slender(vec![RigidBody::point_mass(l, mass)]);
    let (bare, _) = slender(vec![]);
    let (a, b) = (tip(&with_mass, 0.0), tip(&bare, mass * g));
    assert!(a[2] < -0.1, "a large deflection: {a}");
    assert!((a - b).amax() < 1e-10, "body {a} vs force {b}");
    // on the massless stiff rod, against linear beam theory
    let (m, mat) = slender_of(stiff, vec![RigidBody::point_mass(l, mass)]);
    let s = SectionProps::circular(&mat, 0.005);
    let p = mass * g;
    let closed = p * l.powi(3) / (3.0 * s.es[1]) + p * l / s.es[4];
    let dz = -tip(&m, 0.0)[2];
    assert!(
        ((dz - closed) / closed).abs() < 1e-3,
        "payload deflection {dz} m vs {closed} m"
    );
}

/// Undamped 3-D motion with the off-centre bodies under oblique gravity conserves
/// `½ q̇ᵀ M q̇ + U_e + U_g` (the bodies in `M` and `U_g`).
#[test]
fn energy_is_conserved_with_off_centre_bodies() {
    let m = model_with_bodies(0.0);
    let n = m.n_dof();
    let mut q0 = DVector::zeros(n);
    q0[0] = 0.4;
    q0[2] = -0.6;
    q0[5] = 0.4;
    let mut qd0 = DVector::zeros(n);
    qd0[0] = 6.0;
    qd0[5] = -4.0;
    let t: Vec<f64> = (0..=20).map(|k| 0.005 * k as f64).collect();
    let opts = IntegratorOptions {
        method: Method::Ndf(NdfOptions {
            rtol: 1e-10,
            atol: 1e-13,
            ..NdfOptions::default()
        }),
        jacobian: OdeJacobian::Structured,
    };
    let sim = simulate(
        &m,
        &Signal::constant(&[0.0]),
        &gravity_loads(),
        None,
        &InitialState::Given { q: q0, qd: qd0 },
        &t,
        &opts,
    )
    .unwrap();
    assert!(sim.error.is_none(), "{:?}", sim.error);
    let mut ws = m.workspace();
    let e: Vec<_> = (sim.trajectory.q.iter().zip(&sim.trajectory.qd))
        .map(|(q, qd)| m.energy(q, qd, &GRAVITY, &mut ws))
        .collect();
    let kin_max = e.iter().map(|x| x.kinetic).fold(0.0, f64::max);
    let drift = e
        .iter()
        .map(|x| (x.total() - e[0].total()).abs())
        .fold(0.0, f64::max);
    assert!(kin_max > 1e-3, "{kin_max}");
    assert!(
        drift < 1e-8 * kin_max,
        "energy drift {drift:e} J of {kin_max:e} J"
    );
}

/// A body where the discretization has no point is refused, naming the body.
#[test]
fn body_off_the_points_is_refused_by_name() {
    let m = common::iva_rod_3d(0.0, 12, &[], vec![]);
    let e = m
        .with_bodies(vec![payload(0.123)])
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("bodies[0].x") && e.contains("extra points"),
        "{e}"
    );
}

/// A light column (E = 10 MPa, ρ = 1, 1e-3 and 0 kg/m³: 0.04 g, 0.04 mg, nothing) standing on
/// its base and carrying a 10 g tip body at twice Euler's load `π²EI/4L²`: the straight
/// equilibrium diverges, and the statics must say so and leave it for the buckled one, whose turn
/// about the vertical is neutral (not divergent). The divergent `ω²` (−12.3 1/s², the payload's)
/// is 2e-11 of the light rod's stiffest mode at ρ = 1 (6e11 1/s²) and 2e-14 at ρ = 1e-3; a
/// threshold of 1e-10 of it missed it, and the solver reported the straight column as stable (a
/// review, 2026-12-07); so did one of 1e-13 at ρ = 1e-3 (a second review).
#[test]
fn a_column_buckled_by_its_heavy_payload_is_found_unstable() {
    for density in [1.0, 1e-3, 0.0] {
        column_buckled_by_its_payload(density);
    }
}

fn column_buckled_by_its_payload(density: f64) {
    let mat = Material {
        youngs_modulus: 1e7,
        poisson_ratio: 0.5,
        density,
        damping: 1e4,
    };
    let rod = Rod::tapered(mat, 0.5, 0.005, 0.005);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 21 }], MagnusOrder::Z4, &[]).unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [false, true, true, true, true, true],
            orders: [6; 6],
        }],
    )
    .unwrap();
    // local x along world +z
    let up = nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), -PI / 2.0).into_inner();
    let s = SectionProps::circular(&mat, 0.005);
    let euler = PI * PI * s.es[1] / (4.0 * 0.25);
    let mass = 2.0 * euler / 9.81;
    let m = Model::new(rod, disc, b, vec![])
        .unwrap()
        .with_base(gvs::lie::Pose::new(up, Vector3::zeros()))
        .with_bodies(vec![RigidBody::point_mass(0.5, mass)])
        .unwrap();
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    };
    let prepared = m.prepare_loads(&loads).unwrap();
    let mut ws = m.workspace();
    let straight = DVector::zeros(m.n_dof());
    // the straight column is an equilibrium (axial load only) that diverges
    let w2 = gvs::solve::stability::divergence_at(&m, &straight, &[], &prepared, &mut ws);
    let modes = m
        .linearized_modes(&straight, &[], &prepared, &mut ws)
        .unwrap();
    let least = modes[0].omega_squared;
    assert!(
        least < 0.0 && least > -1e3,
        "ρ = {density}: the payload's divergent ω² = {least}"
    );
    let w2 = w2.expect("the straight column diverges");
    assert!(
        ((w2 - least) / least).abs() < 1e-9,
        "ρ = {density}: divergence {w2} vs mode {least}"
    );
    let sol = solve_statics(&m, &[], &loads, None, &StaticsOptions::default()).unwrap();
    assert!(
        sol.buckled.is_some() && sol.divergence.is_none(),
        "ρ = {density}: buckled {:?}, divergence {:?}",
        sol.buckled,
        sol.divergence
    );
    m.forward(&sol.q, &mut ws, false);
    let tip = m.tip_pose(&ws).pos;
    assert!(
        tip[0].hypot(tip[1]) > 0.2,
        "ρ = {density}: the column buckled: tip {tip}"
    );
}
