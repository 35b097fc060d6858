//! The rod: material, the divisions' geometry and the base pose.

use super::limits::*;
use crate::error::ScenarioError;
use crate::scenario::{DivisionSpec, Scenario, SectionShapeSpec};
use gvs::lie::{Pose, M3, V3};
use gvs::rod::{DivisionGeometry, Material, Section, Shape};

pub(super) fn material(s: &Scenario) -> Result<Material, ScenarioError> {
    let m = &s.material;
    checked_material(
        "material",
        Material {
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
            density: m.density,
            damping: m.damping,
        },
    )
}

/// Division `j`'s own material (`[divisions.material]`): the rod's `rod` with the keys `d` gives
/// replaced, checked as `[material]` is, its fields named `divisions[j].material.*`; `None` when
/// it gives none or the rod's values (the same physics, recorded and compared as the same).
pub(super) fn division_material(
    j: usize,
    d: &DivisionSpec,
    rod: &Material,
) -> Result<Option<Material>, ScenarioError> {
    let Some(m) = &d.material else {
        return Ok(None);
    };
    let own = Material {
        youngs_modulus: m.youngs_modulus.unwrap_or(rod.youngs_modulus),
        poisson_ratio: m.poisson_ratio.unwrap_or(rod.poisson_ratio),
        density: m.density.unwrap_or(rod.density),
        damping: m.damping.unwrap_or(rod.damping),
    };
    let own = checked_material(&format!("divisions[{j}].material"), own)?;
    Ok((own != *rod).then_some(own))
}

/// `m` if its values are a material's, else an error naming `{prefix}.field`.
fn checked_material(prefix: &str, m: Material) -> Result<Material, ScenarioError> {
    let f = |n: &str| format!("{prefix}.{n}");
    in_range(
        &f("youngs_modulus"),
        m.youngs_modulus,
        YOUNGS_MODULUS_RANGE,
        "Pa",
    )?;
    if !(m.poisson_ratio.is_finite() && m.poisson_ratio > -1.0 && m.poisson_ratio <= 0.5) {
        return Err(ScenarioError::value(
            f("poisson_ratio"),
            m.poisson_ratio,
            "a number in (-1, 0.5]",
        ));
    }
    if m.density != 0.0 {
        in_range(&f("density"), m.density, DENSITY_RANGE, "kg/m^3").map_err(|_| {
            ScenarioError::value(
                f("density"),
                m.density,
                format!(
                    "0 (massless, for statics) or a number in [{}, {}] kg/m^3",
                    num(DENSITY_RANGE.0),
                    num(DENSITY_RANGE.1)
                ),
            )
        })?;
    }
    non_negative(&f("damping"), m.damping, "Pa*s")?;
    Ok(m)
}

