//! Tendon actuation (paper eqs. 11–12, gvs-spec §7.6–7.7).
//!
//! A tendon runs at the local offset `d(X) = [0, d_y, d_z]` interpolated linearly between its start
//! and end offsets over `[X_s, X_e]` ("oblique" routing; `d' = const`), turned about the rod's axis
//! by `φ(X) = 2π n s`, `s = (X − X_s)/(X_e − X_s)`, for a helical routing of `n` turns
//! ([`Tendon::turns`]; `d' = R_x(φ)(d_lin' + φ' e_x × d_lin)`, spec §7.6 "Helical"), or through
//! knots of a custom path ([`Tendon::path`], [`crate::actuation::path`], spec §7.6 "Custom"). At a point with strain
//! `ξ = [k; ν]` its unit tangent in the section frame is `t = t_u/‖t_u‖`, `t_u = ν + k × d + d'`, and
//! it loads the rod with the internal wrench `Φ_a α u`, `Φ_a = [d × t; t]`.
//!
//! **Sign convention** (SoRoSim, paper): `u > 0` pushes the rod along its axis, a **pulling tendon has
//! `u < 0`**; with the tendon at `+z` a negative `u` bends the rod toward `+z`.
//!
//! **Friction** attenuates the tension along the tendon as `α(X) = exp(−μ Θ(X))` where `Θ` is the
//! turning angle of the tendon's world tangent `τ = R t` from the tendon start, accumulated over the
//! tendon's computational points with the tangent rule `Θ_i = Θ_{i−1} + atan2(‖τ_{i−1} × τ_i‖, τ_{i−1}·τ_i)`
//! (spec §7.7), each angle smoothed near 0 by [`smoothed_turning_angle`] so that `Θ(q)` has no kink
//! where the tendon's curvature changes sign. A tendon that ends inside the rod simply stops
//! contributing beyond `X_e`: its termination load is the jump of the internal wrench, no extra point
//! load is added (spec §7.6).

use crate::error::{check_range, fmt_rounded, ModelError};
use crate::lie::V3;
use crate::rod::{DivisionGeometry, Rod};
use serde::{Deserialize, Serialize};

mod local;
pub mod path;
pub use local::*;

/// Default curvature scale `κ_ε` [rad/m] of the friction angle's smoothing
/// ([`Tendon::friction_smoothing`]): 0.05 rad/m, conservative.
///
/// A tendon whose path curves uniformly by `κ` has its angles changed by `ε (h(y) − y)`, `y = κ/κ_ε`
/// (−0.18 ε at y ≈ 0.39, ≈ 2ε y(y − 1) e^{−2y} beyond): 0.05 rad/m keeps that below 3e-7 relative for
/// `κ ≥ 0.45 rad/m` (the capstan closed form of gvs-spec §10.3.7 keeps its 2e-5 accuracy) and still
/// removes about half of the integrator's rejected steps on the IV-A arm (random steps in [−6, 0] N:
/// 6113 steps, 859 rejected, instead of 7676 and 1615). Scenarios whose tendons are strongly curved
/// wherever friction matters can take more: the IV-A preset uses 0.3 rad/m (2848 steps, 123 rejected —
/// about the frictionless arm's 2661 and 83 — with statics tips ≤ 0.0025 % L from the exact rule; at
/// 0.3 rad/m the §10.3.7 rod, bent by only 0.5 rad/m, would be off by 5e-3).
pub const DEFAULT_FRICTION_SMOOTHING: f64 = 0.05;

/// Most helical turns of a tendon ([`Tendon::turns`]) either way: far beyond a tendon a soft
/// arm's cross-section could route, and within what a strain basis of practical order resolves.
pub const MAX_TURNS: f64 = 100.0;

fn default_friction_smoothing() -> f64 {
    DEFAULT_FRICTION_SMOOTHING
}

