//! Gravity, point wrenches and distributed wrenches, checked and converted to the engine's loads.

use super::limits::*;
use crate::error::ScenarioError;
use crate::scenario::{default_pulse_axis, DistributedKind, Scenario};
use gvs::error::fmt_rounded;
use gvs::loads::{DistributedWrench, Loads, PointWrench};

pub(super) fn wrench(moment: [f64; 3], force: [f64; 3]) -> [f64; 6] {
    [
        moment[0], moment[1], moment[2], force[0], force[1], force[2],
    ]
}

/// The validated loads of `s` on a rod of length `l` (part of `build`; a dataset that varies only
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
        let x = on_rod(&f("x"), finite(&f("x"), p.x)?, l)?;
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
                        format!("an abscissa in [0, {}) m", fmt_rounded(l)),
                    ));
                }
                let x_end = finite(&f("x_end"), d.x_end.unwrap_or(l))?;
                let x_end = span_end(&f("x_end"), x_end, x_start, l)?;
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
                let center = on_rod(&f("center"), center, l)?;
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
                direction(&f("axis"), &axis)?;
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