pub(super) fn geometry(j: usize, d: &DivisionSpec) -> Result<DivisionGeometry, ScenarioError> {
    let f = |n: &str| format!("divisions[{j}].{n}");
    positive(&f("length"), d.length, "m")?;
    let length = in_range(&f("length"), d.length, DIVISION_LENGTH_RANGE, "m")?;
    let shape = match d.section.unwrap_or(SectionShapeSpec::Circle) {
        SectionShapeSpec::Circle => None,
        SectionShapeSpec::Rectangle => Some(Shape::Rectangle),
        SectionShapeSpec::Ellipse => Some(Shape::Ellipse),
    };
    let name = match shape {
        None => "circle",
        Some(Shape::Rectangle) => "rectangle",
        Some(Shape::Ellipse) => "ellipse",
        // a tube is a circle given an inner radius, below
        Some(Shape::Tube { .. }) => "tube",
    };
    // a key of the other shape is named before a pair of this one's is checked
    let radius_key = (["radius", "radius_start", "radius_end"].into_iter())
        .zip([d.radius, d.radius_start, d.radius_end])
        .find_map(|(n, v)| v.map(|_| n));
    if let (Some(_), Some(given)) = (shape, radius_key) {
        let article = if name == "ellipse" { "an" } else { "a" };
        return Err(ScenarioError::invalid(
            f(given),
            format!("{article} {name} has a `width` and a `height`, no radius: drop `{given}`"),
        ));
    }
    let radius = tapered(j, "radius", d.radius, d.radius_start, d.radius_end)?;
    let width = tapered(j, "width", d.width, d.width_start, d.width_end)?;
    let height = tapered(j, "height", d.height, d.height_start, d.height_end)?;
    let inner = inner_radius(j, d)?;
    if let (Some(_), Some((given, _))) = (shape, inner) {
        let article = if name == "ellipse" { "an" } else { "a" };
        return Err(ScenarioError::invalid(
            f(given),
            format!("{article} {name} is solid: an inner radius makes a circular section a tube; drop `{given}`"),
        ));
    }
    let Some(shape) = shape else {
        if let Some(name) = [("width", width), ("height", height)]
            .iter()
            .find_map(|(n, v)| v.map(|_| *n))
        {
            return Err(ScenarioError::invalid(
                f(name),
                format!("a circular section has a radius, no {name}: give `section = \"rectangle\"` or `\"ellipse\"` with `width` and `height`, or drop `{name}`"),
            ));
        }
        let Some((r0, r1)) = radius else {
            return Err(ScenarioError::invalid(
                f("radius"),
                "missing: give `radius` or `radius_start` and `radius_end` [m] (or a `section` of another shape)",
            ));
        };
        let Some((_, [i0, i1])) = inner.filter(|(_, r)| *r != [0.0; 2]) else {
            return Ok(DivisionGeometry {
                length,
                radius_start: r0,
                radius_end: r1,
                material: None,
                section: None,
            });
        };
        // a tube: its wall at least MIN_RADIUS thick at both ends (so all along, both linear)
        let uniform = d.inner_radius.is_some();
        for (end, r_i, r) in [("start", i0, r0), ("end", i1, r1)] {
            if r_i > r - MIN_RADIUS {
                let key = match uniform {
                    true => "inner_radius".to_string(),
                    false => format!("inner_radius_{end}"),
                };
                let outer = match d.radius {
                    Some(_) => format!("`radius` = {r} m"),
                    None => format!("the outer radius {r} m at the division's {end}"),
                };
                return Err(ScenarioError::value(
                    f(&key),
                    r_i,
                    format!(
                        "a radius in [0, {}] m: a wall of at least {} m inside {outer}",
                        num(r - MIN_RADIUS),
                        num(MIN_RADIUS)
                    ),
                ));
            }
        }
        return Ok(DivisionGeometry::with_section(
            length,
            Section {
                shape: Shape::Tube {
                    inner_radius: [i0, i1],
                },
                width: [2.0 * r0, 2.0 * r1],
                height: [2.0 * r0, 2.0 * r1],
            },
        ));
    };
    let (Some(w), Some(h)) = (width, height) else {
        let missing = if width.is_none() { "width" } else { "height" };
        let article = if name == "ellipse" { "an" } else { "a" };
        return Err(ScenarioError::invalid(
            f(missing),
            format!("missing: {article} {name} needs `width` (along the section's y axis) and `height` (along z) [m], each uniform or as `_start` and `_end`"),
        ));
    };
    Ok(DivisionGeometry::with_section(
        length,
        Section {
            shape,
            width: [w.0, w.1],
            height: [h.0, h.1],
        },
    ))
}

/// The inner radius of division `j`'s tube, uniform (`inner_radius`) or tapered
/// (`inner_radius_start`, `inner_radius_end`), each `>= 0` \[m\], with the first key given: `None`
/// if none is.
fn inner_radius(
    j: usize,
    d: &DivisionSpec,
) -> Result<Option<(&'static str, [f64; 2])>, ScenarioError> {
    let keys = ["inner_radius", "inner_radius_start", "inner_radius_end"];
    let values = [d.inner_radius, d.inner_radius_start, d.inner_radius_end];
    let Some(given) = keys.iter().zip(values).find_map(|(k, v)| v.map(|_| *k)) else {
        return Ok(None);
    };
    for (k, v) in keys.iter().zip(values) {
        if let Some(v) = v {
            non_negative(&format!("divisions[{j}].{k}"), v, "m")?;
        }
    }
    let f = |n: &str| format!("divisions[{j}].{n}");
    let pair = match values {
        [Some(r), None, None] => [r, r],
        [None, Some(a), Some(b)] => [a, b],
        [Some(_), _, _] => {
            return Err(ScenarioError::invalid(
                f("inner_radius"),
                "give either `inner_radius` (uniform) or `inner_radius_start` and `inner_radius_end` (tapered), not both",
            ))
        }
        [None, Some(_), None] => {
            return Err(ScenarioError::invalid(
                f("inner_radius_end"),
                "missing: `inner_radius_start` needs `inner_radius_end`",
            ))
        }
        [None, None, _] => {
            return Err(ScenarioError::invalid(
                f("inner_radius_start"),
                "missing: `inner_radius_end` needs `inner_radius_start`",
            ))
        }
    };
    Ok(Some((given, pair)))
}

