//! A trained autoencoder decoder as the engine's strain parameterization keeps every engine identity
//! (gvs-spec §10.2, §10.5; the checks of `gvs/tests/jacobians.rs` and `dynamics_structure.rs`, run on
//! `ReducedParam<DecoderMap>` instead of a linear or sigmoid basis).
//!
//! Fixture (built once, shared by the tests): the single-tendon-like rod (tapered 0.25 m, radius
//! 12.5 → 5 mm, E = 0.617 MPa, ρ = 1121 kg/m³; Legendre bend-y 4, elongation 3, shear-z 3; 10 Gauss
//! points, Z4), gravity −z and one tendon with friction. The HOM statics is solved for 60 tensions in
//! [−6, 3] N; the point strains `ξ − ξ*` of the active components (eq. 13 layout) train tanh
//! autoencoders with r = 1 and r = 2 (3 hidden layers); each decoder is folded with the least-squares
//! projection `P` onto the HOM coefficients and bound to the basis by `ReducedParam`.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::inputs::Signal;
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::{Material, Rod};
use gvs::solve::dynamics::{simulate, InitialState, IntegratorOptions, Method, OdeJacobian};
use gvs::solve::ode::NdfOptions;
use gvs::solve::statics::{StaticsOptions, StaticsSolver};
use gvs::strain::testing::derivative_errors;
use gvs::strain::{DivisionBasis, LinearBasis, StrainParam};
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rom::map::CoefficientMap;
use rom::metrics::strain_error_percent;
use rom::nn::{AeDecoderMap, Autoencoder, FineTune, TrainOptions};
use rom::reduced::{point_matrix, projection, projection_residual, PointLayout, ReducedParam};
use std::sync::OnceLock;
use std::time::Instant;

type AeModel = Model<ReducedParam<AeDecoderMap>>;

const N_SAMPLES: usize = 60;
const U_MIN: f64 = -6.0;
const U_MAX: f64 = 3.0;
const GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];
const FRICTION: f64 = 0.5;

fn material(damping: f64) -> Material {
    Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping,
    }
}

fn gravity() -> Loads {
    Loads {
        gravity: GRAVITY,
        ..Loads::default()
    }
}

/// The high-order model: planar bending in x–z (modes bend-y, elongation, shear-z), one tendon.
fn hom(damping: f64) -> Model<LinearBasis> {
    let rod = Rod::tapered(material(damping), 0.25, 0.0125, 0.005);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 10 }], MagnusOrder::Z4, &[]).unwrap();
    let basis = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [false, true, false, true, false, true],
            orders: [0, 4, 0, 3, 0, 3],
        }],
    )
    .unwrap();
    let tendon = Tendon {
        offset_start: [0.0, 0.01],
        offset_end: [0.0, 0.003],
        x_start: 0.0,
        x_end: 0.25,
        friction: FRICTION,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    };
    Model::new(rod, disc, basis, vec![tendon]).unwrap()
}

fn tension(k: usize) -> f64 {
    U_MIN + (U_MAX - U_MIN) * k as f64 / (N_SAMPLES - 1) as f64
}

/// The point strains `ξ_i − ξ*` of the active components at `q` (eq. 13 layout, point-major).
fn snapshot<P: StrainParam>(m: &Model<P>, layout: &PointLayout, q: &DVector<f64>) -> Vec<f64> {
    let mut ws = m.workspace();
    m.forward(q, &mut ws, false);
    let xi = m.point_strains(&ws);
    let mut out = Vec::with_capacity(layout.len());
    for (i, x) in xi.iter().enumerate() {
        let d = x - m.xi_star(i);
        out.extend(layout.active.iter().map(|&a| d[a]));
    }
    out
}

/// HOM statics at `u` (gravity on) from `q0`.
fn hom_statics(m: &Model<LinearBasis>, u: f64, q0: Option<&DVector<f64>>) -> DVector<f64> {
    let mut solver = StaticsSolver::new(m, StaticsOptions::default());
    solver
        .solve(&[u], &gravity(), q0)
        .unwrap_or_else(|e| panic!("HOM statics at u = {u}: {e}"))
        .q
}

struct Trained {
    ae: Autoencoder,
    /// Encodings of the snapshots, row-major (N × r).
    latent: Vec<f64>,
    /// Per latent coordinate, `[min, max]` of the encodings.
    range: Vec<[f64; 2]>,
    rest: DVector<f64>,
}

struct Fixture {
    layout: PointLayout,
    pm: DMatrix<f64>,
    p: DMatrix<f64>,
    /// Snapshots, row-major (N × p·n_a), sample k at tension `tension(k)`.
    snapshots: Vec<f64>,
    /// Trained for r = 1 and r = 2.
    trained: [Trained; 2],
}

impl Fixture {
    fn nf(&self) -> usize {
        self.layout.len()
    }

