//! Scenario files (TOML): the types, parsing with field paths in every error, and `--set path=value`
//! overrides applied to the parsed TOML before it is read into the types.
//!
//! The format is documented key by key in `docs/scenario-format.md`. Every table rejects unknown keys.
//! Reading goes TOML text → `toml::Table` (syntax errors with line and column) → overrides → a check
//! that no number is NaN or infinite → [`Scenario`] (type errors name the key's path, e.g.
//! `divisions[0].basis.order`). Physical validation and conversion to the engine's types are the build
//! layer's (`build`, above this module).

use crate::error::ScenarioError;
use gvs::discretize::MagnusOrder;
use gvs::loads::{Frame, PulseMagnitude};
use gvs::solve::statics::StaticsOptions;
use gvs::strain::FemDegree;
use serde::{Deserialize, Serialize};
use std::path::Path;
use toml::{Table, Value};

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
    #[serde(default)]
    pub solver: StaticsOptions,
    #[serde(default)]
    pub output: OutputSpec,
}

/// Isotropic material (gvs-spec §3.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// E [Pa].
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
    /// ℓ_j [m].
    pub length: f64,
    /// Uniform radius [m] (shorthand for equal `radius_start` and `radius_end`).
    #[serde(default)]
    pub radius: Option<f64>,
    #[serde(default)]
    pub radius_start: Option<f64>,
    #[serde(default)]
    pub radius_end: Option<f64>,
    pub basis: BasisSpec,
    /// Default: Legendre → `gauss = max(order) + 1`, at least 5 (SoRoSim); FEM → the basis's elements
    /// with 2 (linear) or 3 (quadratic) Gauss points each.
    #[serde(default)]
    pub quadrature: Option<QuadratureSpec>,
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
/// offsets are `radial_fraction · r(X) · (cos θ, sin θ)` (on the surface for fraction 1).
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
    /// Tension u [N]; negative pulls (bends the rod toward the tendon).
    #[serde(default)]
    pub tension: f64,
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

impl Scenario {
    /// Parses a scenario from TOML text with `--set` overrides applied. `source_name` names the
    /// text in syntax errors (a path or a preset name).
    pub fn from_toml(
        source_name: &str,
        text: &str,
        overrides: &[String],
    ) -> Result<Scenario, ScenarioError> {
        let mut table = parse_table(source_name, text)?;
        for spec in overrides {
            apply_override(&mut table, spec)?;
        }
        from_table(table)
    }

    /// The resolved scenario as a TOML table: every field, defaults filled in, `--set` overrides
    /// applied. Parsing it back gives the same scenario.
    pub fn to_table(&self) -> Result<Table, ScenarioError> {
        Table::try_from(self).map_err(|e| ScenarioError::invalid("scenario", e.to_string()))
    }

    /// [`Self::to_table`] as TOML text.
    pub fn to_toml(&self) -> Result<String, ScenarioError> {
        toml::to_string(&self.to_table()?)
            .map_err(|e| ScenarioError::invalid("scenario", e.to_string()))
    }

    /// The tensions `u` of the tendons, in order.
    pub fn tensions(&self) -> Vec<f64> {
        self.tendons.iter().map(|t| t.tension).collect()
    }

    /// Sets the tendon tensions: one value for every tendon, or one value per tendon.
    pub fn set_tensions(&mut self, u: &[f64]) -> Result<(), ScenarioError> {
        let u = tensions_for(self.tendons.len(), u)?;
        for (t, u) in self.tendons.iter_mut().zip(u) {
            t.tension = u;
        }
        Ok(())
    }
}

/// The tensions of `n` tendons from `u`: one value for every tendon, or one value per tendon.
pub fn tensions_for(n: usize, u: &[f64]) -> Result<Vec<f64>, ScenarioError> {
    if n == 0 {
        return Err(ScenarioError::invalid(
            "tendons",
            "the scenario has no tendons to set a tension on",
        ));
    }
    if u.len() != 1 && u.len() != n {
        return Err(ScenarioError::invalid(
            "tendons",
            format!(
                "{} tensions given for {n} tendons (give 1 value for all, or {n})",
                u.len()
            ),
        ));
    }
    Ok((0..n)
        .map(|k| if u.len() == 1 { u[0] } else { u[k] })
        .collect())
}

