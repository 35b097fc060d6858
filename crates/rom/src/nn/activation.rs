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
//! Training applies the same function to whole batches ([`tanh_in_place`], and the layer outputs
//! in `batch`): both branches evaluated and one kept, without branches, so that the compiler
//! vectorises it (AVX2 + FMA where the CPU has them, chosen at run time), with `e^{2|x|}` from a
//! Cody–Waite reduction and a degree-13 Taylor polynomial (Estrin's scheme) instead of libm's `exp`:
//! ~1/5 of libm's time. Every path rounds alike (no floating-point contraction; `mul_add` is exactly
//! rounded everywhere), and it agrees with libm to 2 ulp (`tanh_in_place_agrees_with_libm_to_a_few_ulp`),
//! as the scalar [`tanh`] (`tanh_agrees_with_libm_to_a_few_ulp`): far below the reconstruction
//! error of any decoder.

use faer::reborrow::ReborrowMut;
use faer::MatMut;

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

simd_fn! {
    /// `x ← tanh x` for every element (module doc).
    pub fn tanh_in_place(xs: &mut [f64]) {
        xs.iter_mut().for_each(|x| *x = tanh_branchless(*x));
    }
}

simd_fn! {
    /// `a ← tanh(a + b)` (`tanh`) or `a ← a + b` on every row `a` of `out` (`b.len()` columns,
    /// unit column stride): a dense layer's bias and activation in one pass over its output.
    pub(crate) fn add_bias_and_activate(out: MatMut<'_, f64>, b: &[f64], tanh: bool) {
        let Some(mut out) = out.try_as_row_major_mut() else {
            unreachable!("layer outputs are stored row by row");
        };
        for i in 0..out.nrows() {
            let row = out.rb_mut().row_mut(i).as_slice_mut();
            if tanh {
                row.iter_mut().zip(b).for_each(|(a, b)| *a = tanh_branchless(*a + b));
            } else {
                row.iter_mut().zip(b).for_each(|(a, b)| *a += b);
            }
        }
    }
}

/// `ln 2 = LN2_HI + LN2_LO` (fdlibm's split): `LN2_HI` ends in 21 zero bits, so `k · LN2_HI` is
/// exact for the `k ≤ 64` used here.
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
#[allow(clippy::excessive_precision)]
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;
/// `1.5 · 2⁵²`: adding it rounds to an integer kept in the low mantissa bits.
const SHIFTER: f64 = 6_755_399_441_055_744.0;
/// `1/i!` for `i = 0..=13`: `e^r` to below half an ulp for `|r| ≤ ln 2 / 2` (the remainder
/// `r¹⁴/14! < 5e-18`).
const EXP_TAYLOR: [f64; 14] = [
    1.0,
    1.0,
    1.0 / 2.0,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5_040.0,
    1.0 / 40_320.0,
    1.0 / 362_880.0,
    1.0 / 3_628_800.0,
    1.0 / 39_916_800.0,
    1.0 / 479_001_600.0,
    1.0 / 6_227_020_800.0,
];

/// [`tanh`] without branches: both branches evaluated, one division.
#[inline(always)]
fn tanh_branchless(x: f64) -> f64 {
    let a = x.abs();
    // e = e^{2a} (2a clamped to 44: beyond it 1 − 2/(e + 1) rounds to 1; a NaN is restored below)
    let y = if 2.0 * a < 44.0 { 2.0 * a } else { 44.0 };
    let t = y.mul_add(std::f64::consts::LOG2_E, SHIFTER);
    let k = t - SHIFTER;
    let r = (-k).mul_add(LN2_LO, (-k).mul_add(LN2_HI, y));
    // Σ_{i ≤ 13} rⁱ/i! by Estrin's scheme (a shallower dependency chain than Horner's)
    let c = |i: usize| EXP_TAYLOR[i];
    let r2 = r * r;
    let r4 = r2 * r2;
    let r8 = r4 * r4;
    let p03 = r2.mul_add(r.mul_add(c(3), c(2)), r.mul_add(c(1), c(0)));
    let p47 = r2.mul_add(r.mul_add(c(7), c(6)), r.mul_add(c(5), c(4)));
    let p811 = r2.mul_add(r.mul_add(c(11), c(10)), r.mul_add(c(9), c(8)));
    let p1213 = r.mul_add(c(13), c(12));
    let p = r8.mul_add(r4.mul_add(p1213, p811), r4.mul_add(p47, p03));
    // 2^k from the low bits of t (2⁵¹ + k), k in 0..=64
    let two_k = f64::from_bits(t.to_bits().wrapping_add(1023) << 52);
    let e = p * two_k;
    let s = x * x;
    let small = a < 0.625;
    let num = if small {
        x * s * ((P[2] * s + P[1]) * s + P[0])
    } else {
        2.0
    };
    let den = if small {
        ((s + Q[2]) * s + Q[1]) * s + Q[0]
    } else {
        e + 1.0
    };
    let q = num / den;
    let big = (1.0 - q).copysign(x);
    let v = if small { x + q } else { big };
    // ±0 keep their sign (x + q would give +0 for −0), NaN stays NaN
    if x.is_nan() || a == 0.0 {
        x
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> f64 {
        ((a - b) / b.abs().max(f64::MIN_POSITIVE)).abs() / f64::EPSILON
    }

    /// `n + 1` points evenly over [−25, 25] (both branches, their switch at 0.625, the saturation
    /// at 22), tiny inputs, and the switch and saturation points themselves.
    fn probe_points(n: usize) -> Vec<f64> {
        let mut xs: Vec<f64> = (0..=n)
            .map(|i| -25.0 + 50.0 * i as f64 / n as f64)
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
        xs
    }

    #[test]
    fn tanh_agrees_with_libm_to_a_few_ulp() {
        // dense through both branches, their switch at 0.625, the saturation at 22, and tiny inputs;
        // measured worst: 1.71 ulp (at x = −0.668, the exponential branch)
        let mut worst = (0.0, 0.0);
        for x in probe_points(200_000) {
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

    #[test]
    fn tanh_in_place_agrees_with_libm_to_a_few_ulp() {
        // as `tanh_agrees_with_libm_to_a_few_ulp`, through the vectorised batch kernel
        let mut xs = probe_points(400_000);
        xs.extend([1e300, f64::MAX]);
        let negated: Vec<f64> = xs.iter().map(|x| -x).collect();
        xs.extend(negated);
        let mut ys = xs.clone();
        tanh_in_place(&mut ys);
        let mut worst = (0.0, 0.0);
        for (&x, &y) in xs.iter().zip(&ys) {
            let e = ulps(y, x.tanh());
            if e > worst.0 {
                worst = (e, x);
            }
        }
        // measured worst: 1.80 ulp (at x = −0.627, the exponential branch)
        assert!(worst.0 <= 2.0, "{} ulp at x = {}", worst.0, worst.1);
    }

    #[test]
    fn tanh_in_place_keeps_signs_zeros_limits_and_nan() {
        let mut xs = [
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -30.0,
            f64::NAN,
            5e-324,
        ];
        tanh_in_place(&mut xs);
        assert_eq!(xs[0].to_bits(), 0f64.to_bits());
        assert_eq!(xs[1].to_bits(), (-0f64).to_bits());
        assert_eq!(xs[2..5], [1.0, -1.0, -1.0]);
        assert!(xs[5].is_nan());
        assert_eq!(xs[6], 5e-324);
    }
}
