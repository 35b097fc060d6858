//! Tendon actuation (paper eqs. 11–12, gvs-spec §7.6–7.7).
//!
//! A tendon runs at the local offset `d(X) = [0, d_y, d_z]` interpolated linearly between its start
//! and end offsets over `[X_s, X_e]` ("oblique" routing; `d' = const`). At a point with strain
//! `ξ = [k; ν]` its unit tangent in the section frame is `t = t_u/‖t_u‖`, `t_u = ν + k × d + d'`, and
//! it loads the rod with the internal wrench `Φ_a α u`, `Φ_a = [d × t; t]`.
//!
//! **Sign convention** (SoRoSim, paper): `u > 0` pushes the rod along its axis, a **pulling tendon has
//! `u < 0`**; with the tendon at `+z` a negative `u` bends the rod toward `+z`.
//!
//! **Friction** attenuates the tension along the tendon as `α(X) = exp(−μ Θ(X))` where `Θ` is the
//! turning angle of the tendon's world tangent `τ = R t` from the tendon start, accumulated over the
//! tendon's computational points with the tangent rule `Θ_i = Θ_{i−1} + atan2(‖τ_{i−1} × τ_i‖, τ_{i−1}·τ_i)`
//! (spec §7.7). A tendon that ends inside the rod simply stops contributing beyond `X_e`: its
//! termination load is the jump of the internal wrench, no extra point load is added (spec §7.6).

use crate::error::{check_range, ModelError};
use crate::lie::{tilde, M3, M6, V3, V6};
use crate::rod::Rod;
use serde::{Deserialize, Serialize};

/// A tendon routed between two offsets in the section plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tendon {
    /// `(d_y, d_z)` offset at `x_start` [m].
    pub offset_start: [f64; 2],
    /// `(d_y, d_z)` offset at `x_end` [m].
    pub offset_end: [f64; 2],
    /// Start of the tendon's span (its actuated end) [m].
    pub x_start: f64,
    /// Termination [m].
    pub x_end: f64,
    /// Coulomb friction coefficient μ ≥ 0 of the capstan law.
    pub friction: f64,
}

impl Tendon {
    /// `d(X)` in the section frame.
    #[inline]
    pub fn offset(&self, x: f64) -> V3 {
        let s = (x - self.x_start) / (self.x_end - self.x_start);
        let y = self.offset_start[0] + s * (self.offset_end[0] - self.offset_start[0]);
        let z = self.offset_start[1] + s * (self.offset_end[1] - self.offset_start[1]);
        V3::new(0.0, y, z)
    }

    /// `d' = ∂d/∂X` (constant).
    #[inline]
    pub fn offset_rate(&self) -> V3 {
        let l = self.x_end - self.x_start;
        V3::new(
            0.0,
            (self.offset_end[0] - self.offset_start[0]) / l,
            (self.offset_end[1] - self.offset_start[1]) / l,
        )
    }

    /// Checks span, friction, and that the path stays inside the cross-section at every division end
    /// inside the span (the radius is linear per division, the offset linear along the span).
    pub fn validate(&self, rod: &Rod, index: usize) -> Result<(), ModelError> {
        let f = |name: &str| format!("tendons[{index}].{name}");
        let l = rod.length();
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
            &format!("an abscissa in [0, {l}) m"),
        )?;
        check_range(
            &f("x_end"),
            self.x_end,
            Some((self.x_start, false)),
            Some((l * (1.0 + 1e-12), true)),
            &format!("an abscissa in ({}, {l}] m", self.x_start),
        )?;
        check_range(
            &f("friction"),
            self.friction,
            Some((0.0, true)),
            None,
            "a finite coefficient >= 0",
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
        for x in xs {
            let r = radius_at(rod, x);
            let d = self.offset(x);
            let dn = (d[1] * d[1] + d[2] * d[2]).sqrt();
            if dn > r * (1.0 + 1e-9) {
                let which = if (x - self.x_start).abs() < 1e-12 {
                    "offset_start"
                } else {
                    "offset_end"
                };
                return Err(ModelError::value(
                    f(which),
                    dn,
                    format!("an offset of norm <= the section radius {r} m at X = {x} m (the tendon must stay inside the rod)"),
                ));
            }
        }
        Ok(())
    }
}

/// Smallest radius of the rod at `x` (both sides at a division junction).
fn radius_at(rod: &Rod, x: f64) -> f64 {
    let mut x0 = 0.0;
    let mut r = f64::INFINITY;
    for d in &rod.divisions {
        if x >= x0 - 1e-12 && x <= x0 + d.length + 1e-12 {
            r = r.min(d.radius_at(((x - x0) / d.length).clamp(0.0, 1.0)));
        }
        x0 += d.length;
    }
    r
}

