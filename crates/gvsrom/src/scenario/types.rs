//! The scenario's types: one struct per table of the format (`docs/scenario-format.md`), every
//! table rejecting unknown keys, with the documented defaults.

use gvs::discretize::MagnusOrder;
use gvs::loads::{Frame, PulseMagnitude};
use gvs::solve::statics::StaticsOptions;
use gvs::strain::FemDegree;
use serde::{Deserialize, Serialize};

/// A complete scenario: a rod, its discretization and strain basis, tendons, loads, solver and
/// output options.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name shown in summaries and written to the JSON output (default: the preset name or the
    /// file stem).
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub description: Option<String>,
    pub material: MaterialSpec,
    #[serde(default)]
    pub base: BaseSpec,
    /// Magnus (Zanna) order of the kinematics between computational points: `"z2"` or `"z4"`.
    #[serde(default)]
    pub magnus: MagnusOrder,
    pub divisions: Vec<DivisionSpec>,
    #[serde(default)]
    pub tendons: Vec<TendonSpec>,
    #[serde(default)]
    pub loads: LoadsSpec,
    /// Rigid bodies fixed to the rod (a payload, a gripper, discs).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bodies: Vec<BodySpec>,
    #[serde(default)]
    pub solver: StaticsOptions,
    #[serde(default)]
    pub output: OutputSpec,
}

/// Isotropic material (gvs-spec §3.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// E \[Pa\].
    pub youngs_modulus: f64,
    /// ν, in (−1, 0.5].
    pub poisson_ratio: f64,
    /// ρ [kg/m³].
    pub density: f64,
    /// Damping constant η [Pa·s] (SoRoSim default 1e4; statics does not use it).
    #[serde(default = "default_damping")]
    pub damping: f64,
}

fn default_damping() -> f64 {
    1e4
}

/// A division's material where it differs from `[material]` (`[divisions.material]`): each key
/// given replaces the rod's, the others are the rod's (a stiffer base: `youngs_modulus` alone).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DivisionMaterialSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub youngs_modulus: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson_ratio: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
}

/// Base pose `g(0)`: position and rotation of the first cross-section in the world frame. The
/// rotation is either a matrix (`rotation`, rows) or an axis and an angle in degrees; default identity.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseSpec {
    #[serde(default)]
    pub position: [f64; 3],
    #[serde(default)]
    pub rotation: Option<[[f64; 3]; 3]>,
    #[serde(default)]
    pub axis: Option<[f64; 3]>,
    #[serde(default)]
    pub angle_deg: Option<f64>,
}

/// One division of the rod: geometry, strain basis, quadrature.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DivisionSpec {
    /// ℓ_j \[m\].
    pub length: f64,
    /// Uniform radius \[m\] (shorthand for equal `radius_start` and `radius_end`).
    #[serde(default)]
    pub radius: Option<f64>,
    #[serde(default)]
    pub radius_start: Option<f64>,
    #[serde(default)]
    pub radius_end: Option<f64>,
    /// The inner radius \[m\] of a circular section: a tube (`0 <= inner_radius`, a wall of at
    /// least 1e-7 m; 0 builds the solid circle). Uniform, or tapered by `_start` and `_end`;
    /// absent (the default) it is not written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_radius_start: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_radius_end: Option<f64>,
    /// The section's shape: `"circle"` (the default: `radius`), `"rectangle"` or `"ellipse"`
    /// (`width` along the section's y axis and `height` along z, each uniform or tapered by its
    /// `_start` and `_end`); not written when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub section: Option<SectionShapeSpec>,
    /// Uniform width \[m\] of a rectangle or an ellipse (its extent along y).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_start: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_end: Option<f64>,
    /// Uniform height \[m\] of a rectangle or an ellipse (its extent along z).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_start: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_end: Option<f64>,
    pub basis: BasisSpec,
    /// Default: Legendre → `gauss = max(order) + 1`, at least 5 (SoRoSim), or `3 (max(order) + 1)`
    /// above order 3 (what the Z4 kinematics needs); FEM → the basis's elements with 2 (linear) or
    /// 3 (quadratic) Gauss points each.
    #[serde(default)]
    pub quadrature: Option<QuadratureSpec>,
    /// Reference strain ξ* `[torsion, bend_y, bend_z, elongation, shear_y, shear_z]` of the
    /// division, constant along it: the stress-free shape (gvs-spec §3.3). Default: the straight,
    /// unstretched rod `[0, 0, 0, 1, 0, 0]`; not written when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_strain: Option<[f64; 6]>,
    /// The division's material where it differs from the rod's `[material]` (the keys given
    /// replace the rod's); not written when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<DivisionMaterialSpec>,
}

/// A division's section shape (`divisions[j].section`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SectionShapeSpec {
    Circle,
    Rectangle,
    Ellipse,
}

/// A strain component, in the engine's order `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StrainMode {
    Torsion,
    BendY,
    BendZ,
    Elongation,
    ShearY,
    ShearZ,
}