    fn row(&self, k: usize) -> &[f64] {
        &self.snapshots[k * self.nf()..(k + 1) * self.nf()]
    }

    fn trained(&self, r: usize) -> &Trained {
        &self.trained[r - 1]
    }

    /// The encoding of training sample `k` for latent size `r`.
    fn z(&self, r: usize, k: usize) -> DVector<f64> {
        DVector::from_column_slice(&self.trained(r).latent[k * r..(k + 1) * r])
    }

    /// The ROM: the HOM's rod, discretization and tendon with the AE parameterization.
    fn rom(&self, r: usize, damping: f64) -> AeModel {
        let h = hom(damping);
        let t = self.trained(r);
        let map = t.ae.decoder_map(self.p.as_slice(), self.p.nrows()).unwrap();
        let param = ReducedParam::new(&h.param, map, t.rest.clone()).unwrap();
        Model::new(h.rod, h.disc, param, h.tendons).unwrap()
    }
}

fn train(x: &[f64], nf: usize, latent: usize) -> Trained {
    let opts = TrainOptions {
        latent,
        hidden_layers: 3,
        lambda: 1e-6,
        epochs: 400,
        batch_size: 16,
        learning_rate: 3e-3,
        validation_fraction: 0.0,
        patience: None,
        fine_tune: FineTune::Lbfgs {
            iterations: 400,
            memory: 10,
        },
        seed: 7 + latent as u64,
        ..TrainOptions::default()
    };
    let (ae, report) = Autoencoder::train(x, nf, &opts, &mut |_, _, _| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap();
    eprintln!(
        "AE r = {latent}: train RMSE {:.3e} (strain units), {} epochs, {:?}",
        report.final_train_rmse, report.epochs_run, report.wall_time
    );
    let latent_rows = ae.encode(x).unwrap();
    let mut range = vec![[f64::INFINITY, f64::NEG_INFINITY]; latent];
    for z in latent_rows.chunks_exact(latent) {
        for (d, v) in z.iter().enumerate() {
            range[d][0] = range[d][0].min(*v);
            range[d][1] = range[d][1].max(*v);
        }
    }
    // the rest guess: the encoding of the snapshot closest to the straight rod, refined
    let nearest = x
        .chunks_exact(nf)
        .enumerate()
        .map(|(k, row)| (k, row.iter().map(|v| v * v).sum::<f64>()))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap()
        .0;
    let z0 = DVector::from_column_slice(&latent_rows[nearest * latent..(nearest + 1) * latent]);
    Trained {
        ae,
        latent: latent_rows,
        range,
        rest: z0,
    }
}

fn fixture() -> &'static Fixture {
    static FX: OnceLock<Fixture> = OnceLock::new();
    FX.get_or_init(|| {
        let start = Instant::now();
        let m = hom(1e4);
        let layout = PointLayout::active_in(&m.param, &m.disc);
        assert_eq!(layout.active, vec![1, 3, 5]);
        let pm = point_matrix(&m.param, &layout);
        let p = projection(&pm).unwrap();
        // sweep from the sample nearest u = 0 outwards, warm-starting each solve
        let k0 = (0..N_SAMPLES)
            .min_by(|&a, &b| tension(a).abs().total_cmp(&tension(b).abs()))
            .unwrap();
        let mut qs: Vec<Option<DVector<f64>>> = vec![None; N_SAMPLES];
        qs[k0] = Some(hom_statics(&m, tension(k0), None));
        for k in (0..k0).rev() {
            qs[k] = Some(hom_statics(&m, tension(k), qs[k + 1].as_ref()));
        }
        for k in k0 + 1..N_SAMPLES {
            qs[k] = Some(hom_statics(&m, tension(k), qs[k - 1].as_ref()));
        }
        let mut snapshots = Vec::with_capacity(N_SAMPLES * layout.len());
        for q in qs.iter().flatten() {
            let x = snapshot(&m, &layout, q);
            // HOM snapshots lie in the HOM's span: P recovers q
            let back = &p * DVector::from_column_slice(&x);
            assert!((&back - q).amax() < 1e-8 * (1.0 + q.amax()));
            snapshots.extend(x);
        }
        let hom_time = start.elapsed();
        let nf = layout.len();
        let t1 = train(&snapshots, nf, 1);
        let t2 = train(&snapshots, nf, 2);
        eprintln!(
            "fixture: {N_SAMPLES} HOM statics in {hom_time:?}, total with training {:?}",
            start.elapsed()
        );
        let mut fx = Fixture {
            layout,
            pm,
            p,
            snapshots,
            trained: [t1, t2],
        };
        // refine the rest coordinates (c(z) ≈ 0) from the nearest encoding
        for r in [1, 2] {
            let t = &fx.trained[r - 1];
            let map = t.ae.decoder_map(fx.p.as_slice(), fx.p.nrows()).unwrap();
            let (z, norm) = ReducedParam::find_rest(&map, &t.rest);
            eprintln!("r = {r}: rest z = {:?}, ‖c(z)‖ = {norm:.3e}", z.as_slice());
            fx.trained[r - 1].rest = z;
        }
        fx
    })
}

