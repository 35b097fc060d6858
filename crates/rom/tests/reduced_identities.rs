//! The reduced model is the high-order model (HOM) seen through the map `q = c(z)`: every term of
//! its equations of motion is the HOM's term at the mapped state, projected by the map's Jacobian
//! `C_z = ∂c/∂z` (n × r), plus the map's curvature where a second derivative of `c` enters.
//!
//! A reduced parameterization `Ψ_s(z) = Φ_s c(z)` (`rom::reduced`, paper eq. 16, gvs-spec §4.5)
//! gives at every strain site the HOM's strain at `q = c(z)`, so the poses agree, and
//! `Ψ_q,s = Φ_s C_z` makes the Magnus step Jacobian `Z_r = Z C_z` and the geometric Jacobian
//! `J_r = J C_z` (§5.3, §6). With `q̇ = C_z ż` the twists agree, `η = J_r ż = J q̇`, and the body
//! accelerations agree with `q̈ = C_z z̈ + Ċ_z ż` (`Ċ_z = ∂²c/∂z² ż`, paper eq. 17). Hence, to
//! round-off, with `M, K, D, F, B, C, R, ε` those of the HOM at `q = c(z)`:
//!
//! ```text
//! mass                M_r(z)          = C_zᵀ M(q) C_z                                  §7.1
//! elastic             K₁,r(z)         = C_zᵀ K q          (Ψ = ξ − ξ*: reference strain) §7.3
//! external            F_r(z)          = C_zᵀ F(q)         (gravity, point, distributed)  §7.5
//! actuation           B_r(z)          = C_zᵀ B(q)         (per tendon, friction on)      §7.6–7.7
//! statics residual    R_r(z)          = C_zᵀ R(q)         (R = −K₁ + F + B u)            §8.1
//! damping             D_r(z)          = C_zᵀ D C_z,   D₁,r = C_zᵀ D q̇                    §7.4
//! Coriolis force      C_r ż           = C_zᵀ (C(q, q̇) q̇ + M(q) Ċ_z ż)                   §7.2
//! Coriolis matrix     C_r(z, ż)       = C_zᵀ C(q, q̇) C_z + C_zᵀ M(q) Ċ_z                §7.2, §6
//! dynamics residual   ε_r(z, ż, z̈)    = C_zᵀ ε(q, C_z ż, C_z z̈ + Ċ_z ż)                §7.8
//!                     τ_r(z, ż)       = C_zᵀ (τ(q, q̇) − M(q) Ċ_z ż)                     §9.1
//! statics tangent     K_T,r(z)        = C_zᵀ K_T(q) C_z − Σ_i R_i(q) ∇²c_i(z)           §8.2
//! ```
//!
//! (`K_T = −∂R/∂q`; the last term is the statics Jacobian's weighted Hessian of §4.5/§8.2, which
//! vanishes only at an equilibrium of the HOM, `R = 0`.) The reduced side is the engine run on
//! `Model<ReducedParam<_>>` (or a composed linear basis); the HOM side is the engine on
//! `Model<LinearBasis>` at `q = c(z)`. `C_z` comes from eighth-order central differences of `c`;
//! `Ċ_z ż` and `Σ_i R_i ∇²c_i` from those of the map's own first derivative (which the first-order
//! identities check), never from the map's second-order code (the eq. 17 rate, the motion pass,
//! the weighted Hessian) that the reduced model runs on. A linear (POD) map has `C_z = B`, `Ċ_z = 0`.
//!
//! Fixture: a 3-D rod, two tapered divisions (0.15 m, 18 → 14 mm; 0.10 m, 14 → 9 mm; E = 1 MPa,
//! ν = 0.45, ρ = 1100 kg/m³, η = 1e4 Pa·s), Legendre orders [1, 2, 2, 1, 1, 1] on all six strain
//! components of each division (28 HOM coordinates), 4 Gauss points per division, Z4, a rotated and
//! shifted base, gravity along neither the rod nor an axis, a full-length tendon with an off-axis
//! oblique route and friction and a half-length one, point wrenches (follower, world-fixed) and
//! distributed ones (uniform follower and world-fixed, the IV-B triangular pulse). Maps: an untrained
//! tanh decoder (Glorot weights, random biases, fixed seed; r = 3) folded with the least-squares
//! projection `P`, the same kind of decoder in the scaled form `c = z₁ c̃(z)` (r = 2), and a POD
//! basis (r = 4, `LinearBasis::compose`).

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::inputs::SplitMix64;
use gvs::lie::{Pose, V3};
use gvs::loads::{DistributedWrench, Frame, Loads, PointWrench, PulseMagnitude};
use gvs::model::{Model, PreparedLoads};
use gvs::rod::{DivisionGeometry, Material, Rod};
use gvs::strain::{DivisionBasis, LinearBasis, StrainParam};
use nalgebra::{DMatrix, DVector, Rotation3};
use rom::map::CoefficientMap;
use rom::nn::{AeDecoderMap, DecoderForm, DecoderMap, Mlp, Scaling};
use rom::pod::Pod;
use rom::reduced::{point_matrix, projection, PointLayout, ReducedParam};

