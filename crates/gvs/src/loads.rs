//! External loads (gvs-spec §7.5): gravity, point wrenches (follower or world-fixed, at any X that is a
//! computational point), and distributed wrench densities, among them the paper's triangular-pulse
//! moment (Section IV-B).
//!
//! Wrenches are 6-vectors `[m; f]` (moment first). A *local* (follower) wrench is expressed in the
//! cross-section frame and turns with it; a *global* one keeps its world components.

use crate::error::{check_finite, check_range, fmt_rounded, fmt_value, ModelError};
use crate::lie::{V3, V6};
use serde::{Deserialize, Serialize};

/// The frame a wrench's components are given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Frame {
    /// Follower load: components in the cross-section frame.
    #[default]
    Local,
    /// World-fixed load: components in the world (base) frame.
    Global,
}

/// A concentrated wrench `[m; f]` at abscissa `x`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointWrench {
    pub x: f64,
    pub wrench: [f64; 6],
    #[serde(default)]
    pub frame: Frame,
}

/// How the magnitude of a triangular pulse is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum PulseMagnitude {
    /// Peak line density `M_e` [N·m/m] (gvs-spec §7.5, the reading consistent with the paper's figures).
    #[default]
    Peak,
    /// Total moment `∫ m dX` [N·m]; the peak is `2 M / w`.
    Total,
}

/// A distributed wrench density along the rod.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum DistributedWrench {
    /// A constant density `[m; f]` per metre on `[x_start, x_end]`.
    Uniform {
        x_start: f64,
        x_end: f64,
        density: [f64; 6],
        #[serde(default)]
        frame: Frame,
    },
    /// The paper's triangular-pulse moment (IV-B): a follower moment about the local unit `axis` with
    /// line density `m(X) = m̂ max(0, 1 − |X − X₀|/(w/2))`, `m̂` from `magnitude` by `convention`.
    TriangularPulse {
        center: f64,
        width: f64,
        magnitude: f64,
        axis: [f64; 3],
        #[serde(default)]
        convention: PulseMagnitude,
    },
}

impl DistributedWrench {
    /// Density `[m; f]` at `x` and its frame: `s(x)` × [`Self::peak_density`].
    pub fn density_at(&self, x: f64) -> (V6, Frame) {
        let (peak, frame) = self.peak_density();
        (peak * self.profile(x), frame)
    }

    /// The density where the profile is 1 (`density` of a uniform load; the pulse's peak moment
    /// density `m̂` about its unit axis) and its frame.
    pub fn peak_density(&self) -> (V6, Frame) {
        match *self {
            DistributedWrench::Uniform { density, frame, .. } => {
                (V6::from_row_slice(&density), frame)
            }
            DistributedWrench::TriangularPulse {
                width,
                magnitude,
                axis,
                convention,
                ..
            } => {
                let peak = match convention {
                    PulseMagnitude::Peak => magnitude,
                    PulseMagnitude::Total => 2.0 * magnitude / width,
                };
                let a = unit_axis(&axis).unwrap_or_else(V3::zeros) * peak;
                (V6::new(a[0], a[1], a[2], 0.0, 0.0, 0.0), Frame::Local)
            }
        }
    }

    /// The load's shape along the rod, `s(X) ∈ [0, 1]` with `density(X) = s(X) · density_max`: the
    /// indicator of `[x_start, x_end]` for a uniform load, `max(0, 1 − |X − X₀|/(w/2))` for the pulse.
    pub fn profile(&self, x: f64) -> f64 {
        match *self {
            DistributedWrench::Uniform { x_start, x_end, .. } => {
                f64::from(u8::from(x >= x_start && x <= x_end))
            }
            DistributedWrench::TriangularPulse { center, width, .. } => {
                (1.0 - (x - center).abs() / (0.5 * width)).max(0.0)
            }
        }
    }

    /// `∫_lo^hi s(X) dX` of [`Self::profile`], in closed form: the overlap with `[x_start, x_end]`
    /// for a uniform load; for the pulse, linear on each half `[X₀ − w/2, X₀]`, `[X₀, X₀ + w/2]`,
    /// the overlap `[a, b]` with each half gives `(b − a) s((a + b)/2)` (exact for a linear
    /// profile, and free of the cancellation of a cumulative `(X − X₀ + w/2)²/w` at large `w`).
    pub fn profile_integral(&self, lo: f64, hi: f64) -> f64 {
        let overlap = |a: f64, b: f64| (lo.max(a), hi.min(b));
        match *self {
            DistributedWrench::Uniform { x_start, x_end, .. } => {
                let (a, b) = overlap(x_start, x_end);
                (b - a).max(0.0)
            }
            DistributedWrench::TriangularPulse { center, width, .. } => {
                let h = 0.5 * width;
                [(center - h, center), (center, center + h)]
                    .into_iter()
                    .map(|(a, b)| overlap(a, b))
                    .filter(|(a, b)| b > a)
                    .map(|(a, b)| (b - a) * self.profile(0.5 * (a + b)))
                    .sum()
            }
        }
    }