/// Latent points inside the training range: the encodings of a few training samples.
fn latent_points(fx: &Fixture, r: usize) -> Vec<DVector<f64>> {
    [8, 25, 41, 55].iter().map(|&k| fx.z(r, k)).collect()
}

/// A latent velocity of the size of the training range (per coordinate) over about 0.1 s.
fn latent_velocity(fx: &Fixture, r: usize, seed: usize) -> DVector<f64> {
    let range = &fx.trained(r).range;
    DVector::from_fn(r, |i, _| {
        let w = range[i][1] - range[i][0];
        let sign = if (i + seed).is_multiple_of(2) {
            1.0
        } else {
            -0.7
        };
        sign * 10.0 * w
    })
}

#[test]
fn trained_decoders_reconstruct_the_hom_snapshots_within_the_hom_span() {
    let fx = fixture();
    for r in [1, 2] {
        let ae = &fx.trained(r).ae;
        // the folded map is c(z) = P D(z) (A passed column-major, m × n)
        let map = ae.decoder_map(fx.p.as_slice(), fx.p.nrows()).unwrap();
        let m = map.n_out();
        let mut scratch = vec![0.0; map.scratch_len()];
        let (mut c, mut cz) = (vec![0.0; m], vec![0.0; m * r]);
        let mut fold_err = 0.0f64;
        for k in [0, 20, 40, 59] {
            let z = fx.z(r, k);
            map.eval(z.as_slice(), &mut c, &mut cz, &mut scratch);
            let expected = &fx.p * DVector::from_vec(ae.decode(z.as_slice()).unwrap());
            fold_err =
                fold_err.max((DVector::from_vec(c.clone()) - &expected).amax() / expected.amax());
        }
        eprintln!("r = {r}: folded decoder map vs P·D(z): {fold_err:.3e}");
        assert!(fold_err < 1e-12, "r = {r}: c(z) vs P D(z) {fold_err:e}");
        let (mut worst_err, mut worst_proj) = (0.0f64, 0.0f64);
        for k in 0..N_SAMPLES {
            let x = fx.row(k);
            let rec = ae.reconstruct(x).unwrap();
            worst_err = worst_err.max(strain_error_percent(x, &rec));
            worst_proj =
                worst_proj.max(projection_residual(&fx.pm, &fx.p, &DVector::from_vec(rec)));
        }
        eprintln!(
            "r = {r}: worst reconstruction strain error {worst_err:.3} %, worst projection residual {worst_proj:.3e}"
        );
        assert!(
            worst_err < 1.0,
            "r = {r}: reconstruction error {worst_err} %"
        );
    }
}

#[test]
fn decoder_param_derivatives_match_central_differences() {
    // value/Jacobian Ψ_q, the eq. (17) term Ψ̇_q and the weighted Hessian, at latent points inside the
    // training range
    let fx = fixture();
    for r in [1, 2] {
        let m = fx.rom(r, 0.0);
        for (k, z) in latent_points(fx, r).iter().enumerate() {
            let zd = latent_velocity(fx, r, k);
            let e = derivative_errors(&m.param, z, &zd, 1e-6);
            eprintln!("r = {r}, z = {:?}: {e:?}", z.as_slice());
            assert!(e.max() <= 1e-6, "r = {r}, z = {z}: {e:?}");
        }
    }
}

#[test]
fn geometric_jacobian_matches_finite_differences_with_ae_param() {
    let fx = fixture();
    for r in [1, 2] {
        let m = fx.rom(r, 0.0);
        let n = m.n_dof();
        for q in latent_points(fx, r) {
            let mut ws = m.workspace();
            m.forward(&q, &mut ws, true);
            let (mut wp, mut wm) = (m.workspace(), m.workspace());
            let h = 1e-6;
            let mut worst: f64 = 0.0;
            for j in 0..n {
                let mut qp = q.clone();
                qp[j] += h;
                let mut qm = q.clone();
                qm[j] -= h;
                m.forward(&qp, &mut wp, false);
                m.forward(&qm, &mut wm, false);
                for i in 0..m.disc.n_points() {
                    let d = (wp.g[i].to_homogeneous() - wm.g[i].to_homogeneous()) / (2.0 * h);
                    let g = ws.g[i].inverse().to_homogeneous() * d;
                    let fd = [
                        g[(2, 1)],
                        g[(0, 2)],
                        g[(1, 0)],
                        g[(0, 3)],
                        g[(1, 3)],
                        g[(2, 3)],
                    ];
                    let an = ws.jac.column(i * n + j);
                    for a in 0..6 {
                        worst = worst.max((fd[a] - an[a]).abs() / (1.0 + an[a].abs()));
                    }
                }
            }
            eprintln!("r = {r}: J vs central differences, worst relative error {worst:.3e}");
            assert!(worst < 1e-7, "r = {r}: J vs FD {worst:e}");
        }
    }
}