/// A tendon routed between two offsets in the section plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tendon {
    /// `(d_y, d_z)` offset at `x_start` \[m\].
    pub offset_start: [f64; 2],
    /// `(d_y, d_z)` offset at `x_end` \[m\].
    pub offset_end: [f64; 2],
    /// Start of the tendon's span (its actuated end) \[m\].
    pub x_start: f64,
    /// Termination \[m\].
    pub x_end: f64,
    /// Coulomb friction coefficient μ ≥ 0 of the capstan law.
    pub friction: f64,
    /// Curvature scale `κ_ε ≥ 0` [rad/m] below which the friction angle is smoothed: each turning
    /// angle between consecutive tendon points is [`smoothed_turning_angle`] with
    /// `ε = κ_ε |ΔX|` ([`Tendon::smoothing_angle`]); 0 gives the exact, kinked tangent rule. Default
    /// [`DEFAULT_FRICTION_SMOOTHING`].
    #[serde(default = "default_friction_smoothing")]
    pub friction_smoothing: f64,
    /// Turns `n` of a helical routing: the offset turns about the rod's axis (`+x`, right-handed)
    /// by `φ = 2π n s` over the span; 0 (the default) is the oblique routing. A helix of radius
    /// `ρ` has `offset_start = offset_end` of norm `ρ`.
    #[serde(default)]
    pub turns: f64,
    /// Knots `[X, d_y, d_z]` \[m\] of a custom routing ([`crate::actuation::path`]: a `C¹` cubic
    /// through them); empty (the default) for the oblique or helical routing. A path has
    /// `x_start`, `x_end`, `offset_start` and `offset_end` at its first and last knots, and no
    /// `turns`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub path: Vec<[f64; 3]>,
    /// Axial stiffness `EA` \[N\] of the thread (Young's modulus times its section: 20 kN for a
    /// 0.5 mm Dyneema line, 30 kN for a 0.45 mm steel wire); `None` (the default) for an
    /// inextensible tendon. It matters only for a tendon driven by its displacement: a tension `u`
    /// stretches it by `c |u|` with the compliance `c = ℓ_rest / EA`
    /// ([`crate::model::Model::tendon_compliances`]), and in dynamics that spring is what carries
    /// the motor's displacement to the rod ([`crate::solve::dynamics::drive`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_stiffness: Option<f64>,
}

impl Tendon {
    /// `d(X) = R_x(φ(X)) d_lin(X)` in the section frame: the linear interpolation of the end
    /// offsets, turned by `φ = 2π n s` (`s` the fraction of the span, `n` = [`Tendon::turns`]).
    #[inline]
    pub fn offset(&self, x: f64) -> V3 {
        let (d, _) = self.offset_and_rate(x);
        d
    }

    /// `d' = ∂d/∂X = R_x(φ) (d_lin' + φ' e_x × d_lin)`, `φ' = 2π n / (X_e − X_s)` (constant for
    /// the oblique routing, `n = 0`).
    #[inline]
    pub fn offset_rate(&self, x: f64) -> V3 {
        let (_, dp) = self.offset_and_rate(x);
        dp
    }

    /// `(d(X), d'(X))`.
    #[inline]
    pub fn offset_and_rate(&self, x: f64) -> (V3, V3) {
        if !self.path.is_empty() {
            return path::offset_and_rate(&self.path, x);
        }
        let l = self.x_end - self.x_start;
        let s = (x - self.x_start) / l;
        let [y0, z0] = self.offset_start;
        let [y1, z1] = self.offset_end;
        let (y, z) = (y0 + s * (y1 - y0), z0 + s * (z1 - z0));
        let (yp, zp) = ((y1 - y0) / l, (z1 - z0) / l);
        if self.turns == 0.0 {
            return (V3::new(0.0, y, z), V3::new(0.0, yp, zp));
        }
        let phi_rate = std::f64::consts::TAU * self.turns / l;
        // e_x × [0, y, z] = [0, −z, y]
        let (ry, rz) = (yp - phi_rate * z, zp + phi_rate * y);
        let (sn, cs) = (phi_rate * (x - self.x_start)).sin_cos();
        let turn = |a: f64, b: f64| V3::new(0.0, cs * a - sn * b, sn * a + cs * b);
        (turn(y, z), turn(ry, rz))
    }