/// Relative discrepancy allowed in an identity, `‖reduced − projected HOM‖ / ‖projected HOM‖`
/// (Frobenius / Euclidean norm): round-off of the two engine passes plus the error of the
/// eighth-order differences of `c` (largest measured: 2e-13; each test prints its own).
const TOL: f64 = 1e-11;

/// World gravity [m/s²], along neither the rod (local x at the base) nor a world axis.
const GRAVITY: [f64; 3] = [2.5, -3.0, -8.9];

/// Tensions [N]: the full-length tendon pulls, the half-length one pushes.
const U: [f64; 2] = [-1.5, 0.8];

/// Step of the central differences of `c` in z-space. The largest discrepancy of all identities
/// is 7e-13 at 0.005 (round-off, ∝ 1/h), 2e-13 at 0.01, 5e-13 at 0.02, 1e-10 at 0.04 (truncation,
/// ∝ h⁸).
const FD_STEP: f64 = 0.01;

/// Weights `w_k` of the eighth-order central difference `f' ≈ Σ_k w_k (f(kh) − f(−kh)) / h`.
const FD8: [(f64, f64); 4] = [
    (1.0, 4.0 / 5.0),
    (2.0, -1.0 / 5.0),
    (3.0, 4.0 / 105.0),
    (4.0, -1.0 / 280.0),
];

fn rod() -> Rod {
    Rod {
        material: Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.45,
            density: 1100.0,
            damping: 1e4,
        },
        divisions: vec![
            DivisionGeometry {
                length: 0.15,
                radius_start: 0.018,
                radius_end: 0.014,
                material: None,
                section: None,
            },
            DivisionGeometry {
                length: 0.10,
                radius_start: 0.014,
                radius_end: 0.009,
                material: None,
                section: None,
            },
        ],
    }
}

/// Extra computational points carrying the point wrenches (the tip, 0.25 m, is one already).
const EXTRA_X: [f64; 2] = [0.07, 0.2];

fn discretization(rod: &Rod) -> Discretization {
    let q = Quadrature::Gauss { n: 4 };
    Discretization::new(rod, &[q, q], MagnusOrder::Z4, &EXTRA_X).unwrap()
}

fn tendons() -> Vec<Tendon> {
    vec![
        // full length, off-axis in y and z, oblique (d' ≠ 0), with friction
        Tendon {
            offset_start: [0.006, 0.009],
            offset_end: [-0.004, 0.005],
            x_start: 0.0,
            x_end: 0.25,
            friction: 0.3,
            friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
            turns: 0.0,
            path: Vec::new(),
            axial_stiffness: None,
        },
        // first division only, frictionless
        Tendon {
            offset_start: [-0.008, -0.004],
            offset_end: [-0.006, -0.006],
            x_start: 0.0,
            x_end: 0.15,
            friction: 0.0,
            friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
            turns: 0.0,
            path: Vec::new(),
            axial_stiffness: None,
        },
    ]
}

fn base() -> Pose {
    Pose::new(
        Rotation3::from_euler_angles(0.3, -0.4, 0.7).into_inner(),
        V3::new(0.1, -0.05, 0.2),
    )
}

/// The high-order model: every strain component active in both divisions.
fn hom() -> Model<LinearBasis> {
    let rod = rod();
    let disc = discretization(&rod);
    let legendre = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [1, 2, 2, 1, 1, 1],
    };
    let basis = LinearBasis::per_division(&disc, &[legendre.clone(), legendre]).unwrap();
    Model::new(rod, disc, basis, tendons())
        .unwrap()
        .with_base(base())
}