#[test]
fn the_pose_alone_equals_the_full_forward_pass_with_ae_param() {
    // `forward_pose` takes the decoder's value without its tangents; the poses and strains must be
    // those of the full pass (which the Jacobian test above checks against differences)
    let fx = fixture();
    for r in [1, 2] {
        let m = fx.rom(r, 0.0);
        for q in latent_points(fx, r) {
            let (mut full, mut pose) = (m.workspace(), m.workspace());
            m.forward(&q, &mut full, true);
            m.forward_pose(&q, &mut pose);
            let (xf, xp) = (m.point_strains(&full), m.point_strains(&pose));
            for i in 0..m.disc.n_points() {
                let dg = (full.g[i].to_homogeneous() - pose.g[i].to_homogeneous()).amax();
                let dxi = (xf[i] - xp[i]).amax();
                assert!(dg < 1e-13, "r = {r}: g at point {i} off by {dg:e}");
                assert!(
                    dxi < 1e-12 * (1.0 + xf[i].amax()),
                    "r = {r}: ξ at {i} off by {dxi:e}"
                );
            }
        }
    }
}

#[test]
fn statics_jacobian_matches_finite_differences_with_gravity_and_tendon_friction() {
    let fx = fixture();
    for c in cases(fx, 1e4) {
        let (r, label, m) = (c.r, &c.label, &c.model);
        let n = m.n_dof();
        let pl = m.prepare_loads(&gravity()).unwrap();
        let mut ws = m.workspace();
        // off equilibrium: the shape of one tension under another
        for (k, u) in [(8, -1.5), (30, -4.2), (50, 0.8)] {
            let q = c.point(fx.z(r, k));
            let mut an = DMatrix::zeros(n, n);
            m.statics_jacobian(&q, &[u], &pl, &mut ws, &mut an);
            let mut fd = DMatrix::zeros(n, n);
            let (mut rp, mut rm) = (DVector::zeros(n), DVector::zeros(n));
            for j in 0..n {
                let h = 1e-6 * (1.0 + q[j].abs());
                let mut qp = q.clone();
                qp[j] += h;
                let mut qm = q.clone();
                qm[j] -= h;
                m.statics_residual(&qp, &[u], &pl, &mut ws, &mut rp);
                m.statics_residual(&qm, &[u], &pl, &mut ws, &mut rm);
                fd.set_column(j, &((&rp - &rm) / (2.0 * h)));
            }
            let err = (&an - &fd).norm() / fd.norm();
            eprintln!("r = {label}, u = {u}: statics Jacobian vs central differences {err:.3e}");
            assert!(err < 1e-6, "r = {label}, u = {u}: ∂R/∂q vs FD {err:e}");
        }
    }
}

#[test]
fn mass_matrix_is_spd_and_mdot_minus_2c_is_skew_with_ae_param() {
    let fx = fixture();
    for c in cases(fx, 0.0) {
        let (r, label, m) = (c.r, &c.label, &c.model);
        let mut ws = m.workspace();
        for (k, q) in c.points.iter().enumerate() {
            let qd = latent_velocity(fx, r, k);
            let mass = m.mass_matrix(q, &mut ws);
            let asym = (&mass - mass.transpose()).amax() / mass.amax();
            let eig = SymmetricEigen::new(mass.clone()).eigenvalues;
            let e = 1e-6;
            let mp = m.mass_matrix(&(q + &qd * e), &mut ws);
            let mm = m.mass_matrix(&(q - &qd * e), &mut ws);
            let mdot = (mp - mm) / (2.0 * e);
            let c = m.coriolis_matrix(q, &qd, &mut ws);
            let nmat = &mdot - &c * 2.0;
            let sym = (&nmat + nmat.transpose()).amax() / mdot.amax().max(c.amax());
            eprintln!(
                "r = {label}, z = {:?}: M asymmetry {asym:.1e}, λ_min(M) = {:.3e}, ‖Ṁ − 2C + (Ṁ − 2C)ᵀ‖/‖·‖ = {sym:.3e}",
                q.as_slice(),
                eig.min()
            );
            assert!(asym < 1e-14, "r = {label}: M asymmetry {asym:e}");
            assert!(
                eig.min() > 0.0,
                "r = {label}: M not positive definite: {eig}"
            );
            assert!(
                sym < 1e-7,
                "r = {label}: Ṁ − 2C not skew-symmetric: {sym:e}"
            );
        }
    }
}

