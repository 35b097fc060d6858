//! Plausibility of the loads: an estimate, by linear beam theory on the straight reference rod, of
//! the bending and the axial/shear strain each load implies on its own, so that loads far beyond any
//! elastic range are rejected before solving, naming the load, instead of ending in a
//! non-convergence that names nothing.
//!
//! For a load with internal bending moment `M_b(s)` and internal force `N(s)` at the section `s`
//! (magnitudes, cantilever clamped at X = 0, reference configuration):
//!
//! - implied bending angle `θ = ∫₀ᴸ M_b(s) / EI(s) ds` [rad] (the tip rotation of a linear beam);
//! - implied strain `ε = max_s N(s) / EA(s)` for a tendon (axial), `max_s N(s) / min(EA, GA)(s)` for
//!   a force of unknown direction (axial or shear).
//!
//! The resultants per load (all on `s ≤ X` of the load; zero beyond it):
//!
//! | load | `M_b(s)` | `N(s)` |
//! |---|---|---|
//! | tendon k, tension u, offset d(X) on `[a, b]` | `|u| |d(s)|` on `[a, b]` | `|u|` on `[a, b]` |
//! | point wrench at X: force F, moment M | `|M| + |F| (X − s)` | `|F|` |
//! | uniform density f, m on `[a, b]` | `|m| ℓ(s) + |f| ((b − s)² − (max(s, a) − s)²)/2` | `|f| ℓ(s)`, `ℓ(s) = b − max(s, a)` |
//! | triangular pulse, peak m̂ | `m̂ ∫ₛᴸ tri(x) dx` | 0 |
//! | gravity g, density ρ | `∫ₛᴸ ρ A(x) |g| (x − s) dx` | `∫ₛᴸ ρ A(x) |g| dx` |
//!
//! (The pulse's peak is `magnitude` or `2·magnitude/width` by its convention; friction only lowers a
//! tendon's tension and is ignored.) The integrals are evaluated on a grid of [`GRID_POINTS`]
//! intervals per division with the sections of that division (trapezoid rule), which also uses the
//! taper: a thin tip and a thick base each count where they are.
//!
//! A load is rejected when `θ > MAX_BENDING` (200 rad, about 30 turns) or `ε > MAX_STRAIN` (1: an
//! axial strain of −1 is the elongation ν₁ = 0, a section squeezed to nothing). The paper's presets
//! stay inside: single-tendon at ±30 N implies about 24 rad and an axial strain of 0.62,
//! six-tendon's full-length tendons at ±30 N about 8.6 rad and 0.095 each, the soft beam at a total
//! moment of 5 N·m (its preset's reading; the coiled beam) at most about 96 rad, at a peak of
//! 5 N·m/m (`soft-beam-peak`) at most about 4 rad.
//!
//! Every product is formed so that an overflow gives `inf` (never `0 · inf = NaN`) and every
//! comparison rejects `inf` and NaN.

use crate::error::ScenarioError;
use gvs::error::fmt_value;
use gvs::lie::V3;
use gvs::loads::{DistributedWrench, Loads, PulseMagnitude};
use gvs::model::Model;
use gvs::strain::LinearBasis;
use std::f64::consts::PI;

/// Largest implied bending angle `θ` accepted [rad] (about 30 turns).
pub const MAX_BENDING: f64 = 200.0;
/// Largest implied axial or shear strain accepted.
pub const MAX_STRAIN: f64 = 1.0;
/// Grid intervals per division of the estimate (fewer when the rod has many divisions, at least 4).
pub const GRID_POINTS: usize = 64;

/// What the check reads of a built scenario (the build layer's `Built` converts into it): the model, the
/// scenario's own tensions and its loads. The check depends on the engine only, not on `build`.
#[derive(Clone, Copy)]
pub struct Subject<'a> {
    pub model: &'a Model<LinearBasis>,
    pub u: &'a [f64],
    pub loads: &'a Loads,
}