/// The loads, one kind at a time, and all together.
fn load_sets() -> Vec<(&'static str, Loads)> {
    let gravity = Loads {
        gravity: GRAVITY,
        ..Loads::default()
    };
    let point = Loads {
        point: vec![
            PointWrench {
                x: 0.25,
                wrench: [0.01, -0.02, 0.015, 0.3, -0.2, 0.4],
                frame: Frame::Global,
            },
            PointWrench {
                x: 0.07,
                wrench: [-0.01, 0.02, 0.005, -0.1, 0.25, 0.15],
                frame: Frame::Local,
            },
            PointWrench {
                x: 0.2,
                wrench: [0.004, 0.0, -0.012, 0.05, 0.1, -0.2],
                frame: Frame::Global,
            },
        ],
        ..Loads::default()
    };
    let distributed = Loads {
        distributed: vec![
            DistributedWrench::Uniform {
                x_start: 0.02,
                x_end: 0.12,
                density: [0.05, 0.0, -0.03, 0.5, 1.0, -0.8],
                frame: Frame::Global,
            },
            // in the second division, ends inside cells of its 51 mm spacing
            DistributedWrench::Uniform {
                x_start: 0.16,
                x_end: 0.23,
                density: [-0.02, 0.04, 0.01, 0.3, -0.6, 0.9],
                frame: Frame::Local,
            },
            DistributedWrench::TriangularPulse {
                center: 0.18,
                width: 0.2,
                magnitude: 0.4,
                axis: [0.2, 1.0, -0.6],
                convention: PulseMagnitude::Peak,
            },
        ],
        ..Loads::default()
    };
    let all = Loads {
        gravity: GRAVITY,
        point: point.point.clone(),
        distributed: distributed.distributed.clone(),
    };
    vec![
        ("gravity", gravity),
        ("point wrenches", point),
        ("distributed wrenches", distributed),
        ("all loads", all),
    ]
}

fn all_loads() -> Loads {
    load_sets().pop().unwrap().1
}

/// The coefficient map `c: Rʳ → Rⁿ` of a reduced model.
enum Coeffs {
    /// A decoder folded with the projection `P`, evaluated by its own [`CoefficientMap::eval`].
    Decoder(AeDecoderMap),
    /// `c(z) = B z` (POD).
    Linear(DMatrix<f64>),
}

impl Coeffs {
    /// `c(z)` and the map's own Jacobian (`B` for a linear map).
    fn eval(&self, z: &DVector<f64>) -> (DVector<f64>, DMatrix<f64>) {
        match self {
            Coeffs::Decoder(map) => {
                let (m, r) = (map.n_out(), map.n_in());
                let mut scratch = vec![0.0; map.scratch_len()];
                let (mut c, mut cz) = (vec![0.0; m], vec![0.0; m * r]);
                map.eval(z.as_slice(), &mut c, &mut cz, &mut scratch);
                (DVector::from_vec(c), DMatrix::from_vec(m, r, cz))
            }
            Coeffs::Linear(b) => (b * z, b.clone()),
        }
    }

    fn value(&self, z: &DVector<f64>) -> DVector<f64> {
        self.eval(z).0
    }
}

/// A reduced model, its map and the reduced states `(z, ż, z̈)` it is checked at.
struct Case<P: StrainParam> {
    label: &'static str,
    rom: Model<P>,
    c: Coeffs,
    states: Vec<[DVector<f64>; 3]>,
}

/// The HOM quantities of the map at a reduced state: `q = c(z)`, `C_z`, `Ċ_z = ∂C_z/∂z ż`,
/// `q̇ = C_z ż`, `q̈ = C_z z̈ + Ċ_z ż`.
struct Mapped {
    q: DVector<f64>,
    cz: DMatrix<f64>,
    czd: DMatrix<f64>,
    qd: DVector<f64>,
    qdd: DVector<f64>,
}

/// Eighth-order central difference of `f` at `z` along `dir` (a step of [`FD_STEP`] in z-space).
fn directional(
    f: &dyn Fn(&DVector<f64>) -> DMatrix<f64>,
    z: &DVector<f64>,
    dir: &DVector<f64>,
) -> DMatrix<f64> {
    let s = FD_STEP / dir.norm();
    let mut d: Option<DMatrix<f64>> = None;
    for &(k, w) in &FD8 {
        let term = (f(&(z + dir * (k * s))) - f(&(z - dir * (k * s)))) * (w / s);
        d = Some(match d {
            Some(d) => d + term,
            None => term,
        });
    }
    d.unwrap()
}

fn unit(r: usize, j: usize) -> DVector<f64> {
    DVector::from_fn(r, |i, _| if i == j { 1.0 } else { 0.0 })
}

impl<P: StrainParam> Case<P> {
    fn r(&self) -> usize {
        self.rom.n_dof()
    }