#[test]
fn coriolis_matrix_agrees_with_force_path_with_ae_param() {
    // without damping: τ(q, q̇) − τ(q, 0) = −C(q, q̇) q̇
    let fx = fixture();
    for c in cases(fx, 0.0) {
        let (r, label, m) = (c.r, &c.label, &c.model);
        let n = m.n_dof();
        let loads = m.prepare_loads(&gravity()).unwrap();
        let mut ws = m.workspace();
        for (k, q) in c.points.iter().enumerate() {
            let qd = latent_velocity(fx, r, k);
            let (mut t1, mut t0) = (DVector::zeros(n), DVector::zeros(n));
            m.dynamic_forces(q, &qd, &[-1.0], &loads, &mut ws, &mut t1);
            m.dynamic_forces(q, &DVector::zeros(n), &[-1.0], &loads, &mut ws, &mut t0);
            let cqd = m.coriolis_matrix(q, &qd, &mut ws) * &qd;
            let err = (&t0 - &t1 - &cqd).amax() / cqd.amax();
            eprintln!("r = {label}: C q̇ force path vs matrix {err:.3e}");
            assert!(err < 1e-10, "r = {label}: C q̇ vs force path {err:e}");
        }
    }
}

#[test]
fn dynamics_residual_is_m_qdd_minus_tau_with_ae_param() {
    // the recursive residual of the second-order integrators, ε(q, q̇, q̈), against M(q) q̈ − τ(q, q̇)
    // from the mass matrix and the force path, with damping and gravity
    let fx = fixture();
    for c in cases(fx, 1e4) {
        let (r, label, m) = (c.r, &c.label, &c.model);
        let n = m.n_dof();
        let loads = m.prepare_loads(&gravity()).unwrap();
        let mut ws = m.workspace();
        for (k, q) in c.points.iter().enumerate() {
            let qd = latent_velocity(fx, r, k);
            let qdd = latent_velocity(fx, r, k + 1) * 30.0;
            let mut tau = DVector::zeros(n);
            m.dynamic_forces(q, &qd, &[-1.0], &loads, &mut ws, &mut tau);
            let expected = m.mass_matrix(q, &mut ws) * &qdd - &tau;
            let mut eps = DVector::zeros(n);
            m.dynamics_residual(q, &qd, &qdd, &[-1.0], &loads, &mut ws, &mut eps);
            let err = (&eps - &expected).amax() / expected.amax();
            eprintln!("r = {label}: ε vs M q̈ − τ {err:.3e}");
            assert!(err < 1e-10, "r = {label}: ε vs M q̈ − τ {err:e}");
            // the same residual from the forward pass that also renews M (Ψ_q evaluated too)
            let mut mass = DMatrix::zeros(n, n);
            m.dynamics_residual_and_mass(q, &qd, &qdd, &[-1.0], &loads, &mut ws, &mut eps);
            mass.copy_from(&ws.mass);
            let err = (&eps - &expected).amax() / expected.amax();
            assert!(err < 1e-10, "r = {label}: ε with M vs M q̈ − τ {err:e}");
            let m_err = (&mass - m.mass_matrix(q, &mut ws)).amax() / mass.amax();
            assert!(
                m_err < 1e-12,
                "r = {label}: M of the residual pass off by {m_err:e}"
            );
        }
    }
}

#[test]
fn velocity_and_jdot_recursions_match_finite_differences_with_ae_param() {
    // η_i = J_i q̇ and ζ_i = J̇_i q̇ with J̇ from central differences of J along q̇
    let fx = fixture();
    for r in [1, 2] {
        let m = fx.rom(r, 0.0);
        let n = m.n_dof();
        for (k, q) in latent_points(fx, r).iter().enumerate() {
            let qd = latent_velocity(fx, r, k);
            let mut ws = m.workspace();
            m.forward(q, &mut ws, true);
            m.velocities(q, &qd, &mut ws);
            let e = 1e-6;
            let (mut wp, mut wm) = (m.workspace(), m.workspace());
            m.forward(&(q + &qd * e), &mut wp, true);
            m.forward(&(q - &qd * e), &mut wm, true);
            let (mut worst_eta, mut worst_zeta): (f64, f64) = (0.0, 0.0);
            for i in 0..m.disc.n_points() {
                let ji = ws.jac.columns(i * n, n);
                let eta_fd = ji * &qd;
                worst_eta = worst_eta.max((eta_fd - ws.eta[i]).amax());
                let jdot = (wp.jac.columns(i * n, n) - wm.jac.columns(i * n, n)) / (2.0 * e);
                let zeta_fd = jdot * &qd;
                let zeta = m.point_acceleration_bias(&ws, i);
                worst_zeta = worst_zeta.max((zeta_fd - zeta).amax() / (1.0 + zeta.amax()));
            }
            eprintln!(
                "r = {r}, z = {:?}: η error {worst_eta:.3e}, ζ = J̇q̇ relative error {worst_zeta:.3e}",
                q.as_slice()
            );
            assert!(worst_eta < 1e-10, "r = {r}: η vs J q̇ {worst_eta:e}");
            assert!(worst_zeta < 1e-7, "r = {r}: ζ vs FD {worst_zeta:e}");
        }
    }
}

