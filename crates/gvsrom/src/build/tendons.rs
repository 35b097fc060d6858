//! Tendons: routing, termination and friction, checked against the rod they run along.

use super::limits::*;
use crate::error::ScenarioError;
use crate::scenario::TendonSpec;
use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::error::{fmt_rounded, fmt_value};
use gvs::rod::{DivisionGeometry, Rod};

/// The division at `x` and `X̄` there, on the side given: `after = true` takes the division
/// starting at `x` at a junction.
fn division_at(rod: &Rod, x: f64, after: bool) -> Option<(&DivisionGeometry, f64)> {
    let starts = rod.division_starts();
    let tol = 1e-12 * rod.length();
    let mut found = None;
    for (j, d) in rod.divisions.iter().enumerate() {
        let (x0, x1) = (starts[j], starts[j] + d.length);
        if x >= x0 - tol && x <= x1 + tol {
            found = Some((d, ((x - x0) / d.length).clamp(0.0, 1.0)));
            if !after {
                break;
            }
        }
    }
    found
}

/// How far the section at `x` reaches from the axis in the direction `θ` from `y` toward `z`
/// (the radius of a circle), on the side given ([`division_at`]).
pub(super) fn reach_at(rod: &Rod, x: f64, after: bool, theta: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    division_at(rod, x, after).map_or(f64::NAN, |(d, x_bar)| 1.0 / d.gauge_at(x_bar, c, s))
}

/// The section's gauge of the offset `(y, z)` at `x` of a tendon spanning `span` (> 1 outside;
/// the larger side of a junction the span enters, [`gvs::actuation::section_gauge`]) and
/// what the section there is, for a message.
fn gauge_at(rod: &Rod, span: (f64, f64), x: f64, y: f64, z: f64) -> (f64, String) {
    gvs::actuation::section_gauge(rod, span, x, y, z)
        .map_or((f64::NAN, String::new()), |(g, d, x_bar)| {
            (g, d.describe_at(x_bar))
        })
}

