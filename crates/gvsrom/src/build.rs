//! Scenario → engine: validates every value against its accepted range (naming the TOML field) and
//! builds the rod, discretization, strain basis, tendons, loads and solver options of the engine.
//!
//! The engine validates too; the checks here come first so that messages use the scenario's own key
//! paths, and they add what the engine cannot know (conflicting shorthand keys, sizes).

use crate::error::ScenarioError;
use crate::scenario::{
    default_pulse_axis, BasisKind, DistributedKind, DivisionSpec, Scenario, StrainMode, TendonSpec,
};
use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, Quadrature};
use gvs::lie::{Pose, M3, V3};
use gvs::loads::{DistributedWrench, Loads, PointWrench};
use gvs::model::Model;
use gvs::rod::{DivisionGeometry, Material, Rod};
use gvs::solve::statics::StaticsOptions;
use gvs::strain::{DivisionBasis, FemDegree, LinearBasis};

/// Largest Legendre order per mode accepted (higher orders are numerically pointless here).
pub const MAX_LEGENDRE_ORDER: usize = 50;
/// Largest number of Gauss points per division, or of elements per division.
pub const MAX_POINTS: usize = 5000;
/// Largest number of Gauss points per element.
pub const MAX_GAUSS_PER_ELEMENT: usize = 20;
/// Largest `n_dof × strain sites`: the tabulated basis and Jacobians are 6 × n·sites matrices
/// (5e6 ≈ 240 MB each).
pub const MAX_BASIS_SIZE: usize = 5_000_000;
/// Largest number of generalized coordinates (DOF). Statics factorizes a dense n × n Jacobian per
/// iteration (O(n³)): 2000 DOF is about a second per iteration on one core.
pub const MAX_DOF: usize = 2000;
/// Accepted Young's modulus E [Pa]: from the softest hydrogels (≈ 1 kPa) with three decades of
/// room below, to stiffer than diamond (1.2e12 Pa).
pub const YOUNGS_MODULUS_RANGE: (f64, f64) = (1.0, 1e13);
/// Accepted density ρ [kg/m³]: 0 (massless) to 1e5, five times the densest element (osmium 2.26e4).
pub const DENSITY_RANGE: (f64, f64) = (0.0, 1e5);
/// Largest gravitational acceleration |g| [m/s²] (1000 g).
pub const MAX_GRAVITY: f64 = 1e4;
/// Accepted division length ℓ_j [m]: 1 µm to 1 km.
pub const DIVISION_LENGTH_RANGE: (f64, f64) = (1e-6, 1e3);
/// Smallest radius [m] (0.1 µm); the largest is the rod's total length L (a rod is slender).
pub const MIN_RADIUS: f64 = 1e-7;
/// Largest number of centreline samples.
pub const MAX_CENTERLINE_POINTS: usize = 100_000;

/// Everything a statics run needs, built and validated.
pub struct Built {
    pub name: String,
    pub model: Model<LinearBasis>,
    pub loads: Loads,
    /// Tendon tensions u [N], in tendon order.
    pub u: Vec<f64>,
    pub options: StaticsOptions,
    pub centerline_points: usize,
    /// A reduced model (`--model`) that replaces the scenario's basis in statics and dynamics.
    pub reduced: Option<crate::reduce::Reduced>,
}

impl Built {
    /// Generalized coordinates of the model that runs: the reduced one if attached.
    pub fn n_dof(&self) -> usize {
        match &self.reduced {
            Some(r) => r.model.n_dof(),
            None => self.model.n_dof(),
        }
    }

    /// Tensions `u` [N] for a run in place of the scenario's, checked as a scenario built with
    /// them (`--tension`) would be: one value for every tendon or one per tendon
    /// ([`crate::scenario::tensions_for`]), finite, and plausible with the loads
    /// ([`crate::plausibility::check`]). Returns one value per tendon.
    pub fn tensions(&self, u: &[f64]) -> Result<Vec<f64>, ScenarioError> {
        let u = crate::scenario::tensions_for(self.model.n_actuators(), u)?;
        for (k, v) in u.iter().enumerate() {
            finite(&format!("tendons[{k}].tension"), *v)?;
        }
        let u_abs: Vec<f64> = u.iter().map(|v| v.abs()).collect();
        crate::plausibility::check(self, &u_abs, 1.0)?;
        Ok(u)
    }
}