#[test]
fn energy_is_conserved_without_damping_and_actuation_with_ae_param() {
    // released at rest from the shape of a pulled tendon, under gravity, no damping, tension 0:
    // kinetic, elastic and gravitational energy are exchanged, the total stays constant. The release
    // shape (u ≈ −1.3 N) is chosen so that the swing stays inside the training range: released from
    // u ≈ −4.5 N the r = 1 ROM overshoots the encodings' range, the decoder's tanh units saturate,
    // M(z) → 0 (z → −12 at t = 0.15 s, M = 8e-9) and the integrator stops with a step-size underflow.
    let fx = fixture();
    for r in [1, 2] {
        let m = fx.rom(r, 0.0);
        let n = m.n_dof();
        let q0 = fx.z(r, 31);
        let t: Vec<f64> = (0..=40).map(|k| 0.3 * k as f64 / 40.0).collect();
        let options = IntegratorOptions {
            method: Method::Ndf(NdfOptions {
                rtol: 1e-9,
                atol: 1e-12,
                ..NdfOptions::default()
            }),
            jacobian: OdeJacobian::Structured,
        };
        let sim = simulate(
            &m,
            &Signal::constant(&[0.0]),
            &gravity(),
            None,
            &InitialState::Given {
                q: q0,
                qd: DVector::zeros(n),
            },
            &t,
            &options,
        )
        .unwrap();
        assert!(sim.error.is_none(), "r = {r}: {:?}", sim.error);
        let mut ws = m.workspace();
        let e: Vec<_> = sim
            .trajectory
            .q
            .iter()
            .zip(&sim.trajectory.qd)
            .map(|(q, qd)| m.energy(q, qd, &GRAVITY, &mut ws))
            .collect();
        let exchanged = e.iter().map(|x| x.kinetic).fold(0.0, f64::max);
        let drift = e
            .iter()
            .map(|x| (x.total() - e[0].total()).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "r = {r}: max kinetic energy {exchanged:.3e} J, energy drift {drift:.3e} J ({:.2e} relative), {} steps, {:.2} s wall",
            drift / exchanged,
            sim.stats.steps,
            sim.wall_time_s
        );
        // how far the swing leaves the encodings' box, in units of the box width
        let range = &fx.trained(r).range;
        let mut outside = 0.0f64;
        for q in &sim.trajectory.q {
            for (d, v) in q.iter().enumerate() {
                let w = range[d][1] - range[d][0];
                outside = outside.max((range[d][0] - v).max(v - range[d][1]) / w);
            }
        }
        eprintln!("r = {r}: largest excursion beyond the training range {outside:.3} × its width");
        if r == 1 {
            // r = 1: the latent line is the data manifold; the swing stays on the trained part. (r = 2
            // leaves the box along the direction the data do not constrain, where M is small and the
            // motion fast, and still conserves energy.)
            assert!(
                outside <= 0.0,
                "r = 1: the swing leaves the training range by {outside} × its width"
            );
        }
        assert!(exchanged > 1e-5, "r = {r}: the rod moves: {exchanged:e} J");
        assert!(
            drift < 1e-6 * exchanged,
            "r = {r}: energy drift {drift:e} J vs {exchanged:e} J exchanged"
        );
    }
}

#[test]
fn rom_statics_with_ae_param_matches_the_hom_inside_the_training_range() {
    let fx = fixture();
    let hom_model = hom(1e4);
    for u in [-4.37, -1.91, 1.23] {
        let q_hom = hom_statics(&hom_model, u, None);
        let x_hom = snapshot(&hom_model, &fx.layout, &q_hom);
        // nearest training sample
        let k = (0..N_SAMPLES)
            .min_by(|&a, &b| (tension(a) - u).abs().total_cmp(&(tension(b) - u).abs()))
            .unwrap();
        for r in [1, 2] {
            let m = fx.rom(r, 1e4);
            let z0 = fx.z(r, k);
            let mut solver = StaticsSolver::new(&m, StaticsOptions::default());
            let sol = solver
                .solve(&[u], &gravity(), Some(&z0))
                .unwrap_or_else(|e| panic!("r = {r}, u = {u}: ROM statics: {e}"));
            let x_rom = snapshot(&m, &fx.layout, &sol.q);
            let err = strain_error_percent(&x_hom, &x_rom);
            eprintln!(
                "r = {r}, u = {u}: ROM statics in {} iterations, ‖R‖∞ = {:.2e}, strain error {err:.3} % (MAE / peak)",
                sol.iterations, sol.residual_norm
            );
            assert!(err < 1.0, "r = {r}, u = {u}: strain error {err} %");
        }
    }
}