    /// Smoothing angle `ε = κ_ε |ΔX|` \[rad\] of the turning angle between two tendon points `ΔX`
    /// apart: `κ_ε` is a curvature, so only pairs whose tendon-path curvature `φ/|ΔX|` is within a
    /// few `κ_ε` of 0 are smoothed, however the points are spaced, and `Θ = Σ φ_ε` converges with the
    /// discretization (an absolute ε would erase the friction of a finely discretized tendon, whose
    /// per-point angles `κ h` all fall below ε, and over-smooth the closely spaced Gauss points at
    /// division ends). The two points at a division junction inside the span (`ΔX = 0`) get `ε = 0`:
    /// their angle is the tangent's kink from the strain jump, not a curvature, and counts exactly.
    #[inline]
    pub fn smoothing_angle(&self, dx: f64) -> f64 {
        self.friction_smoothing * dx.abs()
    }

    /// Checks span, friction, and that the path stays inside the cross-section at every division end
    /// inside the span (the radius is linear per division, the offset linear along the span); a
    /// custom path ([`Tendon::path`]) is checked by [`Tendon::validate_path`] first.
    pub fn validate(&self, rod: &Rod, index: usize) -> Result<(), ModelError> {
        let f = |name: &str| format!("tendons[{index}].{name}");
        let l = rod.length();
        if !self.path.is_empty() {
            self.validate_path(rod, index)?;
        }
        for (name, v) in [
            ("offset_start[0]", self.offset_start[0]),
            ("offset_start[1]", self.offset_start[1]),
            ("offset_end[0]", self.offset_end[0]),
            ("offset_end[1]", self.offset_end[1]),
        ] {
            check_range(&f(name), v, None, None, "a finite offset in m")?;
        }
        check_range(
            &f("x_start"),
            self.x_start,
            Some((0.0, true)),
            Some((l, false)),
            &format!("an abscissa in [0, {}) m", fmt_rounded(l)),
        )?;
        check_range(
            &f("x_end"),
            self.x_end,
            Some((self.x_start, false)),
            Some((l * (1.0 + 1e-12), true)),
            &format!("an abscissa in ({}, {}] m", self.x_start, fmt_rounded(l)),
        )?;
        check_range(
            &f("friction"),
            self.friction,
            Some((0.0, true)),
            None,
            "a finite coefficient >= 0",
        )?;
        check_range(
            &f("friction_smoothing"),
            self.friction_smoothing,
            Some((0.0, true)),
            None,
            "a finite curvature scale >= 0 in rad/m",
        )?;
        if let Some(ea) = self.axial_stiffness {
            check_range(
                &f("axial_stiffness"),
                ea,
                Some((0.0, false)),
                None,
                "a finite axial stiffness EA > 0 in N (omit it for an inextensible tendon)",
            )?;
        }
        check_range(
            &f("turns"),
            self.turns,
            Some((-MAX_TURNS, true)),
            Some((MAX_TURNS, true)),
            &format!("a number of helical turns in [-{MAX_TURNS}, {MAX_TURNS}]"),
        )?;
        // radius check at both ends of the span and at every division boundary inside it
        let mut xs = vec![self.x_start, self.x_end];
        let mut x0 = 0.0;
        for d in &rod.divisions {
            for x in [x0, x0 + d.length] {
                if x > self.x_start && x < self.x_end {
                    xs.push(x);
                }
            }
            x0 += d.length;
        }
        // a rectangle or an ellipse is no cone along the span, nor turned into itself by a
        // helix: its widest excursion between
        if rod.divisions.iter().any(|d| d.section.is_some()) {
            xs.push(self.widest_excursion(rod).0);
        }
        for x in xs {
            let d = self.offset(x);
            if let Some(accepted) = outside_section(rod, (self.x_start, self.x_end), x, &d) {
                let which = if (x - self.x_start).abs() < 1e-12 {
                    "offset_start"
                } else {
                    "offset_end"
                };
                return Err(ModelError::value(
                    f(which),
                    d[1].hypot(d[2]),
                    format!("{accepted} at X = {x} m (the tendon must stay inside the rod)"),
                ));
            }
        }
        Ok(())
    }
}

impl Tendon {
    /// Samples per knot interval at which a custom path is checked to stay inside the rod (the
    /// cubic between two knots may bulge beyond both).
    pub const PATH_SAMPLES: usize = 32;