/// Checks the loads and tensions a run will see. `u_max[k]` is the largest |tension| of tendon k over the run,
/// `load_scale_max` the largest |λ| applied to the external loads and gravity (1.0 for statics).
pub fn check<'a>(
    subject: impl Into<Subject<'a>>,
    u_max: &[f64],
    load_scale_max: f64,
) -> Result<(), ScenarioError> {
    let built = subject.into();
    let n_a = built.model.n_actuators();
    if u_max.len() != n_a {
        return Err(ScenarioError::invalid(
            "tendons",
            format!(
                "{} tension bounds given for {n_a} tendons (the plausibility check needs one per tendon)",
                u_max.len()
            ),
        ));
    }
    let worst = estimates(&built, u_max, load_scale_max, true)
        .into_iter()
        .filter(|e| !(e.bending <= MAX_BENDING && e.strain <= MAX_STRAIN))
        .max_by(|a, b| a.severity().total_cmp(&b.severity()));
    match worst {
        None => Ok(()),
        Some(e) => Err(ScenarioError::Implausible {
            load: e.name,
            message: format!(
                "implies a bending of ~{} rad over the rod (accepted <= {MAX_BENDING} rad){}: far beyond the rod's elastic range",
                approx(e.bending),
                if e.strain > 0.0 || e.strain.is_nan() {
                    format!(
                        " and {} of ~{} (accepted <= {MAX_STRAIN})",
                        e.strain_kind,
                        approx(e.strain)
                    )
                } else {
                    String::new()
                }
            ),
        }),
    }
}

/// One phrase naming the load with the largest implied strain, e.g. "the largest load is tendons[0].tension = -40 N (implied bending ~12 rad)", or None without loads.
pub fn largest_load<'a>(
    subject: impl Into<Subject<'a>>,
    u: &[f64],
    load_scale: f64,
) -> Option<String> {
    let e = estimates(&subject.into(), u, load_scale, false)
        .into_iter()
        .filter(|e| e.severity() > 0.0)
        .max_by(|a, b| a.severity().total_cmp(&b.severity()))?;
    let strain = if e.strain > 0.0 {
        format!(", {} ~{}", e.strain_kind, approx(e.strain))
    } else {
        String::new()
    };
    Some(format!(
        "the largest load is {} (implied bending ~{} rad{strain})",
        e.name,
        approx(e.bending)
    ))
}

/// The estimate of one load.
struct Estimate {
    /// The load by its scenario path and value, e.g. `tendons[0].tension = -3 N`.
    name: String,
    /// Implied bending angle θ [rad].
    bending: f64,
    /// Implied axial (tendons) or axial/shear (forces) strain.
    strain: f64,
    strain_kind: &'static str,
}