    /// `C_z` (n × r): `B` for a linear map, else column j the difference of `c` along `e_j`.
    fn jacobian(&self, z: &DVector<f64>) -> DMatrix<f64> {
        if let Coeffs::Linear(b) = &self.c {
            return b.clone();
        }
        let value = |x: &DVector<f64>| {
            let c = self.c.value(x);
            DMatrix::from_column_slice(c.len(), 1, c.as_slice())
        };
        let cols: Vec<DVector<f64>> = (0..self.r())
            .map(|j| {
                directional(&value, z, &unit(self.r(), j))
                    .column(0)
                    .into_owned()
            })
            .collect();
        DMatrix::from_columns(&cols)
    }

    /// The map's own `C_z`, whose differences give the second-order terms (one level of
    /// differences instead of two; the first-order identities, which use [`Case::jacobian`], hold
    /// only if it is right).
    fn map_jacobian(&self, z: &DVector<f64>) -> DMatrix<f64> {
        self.c.eval(z).1
    }

    fn mapped(&self, state: &[DVector<f64>; 3]) -> Mapped {
        let [z, zd, zdd] = state;
        let q = self.c.value(z);
        let cz = self.jacobian(z);
        let czd = self.curvature(z, zd);
        let qd = &cz * zd;
        let qdd = &cz * zdd + &czd * zd;
        Mapped {
            q,
            cz,
            czd,
            qd,
            qdd,
        }
    }

    /// `Ċ_z = (∂C_z/∂z) ż`: zero for a linear map, else the difference of `C_z` along `ż`.
    fn curvature(&self, z: &DVector<f64>, zd: &DVector<f64>) -> DMatrix<f64> {
        match &self.c {
            Coeffs::Linear(b) => DMatrix::zeros(b.nrows(), b.ncols()),
            Coeffs::Decoder(_) => directional(&|x| self.map_jacobian(x), z, zd),
        }
    }

    /// `Σ_i w_i ∇²c_i(z)` (r × r): column j is `(∂C_z/∂z_j)ᵀ w`, i.e. the curvature along `e_j`.
    fn weighted_hessian(&self, z: &DVector<f64>, w: &DVector<f64>) -> DMatrix<f64> {
        let cols: Vec<DVector<f64>> = (0..self.r())
            .map(|j| self.curvature(z, &unit(self.r(), j)).transpose() * w)
            .collect();
        DMatrix::from_columns(&cols)
    }
}

/// `‖a − b‖ / ‖b‖` (Frobenius).
fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    assert_eq!(a.shape(), b.shape());
    let nb = b.norm();
    assert!(nb > 0.0, "the reference is zero");
    (a - b).norm() / nb
}

fn relv(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    assert_eq!(a.len(), b.len());
    let nb = b.norm();
    assert!(nb > 0.0, "the reference is zero");
    (a - b).norm() / nb
}

/// Asserts an identity and prints its discrepancy.
fn check(label: &str, what: &str, err: f64) {
    eprintln!("{label}: {what}: relative discrepancy {err:.2e}");
    assert!(
        err < TOL,
        "{label}: {what}: relative discrepancy {err:e} ≥ {TOL:e}"
    );
}

/// A random tanh decoder `r → 6p` (Glorot weights, biases uniform in ±0.5) in physical strain units
/// (`μ`, `s` per component: torsion, bending y/z [1/m], stretch, shear), folded with `P`.
fn random_decoder(
    hom: &Model<LinearBasis>,
    r: usize,
    seed: u64,
    form: DecoderForm,
) -> AeDecoderMap {
    let layout = PointLayout::active_in(&hom.param, &hom.disc);
    assert_eq!(layout.active, vec![0, 1, 2, 3, 4, 5]);
    let p = projection(&point_matrix(&hom.param, &layout)).unwrap();
    let nf = layout.len();
    let sizes = [r, 10, 20, nf];
    let mut rng = SplitMix64::new(seed);
    let glorot = Mlp::glorot(&sizes, &mut rng).unwrap();
    let weights = (0..sizes.len() - 1)
        .map(|k| glorot.weights(k).to_vec())
        .collect();
    let biases = (0..sizes.len() - 1)
        .map(|k| (0..sizes[k + 1]).map(|_| rng.range(-0.5, 0.5)).collect())
        .collect();
    let mlp = Mlp::new(&sizes, weights, biases).unwrap();
    let (mean, scale) = match form {
        // a bent, twisted, stretched and sheared reference around which z moves the rod
        DecoderForm::Plain => (
            [0.8, 2.0, -1.5, 0.02, 0.01, -0.015],
            [1.0, 2.5, 2.5, 0.02, 0.015, 0.015],
        ),
        // c = z₁ c̃(z): the mean is scaled by z₁ too
        DecoderForm::Scaled => (
            [0.6, -1.5, 2.0, -0.015, 0.01, 0.02],
            [0.8, 2.0, 2.0, 0.015, 0.01, 0.01],
        ),
    };
    let scaling = Scaling::new(
        (0..nf).map(|f| mean[layout.active[f % 6]]).collect(),
        (0..nf).map(|f| scale[layout.active[f % 6]]).collect(),
    )
    .unwrap();
    let map = DecoderMap::new(&mlp, &scaling, p.as_slice(), p.nrows()).unwrap();
    AeDecoderMap::new(map, form)
}

