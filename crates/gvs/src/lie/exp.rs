//! The exponential map of se(3) and its inverse (gvs-spec §2.3–2.4, §2.6): the coefficients `a₂, a₃`
//! of `exp(Ω̂)` and `f_r, φ_r` of `T(Ω)` at `θ = ‖Ω_k‖`, in closed form with small-angle series,
//! `exp(Ω̂)` itself, and the logarithm `log_se3`.

use super::{ang, lin, tilde, Pose, M3, V3, V6};

/// Below this angle the exponential and tangent coefficients use their Taylor series.
///
/// The spec (§2.3–2.4) switches at 1e-2 with series to θ⁶; but the closed forms of `f₃, f₄` and
/// `φ_r` cancel catastrophically there (`f₄` loses ~1e-5 relative). Series to θ¹² (θ¹⁰ for `φ`)
/// keep ≤ 1e-15 truncation error up to θ = 0.5, where the closed forms are accurate to ~1e-13.
pub const SMALL_ANGLE: f64 = 0.5;

/// Coefficients of `exp(Ω̂)` and `T(Ω)` at `θ = ‖Ω_k‖` (spec §2.3–2.4):
/// `a₂, a₃` of the exponential, `f₁..f₄` of `T`, and `φ_r = f_r'(θ)/θ` (finite at 0).
#[derive(Debug, Clone, Copy)]
pub struct ExpCoeffs {
    pub a2: f64,
    pub a3: f64,
    pub f: [f64; 4],
    pub phi: [f64; 4],
}

/// `Σ_k c_k x^k` in Horner form.
#[inline(always)]
fn horner<const N: usize>(x: f64, c: &[f64; N]) -> f64 {
    let mut acc = c[N - 1];
    for k in (0..N - 1).rev() {
        acc = acc * x + c[k];
    }
    acc
}

/// Taylor coefficients of [`exp_coeffs`] in powers of `θ²` (entry k multiplies `θ²ᵏ`), stored as
/// reciprocals so that a series costs multiplications only.
mod series {
    pub const A2: [f64; 7] = [
        1.0 / 2.0,
        -1.0 / 24.0,
        1.0 / 720.0,
        -1.0 / 40320.0,
        1.0 / 3628800.0,
        -1.0 / 479001600.0,
        1.0 / 87178291200.0,
    ];
    pub const A3: [f64; 7] = [
        1.0 / 6.0,
        -1.0 / 120.0,
        1.0 / 5040.0,
        -1.0 / 362880.0,
        1.0 / 39916800.0,
        -1.0 / 6227020800.0,
        1.0 / 1307674368000.0,
    ];
    pub const F: [[f64; 7]; 4] = [
        [
            1.0 / 2.0,
            0.0,
            -1.0 / 720.0,
            1.0 / 20160.0,
            -1.0 / 1209600.0,
            1.0 / 119750400.0,
            -1.0 / 17435658240.0,
        ],
        [
            1.0 / 6.0,
            0.0,
            -1.0 / 5040.0,
            1.0 / 181440.0,
            -1.0 / 13305600.0,
            1.0 / 1556755200.0,
            -1.0 / 261534873600.0,
        ],
        [
            1.0 / 24.0,
            -1.0 / 360.0,
            1.0 / 13440.0,
            -1.0 / 907200.0,
            1.0 / 95800320.0,
            -1.0 / 14529715200.0,
            1.0 / 2988969984000.0,
        ],
        [
            1.0 / 120.0,
            -1.0 / 2520.0,
            1.0 / 120960.0,
            -1.0 / 9979200.0,
            1.0 / 1245404160.0,
            -1.0 / 217945728000.0,
            1.0 / 50812489728000.0,
        ],
    ];
    pub const PHI: [[f64; 6]; 4] = [
        [
            0.0,
            -1.0 / 180.0,
            1.0 / 3360.0,
            -1.0 / 151200.0,
            1.0 / 11975040.0,
            -1.0 / 1452971520.0,
        ],
        [
            0.0,
            -1.0 / 1260.0,
            1.0 / 30240.0,
            -1.0 / 1663200.0,
            1.0 / 155675520.0,
            -1.0 / 21794572800.0,
        ],
        [
            -1.0 / 180.0,
            1.0 / 3360.0,
            -1.0 / 151200.0,
            1.0 / 11975040.0,
            -1.0 / 1452971520.0,
            1.0 / 249080832000.0,
        ],
        [
            -1.0 / 1260.0,
            1.0 / 30240.0,
            -1.0 / 1663200.0,
            1.0 / 155675520.0,
            -1.0 / 21794572800.0,
            1.0 / 4234374144000.0,
        ],
    ];
}