/// A dimension of division `j` given uniform (`name`) or tapered (`name_start`, `name_end`), each
/// positive: `None` if none of them is given.
fn tapered(
    j: usize,
    name: &str,
    uniform: Option<f64>,
    start: Option<f64>,
    end: Option<f64>,
) -> Result<Option<(f64, f64)>, ScenarioError> {
    let f = |n: &str| format!("divisions[{j}].{n}");
    let (s, e) = (format!("{name}_start"), format!("{name}_end"));
    Ok(Some(match (uniform, start, end) {
        (Some(r), None, None) => (positive(&f(name), r, "m")?, positive(&f(name), r, "m")?),
        (None, Some(a), Some(b)) => (positive(&f(&s), a, "m")?, positive(&f(&e), b, "m")?),
        (Some(_), _, _) => {
            return Err(ScenarioError::invalid(
                f(name),
                format!("give either `{name}` (uniform) or `{s}` and `{e}` (tapered), not both"),
            ))
        }
        (None, Some(_), None) => {
            return Err(ScenarioError::invalid(
                f(&e),
                format!("missing: `{s}` needs `{e}`"),
            ))
        }
        (None, None, Some(_)) => {
            return Err(ScenarioError::invalid(
                f(&s),
                format!("missing: `{e}` needs `{s}`"),
            ))
        }
        (None, None, None) => return Ok(None),
    }))
}

/// Checks the radii (or widths and heights) of division `j` lie in `[MIN_RADIUS, L]`, `L` the
/// rod's total length.
pub(super) fn radius_range(j: usize, d: &DivisionSpec, l: f64) -> Result<(), ScenarioError> {
    let pairs = [
        ("radius", d.radius),
        ("radius_start", d.radius_start),
        ("radius_end", d.radius_end),
        ("width", d.width),
        ("width_start", d.width_start),
        ("width_end", d.width_end),
        ("height", d.height),
        ("height_start", d.height_start),
        ("height_end", d.height_end),
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

pub(super) fn base_pose(s: &Scenario) -> Result<Pose, ScenarioError> {
    let b = &s.base;
    for (i, v) in b.position.iter().enumerate() {
        let field = format!("base.position[{i}]");
        finite(&field, *v)?;
        if v.abs() > MAX_BASE_POSITION {
            return Err(ScenarioError::value(
                field,
                *v,
                format!("a number in [-{MAX_BASE_POSITION}, {MAX_BASE_POSITION}] m (the rod's size would vanish in the rounding of positions farther out)"),
            ));
        }
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
            let a = direction("base.axis", &axis)?;
            let angle = in_range("base.angle_deg", angle, ANGLE_RANGE_DEG, "deg")?.to_radians();
            *nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_unchecked(a), angle).matrix()
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

/// The straight, unstretched reference strain `[0, 0, 0, 1, 0, 0]`.
pub(super) const STRAIGHT: gvs::lie::V6 = gvs::lie::V6::new(0.0, 0.0, 0.0, 1.0, 0.0, 0.0);

/// Division `j`'s reference strain ξ* (default [`STRAIGHT`]): finite; a stretch `ν₁` in
/// (0, 10]; shears within ±1; curvatures that turn the division by at most
/// [`crate::plausibility::MAX_BENDING`] rad over its length.
pub(super) fn reference_strain(j: usize, d: &DivisionSpec) -> Result<gvs::lie::V6, ScenarioError> {
    let Some(x) = d.reference_strain else {
        return Ok(STRAIGHT);
    };
    let f = |i: usize| format!("divisions[{j}].reference_strain[{i}]");
    let turn = crate::plausibility::MAX_BENDING / d.length;
    for i in 0..3 {
        in_range(
            &f(i),
            x[i],
            (-turn, turn),
            "1/m (a curvature; at most 200 rad over the division)",
        )?;
    }
    // a rest length below a tenth of the rod's (1e-300 passed once: statics failed, a simulation
    // crawled and stopped on a NaN that named nothing)
    if !(x[3].is_finite() && (0.1..=10.0).contains(&x[3])) {
        return Err(ScenarioError::value(
            f(3),
            x[3],
            "a stretch in [0.1, 10] (1 = unstretched)",
        ));
    }
    for i in 4..6 {
        in_range(&f(i), x[i], (-1.0, 1.0), "(a shear strain)")?;
    }
    Ok(gvs::lie::V6::from_column_slice(&x))
}
