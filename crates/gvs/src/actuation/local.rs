//! The tendon at one point (gvs-spec §7.6–7.7): its unit tangent and actuation wrench
//! `Φ_a = [d × t; t]` with their Jacobians in the strain, and the (smoothed) turning angle between
//! consecutive tangents that the capstan friction accumulates.

use crate::lie::{tilde, M3, M6, V3, V6};

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

/// Smoothed turning angle `φ_ε = φ tanh z + (ε/2) z² sech² z`, `z = φ/ε`, of
/// `φ = atan2(‖a×b‖, a·b)`, with its exact gradients w.r.t. `a` and `b`; `ε = 0` gives [`turning_angle`].
///
/// Why: `φ` has a kink at 0 (a cone in `b − a`) wherever the curvature of the tendon path changes
/// sign, so the friction factor `exp(−μ Σ φ)` has a Jacobian that jumps there, which the integrator's
/// Newton iterations and error estimator fight (step rejections).
///
/// Properties (`h(y) = φ_ε/ε` as a function of `y = φ/ε`):
/// - C∞: `h` is even and analytic and `φ²` is smooth in `(a, b)` near `φ = 0`; `φ_ε ≈ 3φ²/(2ε)` there,
///   `φ_ε ≥ 0`, increasing in `φ`.
/// - Exact far from 0 to exponential order: `φ_ε − φ ≈ 2ε z(z − 1) e^{−2z}` (< 1e-13 ε above 19 ε).
///   Only angles within a few ε change: by −0.18 ε at most (at `φ ≈ 0.39 ε`) and +0.072 ε (at 1.8 ε).
/// - Unbiased across a sign change: `∫(h(y) − |y|) dy = −π²/12 + π²/12 = 0` (the `tanh` term alone,
///   `∫ |y|(tanh|y| − 1) = −π²/12`, is compensated by `∫ y² sech² y/2 = π²/12`). With per-point angles
///   `φ_i ≈ κ' h²|i − i₀|` through a zero of the path curvature `κ` and `ε = κ_ε h`, the `tanh` term
///   alone would lower `Θ` by `(π²/12) κ_ε²/|κ'|` per crossing; with the compensation the first-order
///   deficit vanishes and what remains comes from the curvature of `κ(X)` and the sampling. (The
///   smooth absolute values `√(φ² + ε²) − ε` and `√(φ² + ε²)` would shift *every* angle, by ≈ −ε
///   and by +ε at straight pairs: a bias in `Θ` that grows with the number of points.)
///
/// Gradients: `∂φ_ε/∂a = g'(φ) ∂φ/∂a` with `g'(φ) = tanh z + sech² z (2z − z² tanh z)` and
/// `∂φ/∂a = (c b×(a×b)/s − s b)/(s² + c²)` (`s = ‖a×b‖`, `c = a·b`; `∂/∂b` likewise with
/// `(a×b)×a` and `a`). The `1/s` is absorbed by `g'(φ)/s = (tanh z/z + sech² z (2 − z tanh z))/ε · φ/s`,
/// finite at `s = 0` (`φ/s → 1/c`), so the gradients vanish continuously at `φ = 0` (`≈ 3φ/ε` in
/// norm for unit vectors). Antiparallel vectors (φ = π, never two consecutive tangents of a tendon)
/// get zero gradients, as in [`turning_angle`].
#[inline]
pub fn smoothed_turning_angle(a: &V3, b: &V3, eps: f64) -> (f64, V3, V3) {
    smoothed_turning_angle_with(a, b, eps, true)
}

/// The value of [`smoothed_turning_angle`] alone (what a residual needs): the same operations up to
/// `φ_ε`, so the same bits, without the gradients' divisions and cross products.
#[inline]
pub fn smoothed_turning_angle_value(a: &V3, b: &V3, eps: f64) -> f64 {
    smoothed_turning_angle_with(a, b, eps, false).0
}