/// Closed forms above [`SMALL_ANGLE`], Taylor series below (spec §2.3–2.4, extended to θ¹²).
///
/// The series run in Horner form in `θ²`; the closed forms take one division (`1/θ`) and its powers.
pub fn exp_coeffs(theta: f64) -> ExpCoeffs {
    let t = theta;
    let t2 = t * t;
    if t < SMALL_ANGLE {
        ExpCoeffs {
            a2: horner(t2, &series::A2),
            a3: horner(t2, &series::A3),
            f: series::F.map(|c| horner(t2, &c)),
            phi: series::PHI.map(|c| horner(t2, &c)),
        }
    } else {
        let (s, c) = t.sin_cos();
        let i1 = 1.0 / t;
        let i2 = i1 * i1;
        let i3 = i2 * i1;
        let i4 = i2 * i2;
        let i5 = i4 * i1;
        let i6 = i3 * i3;
        let i7 = i6 * i1;
        let u3 = -8.0 + (8.0 - t2) * c + 5.0 * t * s;
        let u4 = -8.0 * t + (15.0 - t2) * s - 7.0 * t * c;
        ExpCoeffs {
            a2: (1.0 - c) * i2,
            a3: (t - s) * i3,
            f: [
                (4.0 - 4.0 * c - t * s) * (0.5 * i2),
                (4.0 * t - 5.0 * s + t * c) * (0.5 * i3),
                (2.0 - 2.0 * c - t * s) * (0.5 * i4),
                (2.0 * t - 3.0 * s + t * c) * (0.5 * i5),
            ],
            phi: [
                u3 * (0.5 * i4),
                u4 * (0.5 * i5),
                u3 * (0.5 * i6),
                u4 * (0.5 * i7),
            ],
        }
    }
}

/// Exponential map `g = exp(Ω̂) = I + Ω̂ + a₂ Ω̂² + a₃ Ω̂³` with `θ = ‖Ω_k‖` (spec §2.3).
///
/// Evaluated blockwise: `R = I + a₁' k̃ + a₂ k̃²` with `a₁' = sin θ/θ = 1 − a₃θ²`, and
/// `p = (I + a₂ k̃ + a₃ k̃²) ν`.
pub fn exp_se3(omega: &V6) -> Pose {
    let k = ang(omega);
    let nu = lin(omega);
    let theta = k.norm();
    let c = exp_coeffs(theta);
    exp_with(&k, &nu, theta, &c)
}

/// [`exp_se3`] from its coefficients. With `k̃² = k kᵀ − θ² I`: `R = (1 − a₂θ²) I + a₁' k̃ + a₂ k kᵀ` and
/// `p = ν + a₂ k × ν + a₃ k × (k × ν)` (no 3×3 products).
#[inline]
pub(super) fn exp_with(k: &V3, nu: &V3, theta: f64, c: &ExpCoeffs) -> Pose {
    let t2 = theta * theta;
    let a1 = 1.0 - c.a3 * t2; // sin θ / θ
    let d = 1.0 - c.a2 * t2; // cos θ
    let (a2k, a1k) = (k * c.a2, k * a1);
    let rot = M3::new(
        d + a2k[0] * k[0],
        a2k[0] * k[1] - a1k[2],
        a2k[0] * k[2] + a1k[1],
        a2k[1] * k[0] + a1k[2],
        d + a2k[1] * k[1],
        a2k[1] * k[2] - a1k[0],
        a2k[2] * k[0] - a1k[1],
        a2k[2] * k[1] + a1k[0],
        d + a2k[2] * k[2],
    );
    let kxnu = k.cross(nu);
    let pos = nu + kxnu * c.a2 + k.cross(&kxnu) * c.a3;
    Pose { rot, pos }
}