impl StrainMode {
    pub const ALL: [StrainMode; 6] = [
        StrainMode::Torsion,
        StrainMode::BendY,
        StrainMode::BendZ,
        StrainMode::Elongation,
        StrainMode::ShearY,
        StrainMode::ShearZ,
    ];

    /// Row of the mode in the strain 6-vector.
    pub fn index(self) -> usize {
        self as usize
    }

    pub fn name(self) -> &'static str {
        [
            "torsion",
            "bend_y",
            "bend_z",
            "elongation",
            "shear_y",
            "shear_z",
        ][self.index()]
    }
}

/// The strain basis of one division (gvs-spec §4). `kind = "legendre"`: Legendre polynomials
/// `P_0..P_k` per active mode, `order` for every mode in `modes` unless `orders` names the mode.
/// `kind = "fem"`: FEM-like local (nodal) basis on `elements` equal elements per active mode, of
/// `degree` linear (default) or quadratic. (One flat table rather than a tagged enum, so that every
/// error can name its key.)
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BasisSpec {
    pub kind: BasisKind,
    pub modes: Vec<StrainMode>,
    #[serde(default)]
    pub order: Option<usize>,
    #[serde(default)]
    pub orders: ModeOrders,
    #[serde(default)]
    pub elements: Option<usize>,
    #[serde(default)]
    pub degree: Option<FemDegree>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BasisKind {
    Legendre,
    Fem,
}

/// Per-mode Legendre orders (override `order`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModeOrders {
    pub torsion: Option<usize>,
    pub bend_y: Option<usize>,
    pub bend_z: Option<usize>,
    pub elongation: Option<usize>,
    pub shear_y: Option<usize>,
    pub shear_z: Option<usize>,
}

impl ModeOrders {
    pub fn get(&self, mode: StrainMode) -> Option<usize> {
        [
            self.torsion,
            self.bend_y,
            self.bend_z,
            self.elongation,
            self.shear_y,
            self.shear_z,
        ][mode.index()]
    }
}

/// Computational points of a division (gvs-spec §5.1): `gauss` Gauss points over the whole
/// division plus its two ends, or `gauss_per_element` Gauss points in each of `elements` equal
/// elements plus the element ends.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadratureSpec {
    pub gauss: Option<usize>,
    pub elements: Option<usize>,
    pub gauss_per_element: Option<usize>,
}

/// A tendon (gvs-spec §7.6–7.7). Its offset `d(X) = [0, y, z]` is interpolated linearly from
/// `offset_start` at `x_start` to `offset_end` at `x_end`; or, with `angle_deg`, the two end
/// offsets are `radial_fraction · r(X, θ) · (cos θ, sin θ)`, `r(X, θ)` how far the section
/// reaches in that direction (on the surface for fraction 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TendonSpec {
    #[serde(default)]
    pub offset_start: Option<[f64; 2]>,
    #[serde(default)]
    pub offset_end: Option<[f64; 2]>,
    #[serde(default)]
    pub angle_deg: Option<f64>,
    #[serde(default)]
    pub radial_fraction: Option<f64>,
    #[serde(default)]
    pub x_start: f64,
    /// Default: the rod's length.
    #[serde(default)]
    pub x_end: Option<f64>,
    /// Capstan friction coefficient μ.
    #[serde(default)]
    pub friction: f64,
    /// Curvature scale κ_ε [rad/m] below which the friction angle is smoothed (default
    /// `gvs::actuation::DEFAULT_FRICTION_SMOOTHING`; 0 = the exact, kinked tangent rule).
    #[serde(default)]
    pub friction_smoothing: Option<f64>,
    /// Helical routing: turns of the offset about the rod's axis (+x, right-handed) over the
    /// span; 0 (default) = the oblique routing between the two offsets. Not written when 0, so
    /// that the resolved TOML (and every hash of it) of a scenario without helical tendons is
    /// what it was before the key existed.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub turns: f64,
    /// Custom routing: knots `[X, d_y, d_z]` \[m\] the offset passes through (a `C¹` cubic,
    /// `gvs::actuation::path`), in place of the two end offsets; the span is the first to the last
    /// knot. Not written when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<Vec<[f64; 3]>>,
    /// Tension u \[N\]; negative pulls (bends the rod toward the tendon).
    #[serde(default)]
    pub tension: f64,
    /// Instead of `tension`: the length δ \[m\] its actuator has wound in from the rest length
    /// (negative pays out); statics finds the tension, or the tendon goes slack
    /// (`gvs::solve::tendon_drive`). Not written when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<f64>,
    /// Axial stiffness `EA` \[N\] of the thread (`gvs::actuation::Tendon::axial_stiffness`);
    /// absent for an inextensible tendon. A tendon driven by `displacement` stretches by
    /// `ℓ_rest |u| / EA` under its tension; `simulate` needs it for such a tendon (the stretch is
    /// the spring through which the motor moves the rod). Not written when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_stiffness: Option<f64>,
}