fn decoder_case(
    label: &'static str,
    r: usize,
    seed: u64,
    form: DecoderForm,
    states: Vec<[DVector<f64>; 3]>,
) -> Case<ReducedParam<AeDecoderMap>> {
    let h = hom();
    let map = random_decoder(&h, r, seed, form);
    let param = ReducedParam::new(&h.param, map.clone(), DVector::zeros(r)).unwrap();
    let rom = Model::new(h.rod, h.disc, param, h.tendons)
        .unwrap()
        .with_base(base());
    Case {
        label,
        rom,
        c: Coeffs::Decoder(map),
        states,
    }
}

fn v(x: &[f64]) -> DVector<f64> {
    DVector::from_column_slice(x)
}

/// The untrained tanh decoder, r = 3, at two states.
fn plain_decoder() -> Case<ReducedParam<AeDecoderMap>> {
    decoder_case(
        "tanh decoder (r = 3)",
        3,
        11,
        DecoderForm::Plain,
        vec![
            [
                v(&[0.4, -0.7, 0.9]),
                v(&[1.5, -2.0, 0.8]),
                v(&[-20.0, 35.0, 12.0]),
            ],
            [
                v(&[-0.9, 0.3, -0.2]),
                v(&[-0.6, 1.1, 2.3]),
                v(&[15.0, -8.0, 30.0]),
            ],
        ],
    )
}

/// The scaled decoder `c = z₁ c̃(z)`, r = 2 (z₁ away from 0, where its tangent degenerates).
fn scaled_decoder() -> Case<ReducedParam<AeDecoderMap>> {
    decoder_case(
        "scaled tanh decoder (r = 2)",
        2,
        23,
        DecoderForm::Scaled,
        vec![
            [v(&[1.2, -0.5]), v(&[-1.4, 2.2]), v(&[25.0, -18.0])],
            [v(&[-0.8, 0.7]), v(&[0.9, 1.6]), v(&[-12.0, 30.0])],
        ],
    )
}

/// POD, r = 4, of the HOM's point strains at 12 random coordinates (angles ±0.6, linear ±0.03):
/// `c(z) = P V z`; the states are the encodings of two of the snapshots.
fn pod() -> Case<LinearBasis> {
    let h = hom();
    let layout = PointLayout::active_in(&h.param, &h.disc);
    let pm = point_matrix(&h.param, &layout);
    let p = projection(&pm).unwrap();
    let n = h.n_dof();
    let mut rng = SplitMix64::new(5);
    let mut rows = Vec::new();
    let mut qs = Vec::new();
    for _ in 0..12 {
        // per division: 8 angular coordinates (torsion 2, bending 3 + 3), then 6 linear
        let q = DVector::from_fn(n, |i, _| {
            if i % 14 < 8 {
                rng.range(-0.6, 0.6)
            } else {
                rng.range(-0.03, 0.03)
            }
        });
        rows.extend((&pm * &q).iter());
        qs.push(q);
    }
    let pod = Pod::compute(&rows, layout.len(), 4).unwrap();
    let b = &p * &pod.modes;
    let basis = h.param.compose(&b).unwrap();
    let rom = Model::new(h.rod, h.disc, basis, h.tendons)
        .unwrap()
        .with_base(base());
    let z = |k: usize| pod.encode(&(&pm * &qs[k]));
    let states = vec![
        [z(2), z(7) * 10.0, z(4) * 150.0],
        [z(9), z(0) * -8.0, z(11) * 120.0],
    ];
    Case {
        label: "POD (r = 4)",
        rom,
        c: Coeffs::Linear(b),
        states,
    }
}

/// Runs `$body` with `$case` bound to each reduced model in turn.
macro_rules! for_each_case {
    (|$case:ident| $body:block) => {{
        {
            let $case = &plain_decoder();
            $body
        }
        {
            let $case = &scaled_decoder();
            $body
        }
        {
            let $case = &pod();
            $body
        }
    }};
}

