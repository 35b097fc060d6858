//! The rod: material, the divisions' geometry and the base pose.

use super::limits::*;
use crate::error::ScenarioError;
use crate::scenario::{DivisionSpec, Scenario};
use gvs::lie::{Pose, M3, V3};
use gvs::rod::{DivisionGeometry, Material};

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
        material: None,
    })
}

/// Checks the radii of division `j` lie in `[MIN_RADIUS, L]`, `L` the rod's total length.
pub(super) fn radius_range(j: usize, d: &DivisionSpec, l: f64) -> Result<(), ScenarioError> {
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