    /// Samples per helical turn of [`Self::widest_excursion`].
    pub const SAMPLES_PER_TURN: usize = 64;

    /// Where the routed (oblique or helical) tendon's offset reaches farthest toward or beyond
    /// the rod's section over its span: `(X, g)` with `g` the section's gauge there
    /// ([`crate::rod::DivisionGeometry::gauge_at`], ≤ 1 inside; the larger side at a junction).
    /// The span is sampled at [`Self::PATH_SAMPLES`] points per division and
    /// [`Self::SAMPLES_PER_TURN`] per helical turn, with the division junctions, and each local
    /// maximum is refined by a golden-section search between its neighbours: a helix whose turns
    /// are commensurate with the samples is found where it leaves a rectangle all the same.
    pub fn widest_excursion(&self, rod: &Rod) -> (f64, f64) {
        let gauge = |x: f64| {
            let d = self.offset(x);
            let span = (self.x_start, self.x_end);
            section_gauge(rod, span, x, d[1], d[2]).map_or(f64::NAN, |(g, _, _)| g)
        };
        let span = self.x_end - self.x_start;
        let n = Self::PATH_SAMPLES * rod.divisions.len()
            + (Self::SAMPLES_PER_TURN as f64 * self.turns.abs()).ceil() as usize;
        let mut xs: Vec<f64> = (0..=n)
            .map(|i| self.x_start + span * i as f64 / n as f64)
            .collect();
        let mut x0 = 0.0;
        for d in &rod.divisions {
            x0 += d.length;
            if x0 > self.x_start && x0 < self.x_end {
                xs.push(x0);
            }
        }
        xs.sort_by(f64::total_cmp);
        let g: Vec<f64> = xs.iter().map(|&x| gauge(x)).collect();
        let mut best = (xs[0], g[0]);
        for i in 0..xs.len() {
            let mut here = (xs[i], g[i]);
            let (lo, hi) = (i.saturating_sub(1), (i + 1).min(xs.len() - 1));
            if g[i] >= g[lo] && g[i] >= g[hi] && lo < hi {
                here = golden_max(&gauge, xs[lo], xs[hi], here);
            }
            if here.1 > best.1 {
                best = here;
            }
        }
        best
    }

    /// A custom path: its knots ([`path::check`]); its ends are the tendon's
    /// `x_start`, `x_end`, `offset_start` and `offset_end`; no `turns`; and the curve stays inside
    /// the cross-section at every knot, at [`Tendon::PATH_SAMPLES`] points of each interval and at
    /// the division junctions inside the span.
    pub fn validate_path(&self, rod: &Rod, index: usize) -> Result<(), ModelError> {
        let f = |name: &str| format!("tendons[{index}].{name}");
        let knots = &self.path;
        path::check(knots).map_err(|(i, m)| match i {
            Some(i) => ModelError::invalid(f(&format!("path[{i}]")), m),
            None => ModelError::invalid(f("path"), m),
        })?;
        let (first, last) = (knots[0], knots[knots.len() - 1]);
        for (name, v, want) in [
            ("x_start", self.x_start, first[0]),
            ("x_end", self.x_end, last[0]),
            ("offset_start[0]", self.offset_start[0], first[1]),
            ("offset_start[1]", self.offset_start[1], first[2]),
            ("offset_end[0]", self.offset_end[0], last[1]),
            ("offset_end[1]", self.offset_end[1], last[2]),
        ] {
            if v != want {
                return Err(ModelError::value(
                    f(name),
                    v,
                    format!("{want}, the value at the path's end knot"),
                ));
            }
        }
        if self.turns != 0.0 {
            return Err(ModelError::value(
                f("turns"),
                self.turns,
                "0 with a custom path (the path's knots give the routing)",
            ));
        }
        // the knots first, so that a knot outside the rod is named as such
        let mut xs: Vec<(f64, usize)> = (0..knots.len())
            .map(|i| (knots[i][0], i.min(knots.len() - 2)))
            .collect();
        for (i, w) in knots.windows(2).enumerate() {
            for k in 1..Self::PATH_SAMPLES {
                xs.push((
                    w[0][0] + (w[1][0] - w[0][0]) * k as f64 / Self::PATH_SAMPLES as f64,
                    i,
                ));
            }
        }
        let mut x0 = 0.0;
        for d in &rod.divisions {
            x0 += d.length;
            if x0 > first[0] && x0 < last[0] {
                let i = knots.partition_point(|k| k[0] <= x0).saturating_sub(1);
                xs.push((x0, i.min(knots.len() - 2)));
            }
        }
        for (x, i) in xs {
            let d = self.offset(x);
            let dn = d[1].hypot(d[2]);
            if let Some(accepted) = outside_section(rod, (self.x_start, self.x_end), x, &d) {
                let knot = knots.iter().position(|k| k[0] == x);
                let (field, place) = match knot {
                    Some(k) => (format!("path[{k}]"), "at this knot".to_string()),
                    None => (
                        "path".to_string(),
                        format!(
                            "between path[{i}] (X = {} m) and path[{}] (X = {} m), where the cubic through the knots bulges (add knots there)",
                            knots[i][0],
                            i + 1,
                            knots[i + 1][0]
                        ),
                    ),
                };
                return Err(ModelError::value(
                    f(&field),
                    dn,
                    format!("{accepted} at X = {x} m: the tendon leaves the rod {place}"),
                ));
            }
        }
        Ok(())
    }
}