#[inline(always)]
fn smoothed_turning_angle_with(a: &V3, b: &V3, eps: f64, gradients: bool) -> (f64, V3, V3) {
    if eps <= 0.0 {
        return turning_angle(a, b);
    }
    let axb = a.cross(b);
    let s = axb.norm();
    let c = a.dot(b);
    let phi = s.atan2(c);
    let z = phi / eps;
    // tanh z and sech² z from one exponential: with m = e^{−2z} − 1 (z ≥ 0, m ∈ (−1, 0]),
    // tanh z = −m/(2 + m), sech² z = 4(1 + m)/(2 + m)² (expm1 keeps tanh's relative precision at small z)
    // (above z = 19, e^{−2z} < 2⁻⁵⁴ and m is −1 exactly: the exact value without the call)
    let m = if z < 19.0 { (-2.0 * z).exp_m1() } else { -1.0 };
    let inv = 1.0 / (2.0 + m);
    let th = -m * inv;
    let sech2 = 4.0 * (1.0 + m) * inv * inv;
    let value = phi * th + 0.5 * eps * z * z * sech2;
    if !gradients {
        return (value, V3::zeros(), V3::zeros());
    }
    // φ/s, with its limit 1/c at s = 0 (φ = atan(s/c) = s/c (1 − (s/c)²/3 + …))
    let phi_over_s = if s > 1e-150 {
        phi / s
    } else if c > 0.0 {
        1.0 / c
    } else {
        return (value, V3::zeros(), V3::zeros());
    };
    // tanh z / z = 1 − z²/3 + …: exactly 1 in f64 below z = 1e-8
    let th_over_z = if z > 1e-8 { th / z } else { 1.0 };
    let dg_over_phi = (th_over_z + sech2 * (2.0 - z * th)) / eps;
    let w = dg_over_phi * phi_over_s / (s * s + c * c);
    let ga = (b.cross(&axb) * c - b * (s * s)) * w;
    let gb = (axb.cross(a) * c - a * (s * s)) * w;
    (value, ga, gb)
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
    /// `b` = `a` rotated by `phi` about the unit axis `axis ⊥ a` (Rodrigues).
    fn rotated(a: &V3, axis: &V3, phi: f64) -> V3 {
        a * phi.cos() + axis.cross(a) * phi.sin()
    }

    /// Worst |analytic − central difference| of the gradients of `φ_ε` w.r.t. `a` and `b`.
    fn smoothed_gradient_error(a: &V3, b: &V3, eps: f64, h: f64) -> f64 {
        let (_, ga, gb) = smoothed_turning_angle(a, b, eps);
        let mut worst: f64 = 0.0;
        for c in 0..3 {
            let mut e = V3::zeros();
            e[c] = h;
            let f = |a: &V3, b: &V3| smoothed_turning_angle(a, b, eps).0;
            let fa = (f(&(a + e), b) - f(&(a - e), b)) / (2.0 * h);
            let fb = (f(a, &(b + e)) - f(a, &(b - e))) / (2.0 * h);
            worst = worst.max((fa - ga[c]).abs()).max((fb - gb[c]).abs());
        }
        worst
    }

    #[test]
    fn smoothed_turning_angle_gradients_match_central_differences_at_and_near_zero() {
        // where the exact angle has its kink (φ = 0) and across the smoothing zone, in 3-D, with
        // non-unit perturbations (the gradients are w.r.t. a and b in R³)
        let eps = 1e-2;
        let a = V3::new(0.9, 0.3, -0.1).normalize();
        let axis = a.cross(&V3::new(0.2, -0.5, 0.8)).normalize();
        for y in [0.0, 1e-9, 1e-4, 0.1, 0.39, 1.0, 1.81, 3.0, 10.0, 30.0] {
            let b = rotated(&a, &axis, y * eps);
            // h ≪ ε: the FD truncation error ~ h²/ε² of a gradient of order 1
            let err = smoothed_gradient_error(&a, &b, eps, 1e-8);
            assert!(err < 1e-6, "φ = {y} ε: gradient error {err:e}");
            // and with non-unit vectors
            let err = smoothed_gradient_error(&(a * 1.3), &(b * 0.8), eps, 1e-8);
            assert!(err < 1e-6, "φ = {y} ε (non-unit): gradient error {err:e}");
        }
        // exactly at 0 the gradients are exactly 0 (φ_ε is smooth and even there)
        let (v, ga, gb) = smoothed_turning_angle(&a, &a, eps);
        assert_eq!((v, ga, gb), (0.0, V3::zeros(), V3::zeros()));
    }

    #[test]
    fn smoothed_turning_angle_gradient_is_continuous_through_zero() {
        // the exact angle's gradient jumps between opposite unit vectors across φ = 0 (b passing
        // a along a great circle); the smoothed one goes to 0 linearly, ‖∇_b φ_ε‖ ≈ 3φ/ε
        let eps = 1e-3;
        let a = V3::new(0.0, 0.6, 0.8);
        let axis = V3::new(1.0, 0.0, 0.0);
        for delta in [1e-3, 1e-5, 1e-7] {
            let (bp, bm) = (
                rotated(&a, &axis, delta * eps),
                rotated(&a, &axis, -delta * eps),
            );
            let (_, _, exact_p) = turning_angle(&a, &bp);
            let (_, _, exact_m) = turning_angle(&a, &bm);
            assert!(
                (exact_p - exact_m).norm() > 1.99,
                "the exact gradient jumps by 2"
            );
            let (_, gap, gbp) = smoothed_turning_angle(&a, &bp, eps);
            let (_, gam, gbm) = smoothed_turning_angle(&a, &bm, eps);
            for g in [gap, gbp, gam, gbm] {
                assert_relative_eq!(g.norm(), 3.0 * delta, max_relative = 1e-5);
            }
            assert!((gbp - gbm).norm() <= 6.0 * delta * (1.0 + 1e-5));
        }
    }

    #[test]
    fn smoothed_turning_angle_is_exact_far_from_zero_and_bounded_near_it() {
        let eps = 2e-3;
        let a = V3::new(0.9, 0.3, -0.1).normalize();
        let axis = a.cross(&V3::new(0.7, -0.2, 0.4)).normalize();
        // ε = 0 is the exact rule, bit for bit
        let b = rotated(&a, &axis, 0.3);
        assert_eq!(smoothed_turning_angle(&a, &b, 0.0), turning_angle(&a, &b));
        for i in 1..=4000 {
            let y = i as f64 * 0.01;
            let b = rotated(&a, &axis, y * eps);
            let (exact, _, _) = turning_angle(&a, &b);
            let (smooth, _, _) = smoothed_turning_angle(&a, &b, eps);
            let dev = (smooth - exact) / eps;
            // extremes of h(y) − y: −0.1796 at y ≈ 0.39, +0.0720 at y ≈ 1.81
            assert!((-0.1797..=0.0721).contains(&dev), "y = {y}: {dev}");
            if y >= 19.0 {
                // 2 y (y − 1) e^{−2y} < 1e-13, plus the round-off of the exact angle
                assert!(dev.abs() < 1e-12, "y = {y}: {dev:e}");
            }
        }
    }

    #[test]
    fn smoothing_is_unbiased_across_a_curvature_sign_change() {
        // planar path with curvature κ(X) = κ' (X − X₀) on [0, 80 h]: tangent angle θ = κ'(X − X₀)²/2,
        // per-point angles φ_i = Δ |i − ½ − X₀/h| with Δ = κ'h², continuum friction angle
        // ∫|κ| dX = κ'/2 (X₀² + (80h − X₀)²).
        // - The exact rule misses the turning that cancels inside the interval holding X₀: its error
        //   is −Δ min(s, 1 − s)² ∈ [−Δ/4, 0], s = X₀/h mod 1.
        // - Without the compensating sech² term the smoothing would lower the total by
        //   (π²/12) κ_ε²/κ' (the integral of |y|(1 − tanh|y|)); with it the integral of the change is
        //   0, and Σ φ_ε is a midpoint sum of an analytic function of slope −Δ … +Δ: by
        //   Euler–Maclaurin it is the continuum minus Δ/12, wherever X₀ falls, up to exponentially
        //   small terms (ε/Δ = κ_ε/(κ'h) ≈ 2.6 here). Both are O(h²) discretization errors.
        let (kp, h, kappa_eps) = (46.0, 2.5e-3, 0.3);
        let eps = kappa_eps * h;
        let delta = kp * h * h;
        let tanh_only_deficit = std::f64::consts::PI.powi(2) / 12.0 * kappa_eps * kappa_eps / kp;
        assert!(tanh_only_deficit > 5.0 * delta);
        let x_end = 80.0 * h;
        for s in [0.0, 0.15, 0.4, 0.5, 0.77] {
            let x0 = (40.0 + s) * h;
            let tau = |i: usize| {
                let x = i as f64 * h;
                let th = 0.5 * kp * (x - x0) * (x - x0);
                V3::new(th.cos(), 0.0, th.sin())
            };
            let continuum = 0.5 * kp * (x0 * x0 + (x_end - x0) * (x_end - x0));
            let (mut exact, mut smooth) = (0.0, 0.0);
            for i in 1..=80 {
                exact += turning_angle(&tau(i - 1), &tau(i)).0;
                smooth += smoothed_turning_angle(&tau(i - 1), &tau(i), eps).0;
            }
            let exact_expected = continuum - delta * s.min(1.0 - s).powi(2);
            let smooth_expected = continuum - delta / 12.0;
            assert!(
                (exact - exact_expected).abs() < 1e-12,
                "X₀ = {x0}: exact rule {exact} vs {exact_expected}"
            );
            assert!(
                // the exponentially small remainder is ~3e-12 here, the effects tested ≥ 2e-5
                (smooth - smooth_expected).abs() < 1e-10,
                "X₀ = {x0}: smoothed {smooth} vs {smooth_expected} (continuum {continuum})"
            );
        }
        // a straight path has no friction angle, smoothed or not
        let t = V3::new(0.6, 0.0, 0.8);
        assert_eq!(smoothed_turning_angle(&t, &t, eps).0, 0.0);
    }
}
