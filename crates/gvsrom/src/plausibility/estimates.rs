//! The estimate of each load on its own: the implied bending angle `θ = ∫ M_b/EI` and strain
//! `ε = max N/EA` (or `N/min(EA, GA)`) of its resultants on the straight reference rod, integrated
//! on a grid of sections (the table of resultants is in the module above).

use super::{Subject, GRID_POINTS, MAX_BENDING, MAX_STRAIN};
use gvs::error::fmt_value;
use gvs::lie::V3;
use gvs::loads::{DistributedWrench, Frame, PulseMagnitude};
use std::f64::consts::PI;

/// The estimate of one load.
pub(super) struct Estimate {
    /// The load by its scenario path and value, e.g. `tendons[0].tension = -3 N`.
    pub(super) name: String,
    /// Implied bending angle θ [rad].
    pub(super) bending: f64,
    /// Implied axial (tendons) or axial/shear (forces) strain.
    pub(super) strain: f64,
    pub(super) strain_kind: &'static str,
}

impl Estimate {
    /// The larger of the two ratios to their bounds (NaN counts as infinite).
    pub(super) fn severity(&self) -> f64 {
        let s = (self.bending / MAX_BENDING).max(self.strain / MAX_STRAIN);
        if s.is_nan() {
            f64::INFINITY
        } else {
            s
        }
    }
}

/// `a · b` with `0 · anything = 0` (no NaN from `0 · inf`).
fn mul(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 {
        0.0
    } else {
        a * b
    }
}

fn vec3(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| fmt_value(*x)).collect();
    format!("[{}]", items.join(", "))
}

/// One grid interval `[a, b]` with the section stiffnesses at its ends (of its own division).
struct Interval {
    a: f64,
    b: f64,
    /// The weaker of `EI_y`, `EI_z`.
    ei: [f64; 2],
    ea: [f64; 2],
    /// `min(EA, GA)`.
    ea_ga: [f64; 2],
    /// The section's area.
    area: [f64; 2],
    /// ρ of its division's material.
    density: f64,
}

fn grid(built: &Subject<'_>) -> Vec<Interval> {
    let rod = &built.model.rod;
    let per_div = (8192 / rod.divisions.len().max(1)).clamp(4, GRID_POINTS);
    let mut out = Vec::with_capacity(per_div * rod.divisions.len());
    for ((d, x0), material) in (rod.divisions.iter())
        .zip(rod.division_starts())
        .zip(rod.materials())
    {
        for i in 0..per_div {
            let (t0, t1) = (i as f64 / per_div as f64, (i + 1) as f64 / per_div as f64);
            // the section's weaker bending axis, its extension, and the weaker of extension and
            // shear
            let s = [d.props_at(material, t0), d.props_at(material, t1)];
            out.push(Interval {
                a: x0 + t0 * d.length,
                b: x0 + t1 * d.length,
                ei: s.map(|s| s.es[1].min(s.es[2])),
                ea: s.map(|s| s.es[3]),
                ea_ga: s.map(|s| s.es[3].min(s.es[4])),
                area: s.map(|s| s.area),
                density: material.density,
            });
        }
    }
    out
}

/// `(θ, ε)` of unit resultants `mb(s)`, `n(s)`: `θ = ∫ mb/EI`, `ε = max n/EA` (or `n/min(EA, GA)`
/// with `shear`).
fn integrate(
    grid: &[Interval],
    mb: impl Fn(f64) -> f64,
    n: impl Fn(f64) -> f64,
    shear: bool,
) -> (f64, f64) {
    let mut theta = 0.0;
    let mut eps: f64 = 0.0;
    for iv in grid {
        // just inside the interval, so that a jump at a grid point (a tendon's end, a span's end)
        // counts on its own side
        let inset = 1e-9 * (iv.b - iv.a);
        let (a, b) = (iv.a + inset, iv.b - inset);
        theta += 0.5 * (iv.b - iv.a) * (mb(a) / iv.ei[0] + mb(b) / iv.ei[1]);
        let stiff = if shear { iv.ea_ga } else { iv.ea };
        eps = eps.max(n(a) / stiff[0]).max(n(b) / stiff[1]);
    }
    (theta, eps)
}

/// `∫ₛ^∞ tri(x) dx` for the unit triangle of half-width `h` centred at `c`.
fn tri_tail(s: f64, c: f64, h: f64) -> f64 {
    if s <= c - h {
        h
    } else if s <= c {
        h - (s - c + h).powi(2) / (2.0 * h)
    } else if s < c + h {
        (c + h - s).powi(2) / (2.0 * h)
    } else {
        0.0
    }
}