/// A one-line description of the scenario as built (after `--set` and `--tension`), for the
/// summaries: `0.25 m tapered rod, gravity 9.81 m/s², 1 tendon (friction 0.88), 33-DOF Legendre
/// basis`. Derived from the model, never from the scenario's free-text `description`, so that it
/// cannot contradict the run.
pub fn describe(s: &Scenario, built: &Built) -> String {
    let m = &built.model;
    let g = &m.rod.divisions;
    let tapered = g.iter().any(|d| d.radius_start != d.radius_end)
        || g.windows(2).any(|w| w[0].radius_end != w[1].radius_start);
    let mut parts = vec![format!(
        "{} m {} rod{}",
        m.rod.length(),
        if tapered { "tapered" } else { "uniform" },
        match g.len() {
            1 => String::new(),
            n => format!(" in {n} divisions"),
        }
    )];
    let gravity = built
        .loads
        .gravity
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt();
    parts.push(if gravity > 0.0 {
        format!("gravity {gravity} m/s²")
    } else {
        "no gravity".into()
    });
    let tendons = &m.tendons;
    parts.push(match tendons.len() {
        0 => "no tendons".into(),
        n => {
            let (lo, hi) = tendons
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
                    (lo.min(t.friction), hi.max(t.friction))
                });
            let friction = if lo == hi {
                format!("friction {lo}")
            } else {
                format!("friction {lo} to {hi}")
            };
            format!("{n} tendon{} ({friction})", if n == 1 { "" } else { "s" })
        }
    });
    let count = |n: usize, what: &str| match n {
        0 => None,
        1 => Some(format!("1 {what}")),
        n => Some(format!("{n} {what}es")),
    };
    parts.extend(count(built.loads.point.len(), "point wrench"));
    parts.extend(count(built.loads.distributed.len(), "distributed wrench"));
    let mut kinds: Vec<&str> = vec![];
    for d in &s.divisions {
        let kind = match (d.basis.kind, d.basis.degree) {
            (BasisKind::Legendre, _) => "Legendre",
            (BasisKind::Fem, Some(FemDegree::Quadratic)) => "quadratic FEM-like",
            (BasisKind::Fem, _) => "linear FEM-like",
        };
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
    }
    parts.push(format!("{}-DOF {} basis", m.n_dof(), kinds.join(" + ")));
    parts.join(", ")
}