/// Central differences of `q̈ ↦ ε(q + c_q q̈, q̇ + c_v q̈, q̈)` at `q̈ = 0`: the exact `c ∂ε/∂d_v` of
/// the NDF corrector (`c_v = c`, `c_q = c²`), column by column.
#[allow(clippy::too_many_arguments)]
fn exact_iteration_matrix(
    m: &AeModel,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    (cv, cq): (f64, f64),
    u: &[f64],
    loads: &gvs::model::PreparedLoads,
) -> DMatrix<f64> {
    let n = m.n_dof();
    let mut ws = m.workspace();
    let mut fd = DMatrix::zeros(n, n);
    let (mut ep, mut em) = (DVector::zeros(n), DVector::zeros(n));
    for j in 0..n {
        let e = 1e-3;
        let mut a = DVector::zeros(n);
        a[j] = e;
        m.dynamics_residual(
            &(q + &a * cq),
            &(qd + &a * cv),
            &a,
            u,
            loads,
            &mut ws,
            &mut ep,
        );
        a[j] = -e;
        m.dynamics_residual(
            &(q + &a * cq),
            &(qd + &a * cv),
            &a,
            u,
            loads,
            &mut ws,
            &mut em,
        );
        fd.set_column(j, &((&ep - &em) / (2.0 * e)));
    }
    fd
}

/// The structured iteration matrix `S = M + c D + c² K_T` of the second-order NDF
/// ([`Model::iteration_parts`], `K_T` with the decoder's Hessian term) against central differences
/// of the recursive residual: exact at an equilibrium at rest of the reduced model; away from rest
/// it drops only terms that vanish with the velocity (`∂(C q̇)/∂q̇`, `∂(C q̇)/∂q`), so its error
/// shrinks with `q̇`.
#[test]
fn iteration_matrix_matches_finite_differences_of_the_residual_with_ae_param() {
    let fx = fixture();
    let u = [-2.5];
    for r in [1, 2] {
        let m = fx.rom(r, 1e4);
        let n = m.n_dof();
        let loads = m.prepare_loads(&gravity()).unwrap();
        let z0 = fx.z(r, 20);
        let qe = StaticsSolver::new(&m, StaticsOptions::default())
            .solve(&u, &gravity(), Some(&z0))
            .unwrap_or_else(|e| panic!("r = {r}: ROM statics: {e}"))
            .q;
        let mut ws = m.workspace();
        let (mut mm, mut dd, mut kk) = (
            DMatrix::zeros(n, n),
            DMatrix::zeros(n, n),
            DMatrix::zeros(n, n),
        );
        m.iteration_parts(&qe, &u, &loads, &mut ws, &mut mm, &mut dd, &mut kk);
        // c of a 2 ms step and of a 20 ms one: the stiffness part matters in the second
        for c in [2e-3, 2e-2] {
            let s = &mm + &dd * c + &kk * (c * c);
            let zero = DVector::zeros(n);
            let fd = exact_iteration_matrix(&m, &qe, &zero, (c, c * c), &u, &loads);
            let err = (&s - &fd).amax() / fd.amax();
            eprintln!("r = {r}, c = {c}: S vs central differences at rest {err:.3e}");
            assert!(err < 1e-6, "r = {r}, c = {c}: S at rest {err:e}");
            // the K_T part alone is visible: dropping it must be seen
            let without_k = &mm + &dd * c;
            let err_k = (&without_k - &fd).amax() / fd.amax();
            assert!(
                err_k > 1e3 * err,
                "r = {r}, c = {c}: K_T invisible ({err_k:e})"
            );
        }
        // moving: the error is first order in q̇
        let c = 2e-2;
        let s = &mm + &dd * c + &kk * (c * c);
        let qd = latent_velocity(fx, r, 0);
        let errs: Vec<f64> = [1.0, 0.1]
            .iter()
            .map(|&scale| {
                let fd = exact_iteration_matrix(&m, &qe, &(&qd * scale), (c, c * c), &u, &loads);
                (&s - &fd).amax() / fd.amax()
            })
            .collect();
        eprintln!(
            "r = {r}: S vs central differences moving, q̇ and q̇/10: {:.3e} and {:.3e}",
            errs[0], errs[1]
        );
        assert!(
            errs[1] < 0.2 * errs[0] && errs[1] > 1e-6,
            "r = {r}: the dropped velocity terms do not scale with q̇: {:e}, {:e}",
            errs[0],
            errs[1]
        );
    }
}

/// A ROM of the engine-identity tests: the trained decoders for r = 1 and 2, and the r = 2 one
/// scaled by its first coordinate, `c(z) = z₁ c̃(z)` (`DecoderForm::Scaled`: every derivative
/// through the product rule of `ScaledMap`), with the latent points they are checked at.
struct Case {
    r: usize,
    label: String,
    model: AeModel,
    scaled: bool,
    points: Vec<DVector<f64>>,
}