/// Estimates of every load: tendons (with `u[k]`, signed or a bound), point and distributed
/// wrenches and gravity (scaled by `scale`). `bound` phrases tensions as bounds over a run when
/// they are not the scenario's own.
pub(super) fn estimates(built: &Subject<'_>, u: &[f64], scale: f64, bound: bool) -> Vec<Estimate> {
    let grid = grid(built);
    let model = &built.model;
    let l = model.rod.length();
    let scale = scale.abs();
    let scaled = if scale == 1.0 {
        String::new()
    } else {
        format!(" scaled by λ = {}", fmt_value(scale))
    };
    let mut out = Vec::new();

    for (k, (t, &uk)) in model.tendons.iter().zip(u).enumerate() {
        let span = |s: f64| s >= t.x_start && s <= t.x_end;
        let (theta, eps) = integrate(
            &grid,
            |s| if span(s) { t.offset(s).norm() } else { 0.0 },
            |s| if span(s) { 1.0 } else { 0.0 },
            false,
        );
        let own = built.u.get(k).copied();
        let name = match own {
            Some(v) if !bound || v.abs() == uk.abs() => {
                let v = if bound { v } else { uk };
                format!("tendons[{k}].tension = {} N", fmt_value(v))
            }
            _ => format!("tendons[{k}].tension up to |u| = {} N", fmt_value(uk.abs())),
        };
        out.push(Estimate {
            name,
            bending: mul(uk.abs(), theta),
            strain: mul(uk.abs(), eps),
            strain_kind: "an axial strain",
        });
    }

    let loads = built.loads;
    for (k, p) in loads.point.iter().enumerate() {
        let m = V3::from_row_slice(&p.wrench[..3]).norm();
        let f = V3::from_row_slice(&p.wrench[3..]).norm();
        let bends = bending_force(&p.wrench, p.frame);
        let before = |s: f64| s <= p.x;
        let (theta_m, _) = integrate(&grid, |s| if before(s) { 1.0 } else { 0.0 }, |_| 0.0, true);
        let (theta_f, eps_f) = integrate(
            &grid,
            |s| if before(s) { p.x - s } else { 0.0 },
            |s| if before(s) { 1.0 } else { 0.0 },
            true,
        );
        let name = wrench_name(&format!("loads.point[{k}]"), &p.wrench, "N", "N*m");
        out.push(Estimate {
            name: name + &scaled,
            bending: mul(scale, mul(m, theta_m))
                + force_bending(mul(scale, bends), theta_f, p.frame),
            strain: mul(scale, mul(f, eps_f)),
            strain_kind: "an axial/shear strain",
        });
    }

    for (k, d) in loads.distributed.iter().enumerate() {
        let field = format!("loads.distributed[{k}]");
        match *d {
            DistributedWrench::Uniform {
                x_start: a,
                x_end: b,
                density,
                frame,
            } => {
                let m = V3::from_row_slice(&density[..3]).norm();
                let f = V3::from_row_slice(&density[3..]).norm();
                let bends = bending_force(&density, frame);
                let len = |s: f64| (b - s.max(a)).max(0.0);
                let (theta_m, _) = integrate(&grid, len, |_| 0.0, true);
                let (theta_f, eps_f) = integrate(
                    &grid,
                    |s| {
                        if s >= b {
                            0.0
                        } else {
                            0.5 * ((b - s).powi(2) - (s.max(a) - s).powi(2))
                        }
                    },
                    len,
                    true,
                );
                let name = wrench_name(&field, &density, "N/m", "N*m/m");
                out.push(Estimate {
                    name: name + &scaled,
                    bending: mul(scale, mul(m, theta_m))
                        + force_bending(mul(scale, bends), theta_f, frame),
                    strain: mul(scale, mul(f, eps_f)),
                    strain_kind: "an axial/shear strain",
                });
            }
            DistributedWrench::TriangularPulse {
                center,
                width,
                magnitude,
                convention,
                ..
            } => {
                let h = 0.5 * width;
                let (peak, unit) = match convention {
                    PulseMagnitude::Peak => (magnitude.abs(), "N*m/m"),
                    PulseMagnitude::Total => (2.0 * magnitude.abs() / width, "N*m"),
                };
                let tip = tri_tail(l, center, h);
                let (theta, _) = integrate(
                    &grid,
                    |s| (tri_tail(s, center, h) - tip).max(0.0),
                    |_| 0.0,
                    false,
                );
                out.push(Estimate {
                    name: format!(
                        "{field}.magnitude = {} {unit}{scaled}",
                        fmt_value(magnitude)
                    ),
                    bending: mul(scale, mul(peak, theta)),
                    strain: 0.0,
                    strain_kind: "an axial/shear strain",
                });
            }
        }
    }

    let [gx, gy, gz] = loads.gravity;
    let g = gx.hypot(gy).hypot(gz);
    // the heaviest division's density names the load; the resultants weigh each division's own
    let rho = model.rod.materials().map(|m| m.density).fold(0.0, f64::max);
    if mul(g, rho) > 0.0 {
        // resultants of the mass per length ρA(x) at the grid's ends, from the tip backward:
        // N_a = N_b + ∫_a^b ρA, M_a = M_b + N_b (b − a) + ∫_a^b ρA (x − a) dx (A linear-ish:
        // trapezoid weights at the ends)
        let n_iv = grid.len();
        let mut n_end = vec![[0.0; 2]; n_iv];
        let mut m_end = vec![[0.0; 2]; n_iv];
        let (mut n_next, mut m_next) = (0.0, 0.0);
        for (i, iv) in grid.iter().enumerate().rev() {
            let h = iv.b - iv.a;
            let w = 0.5 * h * (iv.area[0] + iv.area[1]) * iv.density;
            let moment_arm =
                h * (iv.area[0] + 2.0 * iv.area[1]) / (3.0 * (iv.area[0] + iv.area[1]));
            n_end[i] = [n_next + w, n_next];
            m_end[i] = [m_next + n_next * h + w * moment_arm, m_next];
            n_next = n_end[i][0];
            m_next = m_end[i][0];
        }
        let mut theta = 0.0;
        let mut eps: f64 = 0.0;
        for (i, iv) in grid.iter().enumerate() {
            theta += 0.5 * (iv.b - iv.a) * (m_end[i][0] / iv.ei[0] + m_end[i][1] / iv.ei[1]);
            eps = eps.max(n_end[i][0] / iv.ea[0]).max(n_end[i][1] / iv.ea[1]);
        }
        let w = mul(scale, g);
        // A dead load turns the rod at most until it hangs along it: the linear beam's angle
        // (thousands of radians for a soft horizontal cantilever, which merely droops) bounds
        // nothing, so it is capped at π; the rod then hangs, stretched by its weight (N / EA).
        out.push(Estimate {
            name: format!(
                "loads.gravity = {} m/s^2 (with {}){scaled}",
                vec3(&loads.gravity),
                match model.rod.divisions.iter().any(|d| d.material.is_some()) {
                    false => format!("material.density = {} kg/m^3", fmt_value(rho)),
                    true => format!("densities up to {} kg/m^3", fmt_value(rho)),
                }
            ),
            bending: mul(w, theta).min(PI),
            strain: mul(w, eps),
            strain_kind: "an axial strain (hanging)",
        });
    }
    // the bodies' weights: dead loads like gravity (bending capped at π, strain the hanging one)
    for (k, b) in model.bodies().enumerate() {
        let weight = mul(mul(scale, g), b.mass);
        if weight == 0.0 {
            continue;
        }
        let arm = V3::from(b.center).norm();
        let before = |s: f64| s <= b.x;
        let (theta, _) = integrate(
            &grid,
            |s| if before(s) { arm + b.x - s } else { 0.0 },
            |_| 0.0,
            true,
        );
        let (_, eps) = integrate(&grid, |_| 0.0, |s| if before(s) { 1.0 } else { 0.0 }, false);
        out.push(Estimate {
            name: format!(
                "bodies[{k}].mass = {} kg under gravity {} m/s^2{scaled}",
                fmt_value(b.mass),
                fmt_value(g)
            ),
            bending: mul(weight, theta).min(PI),
            strain: mul(weight, eps),
            strain_kind: "an axial strain (hanging)",
        });
    }
    out
}