/// Validates `s` and builds the engine's model, loads, tensions and solver options; the loads must
/// pass [`crate::plausibility::check`] with the scenario's tensions and load factor 1.
pub fn build(s: &Scenario) -> Result<Built, ScenarioError> {
    let material = material(s)?;
    if s.divisions.is_empty() {
        return Err(ScenarioError::invalid(
            "divisions",
            "at least one [[divisions]] entry is required",
        ));
    }
    let geometry = s
        .divisions
        .iter()
        .enumerate()
        .map(|(j, d)| geometry(j, d))
        .collect::<Result<Vec<_>, _>>()?;
    let rod = Rod {
        material,
        divisions: geometry,
    };
    let length = rod.length();
    for (j, d) in s.divisions.iter().enumerate() {
        radius_range(j, d, length)?;
    }
    let bases = s
        .divisions
        .iter()
        .enumerate()
        .map(|(j, d)| basis(j, d))
        .collect::<Result<Vec<_>, _>>()?;
    let n_dof: usize = bases.iter().map(DivisionBasis::dofs).sum();
    if n_dof > MAX_DOF {
        return Err(ScenarioError::invalid(
            "divisions",
            format!(
                "the basis has {n_dof} DOF (accepted <= {MAX_DOF}): statics factorizes a dense {n_dof} × {n_dof} Jacobian per iteration; lower the basis orders or elements"
            ),
        ));
    }
    let quads = s
        .divisions
        .iter()
        .zip(&bases)
        .enumerate()
        .map(|(j, (d, b))| quadrature(j, d, b))
        .collect::<Result<Vec<_>, _>>()?;
    let base = base_pose(s)?;
    let tendons = s
        .tendons
        .iter()
        .enumerate()
        .map(|(k, t)| tendon(k, t, &rod))
        .collect::<Result<Vec<_>, _>>()?;
    let u = s
        .tendons
        .iter()
        .enumerate()
        .map(|(k, t)| finite(&format!("tendons[{k}].tension"), t.tension))
        .collect::<Result<Vec<_>, _>>()?;
    let loads = loads(s, length)?;
    s.solver.validate()?;
    let centerline_points = s.output.centerline_points;
    if !(2..=MAX_CENTERLINE_POINTS).contains(&centerline_points) {
        return Err(ScenarioError::value(
            "output.centerline_points",
            centerline_points as f64,
            format!("an integer in [2, {MAX_CENTERLINE_POINTS}]"),
        ));
    }

    let extra_x = loads.point_abscissae();
    let disc = Discretization::new(&rod, &quads, s.magnus, &extra_x)?;
    if n_dof.saturating_mul(disc.n_sites()) > MAX_BASIS_SIZE {
        return Err(ScenarioError::invalid(
            "divisions",
            format!(
                "the model is too large: {n_dof} DOF × {} strain sites = {} (accepted <= {MAX_BASIS_SIZE}); lower the basis orders/elements or the quadrature points",
                disc.n_sites(),
                n_dof * disc.n_sites()
            ),
        ));
    }
    let basis = LinearBasis::per_division(&disc, &bases)?;
    let model = Model::new(rod, disc, basis, tendons)?.with_base(base);
    let built = Built {
        name: s.name.clone().unwrap_or_else(|| "scenario".to_string()),
        model,
        loads,
        u,
        options: s.solver.clone(),
        centerline_points,
        reduced: None,
    };
    let u_abs: Vec<f64> = built.u.iter().map(|v| v.abs()).collect();
    crate::plausibility::check(&built, &u_abs, 1.0)?;
    Ok(built)
}

fn finite(field: &str, v: f64) -> Result<f64, ScenarioError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ScenarioError::value(field, v, "a finite number"))
    }
}

/// A bound for a message: plain in [1e-3, 1e4), else in exponent form (`1e13`).
pub(crate) fn num(v: f64) -> String {
    if v == 0.0 || (1e-3..1e4).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `v` in the closed range `[lo, hi]`, else an error naming `field` and the range.
fn in_range(field: &str, v: f64, (lo, hi): (f64, f64), unit: &str) -> Result<f64, ScenarioError> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(ScenarioError::value(
            field,
            v,
            format!("a number in [{}, {}] {unit}", num(lo), num(hi)),
        ))
    }
}

fn positive(field: &str, v: f64, unit: &str) -> Result<f64, ScenarioError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ScenarioError::value(
            field,
            v,
            format!("a finite number > 0 {unit}"),
        ))
    }
}

fn non_negative(field: &str, v: f64, unit: &str) -> Result<f64, ScenarioError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(ScenarioError::value(
            field,
            v,
            format!("a finite number >= 0 {unit}"),
        ))
    }
}

fn material(s: &Scenario) -> Result<Material, ScenarioError> {
    let m = &s.material;
    in_range(
        "material.youngs_modulus",
        m.youngs_modulus,
        YOUNGS_MODULUS_RANGE,
        "Pa",
    )?;
    if !(m.poisson_ratio.is_finite() && m.poisson_ratio > -1.0 && m.poisson_ratio <= 0.5) {
        return Err(ScenarioError::value(
            "material.poisson_ratio",
            m.poisson_ratio,
            "a number in (-1, 0.5]",
        ));
    }
    in_range("material.density", m.density, DENSITY_RANGE, "kg/m^3")?;
    non_negative("material.damping", m.damping, "Pa*s")?;
    Ok(Material {
        youngs_modulus: m.youngs_modulus,
        poisson_ratio: m.poisson_ratio,
        density: m.density,
        damping: m.damping,
    })
}