/// The largest of `f` on `[a, b]` near a local maximum `start = (x, f(x))` inside it, by 60
/// golden-section steps (the interval shrinks by 1e-12); `start` if none is larger.
fn golden_max(f: &dyn Fn(f64) -> f64, a: f64, b: f64, start: (f64, f64)) -> (f64, f64) {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (a, b);
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..60 {
        if fc > fd {
            (b, d, fd) = (d, c, fc);
            c = b - r * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    let found = if fc > fd { (c, fc) } else { (d, fd) };
    if found.1 > start.1 {
        found
    } else {
        start
    }
}

/// The rod's section gauge of the offset `(y, z)` at `x` of a tendon spanning
/// `span = (x_start, x_end)` ([`crate::rod::DivisionGeometry::gauge_at`], ≤ 1 inside), with the
/// division and `X̄` it was taken in. At a division junction, the larger of the sides the span
/// enters: a tendon that ends where a division ends is fixed to that division's end face, not to
/// the next one's start (a step in the radius there is no limit). `None` for `x` off the rod.
pub fn section_gauge(
    rod: &Rod,
    span: (f64, f64),
    x: f64,
    y: f64,
    z: f64,
) -> Option<(f64, &DivisionGeometry, f64)> {
    let mut x0 = 0.0;
    let mut worst: Option<(f64, &DivisionGeometry, f64)> = None;
    for div in &rod.divisions {
        let x1 = x0 + div.length;
        // the division overlaps the span by more than a rounding (or the span is a point in it)
        let entered = (x0 < span.1 - 1e-12 && x1 > span.0 + 1e-12)
            || (span.1 - span.0 <= 1e-12 && x0 <= span.0 && span.0 <= x1);
        if entered && x >= x0 - 1e-12 && x <= x1 + 1e-12 {
            let x_bar = ((x - x0) / div.length).clamp(0.0, 1.0);
            let g = div.gauge_at(x_bar, y, z);
            if worst.is_none_or(|(w, _, _)| g > w) {
                worst = Some((g, div, x_bar));
            }
        }
        x0 += div.length;
    }
    worst
}

/// `None` if the offset `d` of a tendon spanning `span` lies inside the rod's section at `x`
/// ([`section_gauge`] ≤ 1 + 1e-9); else what is accepted there: "an offset of norm <= the
/// section radius r m", or "an offset inside the section (…)".
fn outside_section(rod: &Rod, span: (f64, f64), x: f64, d: &V3) -> Option<String> {
    let (g, div, x_bar) = section_gauge(rod, span, x, d[1], d[2])?;
    (g > 1.0 + 1e-9).then(|| match div.section {
        None => format!(
            "an offset of norm <= the section radius {} m",
            div.radius_at(x_bar)
        ),
        Some(_) => format!("an offset inside the section, a {}", div.describe_at(x_bar)),
    })
}