/// The error of `path` (given as `field`, e.g. `SCENARIO` or `--input`) that is `kind` ("a FIFO
/// (named pipe)", "a directory", …: [`crate::output::read::file_kind`]) instead of a regular file.
fn not_a_regular_file(field: &str, path: &Path, kind: &str) -> ScenarioError {
    ScenarioError::invalid(
        field,
        format!("`{}` is {kind}, not a regular file", path.display()),
    )
}

/// An error of [`crate::output::read`] reading the input `path` (given as `field`) as a scenario
/// error: a path that is not a regular file is refused naming `field`, the path and what it is; any
/// other error (missing, no permission, not UTF-8) goes through `other`.
pub fn read_error(
    field: &str,
    path: &Path,
    e: std::io::Error,
    other: impl FnOnce(std::io::Error) -> ScenarioError,
) -> ScenarioError {
    match crate::output::read::not_regular_kind(&e) {
        Some(kind) => not_a_regular_file(field, path, kind),
        None => other(e),
    }
}

/// Refuses `path` (given as `field`) if it is something other than a regular file (or a link to
/// one); the error says what it is. A path whose metadata cannot be read (missing, no permission)
/// passes: the reader reports that itself. A check before opening leaves a window in which the path
/// can be replaced: read with [`crate::output::read`] (and [`read_error`]) instead, which also
/// checks the opened file.
pub fn check_regular_file(field: &str, path: &Path) -> Result<(), ScenarioError> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => Err(not_a_regular_file(
            field,
            path,
            crate::output::read::file_kind(&meta.file_type()),
        )),
        _ => Ok(()),
    }
}

/// TOML text → table; syntax errors carry line and column.
pub fn parse_table(source_name: &str, text: &str) -> Result<Table, ScenarioError> {
    text.parse::<Table>().map_err(|e| ScenarioError::Syntax {
        source_name: source_name.to_string(),
        message: one_line(&e.to_string()),
    })
}

/// Table → [`Scenario`], after checking that no number is NaN or infinite. Errors name the key path.
pub fn from_table(table: Table) -> Result<Scenario, ScenarioError> {
    let value = Value::Table(table);
    check_finite(&value, &mut Vec::new())?;
    serde_path_to_error::deserialize::<_, Scenario>(value).map_err(|e| {
        let mut field = e.path().to_string();
        let message = e
            .inner()
            .message()
            .replace("expected usize", "expected an integer >= 0")
            .replace("expected f64", "expected a number");
        // Inside tagged tables (`kind = ...`) the path stops at the table: add the unknown key.
        if let Some(key) = message
            .strip_prefix("unknown field `")
            .and_then(|m| m.split('`').next())
        {
            if !field.ends_with(&format!(".{key}")) && field != key {
                field = if field == "." || field.is_empty() {
                    key.to_string()
                } else {
                    format!("{field}.{key}")
                };
            }
        }
        ScenarioError::Format { field, message }
    })
}