    /// The field whose value sets how finely the load must be resolved (the pulse's `width`, a
    /// uniform load's `x_end`), its value, and the load's extent in words for a message.
    pub fn extent(&self) -> (&'static str, f64, String) {
        match *self {
            DistributedWrench::Uniform { x_start, x_end, .. } => (
                "x_end",
                x_end,
                format!(
                    "the span [x_start, x_end] = [{}, {}] m, {:.3e} m long,",
                    fmt_value(x_start),
                    fmt_value(x_end),
                    x_end - x_start
                ),
            ),
            DistributedWrench::TriangularPulse { width, center, .. } => (
                "width",
                width,
                format!("the pulse at {} m", fmt_value(center)),
            ),
        }
    }

    fn validate(&self, index: usize, length: f64) -> Result<(), ModelError> {
        let f = |n: &str| format!("loads.distributed[{index}].{n}");
        match *self {
            DistributedWrench::Uniform {
                x_start,
                x_end,
                density,
                ..
            } => {
                check_range(
                    &f("x_start"),
                    x_start,
                    Some((0.0, true)),
                    Some((length, false)),
                    &format!("an abscissa in [0, {}) m", fmt_rounded(length)),
                )?;
                check_range(
                    &f("x_end"),
                    x_end,
                    Some((x_start, false)),
                    // the end of divisions summed (0.7 + 0.2 m) is its decimal (0.9 m)
                    Some((length * (1.0 + 1e-12), true)),
                    &format!("an abscissa in ({x_start}, {}] m", fmt_rounded(length)),
                )?;
                for (i, v) in density.iter().enumerate() {
                    check_finite(&f(&format!("density[{i}]")), *v)?;
                }
            }
            DistributedWrench::TriangularPulse {
                center,
                width,
                magnitude,
                axis,
                ..
            } => {
                check_range(
                    &f("center"),
                    center,
                    Some((0.0, true)),
                    Some((length * (1.0 + 1e-12), true)),
                    &format!("an abscissa in [0, {}] m", fmt_rounded(length)),
                )?;
                check_range(
                    &f("width"),
                    width,
                    Some((0.0, false)),
                    None,
                    "a finite width > 0 m",
                )?;
                check_finite(&f("magnitude"), magnitude)?;
                for (i, v) in axis.iter().enumerate() {
                    check_finite(&f(&format!("axis[{i}]")), *v)?;
                }
                if unit_axis(&axis).is_none() {
                    return Err(ModelError::invalid(
                        f("axis"),
                        "[0, 0, 0] has no direction: expected a non-zero axis vector",
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The unit vector along `axis`, scaled by its largest component first so that neither tiny
/// (1e-300) nor huge (1e300) components under- or overflow the norm; `None` for the zero vector
/// or a non-finite one.
pub fn unit_axis(axis: &[f64; 3]) -> Option<V3> {
    let big = axis.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if !(axis.iter().all(|v| v.is_finite()) && big > 0.0) {
        return None;
    }
    let v = V3::from_row_slice(axis) / big;
    Some(v / v.norm())
}

/// Everything that loads the rod besides its tendons. Scaling by a load factor λ scales every entry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Loads {
    /// Gravitational acceleration in the world frame [m/s²] (paper: `(0, 0, −9.81)`).
    pub gravity: [f64; 3],
    #[serde(default)]
    pub point: Vec<PointWrench>,
    #[serde(default)]
    pub distributed: Vec<DistributedWrench>,
}

impl Loads {
    pub fn validate(&self, length: f64) -> Result<(), ModelError> {
        for (i, g) in self.gravity.iter().enumerate() {
            check_finite(&format!("loads.gravity[{i}]"), *g)?;
        }
        for (k, p) in self.point.iter().enumerate() {
            check_range(
                &format!("loads.point[{k}].x"),
                p.x,
                Some((0.0, true)),
                Some((length * (1.0 + 1e-12), true)),
                &format!("an abscissa in [0, {}] m", fmt_rounded(length)),
            )?;
            for (i, v) in p.wrench.iter().enumerate() {
                check_finite(&format!("loads.point[{k}].wrench[{i}]"), *v)?;
            }
        }
        for (k, d) in self.distributed.iter().enumerate() {
            d.validate(k, length)?;
        }
        Ok(())
    }

    /// The same loads multiplied by `lambda` (load ramping).
    pub fn scaled(&self, lambda: f64) -> Loads {
        let mut out = self.clone();
        for g in &mut out.gravity {
            *g *= lambda;
        }
        for p in &mut out.point {
            for w in &mut p.wrench {
                *w *= lambda;
            }
        }
        for d in &mut out.distributed {
            match d {
                DistributedWrench::Uniform { density, .. } => {
                    density.iter_mut().for_each(|v| *v *= lambda)
                }
                DistributedWrench::TriangularPulse { magnitude, .. } => *magnitude *= lambda,
            }
        }
        out
    }

    /// Abscissae of the point wrenches (to be inserted as computational points).
    pub fn point_abscissae(&self) -> Vec<f64> {
        self.point.iter().map(|p| p.x).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangular_pulse_conventions_integrate_to_expected_totals() {
        let w = 0.08;
        for (conv, total) in [
            (PulseMagnitude::Peak, 4.0 * w / 2.0),
            (PulseMagnitude::Total, 4.0),
        ] {
            let p = DistributedWrench::TriangularPulse {
                center: 0.2,
                width: w,
                magnitude: 4.0,
                axis: [0.0, 2.0, 0.0],
                convention: conv,
            };
            // midpoint rule on a fine grid
            let n = 200_000;
            let dx = 0.8 / n as f64;
            let s: f64 = (0..n)
                .map(|i| p.density_at((i as f64 + 0.5) * dx).0[1] * dx)
                .sum();
            assert!((s - total).abs() < 1e-6 * total, "{conv:?}: {s} vs {total}");
        }
    }

    #[test]
    fn profile_integral_is_the_exact_integral_of_the_profile() {
        let pulse = DistributedWrench::TriangularPulse {
            center: 0.03,
            width: 0.1,
            magnitude: 1.0,
            axis: [0.0, 1.0, 0.0],
            convention: PulseMagnitude::Total,
        };
        let uniform = DistributedWrench::Uniform {
            x_start: 0.1,
            x_end: 0.35,
            density: [1.0; 6],
            frame: Frame::Local,
        };
        // the pulse is cut by X = 0; both against a fine midpoint rule
        for (d, lo, hi) in [(pulse, 0.0, 0.8), (pulse, 0.01, 0.05), (uniform, 0.0, 0.2)] {
            let n = 400_000;
            let dx = (hi - lo) / n as f64;
            let s: f64 = (0..n)
                .map(|i| d.profile(lo + (i as f64 + 0.5) * dx) * dx)
                .sum();
            let exact = d.profile_integral(lo, hi);
            assert!(
                (s - exact).abs() < 1e-6 * exact,
                "{d:?} on [{lo}, {hi}]: {s} vs {exact}"
            );
        }
        assert!((pulse.profile_integral(-1.0, 1.0) - 0.05).abs() < 1e-15);
        assert!((uniform.profile_integral(0.0, 0.8) - 0.25).abs() < 1e-15);
    }

    #[test]
    fn an_axis_of_tiny_or_huge_components_has_its_direction() {
        for scale in [1e-300, 1.0, 1e300] {
            let u = unit_axis(&[0.0, 3.0 * scale, -4.0 * scale]).unwrap();
            assert!((u - V3::new(0.0, 0.6, -0.8)).norm() < 1e-15, "{scale}: {u}");
        }
        assert!(unit_axis(&[0.0; 3]).is_none());
        assert!(unit_axis(&[f64::NAN, 1.0, 0.0]).is_none());
    }

    #[test]
    fn invalid_pulse_names_field() {
        let l = Loads {
            gravity: [0.0; 3],
            point: vec![],
            distributed: vec![DistributedWrench::TriangularPulse {
                center: 0.2,
                width: -0.1,
                magnitude: 1.0,
                axis: [0.0, 1.0, 0.0],
                convention: PulseMagnitude::Peak,
            }],
        };
        let e = l.validate(0.8).unwrap_err().to_string();
        assert!(
            e.contains("loads.distributed[0].width") && e.contains("-0.1"),
            "{e}"
        );
    }
}