fn prepared<P: StrainParam>(m: &Model<P>, loads: &Loads) -> PreparedLoads {
    m.prepare_loads(loads).unwrap()
}

/// The fixture's states are not planar: at `q` the rod is twisted, bent about both section axes,
/// stretched and sheared in both directions (largest `|ξ_a − ξ*_a|` over the points, per component,
/// at least 0.3 1/m for the curvatures and 3e-3 for the linear strains).
fn assert_three_dimensional(label: &str, h: &Model<LinearBasis>, q: &DVector<f64>) {
    let mut ws = h.workspace();
    h.forward(q, &mut ws, false);
    let xi = h.point_strains(&ws);
    let peak: Vec<f64> = (0..6)
        .map(|a| {
            xi.iter()
                .enumerate()
                .map(|(i, x)| (x[a] - h.xi_star(i)[a]).abs())
                .fold(0.0, f64::max)
        })
        .collect();
    eprintln!("{label}: largest |ξ − ξ*| per component {peak:.3?}");
    for (a, p) in peak.iter().enumerate() {
        let floor = if a < 3 { 0.3 } else { 3e-3 };
        assert!(
            *p > floor,
            "{label}: strain component {a} hardly excited ({p:e})"
        );
    }
}

#[test]
fn reduced_mass_matrix_is_the_hom_mass_projected_by_the_map_jacobian() {
    // M_r(z) = C_zᵀ M(c(z)) C_z   (§7.1 with J_r = J C_z, §6)
    let h = hom();
    let (mut wh, n) = (h.workspace(), h.n_dof());
    for_each_case!(|case| {
        let mut wr = case.rom.workspace();
        for s in &case.states {
            let mp = case.mapped(s);
            assert_eq!(mp.cz.shape(), (n, case.r()));
            assert_three_dimensional(case.label, &h, &mp.q);
            let expected = mp.cz.transpose() * h.mass_matrix(&mp.q, &mut wh) * &mp.cz;
            let got = case.rom.mass_matrix(&s[0], &mut wr);
            check(case.label, "M_r vs C_zᵀ M C_z", rel(&got, &expected));
        }
    });
}

#[test]
fn reduced_elastic_force_is_the_hom_stiffness_force_projected_by_the_map_jacobian() {
    // K₁,r(z) = Σ W Ψ_qᵀ Es (ξ − ξ*) = C_zᵀ K c(z), K the HOM's constant stiffness   (§7.3)
    let h = hom();
    let k = h.stiffness().unwrap().clone();
    for_each_case!(|case| {
        let mut wr = case.rom.workspace();
        for s in &case.states {
            let mp = case.mapped(s);
            let expected = mp.cz.transpose() * (&k * &mp.q);
            let got = case.rom.elastic_force(&s[0], &mut wr);
            check(case.label, "K₁,r vs C_zᵀ K q", relv(&got, &expected));
        }
    });
}

#[test]
fn reduced_external_forces_are_the_hom_external_forces_projected_by_the_map_jacobian() {
    // F_r(z) = Σ J_r,iᵀ w_i = C_zᵀ F(c(z)) for gravity, point and distributed wrenches   (§7.5)
    let h = hom();
    let mut wh = h.workspace();
    for_each_case!(|case| {
        let mut wr = case.rom.workspace();
        for (what, loads) in load_sets() {
            let (lh, lr) = (prepared(&h, &loads), prepared(&case.rom, &loads));
            for s in &case.states {
                let mp = case.mapped(s);
                let expected = mp.cz.transpose() * h.external_force(&mp.q, &lh, &mut wh);
                let got = case.rom.external_force(&s[0], &lr, &mut wr);
                check(
                    case.label,
                    &format!("F_r vs C_zᵀ F ({what})"),
                    relv(&got, &expected),
                );
            }
        }
    });
}

#[test]
fn reduced_actuation_matrix_is_the_hom_actuation_matrix_projected_by_the_map_jacobian() {
    // B_r(z) = C_zᵀ B(c(z)), column by column (tendon k at unit tension; friction on)   (§7.6–7.7)
    let h = hom();
    let mut wh = h.workspace();
    for_each_case!(|case| {
        let mut wr = case.rom.workspace();
        for s in &case.states {
            let mp = case.mapped(s);
            let expected = mp.cz.transpose() * h.actuation_matrix(&mp.q, &mut wh);
            let got = case.rom.actuation_matrix(&s[0], &mut wr);
            for k in 0..h.n_actuators() {
                check(
                    case.label,
                    &format!("B_r vs C_zᵀ B, tendon {k}"),
                    relv(
                        &got.column(k).into_owned(),
                        &expected.column(k).into_owned(),
                    ),
                );
            }
        }
    });
}