/// The tendon tangent and actuation wrench at one point.
#[derive(Debug, Clone, Copy)]
pub struct TendonLocal {
    /// Unit tangent t in the section frame.
    pub t: V3,
    /// `‖t_u‖`.
    pub nt: f64,
    /// `Φ_a = [d × t; t]`.
    pub phi_a: V6,
}

/// `t_u = ν + k × d + d'`, `t = t_u/‖t_u‖`, `Φ_a = [d × t; t]` (spec §7.6).
#[inline]
pub fn tendon_local(xi: &V6, d: &V3, dp: &V3) -> TendonLocal {
    let k = V3::new(xi[0], xi[1], xi[2]);
    let nu = V3::new(xi[3], xi[4], xi[5]);
    let tu = nu + k.cross(d) + dp;
    let nt = tu.norm();
    let t = tu / nt;
    let m = d.cross(&t);
    TendonLocal {
        t,
        nt,
        phi_a: V6::new(m[0], m[1], m[2], t[0], t[1], t[2]),
    }
}

/// `∂t/∂ξ = (1/‖t_u‖) [t̃² d̃, −t̃²]` (3×6).
#[inline]
pub fn tangent_jacobian(d: &V3, tl: &TendonLocal) -> nalgebra::Matrix3x6<f64> {
    let tt = tilde(&tl.t);
    let tt2 = tt * tt;
    let dt = tilde(d);
    let mut out = nalgebra::Matrix3x6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(tt2 * dt / tl.nt));
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-tt2 / tl.nt));
    out
}

/// `∂Φ_a/∂ξ = (1/‖t_u‖) [d̃ t̃² d̃, −d̃ t̃²; t̃² d̃, −t̃²]` (SoRoSim `PHI_AU`, spec §7.6).
#[inline]
pub fn wrench_jacobian(d: &V3, tl: &TendonLocal) -> M6 {
    let dtdxi = tangent_jacobian(d, tl);
    let dt: M3 = tilde(d);
    let mut out = M6::zeros();
    out.fixed_view_mut::<3, 6>(0, 0).copy_from(&(dt * dtdxi));
    out.fixed_view_mut::<3, 6>(3, 0).copy_from(&dtdxi);
    out
}

/// Angle between unit vectors `a`, `b` by `atan2(‖a×b‖, a·b)` and its gradients w.r.t. `a` and `b`
/// (zero gradients where the angle is 0, its non-smooth point).
#[inline]
pub fn turning_angle(a: &V3, b: &V3) -> (f64, V3, V3) {
    let axb = a.cross(b);
    let s = axb.norm();
    let c = a.dot(b);
    let phi = s.atan2(c);
    if s < 1e-300 {
        return (phi, V3::zeros(), V3::zeros());
    }
    let den = s * s + c * c;
    let ga = (b.cross(&axb) * (c / s) - b * s) / den;
    let gb = (axb.cross(a) * (c / s) - a * s) / den;
    (phi, ga, gb)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn wrench_jacobian_matches_central_differences() {
        let xi = V6::new(0.3, -2.0, 1.5, 1.05, 0.02, -0.03);
        let d = V3::new(0.0, 0.004, 0.008);
        let dp = V3::new(0.0, -0.01, -0.028);
        let an = wrench_jacobian(&d, &tendon_local(&xi, &d, &dp));
        let h = 1e-7;
        for c in 0..6 {
            let mut e = V6::zeros();
            e[c] = h;
            let fd = (tendon_local(&(xi + e), &d, &dp).phi_a
                - tendon_local(&(xi - e), &d, &dp).phi_a)
                / (2.0 * h);
            assert_relative_eq!(an.column(c).into_owned(), fd, epsilon = 1e-8);
        }
    }

    #[test]
    fn turning_angle_gradients_match_central_differences() {
        let a = V3::new(0.9, 0.3, -0.1).normalize();
        let b = V3::new(0.7, -0.2, 0.4).normalize();
        let (phi, ga, gb) = turning_angle(&a, &b);
        assert!((phi - a.dot(&b).acos()).abs() < 1e-14);
        let h = 1e-7;
        for c in 0..3 {
            let mut e = V3::zeros();
            e[c] = h;
            let fa = (turning_angle(&(a + e), &b).0 - turning_angle(&(a - e), &b).0) / (2.0 * h);
            let fb = (turning_angle(&a, &(b + e)).0 - turning_angle(&a, &(b - e)).0) / (2.0 * h);
            assert!((fa - ga[c]).abs() < 1e-7 && (fb - gb[c]).abs() < 1e-7);
        }
    }
}