fn geometry(j: usize, d: &DivisionSpec) -> Result<DivisionGeometry, ScenarioError> {
    let f = |n: &str| format!("divisions[{j}].{n}");
    positive(&f("length"), d.length, "m")?;
    let length = in_range(&f("length"), d.length, DIVISION_LENGTH_RANGE, "m")?;
    let (r0, r1) = match (d.radius, d.radius_start, d.radius_end) {
        (Some(r), None, None) => (
            positive(&f("radius"), r, "m")?,
            positive(&f("radius"), r, "m")?,
        ),
        (None, Some(a), Some(b)) => (
            positive(&f("radius_start"), a, "m")?,
            positive(&f("radius_end"), b, "m")?,
        ),
        (Some(_), _, _) => return Err(ScenarioError::invalid(
            f("radius"),
            "give either `radius` (uniform) or `radius_start` and `radius_end` (tapered), not both",
        )),
        (None, Some(_), None) => {
            return Err(ScenarioError::invalid(
                f("radius_end"),
                "missing: `radius_start` needs `radius_end`",
            ))
        }
        (None, None, Some(_)) => {
            return Err(ScenarioError::invalid(
                f("radius_start"),
                "missing: `radius_end` needs `radius_start`",
            ))
        }
        (None, None, None) => {
            return Err(ScenarioError::invalid(
                f("radius"),
                "missing: give `radius` or `radius_start` and `radius_end` [m]",
            ))
        }
    };
    Ok(DivisionGeometry {
        length,
        radius_start: r0,
        radius_end: r1,
    })
}