impl Estimate {
    /// The larger of the two ratios to their bounds (NaN counts as infinite).
    fn severity(&self) -> f64 {
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

/// About two significant digits: `12`, `0.62`, `3e295`.
fn approx(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let e = v.abs().log10().floor();
    if (-3.0..4.0).contains(&e) {
        let digits = (1.0 - e).max(0.0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{v:.0e}")
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
    ei: [f64; 2],
    ea: [f64; 2],
    /// `min(EA, GA)`.
    ea_ga: [f64; 2],
    /// `πr²`.
    area: [f64; 2],
}

fn grid(built: &Subject<'_>) -> Vec<Interval> {
    let rod = &built.model.rod;
    let e = rod.material.youngs_modulus;
    let g = rod.material.shear_modulus();
    let per_div = (8192 / rod.divisions.len().max(1)).clamp(4, GRID_POINTS);
    let mut out = Vec::with_capacity(per_div * rod.divisions.len());
    for (d, x0) in rod.divisions.iter().zip(rod.division_starts()) {
        for i in 0..per_div {
            let (t0, t1) = (i as f64 / per_div as f64, (i + 1) as f64 / per_div as f64);
            let r = [d.radius_at(t0), d.radius_at(t1)];
            let area = r.map(|r| PI * r * r);
            out.push(Interval {
                a: x0 + t0 * d.length,
                b: x0 + t1 * d.length,
                ei: r.map(|r| e * PI * r.powi(4) / 4.0),
                ea: area.map(|a| e * a),
                ea_ga: area.map(|a| e.min(g) * a),
                area,
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
fn estimates(built: &Subject<'_>, u: &[f64], scale: f64, bound: bool) -> Vec<Estimate> {
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
            bending: mul(scale, mul(m, theta_m) + mul(f, theta_f)),
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
                ..
            } => {
                let m = V3::from_row_slice(&density[..3]).norm();
                let f = V3::from_row_slice(&density[3..]).norm();
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
                    bending: mul(scale, mul(m, theta_m) + mul(f, theta_f)),
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
    let rho = model.rod.material.density;
    if mul(g, rho) > 0.0 {
        // resultants of the unit weight density A(x) at the grid's ends, from the tip backward:
        // N_a = N_b + ∫_a^b A, M_a = M_b + N_b (b − a) + ∫_a^b A (x − a) dx (A linear-ish: trapezoid
        // weights at the ends)
        let n_iv = grid.len();
        let mut n_end = vec![[0.0; 2]; n_iv];
        let mut m_end = vec![[0.0; 2]; n_iv];
        let (mut n_next, mut m_next) = (0.0, 0.0);
        for (i, iv) in grid.iter().enumerate().rev() {
            let h = iv.b - iv.a;
            let w = 0.5 * h * (iv.area[0] + iv.area[1]);
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
            eps = eps
                .max(n_end[i][0] / iv.ea_ga[0])
                .max(n_end[i][1] / iv.ea_ga[1]);
        }
        let w = mul(mul(scale, g), rho);
        out.push(Estimate {
            name: format!(
                "loads.gravity = {} m/s^2 (with material.density = {} kg/m^3){scaled}",
                vec3(&loads.gravity),
                fmt_value(rho)
            ),
            bending: mul(w, theta),
            strain: mul(w, eps),
            strain_kind: "an axial/shear strain",
        });
    }
    out
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::Built;
    use crate::presets;
    use crate::scenario::Scenario;

    fn built(preset: &str, overrides: &[String]) -> Result<Built, ScenarioError> {
        crate::build(&presets::load(preset, overrides)?)
    }

    /// A uniform rod: L = 0.5 m, r = 0.01 m, E = 1e6 Pa, ν = 0.5, ρ = 1000, no gravity, no loads.
    const UNIFORM: &str = r#"
        [material]
        youngs_modulus = 1e6
        poisson_ratio = 0.5
        density = 1000
        [[divisions]]
        length = 0.5
        radius = 0.01
        basis = { kind = "legendre", modes = ["bend_y"], order = 2 }
        [loads]
        gravity = [0, 0, 0]
    "#;

    fn uniform(overrides: &[&str]) -> Result<Built, ScenarioError> {
        let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        crate::build(&Scenario::from_toml("uniform", UNIFORM, &o)?)
    }

    fn only_estimate(b: &Built) -> Estimate {
        let mut e = estimates(&b.into(), &b.u, 1.0, false);
        e.retain(|e| e.severity() > 0.0);
        assert_eq!(e.len(), 1);
        e.pop().unwrap()
    }

    // uniform rod: EI = E π r⁴/4, EA = E π r², GA = EA/3 (ν = 0.5)
    const L: f64 = 0.5;
    fn ei() -> f64 {
        1e6 * PI * 1e-8 / 4.0
    }
    fn ea() -> f64 {
        1e6 * PI * 1e-4
    }

    #[test]
    fn estimates_match_linear_beam_closed_forms_on_a_uniform_rod() {
        // tendon at constant offset d over the whole rod: θ = |u| d L / EI, ε = |u| / EA
        let b = uniform(&[
            "tendons.0.offset_start=[0, 0.005]",
            "tendons.0.offset_end=[0, 0.005]",
            "tendons.0.tension=-2",
        ])
        .unwrap();
        let e = only_estimate(&b);
        assert!(
            (e.bending - 2.0 * 0.005 * L / ei()).abs() < 1e-8 * e.bending,
            "{}",
            e.bending
        );
        assert!((e.strain - 2.0 / ea()).abs() < 1e-8 * e.strain);
        // tendon on the second half only: θ = |u| d (L/2) / EI
        let b = uniform(&[
            "tendons.0.offset_start=[0, 0.005]",
            "tendons.0.offset_end=[0, 0.005]",
            "tendons.0.x_start=0.25",
            "tendons.0.tension=-2",
        ])
        .unwrap();
        let e = only_estimate(&b);
        assert!((e.bending - 2.0 * 0.005 * 0.25 / ei()).abs() < 1e-8 * e.bending);
        // tip moment M: θ = M L / EI
        let b = uniform(&["loads.point.0.x=0.5", "loads.point.0.moment=[0, 0.01, 0]"]).unwrap();
        let e = only_estimate(&b);
        assert!((e.bending - 0.01 * L / ei()).abs() < 1e-8 * e.bending);
        assert_eq!(e.strain, 0.0);
        // tip force F: θ = F L² / (2 EI), shear strain F / GA
        let b = uniform(&["loads.point.0.x=0.5", "loads.point.0.force=[0, 0, -0.01]"]).unwrap();
        let e = only_estimate(&b);
        assert!((e.bending - 0.01 * L * L / (2.0 * ei())).abs() < 1e-8 * e.bending);
        assert!((e.strain - 0.01 / (ea() / 3.0)).abs() < 1e-8 * e.strain);
        // gravity: θ = ρ A g L³ / (6 EI) (trapezoid on a quadratic moment: O(h²) ≈ 1e-4 relative)
        let b = uniform(&["loads.gravity=[0, 0, -9.81]"]).unwrap();
        let e = only_estimate(&b);
        let w = 1000.0 * PI * 1e-4 * 9.81;
        let theta = w * L.powi(3) / (6.0 * ei());
        assert!(
            (e.bending - theta).abs() < 1e-3 * theta,
            "{} vs {theta}",
            e.bending
        );
        assert!((e.strain - w * L / (ea() / 3.0)).abs() < 1e-9 * e.strain);
        // uniform moment density m on the whole rod: θ = m L² / (2 EI)
        let b = uniform(&[
            "loads.distributed.0.kind=uniform",
            "loads.distributed.0.moment=[0, 0.02, 0]",
        ])
        .unwrap();
        let e = only_estimate(&b);
        assert!((e.bending - 0.02 * L * L / (2.0 * ei())).abs() < 1e-8 * e.bending);
        // a triangular pulse of total moment Mt wholly inside: θ ≥ Mt (c − h) / EI and
        // ≤ Mt (c + h) / EI (the moment is Mt up to c − h, decreasing to 0 at c + h)
        let b = uniform(&[
            "loads.distributed.0.kind=triangular_pulse",
            "loads.distributed.0.center=0.25",
            "loads.distributed.0.width=0.1",
            "loads.distributed.0.magnitude=0.01",
            "loads.distributed.0.convention=total",
        ])
        .unwrap();
        let e = only_estimate(&b);
        assert!(
            e.bending > 0.01 * 0.2 / ei() && e.bending < 0.01 * 0.3 / ei(),
            "{}",
            e.bending
        );
        // symmetric pulse: the exact value is Mt · c / EI
        assert!((e.bending - 0.01 * 0.25 / ei()).abs() < 1e-3 * e.bending);
    }

    #[test]
    fn paper_presets_pass_over_their_documented_ranges() {
        for u in [-30.0, 30.0] {
            built("single-tendon", &[format!("tendons.0.tension={u}")]).unwrap();
            let all: Vec<String> = (0..6).map(|k| format!("tendons.{k}.tension={u}")).collect();
            built("six-tendon", &all).unwrap();
            let alternating: Vec<String> = (0..6)
                .map(|k| format!("tendons.{k}.tension={}", if k % 2 == 0 { u } else { -u }))
                .collect();
            built("six-tendon", &alternating).unwrap();
        }
        // the paper's IV-B range, ±5 N·m in total (the coiled beam), and its peak reading ±5 N·m/m
        for preset in ["soft-beam", "soft-beam-peak"] {
            for m in [-5.0, 5.0] {
                for i in 0..=8 {
                    built(
                        preset,
                        &[
                            format!("loads.distributed.0.magnitude={m}"),
                            format!("loads.distributed.0.center={}", i as f64 * 0.1),
                        ],
                    )
                    .unwrap();
                }
            }
        }
        // with a margin: single-tendon at ±30 N, the tightest in strain, at ~24 rad and strain 0.62
        let b = built("single-tendon", &["tendons.0.tension=-30".into()]).unwrap();
        let e = &estimates(&(&b).into(), &b.u, 1.0, false)[0];
        assert!(
            e.bending < MAX_BENDING / 5.0 && e.strain < 0.7,
            "{} {}",
            e.bending,
            e.strain
        );
        // the tightest in bending: 5 N·m in total reaching the tip (X₀ = L − w/2 = 0.76 m) implies
        // θ = M X₀ / EI ≈ 96 rad (the symmetric pulse's closed form above), under half the bound
        let b = built(
            "soft-beam",
            &[
                "loads.distributed.0.magnitude=5".into(),
                "loads.distributed.0.center=0.76".into(),
            ],
        )
        .unwrap();
        let e = only_estimate(&b);
        let theta = 5.0 * 0.76 / (1e6 * PI * 0.015f64.powi(4) / 4.0);
        assert!(
            (e.bending - theta).abs() < 1e-3 * theta && e.bending < MAX_BENDING / 2.0,
            "{} vs {theta}",
            e.bending
        );
    }

    #[test]
    fn absurd_tension_is_rejected_naming_the_tendon_and_its_strains() {
        let e = built("single-tendon", &["tendons.0.tension=1e300".into()])
            .err()
            .unwrap()
            .to_string();
        for needle in [
            "tendons[0].tension = 1e300 N",
            "bending of ~",
            "rad over the rod (accepted <= 200 rad)",
            "axial strain of ~",
            "(accepted <= 1)",
            "far beyond",
        ] {
            assert!(e.contains(needle), "lacks `{needle}`: {e}");
        }
        assert!(!e.contains("NaN"), "{e}");
    }

    #[test]
    fn overflowing_loads_reject_without_nan() {
        // a pulse of total 1e308 over a width of 1e-300: the peak overflows to inf
        let e = built(
            "soft-beam",
            &[
                "loads.distributed.0.magnitude=1e308".into(),
                "loads.distributed.0.width=1e-300".into(),
                "loads.distributed.0.convention=total".into(),
            ],
        )
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("loads.distributed[0].magnitude = 1e308 N*m") && e.contains("~inf rad"),
            "{e}"
        );
        // a moment implies no strain: the message does not claim one
        assert!(!e.contains("strain"), "{e}");
        assert!(!e.contains("NaN"), "{e}");
        // a point force of 1e308 at the tip and 1e308 moment: inf, not NaN
        let e = uniform(&[
            "loads.point.0.x=0.5",
            "loads.point.0.force=[1e308, 1e308, 0]",
            "loads.point.0.moment=[0, 1e308, 0]",
        ])
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("loads.point[0] (force [1e308, 1e308, 0] N"),
            "{e}"
        );
        assert!(e.contains("inf") && !e.contains("NaN"), "{e}");
        // gravity at its bound on a very soft, heavy rod
        let e = uniform(&[
            "loads.gravity=[0, 0, -1e4]",
            "material.youngs_modulus=1",
            "material.density=1e5",
        ])
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("loads.gravity = [0, 0, -10000] m/s^2") && e.contains("100000 kg/m^3"),
            "{e}"
        );
    }

    #[test]
    fn run_bounds_scale_the_loads_and_name_the_bound() {
        let b = built("single-tendon", &["tendons.0.tension=-3".into()]).unwrap();
        // the scenario's own tension, by its sign
        assert!(check(&b, &[3.0], 1.0).is_ok());
        let e = check(&b, &[3000.0], 1.0).unwrap_err().to_string();
        assert!(e.contains("tendons[0].tension up to |u| = 3000 N"), "{e}");
        // gravity implies ~0.83 rad: a load factor of 1000 makes it ~830 rad
        let e = check(&b, &[3.0], 1000.0).unwrap_err().to_string();
        assert!(
            e.contains("loads.gravity") && e.contains("scaled by λ = 1000"),
            "{e}"
        );
        let e = check(&b, &[3.0, 1.0], 1.0).unwrap_err().to_string();
        assert!(e.contains("2 tension bounds given for 1 tendons"), "{e}");
    }

    #[test]
    fn largest_load_names_the_dominant_load() {
        let b = built("single-tendon", &["tendons.0.tension=-3".into()]).unwrap();
        let s = largest_load(&b, &b.u, 1.0).unwrap();
        assert!(
            s.starts_with(
                "the largest load is tendons[0].tension = -3 N (implied bending ~2.4 rad"
            ),
            "{s}"
        );
        // without tension, gravity is the largest
        let s = largest_load(&b, &[0.0], 1.0).unwrap();
        assert!(s.starts_with("the largest load is loads.gravity"), "{s}");
        let b = uniform(&[]).unwrap();
        assert_eq!(largest_load(&b, &[], 1.0), None);
    }

    #[test]
    fn approx_keeps_two_significant_digits() {
        assert_eq!(approx(12.34), "12");
        assert_eq!(approx(0.6234), "0.62");
        assert_eq!(approx(3.7e295), "4e295");
        assert_eq!(approx(f64::INFINITY), "inf");
    }
}