/// SE(3) logarithm `[ω; v]` with `exp(log(g)) = g` (spec §2.6); used for diagnostics and tests.
pub fn log_se3(g: &Pose) -> V6 {
    let r = &g.rot;
    let cos = ((r.trace() - 1.0) * 0.5).clamp(-1.0, 1.0);
    let theta = cos.acos();
    let w_skew = (r - r.transpose()) * 0.5; // sin θ · ω̃/θ
    let s = theta.sin();
    let fac = if theta < 1e-6 {
        1.0 + theta * theta / 6.0
    } else {
        theta / s
    };
    let wt = w_skew * fac;
    let w = V3::new(wt[(2, 1)], wt[(0, 2)], wt[(1, 0)]);
    let c = if theta < 1e-4 {
        1.0 / 12.0 + theta * theta / 720.0
    } else {
        (1.0 - theta * s / (2.0 * (1.0 - cos))) / (theta * theta)
    };
    let wt = tilde(&w);
    let vinv = M3::identity() - wt * 0.5 + wt * wt * c;
    let v = vinv * g.pos;
    V6::new(w[0], w[1], w[2], v[0], v[1], v[2])
}

#[cfg(test)]
mod tests {
    use super::super::test_util::v6;
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn exp_matches_spec_reference_values() {
        // gvs-spec §10.1
        let g = exp_se3(&v6([0.3, -0.2, 0.5, 1.0, 2.0, -0.5])).to_homogeneous();
        let rows = [
            [0.8595338986, -0.497991537, -0.1149169539, 0.4847593971],
            [0.439867633, 0.8353156052, -0.3297943377, 2.2020031485],
            [0.260226714, 0.2329211643, 0.9370324373, -0.1100543789],
        ];
        for (i, row) in rows.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                assert!(
                    (g[(i, j)] - v).abs() < 1e-9,
                    "g[{i},{j}] = {} vs {v}",
                    g[(i, j)]
                );
            }
        }
        let g = exp_se3(&v6([1e-4, 2e-4, -1e-4, 1.0, 2.0, -0.5])).to_homogeneous();
        assert!((g[(0, 3)] - 1.0000499992).abs() < 1e-10);
        assert!((g[(1, 3)] - 1.9999749983).abs() < 1e-10);
        assert!((g[(2, 3)] + 0.50000000417).abs() < 1e-10);
        let g = exp_se3(&v6([2.5, 1.0, -1.5, 0.1, 0.2, 0.3])).to_homogeneous();
        for (i, v) in [0.1281300468, -0.1854554958, 0.0899130808]
            .iter()
            .enumerate()
        {
            assert!((g[(i, 3)] - v).abs() < 1e-9);
        }
    }

    #[test]
    fn coefficients_are_continuous_across_series_switch() {
        let lo = exp_coeffs(SMALL_ANGLE * (1.0 - 1e-12));
        let hi = exp_coeffs(SMALL_ANGLE * (1.0 + 1e-12));
        assert!((lo.a2 - hi.a2).abs() < 1e-13 && (lo.a3 - hi.a3).abs() < 1e-13);
        for r in 0..4 {
            assert!((lo.f[r] - hi.f[r]).abs() < 1e-13, "f{}", r + 1);
            // closed-form φ loses ~θ⁻⁴ relative digits near the switch; 1e-8 is its precision there
            assert!(
                (lo.phi[r] - hi.phi[r]).abs() < 1e-8,
                "phi{}: {} vs {}",
                r + 1,
                lo.phi[r],
                hi.phi[r]
            );
        }
    }

    #[test]
    fn log_inverts_exp() {
        for s in [
            [0.3, -0.2, 0.5, 1.0, 2.0, -0.5],
            [1e-7, 0.0, 2e-7, 0.1, 0.2, 0.3],
            [1.2, 0.4, -0.9, 0.0, 0.5, 0.0],
        ] {
            let om = v6(s);
            assert_relative_eq!(log_se3(&exp_se3(&om)), om, epsilon = 1e-10);
        }
    }
}