/// Checks the radii of division `j` lie in `[MIN_RADIUS, L]`, `L` the rod's total length.
fn radius_range(j: usize, d: &DivisionSpec, l: f64) -> Result<(), ScenarioError> {
    let pairs = [
        ("radius", d.radius),
        ("radius_start", d.radius_start),
        ("radius_end", d.radius_end),
    ];
    for (name, r) in pairs {
        if let Some(r) = r {
            if !(r >= MIN_RADIUS && r <= l) {
                return Err(ScenarioError::value(
                    format!("divisions[{j}].{name}"),
                    r,
                    format!(
                        "a number in [{}, {l}] m (at most the rod's length)",
                        num(MIN_RADIUS)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The six active flags of a mode list; rejects an empty list and repeated modes.
fn mode_flags(field: &str, modes: &[StrainMode]) -> Result<[bool; 6], ScenarioError> {
    if modes.is_empty() {
        return Err(ScenarioError::invalid(
            field,
            "the basis is empty: list at least one strain mode of torsion, bend_y, bend_z, elongation, shear_y, shear_z",
        ));
    }
    let mut flags = [false; 6];
    for m in modes {
        if flags[m.index()] {
            return Err(ScenarioError::invalid(
                field,
                format!("mode `{}` is listed twice", m.name()),
            ));
        }
        flags[m.index()] = true;
    }
    Ok(flags)
}

fn basis(j: usize, d: &DivisionSpec) -> Result<DivisionBasis, ScenarioError> {
    let f = |n: &str| format!("divisions[{j}].basis.{n}");
    let b = &d.basis;
    let flags = mode_flags(&f("modes"), &b.modes)?;
    let not_for = |key: &str, kind: &str| {
        Err(ScenarioError::invalid(
            f(key),
            format!("not used by a {kind} basis (kind = \"{kind}\")"),
        ))
    };
    match b.kind {
        BasisKind::Legendre => {
            if b.elements.is_some() {
                return not_for("elements", "legendre");
            }
            if b.degree.is_some() {
                return not_for("degree", "legendre");
            }
            let mut ords = [0usize; 6];
            for m in StrainMode::ALL {
                let explicit = b.orders.get(m);
                if !flags[m.index()] {
                    if explicit.is_some() {
                        return Err(ScenarioError::invalid(
                            f(&format!("orders.{}", m.name())),
                            format!("mode `{}` is not in `modes`", m.name()),
                        ));
                    }
                    continue;
                }
                let (field, k) = match (explicit, b.order) {
                    (Some(k), _) => (f(&format!("orders.{}", m.name())), k),
                    (None, Some(k)) => (f("order"), k),
                    (None, None) => {
                        return Err(ScenarioError::invalid(
                            f("order"),
                            format!("missing: give `order` (all modes) or `orders.{}`", m.name()),
                        ))
                    }
                };
                if k > MAX_LEGENDRE_ORDER {
                    return Err(ScenarioError::value(
                        field,
                        k as f64,
                        format!("an integer in [0, {MAX_LEGENDRE_ORDER}]"),
                    ));
                }
                ords[m.index()] = k;
            }
            Ok(DivisionBasis::Legendre {
                modes: flags,
                orders: ords,
            })
        }
        BasisKind::Fem => {
            if b.order.is_some() {
                return not_for("order", "fem");
            }
            if let Some(m) = StrainMode::ALL
                .into_iter()
                .find(|&m| b.orders.get(m).is_some())
            {
                return not_for(&format!("orders.{}", m.name()), "fem");
            }
            let Some(elements) = b.elements else {
                return Err(ScenarioError::invalid(
                    f("elements"),
                    format!(
                        "missing: a fem basis needs `elements`, an integer in [1, {MAX_POINTS}]"
                    ),
                ));
            };
            if !(1..=MAX_POINTS).contains(&elements) {
                return Err(ScenarioError::value(
                    f("elements"),
                    elements as f64,
                    format!("an integer in [1, {MAX_POINTS}]"),
                ));
            }
            Ok(DivisionBasis::Fem {
                modes: flags,
                elements,
                degree: b.degree.unwrap_or(FemDegree::Linear),
            })
        }
    }
}

/// The division's quadrature; defaults follow SoRoSim (gvs-spec §5.1): Legendre → `max order + 1`
/// Gauss points, at least 5; FEM → per element, 2 (linear) or 3 (quadratic) points.
fn quadrature(
    j: usize,
    d: &DivisionSpec,
    basis: &DivisionBasis,
) -> Result<Quadrature, ScenarioError> {
    let f = |n: &str| format!("divisions[{j}].quadrature.{n}");
    let check = |field: String, v: usize, max: usize| {
        if (1..=max).contains(&v) {
            Ok(v)
        } else {
            Err(ScenarioError::value(
                field,
                v as f64,
                format!("an integer in [1, {max}]"),
            ))
        }
    };
    let q = d.quadrature.clone().unwrap_or_default();
    match (q.gauss, q.elements, q.gauss_per_element) {
        (None, None, None) => Ok(match basis {
            DivisionBasis::Fem {
                elements, degree, ..
            } => Quadrature::Elements {
                elements: *elements,
                gauss_per_element: match degree {
                    FemDegree::Linear => 2,
                    FemDegree::Quadratic => 3,
                },
            },
            DivisionBasis::Legendre { modes, orders } => {
                let max = (0..6).filter(|&i| modes[i]).map(|i| orders[i]).max().unwrap_or(0);
                Quadrature::Gauss {
                    n: (max + 1).max(5),
                }
            }
        }),
        (Some(n), None, None) => Ok(Quadrature::Gauss {
            n: check(f("gauss"), n, MAX_POINTS)?,
        }),
        (None, elements, Some(g)) => {
            let elements = match (elements, basis) {
                (Some(e), _) => check(f("elements"), e, MAX_POINTS)?,
                (None, DivisionBasis::Fem { elements, .. }) => *elements,
                (None, DivisionBasis::Legendre { .. }) => {
                    return Err(ScenarioError::invalid(
                        f("elements"),
                        "missing: per-element quadrature on a Legendre basis needs `elements`",
                    ))
                }
            };
            Ok(Quadrature::Elements {
                elements,
                gauss_per_element: check(f("gauss_per_element"), g, MAX_GAUSS_PER_ELEMENT)?,
            })
        }
        (Some(_), _, _) => Err(ScenarioError::invalid(
            f("gauss"),
            "give either `gauss` (points over the whole division) or `gauss_per_element` (with optional `elements`), not both",
        )),
        (None, Some(_), None) => Err(ScenarioError::invalid(
            f("gauss_per_element"),
            "missing: `elements` needs `gauss_per_element`",
        )),
    }
}

fn base_pose(s: &Scenario) -> Result<Pose, ScenarioError> {
    let b = &s.base;
    for (i, v) in b.position.iter().enumerate() {
        finite(&format!("base.position[{i}]"), *v)?;
    }
    let rot = match (b.rotation, b.axis, b.angle_deg) {
        (None, None, None) => M3::identity(),
        (Some(r), None, None) => {
            let m = M3::from_fn(|i, j| r[i][j]);
            for (i, row) in r.iter().enumerate() {
                for (j, v) in row.iter().enumerate() {
                    finite(&format!("base.rotation[{i}][{j}]"), *v)?;
                }
            }
            let orth = (m.transpose() * m - M3::identity()).abs().max();
            let det = m.determinant();
            if orth > 1e-6 || det <= 0.0 {
                return Err(ScenarioError::invalid(
                    "base.rotation",
                    format!(
                        "not a rotation matrix (‖RᵀR − I‖max = {orth:.2e}, det = {det:.6}); expected orthonormal rows with det = +1 (to 1e-6)"
                    ),
                ));
            }
            m
        }
        (None, Some(axis), Some(angle)) => {
            let a = V3::from_row_slice(&axis);
            let n = a.norm();
            if !(n.is_finite() && n > 0.0) {
                return Err(ScenarioError::value(
                    "base.axis",
                    n,
                    "a finite non-zero axis vector (its norm is shown)",
                ));
            }
            let angle = finite("base.angle_deg", angle)?.to_radians();
            *nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(a), angle).matrix()
        }
        (None, Some(_), None) => {
            return Err(ScenarioError::invalid(
                "base.angle_deg",
                "missing: `axis` needs `angle_deg`",
            ))
        }
        (None, None, Some(_)) => {
            return Err(ScenarioError::invalid(
                "base.axis",
                "missing: `angle_deg` needs `axis`",
            ))
        }
        (Some(_), _, _) => {
            return Err(ScenarioError::invalid(
                "base.rotation",
                "give either `rotation` or `axis` and `angle_deg`, not both",
            ))
        }
    };
    Ok(Pose::new(rot, V3::from_row_slice(&b.position)))
}

/// Radius at `x` on the side given: `after = true` takes the division starting at `x` at a junction.
fn radius_at(rod: &Rod, x: f64, after: bool) -> f64 {
    let starts = rod.division_starts();
    let tol = 1e-12 * rod.length();
    let mut found = None;
    for (j, d) in rod.divisions.iter().enumerate() {
        let (x0, x1) = (starts[j], starts[j] + d.length);
        if x >= x0 - tol && x <= x1 + tol {
            let r = d.radius_at(((x - x0) / d.length).clamp(0.0, 1.0));
            found = Some(r);
            if !after {
                break;
            }
        }
    }
    found.unwrap_or(f64::NAN)
}

fn tendon(k: usize, t: &TendonSpec, rod: &Rod) -> Result<Tendon, ScenarioError> {
    let f = |n: &str| format!("tendons[{k}].{n}");
    let l = rod.length();
    let x_start = finite(&f("x_start"), t.x_start)?;
    if !(0.0..l).contains(&x_start) {
        return Err(ScenarioError::value(
            f("x_start"),
            x_start,
            format!("an abscissa in [0, {l}) m"),
        ));
    }
    let x_end = finite(&f("x_end"), t.x_end.unwrap_or(l))?;
    if !(x_end > x_start && x_end <= l * (1.0 + 1e-12)) {
        return Err(ScenarioError::value(
            f("x_end"),
            x_end,
            format!("an abscissa in ({x_start}, {l}] m (after x_start)"),
        ));
    }
    let x_end = x_end.min(l);
    let friction = non_negative(&f("friction"), t.friction, "")?;
    let friction_smoothing = non_negative(
        &f("friction_smoothing"),
        t.friction_smoothing.unwrap_or(DEFAULT_FRICTION_SMOOTHING),
        "rad/m (a curvature scale; 0 = no smoothing)",
    )?;
    let explicit = t.offset_start.is_some() || t.offset_end.is_some();
    let polar = t.angle_deg.is_some() || t.radial_fraction.is_some();
    let (offset_start, offset_end) = match (explicit, polar) {
        (true, true) => {
            return Err(ScenarioError::invalid(
                f("angle_deg"),
                "give either `offset_start` and `offset_end`, or `angle_deg` (with optional `radial_fraction`), not both",
            ))
        }
        (false, false) => {
            return Err(ScenarioError::invalid(
                f("offset_start"),
                "missing: give `offset_start` and `offset_end` ([y, z] in m), or `angle_deg`",
            ))
        }
        (true, false) => {
            let (Some(a), Some(b)) = (t.offset_start, t.offset_end) else {
                let missing = if t.offset_start.is_none() { "offset_start" } else { "offset_end" };
                return Err(ScenarioError::invalid(
                    f(missing),
                    "missing: a tendon needs both `offset_start` and `offset_end` ([y, z] in m)",
                ));
            };
            for (name, v) in [("offset_start", a), ("offset_end", b)] {
                for (i, c) in v.iter().enumerate() {
                    finite(&f(&format!("{name}[{i}]")), *c)?;
                }
            }
            (a, b)
        }
        (false, true) => {
            let Some(angle) = t.angle_deg else {
                return Err(ScenarioError::invalid(
                    f("angle_deg"),
                    "missing: `radial_fraction` needs `angle_deg`",
                ));
            };
            let theta = finite(&f("angle_deg"), angle)?.to_radians();
            let c = t.radial_fraction.unwrap_or(1.0);
            if !(c.is_finite() && (0.0..=1.0).contains(&c)) {
                return Err(ScenarioError::value(
                    f("radial_fraction"),
                    c,
                    "a number in [0, 1] (1 = on the surface)",
                ));
            }
            let (s, co) = theta.sin_cos();
            let r0 = radius_at(rod, x_start, true) * c;
            let r1 = radius_at(rod, x_end, false) * c;
            ([r0 * co, r0 * s], [r1 * co, r1 * s])
        }
    };
    let tendon = Tendon {
        offset_start,
        offset_end,
        x_start,
        x_end,
        friction,
        friction_smoothing,
    };
    // |d(X)| is convex along the span and r(X) linear per division: checking the span's ends and
    // the division junctions inside it covers the whole path.
    let mut checks = vec![(x_start, radius_at(rod, x_start, true), "offset_start", "")];
    let starts = rod.division_starts();
    for &xj in starts.iter().skip(1) {
        if xj > x_start && xj < x_end {
            let r = radius_at(rod, xj, true).min(radius_at(rod, xj, false));
            checks.push((
                xj,
                r,
                "offset_end",
                " (a division junction inside the span)",
            ));
        }
    }
    checks.push((x_end, radius_at(rod, x_end, false), "offset_end", ""));
    for (x, r, which, note) in checks {
        let dn = tendon.offset(x).norm();
        if dn > r * (1.0 + 1e-9) {
            let (field, how) = if polar {
                (
                    f("angle_deg"),
                    "the straight path between the surface points at x_start and x_end",
                )
            } else {
                (f(which), "the tendon")
            };
            return Err(ScenarioError::invalid(
                field,
                format!(
                    "{how} leaves the cross-section at X = {x} m{note}: offset norm {dn} m > radius {r} m (accepted: |offset| <= r(X) along the whole span)"
                ),
            ));
        }
    }
    Ok(tendon)
}

fn wrench(moment: [f64; 3], force: [f64; 3]) -> [f64; 6] {
    [
        moment[0], moment[1], moment[2], force[0], force[1], force[2],
    ]
}

/// The validated loads of `s` on a rod of length `l` (part of [`build`]; a dataset that varies only
/// loads rebuilds just these).
pub fn loads(s: &Scenario, l: f64) -> Result<Loads, ScenarioError> {
    let spec = &s.loads;
    for (i, g) in spec.gravity.iter().enumerate() {
        finite(&format!("loads.gravity[{i}]"), *g)?;
    }
    let [gx, gy, gz] = spec.gravity;
    let g = gx.hypot(gy).hypot(gz); // no overflow to inf for finite components
    if g.is_nan() || g > MAX_GRAVITY {
        return Err(ScenarioError::value(
            "loads.gravity",
            g,
            format!(
                "a vector of magnitude <= {} m/s^2 (its magnitude is shown)",
                num(MAX_GRAVITY)
            ),
        ));
    }
    let mut point = Vec::new();
    for (k, p) in spec.point.iter().enumerate() {
        let f = |n: &str| format!("loads.point[{k}].{n}");
        let x = finite(&f("x"), p.x)?;
        if !(0.0..=l).contains(&x) {
            return Err(ScenarioError::value(
                f("x"),
                x,
                format!("an abscissa in [0, {l}] m"),
            ));
        }
        for (name, v) in [("force", p.force), ("moment", p.moment)] {
            for (i, c) in v.iter().enumerate() {
                finite(&f(&format!("{name}[{i}]")), *c)?;
            }
        }
        point.push(PointWrench {
            x,
            wrench: wrench(p.moment, p.force),
            frame: p.frame,
        });
    }
    let mut distributed = Vec::new();
    for (k, d) in spec.distributed.iter().enumerate() {
        let f = |n: &str| format!("loads.distributed[{k}].{n}");
        let not_for = |key: &str, kind: &str| {
            Err(ScenarioError::invalid(
                f(key),
                format!("not used by a {kind} load (kind = \"{kind}\")"),
            ))
        };
        distributed.push(match d.kind {
            DistributedKind::Uniform => {
                for (key, set) in [
                    ("center", d.center.is_some()),
                    ("width", d.width.is_some()),
                    ("magnitude", d.magnitude.is_some()),
                    ("axis", d.axis.is_some()),
                    ("convention", d.convention.is_some()),
                ] {
                    if set {
                        return not_for(key, "uniform");
                    }
                }
                let x_start = finite(&f("x_start"), d.x_start.unwrap_or(0.0))?;
                if !(0.0..l).contains(&x_start) {
                    return Err(ScenarioError::value(
                        f("x_start"),
                        x_start,
                        format!("an abscissa in [0, {l}) m"),
                    ));
                }
                let x_end = finite(&f("x_end"), d.x_end.unwrap_or(l))?;
                if !(x_end > x_start && x_end <= l) {
                    return Err(ScenarioError::value(
                        f("x_end"),
                        x_end,
                        format!("an abscissa in ({x_start}, {l}] m"),
                    ));
                }
                let force = d.force.unwrap_or_default();
                let moment = d.moment.unwrap_or_default();
                for (name, v) in [("force", force), ("moment", moment)] {
                    for (i, c) in v.iter().enumerate() {
                        finite(&f(&format!("{name}[{i}]")), *c)?;
                    }
                }
                DistributedWrench::Uniform {
                    x_start,
                    x_end,
                    density: wrench(moment, force),
                    frame: d.frame.unwrap_or_default(),
                }
            }
            DistributedKind::TriangularPulse => {
                for (key, set) in [
                    ("x_start", d.x_start.is_some()),
                    ("x_end", d.x_end.is_some()),
                    ("force", d.force.is_some()),
                    ("moment", d.moment.is_some()),
                    ("frame", d.frame.is_some()),
                ] {
                    if set {
                        return not_for(key, "triangular_pulse");
                    }
                }
                let required = |key: &str, v: Option<f64>, what: &str| {
                    v.ok_or_else(|| {
                        ScenarioError::invalid(
                            f(key),
                            format!("missing: a triangular_pulse needs `{key}` ({what})"),
                        )
                    })
                };
                let center = finite(
                    &f("center"),
                    required("center", d.center, "the pulse's centre X [m]")?,
                )?;
                if !(0.0..=l).contains(&center) {
                    return Err(ScenarioError::value(
                        f("center"),
                        center,
                        format!("an abscissa in [0, {l}] m"),
                    ));
                }
                let width = positive(
                    &f("width"),
                    required("width", d.width, "the base width [m]")?,
                    "m",
                )?;
                let magnitude = finite(
                    &f("magnitude"),
                    required("magnitude", d.magnitude, "N*m/m peak, or N*m total")?,
                )?;
                let axis = d.axis.unwrap_or_else(default_pulse_axis);
                let n = V3::from_row_slice(&axis).norm();
                if !(n.is_finite() && n > 0.0) {
                    return Err(ScenarioError::value(
                        f("axis"),
                        n,
                        "a finite non-zero axis vector (its norm is shown)",
                    ));
                }
                DistributedWrench::TriangularPulse {
                    center,
                    width,
                    magnitude,
                    axis,
                    convention: d.convention.unwrap_or_default(),
                }
            }
        });
    }
    Ok(Loads {
        gravity: spec.gravity,
        point,
        distributed,
    })
}

impl<'a> From<&'a Built> for crate::plausibility::Subject<'a> {
    fn from(b: &'a Built) -> Self {
        crate::plausibility::Subject {
            model: &b.model,
            u: &b.u,
            loads: &b.loads,
        }
    }
}