/// Gravity, point wrenches and distributed wrenches.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadsSpec {
    /// World gravitational acceleration [m/s²].
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    #[serde(default)]
    pub point: Vec<PointLoadSpec>,
    #[serde(default)]
    pub distributed: Vec<DistributedLoadSpec>,
}

impl Default for LoadsSpec {
    fn default() -> Self {
        LoadsSpec {
            gravity: default_gravity(),
            point: Vec::new(),
            distributed: Vec::new(),
        }
    }
}

fn default_gravity() -> [f64; 3] {
    [0.0, 0.0, -9.81]
}

/// A rigid body fixed to the section at `x` (which becomes a computational point): its `mass`, its
/// centre of mass `center` in the section frame and its `inertia` about that centre, in the
/// section's axes: three principal values on the section's axes or a full symmetric tensor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub x: f64,
    pub mass: f64,
    #[serde(default)]
    pub center: [f64; 3],
    #[serde(default)]
    pub inertia: InertiaSpec,
}

/// A body's inertia tensor about its centre of mass: `[Ixx, Iyy, Izz]` on the section's axes, or
/// the 3 × 3 tensor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged, try_from = "toml::Value")]
pub enum InertiaSpec {
    Principal([f64; 3]),
    Tensor([[f64; 3]; 3]),
}

impl Default for InertiaSpec {
    fn default() -> Self {
        InertiaSpec::Principal([0.0; 3])
    }
}

impl TryFrom<toml::Value> for InertiaSpec {
    type Error = String;

    /// `[a, b, c]` or `[[..], [..], [..]]` of numbers (integers read as numbers), anything else an
    /// error saying what is accepted.
    fn try_from(v: toml::Value) -> Result<Self, String> {
        let number = |v: &toml::Value| match v {
            toml::Value::Float(x) => Some(*x),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        };
        let row = |v: &toml::Value| -> Option<[f64; 3]> {
            let a = v.as_array()?;
            let xs: Vec<f64> = a.iter().map(number).collect::<Option<_>>()?;
            xs.try_into().ok()
        };
        if let Some(p) = row(&v) {
            return Ok(InertiaSpec::Principal(p));
        }
        let rows: Option<Vec<[f64; 3]>> = v.as_array().and_then(|a| a.iter().map(row).collect());
        match rows.map(<[[f64; 3]; 3]>::try_from) {
            Some(Ok(t)) => Ok(InertiaSpec::Tensor(t)),
            _ => Err(format!(
                "{v} is not an inertia: expected [Ixx, Iyy, Izz] (kg*m^2 about the centre of mass, on the section's axes) or the symmetric 3 x 3 tensor [[I11, I12, I13], [I12, I22, I23], [I13, I23, I33]] (its off-diagonal entries are the tensor's, -integral of x*y dm)"
            )),
        }
    }
}

impl InertiaSpec {
    /// The tensor.
    pub fn tensor(&self) -> [[f64; 3]; 3] {
        match *self {
            InertiaSpec::Principal([a, b, c]) => [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]],
            InertiaSpec::Tensor(t) => t,
        }
    }
}

/// A concentrated wrench at abscissa `x` (which becomes a computational point).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLoadSpec {
    pub x: f64,
    #[serde(default)]
    pub force: [f64; 3],
    #[serde(default)]
    pub moment: [f64; 3],
    #[serde(default)]
    pub frame: Frame,
}

/// A distributed wrench density. `kind = "uniform"`: constant `force`/`moment` density on
/// `[x_start, x_end]` (default the whole rod) in `frame`. `kind = "triangular_pulse"`: the paper's
/// follower moment about the local `axis` (default local y), line density
/// `m(X) = m̂ max(0, 1 − |X − center|/(width/2))` with `m̂ = magnitude` (`convention = "peak"`,
/// default) or `2 magnitude / width` (`"total"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DistributedLoadSpec {
    pub kind: DistributedKind,
    // uniform
    #[serde(default)]
    pub x_start: Option<f64>,
    #[serde(default)]
    pub x_end: Option<f64>,
    #[serde(default)]
    pub force: Option<[f64; 3]>,
    #[serde(default)]
    pub moment: Option<[f64; 3]>,
    #[serde(default)]
    pub frame: Option<Frame>,
    // triangular pulse
    #[serde(default)]
    pub center: Option<f64>,
    #[serde(default)]
    pub width: Option<f64>,
    #[serde(default)]
    pub magnitude: Option<f64>,
    #[serde(default)]
    pub axis: Option<[f64; 3]>,
    #[serde(default)]
    pub convention: Option<PulseMagnitude>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DistributedKind {
    Uniform,
    TriangularPulse,
}

/// Default axis of a triangular pulse: local y.
pub fn default_pulse_axis() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// What the statics command reports.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Number of equally spaced centreline samples in the JSON output (≥ 2).
    #[serde(default = "default_centerline_points")]
    pub centerline_points: usize,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            centerline_points: default_centerline_points(),
        }
    }
}

fn default_centerline_points() -> usize {
    21
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}
