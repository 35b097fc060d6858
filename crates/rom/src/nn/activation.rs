//! The tanh activation of the decoder's strain evaluation, without libm's `tanh` call.
//!
//! A one-DOF reduced model evaluates its decoder's 267 hidden units (7 hidden layers, 306 features)
//! at every residual; libm's `tanh` (via `expm1`) was ~10 % of that residual. Here (Cephes' `tanh`,
//! S. L. Moshier):
//!
//! - `|x| < 0.625`: `tanh x = x + x s P(s)/Q(s)`, `s = x²`, with the degree-2 / monic degree-3
//!   rational minimax pair of Cephes (relative error ~1e-16);
//! - `0.625 ≤ |x| ≤ 22`: `tanh |x| = 1 − 2/(e^{2|x|} + 1)` (no cancellation: the result is ≥ 0.55);
//! - `|x| > 22`: `±1` (`1 − tanh 22 ≈ 1.6e-19`, below half an ulp of 1).
//!
//! Training keeps `f64::tanh`; the two agree to 2 ulp (`tanh_agrees_with_libm_to_a_few_ulp`), far
//! below the reconstruction error of any decoder.

// Cephes' published digits (more than an f64 holds; the nearest f64 is taken)
#[allow(clippy::excessive_precision)]
const P: [f64; 3] = [
    -1.614_687_684_417_084_479_52e3,
    -9.928_772_310_019_185_865_64e1,
    -9.643_991_794_250_522_386_28e-1,
];
#[allow(clippy::excessive_precision)]
const Q: [f64; 3] = [
    4.844_063_053_251_254_860_48e3,
    2.235_488_390_601_004_485_83e3,
    1.128_116_784_916_329_314_02e2,
];

/// `tanh x` (see the module doc); ±0 for ±0, NaN for NaN.
#[inline]
pub fn tanh(x: f64) -> f64 {
    let a = x.abs();
    if a == 0.0 {
        x // ±0
    } else if a < 0.625 {
        let s = x * x;
        let p = (P[2] * s + P[1]) * s + P[0];
        let q = ((s + Q[2]) * s + Q[1]) * s + Q[0];
        x + x * s * p / q
    } else if a <= 22.0 {
        let t = 1.0 - 2.0 / ((2.0 * a).exp() + 1.0);
        t.copysign(x)
    } else if a.is_nan() {
        x
    } else {
        1f64.copysign(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> f64 {
        ((a - b) / b.abs().max(f64::MIN_POSITIVE)).abs() / f64::EPSILON
    }

    #[test]
    fn tanh_agrees_with_libm_to_a_few_ulp() {
        // dense through both branches, their switch at 0.625, the saturation at 22, and tiny inputs;
        // measured worst: 1.71 ulp (at x = −0.668, the exponential branch)
        let mut worst = (0.0, 0.0);
        let mut xs: Vec<f64> = (0..200_001)
            .map(|i| -25.0 + 50.0 * i as f64 / 200_000.0)
            .collect();
        xs.extend((0..200).map(|k| 1e-300 * 1.5f64.powi(k)));
        xs.extend([
            0.625,
            0.625 - 1e-16,
            0.625 + 1e-16,
            22.0,
            22.0 + 1e-14,
            1e-8,
            0.3,
        ]);
        for x in xs {
            for x in [x, -x] {
                let e = ulps(tanh(x), x.tanh());
                if e > worst.0 {
                    worst = (e, x);
                }
            }
        }
        assert!(worst.0 <= 2.0, "{} ulp at x = {}", worst.0, worst.1);
    }

    #[test]
    fn tanh_keeps_signs_zeros_limits_and_nan() {
        assert_eq!(tanh(0.0).to_bits(), 0f64.to_bits());
        assert_eq!(tanh(-0.0).to_bits(), (-0f64).to_bits());
        assert_eq!(tanh(f64::INFINITY), 1.0);
        assert_eq!(tanh(f64::NEG_INFINITY), -1.0);
        assert_eq!(tanh(-30.0), -1.0);
        assert!(tanh(f64::NAN).is_nan());
    }
}