/// Rejects NaN and ±inf anywhere in the tree (TOML allows `nan` and `inf`).
fn check_finite(v: &Value, path: &mut Vec<Seg>) -> Result<(), ScenarioError> {
    match v {
        Value::Float(x) if !x.is_finite() => Err(ScenarioError::value(
            render_path(path),
            *x,
            "a finite number",
        )),
        Value::Table(t) => {
            for (k, v) in t {
                path.push(Seg::Key(k.clone()));
                check_finite(v, path)?;
                path.pop();
            }
            Ok(())
        }
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                path.push(Seg::Index(i));
                check_finite(v, path)?;
                path.pop();
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// A segment of a key path.
#[derive(Debug, Clone, PartialEq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// `a.b[0].c`
pub fn render_path(path: &[Seg]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// Parses `tendons.0.tension`, `tendons[0].tension` or `loads.gravity[2]` into segments. A purely
/// numeric dotted segment is an index.
pub fn parse_path(path: &str) -> Result<Vec<Seg>, String> {
    let mut segs = Vec::new();
    for part in path.split('.') {
        if part.is_empty() {
            return Err("empty segment in the key path".into());
        }
        let (key, mut rest) = match part.find('[') {
            Some(p) => (&part[..p], &part[p..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            match key.parse::<usize>() {
                Ok(i) => segs.push(Seg::Index(i)),
                Err(_) => segs.push(Seg::Key(key.to_string())),
            }
        } else if rest.is_empty() {
            return Err("empty segment in the key path".into());
        }
        while !rest.is_empty() {
            let close = rest
                .find(']')
                .ok_or_else(|| format!("unclosed `[` in `{part}`"))?;
            let idx = rest[1..close].parse::<usize>().map_err(|_| {
                format!(
                    "`{}` is not a list index (indices are 0-based non-negative integers)",
                    &rest[1..close]
                )
            })?;
            segs.push(Seg::Index(idx));
            rest = &rest[close + 1..];
            if !rest.is_empty() && !rest.starts_with('[') {
                return Err(format!("unexpected `{rest}` after an index in `{part}`"));
            }
        }
    }
    Ok(segs)
}

/// The value at `path` in `table`, if there is one.
pub fn lookup<'a>(table: &'a Table, path: &[Seg]) -> Option<&'a Value> {
    let (first, rest) = path.split_first()?;
    let Seg::Key(k) = first else { return None };
    let mut node = table.get(k)?;
    for seg in rest {
        node = match (seg, node) {
            (Seg::Key(k), Value::Table(t)) => t.get(k)?,
            (Seg::Index(i), Value::Array(a)) => a.get(*i)?,
            _ => return None,
        };
    }
    Some(node)
}

/// A key segment meant as a list index that is not a valid one: a signed integer or one too large
/// for an index (`-1`, `-0`, `99999999999999999999999`).
fn looks_like_index(key: &str) -> bool {
    let digits = key.trim_start_matches(['-', '+']);
    !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit())
}

/// Parses the right-hand side of `--set` as a TOML value (number, bool, array, inline table,
/// quoted string); anything that is not valid TOML is taken as a bare string (`--set magnus=z2`).
fn parse_value(raw: &str) -> Value {
    let raw = raw.trim();
    match format!("v = {raw}").parse::<Table>() {
        Ok(mut t) => t
            .remove("v")
            .unwrap_or_else(|| Value::String(raw.to_string())),
        Err(_) => Value::String(raw.to_string()),
    }
}

/// Most segments in a `--set` key path. The deepest key of the format has 5
/// (`divisions[0].basis.orders.bend_y`); the limit keeps a path of thousands of segments from
/// building a tree as deep, whose recursive walks would overflow the stack.
pub const MAX_OVERRIDE_SEGMENTS: usize = 16;

/// Applies one `path=value` override. Missing tables on the path are created (the deserializer
/// then rejects keys the format does not know, naming the path); a list index may be at most the
/// list's length (equal appends a new entry).
pub fn apply_override(table: &mut Table, spec: &str) -> Result<(), ScenarioError> {
    let err = |message: String| ScenarioError::Override {
        spec: spec.to_string(),
        message,
    };
    let (path, raw) = spec
        .split_once('=')
        .ok_or_else(|| err("expected `path=value`, e.g. `tendons.0.tension=-2`".into()))?;
    let segs = parse_path(path.trim()).map_err(&err)?;
    if segs.len() > MAX_OVERRIDE_SEGMENTS {
        return Err(err(format!(
            "the key path has {} segments (accepted: at most {MAX_OVERRIDE_SEGMENTS})",
            segs.len()
        )));
    }
    let Some(Seg::Key(_)) = segs.first() else {
        return Err(err("the path must start with a key".into()));
    };
    let value = parse_value(raw);
    let mut root = Value::Table(std::mem::take(table));
    let r = set_at(&mut root, &segs, 0, value);
    if let Value::Table(t) = root {
        *table = t;
    }
    r.map_err(err)
}

fn set_at(node: &mut Value, segs: &[Seg], depth: usize, value: Value) -> Result<(), String> {
    let here = || {
        if depth == 0 {
            "the scenario".to_string()
        } else {
            format!("`{}`", render_path(&segs[..depth]))
        }
    };
    let last = depth + 1 == segs.len();
    match (&segs[depth], node) {
        (Seg::Key(k), Value::Table(t)) => {
            if last {
                t.insert(k.clone(), value);
                return Ok(());
            }
            let child = t.entry(k.clone()).or_insert_with(|| match &segs[depth + 1] {
                Seg::Key(k) if !looks_like_index(k) => Value::Table(Table::new()),
                _ => Value::Array(Vec::new()),
            });
            set_at(child, segs, depth + 1, value)
        }
        (Seg::Index(i), Value::Array(a)) => {
            let i = *i;
            if i > a.len() {
                return Err(format!(
                    "index {i} is out of range: {} has {} entries (use index {} to append one)",
                    here(),
                    a.len(),
                    a.len()
                ));
            }
            if last {
                if i == a.len() {
                    a.push(value);
                } else {
                    a[i] = value;
                }
                return Ok(());
            }
            if i == a.len() {
                a.push(match segs[depth + 1] {
                    Seg::Key(_) => Value::Table(Table::new()),
                    Seg::Index(_) => Value::Array(Vec::new()),
                });
            }
            set_at(&mut a[i], segs, depth + 1, value)
        }
        (Seg::Index(i), Value::Table(_)) => Err(format!(
            "{} is a table, not a list: it has no index {i}",
            here()
        )),
        (Seg::Key(k), Value::Array(a)) if looks_like_index(k) => Err(format!(
            "`{k}` is not a valid index of {}: indices are 0-based non-negative integers and the list has {} entries ({})",
            here(),
            a.len(),
            match a.len() {
                0 => "give 0 to add the first".to_string(),
                1 => "0 changes it, 1 appends one".to_string(),
                n => format!("0 to {} change one, {n} appends one", n - 1),
            }
        )),
        (Seg::Key(k), Value::Array(_)) => Err(format!(
            "{} is a list: give an index before `{k}` (e.g. `{}.0.{k}`)",
            here(),
            render_path(&segs[..depth])
        )),
        (_, other) => Err(format!(
            "{} is a {}, it has no `{}`",
            here(),
            other.type_str(),
            render_path(&segs[depth..=depth]).trim_start_matches('.')
        )),
    }
}

/// Collapses a multi-line error (toml's source excerpt with carets) into one line, keeping the
/// position and the message.
fn one_line(s: &str) -> String {
    let is_excerpt = |l: &str| {
        let rest = l
            .trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start();
        rest.starts_with('|') || l.chars().all(|c| c == '^' || c == ' ')
    };
    let lines: Vec<&str> = s
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !is_excerpt(l))
        .collect();
    lines.join(": ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_round_trips_through_its_resolved_toml() {
        for p in crate::presets::PRESETS {
            let s = crate::presets::load(p.name, &[]).unwrap();
            let text = s.to_toml().unwrap();
            let back = Scenario::from_toml(p.name, &text, &[]).unwrap();
            assert_eq!(
                back.to_table().unwrap(),
                s.to_table().unwrap(),
                "{}",
                p.name
            );
            // every default is written out: the resolved text names the solver and the output
            let table = s.to_table().unwrap();
            for key in [
                "material",
                "divisions",
                "loads",
                "solver",
                "output",
                "magnus",
            ] {
                assert!(table.contains_key(key), "{}: no `{key}` in\n{text}", p.name);
            }
            assert_eq!(format!("{back:?}"), format!("{s:?}"), "{}", p.name);
        }
    }

    const MINIMAL: &str = r#"
        [material]
        youngs_modulus = 1e6
        poisson_ratio = 0.5
        density = 1000
        [[divisions]]
        length = 0.5
        radius = 0.01
        basis = { kind = "legendre", modes = ["bend_y"], order = 3 }
        [[tendons]]
        offset_start = [0.0, 0.005]
        offset_end = [0.0, 0.005]
        tension = -1
    "#;

    #[test]
    fn minimal_scenario_takes_documented_defaults() {
        let s = Scenario::from_toml("t", MINIMAL, &[]).unwrap();
        assert_eq!(s.loads.gravity, [0.0, 0.0, -9.81]);
        assert_eq!(s.material.damping, 1e4);
        assert_eq!(s.magnus, MagnusOrder::Z4);
        assert_eq!(s.output.centerline_points, 21);
        assert_eq!(s.tendons[0].x_end, None);
        assert_eq!(s.solver.ramp_steps, StaticsOptions::default().ramp_steps);
    }

    #[test]
    fn overrides_reach_nested_keys_by_dotted_or_bracket_paths() {
        let s = Scenario::from_toml(
            "t",
            MINIMAL,
            &[
                "tendons.0.tension=-2.5".into(),
                "divisions[0].basis.order=6".into(),
                "solver.ramp_steps=3".into(),
                "loads.gravity=[0, 0, 0]".into(),
                "magnus=z2".into(),
                "tendons.1.offset_start=[0, -0.005]".into(),
                "tendons[1].offset_end=[0, -0.005]".into(),
            ],
        )
        .unwrap();
        assert_eq!(s.tendons[0].tension, -2.5);
        assert_eq!(s.tendons.len(), 2);
        assert_eq!(s.solver.ramp_steps, 3);
        assert_eq!(s.loads.gravity, [0.0; 3]);
        assert_eq!(s.magnus, MagnusOrder::Z2);
        assert_eq!(s.divisions[0].basis.order, Some(6));
    }

    #[test]
    fn unknown_override_path_names_the_path() {
        let e = Scenario::from_toml("t", MINIMAL, &["divisions.0.basis.ordr=6".into()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("divisions[0].basis.ordr") && e.contains("unknown field"),
            "{e}"
        );
        let e = Scenario::from_toml("t", MINIMAL, &["tendons.5.tension=1".into()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("tendons.5.tension") && e.contains("out of range"),
            "{e}"
        );
        let e = Scenario::from_toml("t", MINIMAL, &["material.youngs_modulus.x=1".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("`material.youngs_modulus` is a float"), "{e}");
        let e = Scenario::from_toml("t", MINIMAL, &["tension".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("path=value"), "{e}");
    }

    #[test]
    fn negative_override_index_is_named_as_invalid_with_the_list_size() {
        for path in ["tendons.-1.tension=1", "tendons.-0.tension=1"] {
            let e = Scenario::from_toml("t", MINIMAL, &[path.into()])
                .unwrap_err()
                .to_string();
            let seg = &path[8..10];
            assert!(
                e.contains(&format!("`{seg}` is not a valid index of `tendons`"))
                    && e.contains("0-based non-negative integers")
                    && e.contains("the list has 1 entries"),
                "{e}"
            );
            assert!(!e.contains("tendons.0."), "{e}");
        }
        let e = Scenario::from_toml("t", MINIMAL, &["tendons[-1].tension=1".into()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`-1` is not a list index") && e.contains("non-negative"),
            "{e}"
        );
        // a list the scenario does not have yet: 0 entries
        let e = Scenario::from_toml("t", MINIMAL, &["loads.point.-1.x=0.1".into()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`-1` is not a valid index of `loads.point`") && e.contains("0 entries"),
            "{e}"
        );
    }

    #[test]
    fn override_path_of_thousands_of_segments_is_rejected_not_a_stack_overflow() {
        // Found by tests/scenario_fuzz.rs: 12 000 segments overflowed the stack (an abort, not a
        // panic) in the recursive walks of the tree the path builds.
        for spec in [
            format!("{}=1", vec!["a"; 100_001].join(".")),
            format!("tendons{}=1", "[0]".repeat(100_000)),
        ] {
            let e = Scenario::from_toml("t", MINIMAL, &[spec])
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("100001 segments") && e.contains("at most 16"),
                "{}",
                &e[e.len() - 80..]
            );
        }
        // The deepest keys of the format stay well inside the limit.
        let s = Scenario::from_toml("t", MINIMAL, &["divisions[0].basis.orders.bend_y=4".into()])
            .unwrap();
        assert_eq!(s.divisions[0].basis.orders.bend_y, Some(4));
    }

    #[test]
    fn non_finite_numbers_are_named() {
        let e = Scenario::from_toml("t", MINIMAL, &["tendons.0.offset_end=[0, nan]".into()])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("tendons[0].offset_end[1]") && e.contains("NaN") && e.contains("finite"),
            "{e}"
        );
        let text = MINIMAL.replace("density = 1000", "density = inf");
        let e = Scenario::from_toml("t", &text, &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("material.density") && e.contains("inf"), "{e}");
    }

    #[test]
    fn syntax_error_is_one_line_with_position() {
        let e = Scenario::from_toml("bad.toml", "[material\nyoungs_modulus = 1", &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("bad.toml: not valid TOML") && e.contains("line 1"),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");
    }
}