pub(super) fn tendon(k: usize, t: &TendonSpec, rod: &Rod) -> Result<Tendon, ScenarioError> {
    if let Some(path) = &t.path {
        return path_tendon(k, t, path, rod);
    }
    let f = |n: &str| format!("tendons[{k}].{n}");
    let l = rod.length();
    let x_start = finite(&f("x_start"), t.x_start)?;
    if !(0.0..l).contains(&x_start) {
        return Err(ScenarioError::value(
            f("x_start"),
            x_start,
            format!("an abscissa in [0, {}) m", fmt_rounded(l)),
        ));
    }
    let x_end = finite(&f("x_end"), t.x_end.unwrap_or(l))?;
    let x_end = span_end(&f("x_end"), x_end, x_start, l)?;
    let (friction, friction_smoothing) = friction(k, t, l)?;
    let explicit = t.offset_start.is_some() || t.offset_end.is_some();
    let polar = t.angle_deg.is_some() || t.radial_fraction.is_some();
    let (offset_start, offset_end) = match (explicit, polar) {
        (true, true) => {
            let polar_key = if t.angle_deg.is_some() {
                "angle_deg"
            } else {
                "radial_fraction"
            };
            return Err(ScenarioError::invalid(
                f(polar_key),
                "give either `offset_start` and `offset_end`, or `angle_deg` (with optional `radial_fraction`), not both",
            ));
        }
        (false, false) => {
            return Err(ScenarioError::invalid(
                f("offset_start"),
                "missing: give `offset_start` and `offset_end` ([y, z] in m), or `angle_deg`, or `path` (knots [X, d_y, d_z] in m)",
            ))
        }
        (true, false) => {
            let (Some(a), Some(b)) = (t.offset_start, t.offset_end) else {
                let missing = if t.offset_start.is_none() {
                    "offset_start"
                } else {
                    "offset_end"
                };
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
            let theta = in_range(&f("angle_deg"), angle, ANGLE_RANGE_DEG, "deg")?.to_radians();
            let c = t.radial_fraction.unwrap_or(1.0);
            if !(c.is_finite() && (0.0..=1.0).contains(&c)) {
                return Err(ScenarioError::value(
                    f("radial_fraction"),
                    c,
                    "a number in [0, 1] (1 = on the surface)",
                ));
            }
            let (s, co) = theta.sin_cos();
            let r0 = reach_at(rod, x_start, true, theta) * c;
            let r1 = reach_at(rod, x_end, false, theta) * c;
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
        turns: in_range(
            &f("turns"),
            t.turns,
            (-gvs::actuation::MAX_TURNS, gvs::actuation::MAX_TURNS),
            "(helical turns about the rod's axis over the span; 0 = oblique)",
        )?,
        path: Vec::new(),
        axial_stiffness: t.axial_stiffness,
    };
    // For circles |d(X)| is convex along the span and r(X) linear per division: checking the
    // span's ends and the division junctions inside it covers the whole path. A rectangle or an
    // ellipse is searched between them too (a helix turns the offset toward its narrow side).
    let sectioned = rod.divisions.iter().any(|d| d.section.is_some());
    let mut checks = vec![(x_start, "offset_start", "")];
    let starts = rod.division_starts();
    for &xj in starts.iter().skip(1) {
        if xj > x_start && xj < x_end {
            checks.push((xj, "offset_end", " (a division junction inside the span)"));
        }
    }
    checks.push((x_end, "offset_end", ""));
    if sectioned {
        let (x, _) = tendon.widest_excursion(rod);
        checks.push((
            x,
            "offset_end",
            " (where the path reaches farthest from the axis)",
        ));
    }
    for (x, which, note) in checks {
        let d = tendon.offset(x);
        let dn = d.norm();
        let span = (tendon.x_start, tendon.x_end);
        let (gauge, section) = gauge_at(rod, span, x, d[1], d[2]);
        if gauge > 1.0 + 1e-9 {
            let (field, how) = match (polar, tendon.turns != 0.0) {
                (true, false) => (
                    f("angle_deg"),
                    "the straight path between the surface points at x_start and x_end",
                ),
                (true, true) => (
                    f("angle_deg"),
                    "the helix from the surface point at x_start",
                ),
                (false, _) => (f(which), "the tendon"),
            };
            let (x, dn) = (fmt_value(x), fmt_value(dn));
            let message = match sectioned {
                false => format!(
                    "{how} leaves the cross-section at X = {x} m{note}: offset norm {dn} m > {section} (accepted: |offset| <= r(X) along the whole span)"
                ),
                true => format!(
                    "{how} leaves the cross-section at X = {x} m{note}: offset [{}, {}] m outside the {section} (accepted: offsets inside the section along the whole span)",
                    fmt_value(d[1]),
                    fmt_value(d[2])
                ),
            };
            return Err(ScenarioError::invalid(field, message));
        }
    }
    Ok(tendon)
}

/// The friction coefficient and smoothing of tendon `k` on a rod of length `l`, checked. A
/// smoothing scale above the largest curvature a load may imply (200 rad over the rod) would smooth
/// the friction away at every curvature (1e300 was accepted and turned it off without a word).
fn friction(k: usize, t: &TendonSpec, l: f64) -> Result<(f64, f64), ScenarioError> {
    let f = |n: &str| format!("tendons[{k}].{n}");
    let friction = in_range(
        &f("friction"),
        t.friction,
        FRICTION_RANGE,
        "(a capstan coefficient)",
    )?;
    let most = crate::plausibility::MAX_BENDING / l;
    let smoothing = in_range(
        &f("friction_smoothing"),
        t.friction_smoothing.unwrap_or(DEFAULT_FRICTION_SMOOTHING),
        (0.0, most),
        &format!("rad/m (a curvature scale, at most 200 rad over the rod's {} m: above, it smooths the friction away; 0 = no smoothing)", fmt_rounded(l)),
    )?;
    Ok((friction, smoothing))
}

/// A tendon routed through the knots `path` (`tendons.N.path`, gvs-spec §7.6 "Custom"): the span
/// and end offsets are the path's, so the keys that would give them otherwise are refused (an
/// `x_start` or `x_end` equal to the path's end is accepted); the engine checks the knots and that
/// the curve stays inside the rod ([`Tendon::validate_path`]).
fn path_tendon(
    k: usize,
    t: &TendonSpec,
    path: &[[f64; 3]],
    rod: &Rod,
) -> Result<Tendon, ScenarioError> {
    let f = |n: &str| format!("tendons[{k}].{n}");
    let given = [
        ("offset_start", t.offset_start.is_some()),
        ("offset_end", t.offset_end.is_some()),
        ("angle_deg", t.angle_deg.is_some()),
        ("radial_fraction", t.radial_fraction.is_some()),
        ("turns", t.turns != 0.0),
    ];
    if let Some((key, _)) = given.iter().find(|g| g.1) {
        return Err(ScenarioError::invalid(
            f(key),
            "give either `path` (knots [X, d_y, d_z] in m) or the end offsets (`offset_start` and `offset_end`, or `angle_deg`, optionally with `turns`), not both",
        ));
    }
    let (first, last) = match (path.first(), path.last()) {
        (Some(a), Some(b)) if path.len() >= gvs::actuation::path::MIN_KNOTS => (*a, *b),
        _ => {
            return Err(ScenarioError::invalid(
                f("path"),
                format!(
                    "{} knots (accepted: at least {} knots [X, d_y, d_z] in m)",
                    path.len(),
                    gvs::actuation::path::MIN_KNOTS
                ),
            ))
        }
    };
    if t.x_start != 0.0 && t.x_start != first[0] {
        return Err(ScenarioError::value(
            f("x_start"),
            t.x_start,
            format!("the path's first abscissa {} m, or no `x_start` (a path's span runs from its first to its last knot)", first[0]),
        ));
    }
    if let Some(x_end) = t.x_end.filter(|x| *x != last[0]) {
        return Err(ScenarioError::value(
            f("x_end"),
            x_end,
            format!("the path's last abscissa {} m, or no `x_end` (a path's span runs from its first to its last knot)", last[0]),
        ));
    }
    let l = rod.length();
    if !(first[0] >= 0.0 && first[0] < l) {
        return Err(ScenarioError::value(
            f("path[0][0]"),
            first[0],
            format!(
                "an abscissa in [0, {}) m (the tendon's start)",
                fmt_rounded(l)
            ),
        ));
    }
    if last[0].is_nan() || last[0] > l * (1.0 + 1e-12) {
        return Err(ScenarioError::value(
            f(&format!("path[{}][0]", path.len() - 1)),
            last[0],
            format!(
                "an abscissa <= the rod's length {} m (the tendon's end)",
                fmt_rounded(l)
            ),
        ));
    }
    let (friction, friction_smoothing) = friction(k, t, l)?;
    let tendon = Tendon {
        offset_start: [first[1], first[2]],
        offset_end: [last[1], last[2]],
        x_start: first[0],
        x_end: last[0],
        friction,
        friction_smoothing,
        turns: 0.0,
        path: path.to_vec(),
        axial_stiffness: t.axial_stiffness,
    };
    tendon.validate_path(rod, k)?;
    Ok(tendon)
}