/// The part of a wrench's force that bends the reference rod: a follower force's component across
/// the section (`√(F_y² + F_z²)`: one along the local axis only stretches or compresses the rod,
/// whatever it does), a world-fixed force's whole magnitude (its direction against the rod changes
/// as the rod turns).
fn bending_force(wrench: &[f64; 6], frame: Frame) -> f64 {
    match frame {
        Frame::Local => wrench[4].hypot(wrench[5]),
        Frame::Global => V3::from_row_slice(&wrench[3..]).norm(),
    }
}

/// The bending angle of a force part `f` with unit angle `theta`: `f θ`, for a world-fixed force
/// capped at π like gravity (a dead load turns the rod at most until it lies along the load: a
/// hanging rod pulled down along its axis does not bend).
fn force_bending(f: f64, theta: f64, frame: Frame) -> f64 {
    match frame {
        Frame::Local => mul(f, theta),
        Frame::Global => mul(f, theta).min(PI),
    }
}

/// `field.force = [..] N`, `field.moment = [..] N*m`, or both.
fn wrench_name(field: &str, w: &[f64; 6], force_unit: &str, moment_unit: &str) -> String {
    let (m, f) = (&w[..3], &w[3..]);
    let zero = |v: &[f64]| v.iter().all(|x| *x == 0.0);
    match (zero(m), zero(f)) {
        (true, false) => format!("{field}.force = {} {force_unit}", vec3(f)),
        (false, true) => format!("{field}.moment = {} {moment_unit}", vec3(m)),
        _ => format!(
            "{field} (force {} {force_unit}, moment {} {moment_unit})",
            vec3(f),
            vec3(m)
        ),
    }
}