impl Case {
    /// `z`, with `z₁` moved 0.5 away from 0 for the scaled decoder (its tangent degenerates on
    /// `z₁ = 0`, where every `z₂` decodes to the rest).
    fn point(&self, mut z: DVector<f64>) -> DVector<f64> {
        if self.scaled {
            z[0] = z[0].signum() * (z[0].abs() + 0.5);
        }
        z
    }
}

/// The three [`Case`]s with material damping `damping`.
fn cases(fx: &Fixture, damping: f64) -> Vec<Case> {
    let scaled = {
        let h = hom(damping);
        let t = fx.trained(2);
        let ae = t.ae.clone().with_form(rom::nn::DecoderForm::Scaled);
        let map = ae.decoder_map(fx.p.as_slice(), fx.p.nrows()).unwrap();
        assert!(matches!(map, AeDecoderMap::Scaled(_)));
        let param = ReducedParam::new(&h.param, map, t.rest.clone()).unwrap();
        Model::new(h.rod, h.disc, param, h.tendons).unwrap()
    };
    let mut out: Vec<Case> = [1, 2]
        .into_iter()
        .map(|r| Case {
            r,
            label: r.to_string(),
            model: fx.rom(r, damping),
            scaled: false,
            points: latent_points(fx, r),
        })
        .collect();
    let mut case = Case {
        r: 2,
        label: "2 (scaled decoder)".into(),
        model: scaled,
        scaled: true,
        points: vec![],
    };
    case.points = latent_points(fx, 2)
        .into_iter()
        .map(|z| case.point(z))
        .collect();
    out.push(case);
    out
}

/// An off-centre payload at the tip of the AE-ROM (the decoder's motion evaluation and weighted
/// Hessian carry the body's weight and inertial wrench): `∂R/∂q` against central differences,
/// `Ṁ − 2C` skew and the recursive residual `ε = M q̈ − τ`, for r = 1 and 2.
#[test]
fn an_off_centre_payload_keeps_the_engine_identities_with_ae_param() {
    let fx = fixture();
    let payload = gvs::bodies::RigidBody {
        x: 0.25,
        mass: 0.01,
        center: [0.01, 0.0, -0.004],
        inertia: [[1e-6, 0.0, 0.0], [0.0, 8e-7, 0.0], [0.0, 0.0, 8e-7]],
    };
    for r in [1, 2] {
        let m = fx.rom(r, 1e4).with_bodies(vec![payload.clone()]).unwrap();
        let n = m.n_dof();
        let pl = m.prepare_loads(&gravity()).unwrap();
        let mut ws = m.workspace();
        for (k, q) in latent_points(fx, r).iter().enumerate() {
            let mut an = DMatrix::zeros(n, n);
            m.statics_jacobian(q, &[-2.0], &pl, &mut ws, &mut an);
            let mut fd = DMatrix::zeros(n, n);
            let (mut rp, mut rm) = (DVector::zeros(n), DVector::zeros(n));
            for j in 0..n {
                let h = 1e-6 * (1.0 + q[j].abs());
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[j] += h;
                qm[j] -= h;
                m.statics_residual(&qp, &[-2.0], &pl, &mut ws, &mut rp);
                m.statics_residual(&qm, &[-2.0], &pl, &mut ws, &mut rm);
                fd.set_column(j, &((&rp - &rm) / (2.0 * h)));
            }
            let err = (&an - &fd).norm() / fd.norm();
            assert!(err < 1e-6, "r = {r}: ∂R/∂q with a payload vs FD {err:e}");

            let qd = latent_velocity(fx, r, k);
            let e = 1e-6;
            let mdot = (m.mass_matrix(&(q + &qd * e), &mut ws)
                - m.mass_matrix(&(q - &qd * e), &mut ws))
                / (2.0 * e);
            let c = m.coriolis_matrix(q, &qd, &mut ws);
            let nmat = &mdot - &c * 2.0;
            let sym = (&nmat + nmat.transpose()).amax() / mdot.amax().max(c.amax());
            assert!(
                sym < 1e-7,
                "r = {r}: Ṁ − 2C with a payload not skew: {sym:e}"
            );

            let qdd = latent_velocity(fx, r, k + 1) * 30.0;
            let mut tau = DVector::zeros(n);
            m.dynamic_forces(q, &qd, &[-1.0], &pl, &mut ws, &mut tau);
            let expected = m.mass_matrix(q, &mut ws) * &qdd - &tau;
            let mut eps = DVector::zeros(n);
            m.dynamics_residual(q, &qd, &qdd, &[-1.0], &pl, &mut ws, &mut eps);
            let err = (&eps - &expected).amax() / expected.amax();
            assert!(err < 1e-10, "r = {r}: ε with a payload vs M q̈ − τ {err:e}");
        }
    }
}