#[test]
fn reduced_statics_residual_is_the_hom_residual_projected_by_the_map_jacobian() {
    // R_r(z) = −K₁,r + F_r + B_r u = C_zᵀ R(c(z)) with every load and both tendons   (§8.1)
    let h = hom();
    let (mut wh, n) = (h.workspace(), h.n_dof());
    let loads = all_loads();
    let lh = prepared(&h, &loads);
    for_each_case!(|case| {
        let (mut wr, r) = (case.rom.workspace(), case.r());
        let lr = prepared(&case.rom, &loads);
        for s in &case.states {
            let mp = case.mapped(s);
            let mut res = DVector::zeros(n);
            h.statics_residual(&mp.q, &U, &lh, &mut wh, &mut res);
            let expected = mp.cz.transpose() * res;
            let mut got = DVector::zeros(r);
            case.rom.statics_residual(&s[0], &U, &lr, &mut wr, &mut got);
            check(case.label, "R_r vs C_zᵀ R", relv(&got, &expected));
        }
    });
}

#[test]
fn reduced_damping_matrix_and_force_are_the_hom_damping_projected_by_the_map_jacobian() {
    // D_r(z) = Σ W Ψ_qᵀ Ds Ψ_q = C_zᵀ D C_z and D₁,r(z, ż) = C_zᵀ D q̇, q̇ = C_z ż   (§7.4)
    let h = hom();
    let mut wh = h.workspace();
    h.forward(&DVector::zeros(h.n_dof()), &mut wh, false);
    let d = h.damping_matrix(&wh); // constant for a linear basis
    for_each_case!(|case| {
        let mut wr = case.rom.workspace();
        for s in &case.states {
            let mp = case.mapped(s);
            case.rom.forward(&s[0], &mut wr, false);
            let got = case.rom.damping_matrix(&wr);
            let expected = mp.cz.transpose() * &d * &mp.cz;
            check(case.label, "D_r vs C_zᵀ D C_z", rel(&got, &expected));
            let got = case.rom.damping_force(&s[0], &s[1], &mut wr);
            let expected = mp.cz.transpose() * h.damping_force(&mp.q, &mp.qd, &mut wh);
            check(case.label, "D₁,r vs C_zᵀ D q̇", relv(&got, &expected));
        }
    });
}

#[test]
fn reduced_coriolis_force_is_the_projected_hom_coriolis_force_plus_the_map_curvature_term() {
    // C_r ż = C_zᵀ (C(q, q̇) q̇ + M(q) Ċ_z ż): the body accelerations agree with q̈ = Ċ_z ż at
    // z̈ = 0 (paper eq. 7, §6, §7.2); the Ċ_z term is not small
    let h = hom();
    let mut wh = h.workspace();
    for_each_case!(|case| {
        let mut wr = case.rom.workspace();
        for s in &case.states {
            let mp = case.mapped(s);
            let projected = mp.cz.transpose() * h.coriolis_force(&mp.q, &mp.qd, &mut wh);
            let curvature = mp.cz.transpose() * (h.mass_matrix(&mp.q, &mut wh) * (&mp.czd * &s[1]));
            let expected = &projected + &curvature;
            let got = case.rom.coriolis_force(&s[0], &s[1], &mut wr);
            check(
                case.label,
                "C_r ż vs C_zᵀ (C q̇ + M Ċ_z ż)",
                relv(&got, &expected),
            );
            if matches!(case.c, Coeffs::Decoder(_)) {
                let without = relv(&projected, &expected);
                eprintln!("{}: C_r ż vs C_zᵀ C q̇ alone: {without:.2e}", case.label);
                assert!(
                    without > 1e3 * TOL,
                    "{}: the Ċ_z term is invisible ({without:e})",
                    case.label
                );
            }
        }
    });
}

#[test]
fn reduced_coriolis_matrix_is_the_projected_hom_coriolis_matrix_plus_the_map_curvature_term() {
    // C_r(z, ż) = C_zᵀ C(q, q̇) C_z + C_zᵀ M(q) Ċ_z, from J̇ˢ_r = J̇ˢ C_z + J Ċ_z   (§6, §7.2)
    let h = hom();
    let mut wh = h.workspace();
    for_each_case!(|case| {
        let mut wr = case.rom.workspace();
        for s in &case.states {
            let mp = case.mapped(s);
            let expected = mp.cz.transpose() * h.coriolis_matrix(&mp.q, &mp.qd, &mut wh) * &mp.cz
                + mp.cz.transpose() * h.mass_matrix(&mp.q, &mut wh) * &mp.czd;
            let got = case.rom.coriolis_matrix(&s[0], &s[1], &mut wr);
            check(
                case.label,
                "C_r vs C_zᵀ C C_z + C_zᵀ M Ċ_z",
                rel(&got, &expected),
            );
        }
    });
}

#[test]
fn reduced_dynamics_residual_is_the_projected_hom_residual_at_the_mapped_acceleration() {
    // ε_r(z, ż, z̈) = C_zᵀ ε(q, C_z ż, C_z z̈ + Ċ_z ż) with damping, gravity, every load and both
    // tendons (§7.8); the decoders take the motion path here (eval_motion + one reverse pass), and
    // the pass that also renews M its Ψ_q path. And τ_r = C_zᵀ (τ − M Ċ_z ż)   (§9.1)
    let h = hom();
    let (mut wh, n) = (h.workspace(), h.n_dof());
    let loads = all_loads();
    let lh = prepared(&h, &loads);
    for_each_case!(|case| {
        let (mut wr, r) = (case.rom.workspace(), case.r());
        let lr = prepared(&case.rom, &loads);
        for s in &case.states {
            let [z, zd, zdd] = s;
            let mp = case.mapped(s);
            let mut eps = DVector::zeros(n);
            h.dynamics_residual(&mp.q, &mp.qd, &mp.qdd, &U, &lh, &mut wh, &mut eps);
            let expected = mp.cz.transpose() * eps;
            let mut got = DVector::zeros(r);
            case.rom
                .dynamics_residual(z, zd, zdd, &U, &lr, &mut wr, &mut got);
            check(case.label, "ε_r vs C_zᵀ ε", relv(&got, &expected));
            case.rom
                .dynamics_residual_and_mass(z, zd, zdd, &U, &lr, &mut wr, &mut got);
            check(case.label, "ε_r (with M) vs C_zᵀ ε", relv(&got, &expected));
            let mut tau = DVector::zeros(n);
            h.dynamic_forces(&mp.q, &mp.qd, &U, &lh, &mut wh, &mut tau);
            let expected = mp.cz.transpose() * (tau - &wh.mass * (&mp.czd * zd));
            case.rom.dynamic_forces(z, zd, &U, &lr, &mut wr, &mut got);
            check(
                case.label,
                "τ_r vs C_zᵀ (τ − M Ċ_z ż)",
                relv(&got, &expected),
            );
        }
    });
}

#[test]
fn reduced_statics_tangent_is_the_projected_hom_tangent_plus_the_residual_weighted_map_hessian() {
    // K_T,r = −∂R_r/∂z = C_zᵀ K_T C_z − Σ_i R_i ∇²c_i with R the HOM's statics residual at
    // q = c(z), K_T = −∂R/∂q (§8.2, §4.5): the states are not equilibria, so the Hessian term is
    // present, and without it the identity fails
    let h = hom();
    let (mut wh, n) = (h.workspace(), h.n_dof());
    let loads = all_loads();
    let lh = prepared(&h, &loads);
    for_each_case!(|case| {
        let (mut wr, r) = (case.rom.workspace(), case.r());
        let lr = prepared(&case.rom, &loads);
        for s in &case.states {
            let z = &s[0];
            let mp = case.mapped(s);
            let mut dr = DMatrix::zeros(n, n);
            h.statics_jacobian(&mp.q, &U, &lh, &mut wh, &mut dr);
            let kt = -dr;
            let mut res = DVector::zeros(n);
            h.statics_residual(&mp.q, &U, &lh, &mut wh, &mut res);
            let projected = mp.cz.transpose() * &kt * &mp.cz;
            let expected = &projected - case.weighted_hessian(z, &res);
            let mut got = DMatrix::zeros(r, r);
            case.rom.statics_jacobian(z, &U, &lr, &mut wr, &mut got);
            got.neg_mut();
            check(
                case.label,
                "K_T,r vs C_zᵀ K_T C_z − Σ R_i ∇²c_i",
                rel(&got, &expected),
            );
            if matches!(case.c, Coeffs::Decoder(_)) {
                let without = rel(&projected, &expected);
                eprintln!(
                    "{}: K_T,r vs C_zᵀ K_T C_z alone: {without:.2e} (‖R‖ = {:.3e})",
                    case.label,
                    res.norm()
                );
                assert!(
                    without > 1e3 * TOL,
                    "{}: the Hessian term is invisible ({without:e})",
                    case.label
                );
            }
        }
    });
}
