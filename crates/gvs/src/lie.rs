//! se(3) / SE(3) algebra (gvs-spec §2): `tilde`, hat, `ad`, `coad`, `coadbar`, the adjoint actions of a
//! pose, the closed-form exponential and its left-trivialized tangent operator `T(Ω)` with small-angle
//! series, `Ṫ`, and the Ω-derivatives `∂(T y)/∂Ω`, `∂(Tᵀ F)/∂Ω` used by the Jacobians.
//!
//! Every 6-vector is ordered **angular first**: `ξ = [k; ν]`, `η = [ω; v]`, `F = [m; f]` (spec §1.2).
//! All operators are fixed-size and allocation-free.

use nalgebra::{Matrix3, Matrix4, Matrix6, Vector3, Vector6};

pub type V3 = Vector3<f64>;
pub type V6 = Vector6<f64>;
pub type M3 = Matrix3<f64>;
pub type M6 = Matrix6<f64>;

/// Below this angle the exponential and tangent coefficients use their Taylor series.
///
/// The spec (§2.3–2.4) switches at 1e-2 with series to θ⁶; but the closed forms of `f₃, f₄` and
/// `φ_r` cancel catastrophically there (`f₄` loses ~1e-5 relative). Series to θ¹² (θ¹⁰ for `φ`)
/// keep ≤ 1e-15 truncation error up to θ = 0.5, where the closed forms are accurate to ~1e-13.
pub const SMALL_ANGLE: f64 = 0.5;

#[inline]
fn ang(x: &V6) -> V3 {
    V3::new(x[0], x[1], x[2])
}
#[inline]
fn lin(x: &V6) -> V3 {
    V3::new(x[3], x[4], x[5])
}

/// Skew matrix `ã` with `ã b = a × b`.
#[inline]
pub fn tilde(a: &V3) -> M3 {
    M3::new(0.0, -a[2], a[1], a[2], 0.0, -a[0], -a[1], a[0], 0.0)
}

/// Hat map `ξ̂ = [k̃ ν; 0 0] ∈ se(3)` (4×4).
pub fn hat(xi: &V6) -> Matrix4<f64> {
    let mut h = Matrix4::zeros();
    h.fixed_view_mut::<3, 3>(0, 0).copy_from(&tilde(&ang(xi)));
    h.fixed_view_mut::<3, 1>(0, 3).copy_from(&lin(xi));
    h
}

/// Adjoint of the Lie algebra, `ad_ξ = [k̃ 0; ν̃ k̃]` (spec §2.1).
#[inline]
pub fn ad(xi: &V6) -> M6 {
    let k = tilde(&ang(xi));
    let n = tilde(&lin(xi));
    let mut a = M6::zeros();
    a.fixed_view_mut::<3, 3>(0, 0).copy_from(&k);
    a.fixed_view_mut::<3, 3>(3, 3).copy_from(&k);
    a.fixed_view_mut::<3, 3>(3, 0).copy_from(&n);
    a
}

/// `ad_a b` without forming the matrix: `[k_a × k_b; ν_a × k_b + k_a × ν_b]`.
#[inline]
pub fn ad_mul(a: &V6, b: &V6) -> V6 {
    let (ka, na, kb, nb) = (ang(a), lin(a), ang(b), lin(b));
    let top = ka.cross(&kb);
    let bot = na.cross(&kb) + ka.cross(&nb);
    V6::new(top[0], top[1], top[2], bot[0], bot[1], bot[2])
}

/// Co-adjoint with SoRoSim's sign, `coad_ξ = −ad_ξᵀ = [k̃ ν̃; 0 k̃]` (spec §2.1).
#[inline]
pub fn coad(xi: &V6) -> M6 {
    -ad(xi).transpose()
}

/// `coad_a F` without forming the matrix: `[k_a × m + ν_a × f; k_a × f]`.
#[inline]
pub fn coad_mul(a: &V6, f: &V6) -> V6 {
    let (ka, na, m, fl) = (ang(a), lin(a), ang(f), lin(f));
    let top = ka.cross(&m) + na.cross(&fl);
    let bot = ka.cross(&fl);
    V6::new(top[0], top[1], top[2], bot[0], bot[1], bot[2])
}

/// The "swapped" co-adjoint: `coadbar(F) a = coad_a F`, `coadbar(F) = −[m̃ f̃; f̃ 0]` (spec §2.1).
#[inline]
pub fn coadbar(f: &V6) -> M6 {
    let m = tilde(&ang(f));
    let fl = tilde(&lin(f));
    let mut c = M6::zeros();
    c.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-m));
    c.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-fl));
    c.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-fl));
    c
}

/// A rigid transformation `g = (R, p) ∈ SE(3)`, mapping a cross-section frame to the world (spec §1.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    pub rot: M3,
    pub pos: V3,
}

impl Default for Pose {
    fn default() -> Self {
        Self::identity()
    }
}

impl Pose {
    pub fn identity() -> Self {
        Self {
            rot: M3::identity(),
            pos: V3::zeros(),
        }
    }

    pub fn new(rot: M3, pos: V3) -> Self {
        Self { rot, pos }
    }

    /// `g₁ g₂`.
    #[inline]
    pub fn compose(&self, other: &Pose) -> Pose {
        Pose {
            rot: self.rot * other.rot,
            pos: self.rot * other.pos + self.pos,
        }
    }

    /// `g⁻¹ = (Rᵀ, −Rᵀp)`.
    #[inline]
    pub fn inverse(&self) -> Pose {
        let rt = self.rot.transpose();
        Pose {
            rot: rt,
            pos: -(rt * self.pos),
        }
    }

    /// Homogeneous 4×4 matrix.
    pub fn to_homogeneous(&self) -> Matrix4<f64> {
        let mut h = Matrix4::identity();
        h.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rot);
        h.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.pos);
        h
    }

    /// `Ad_g = [R 0; p̃R R]`: maps body twists at g to the reference frame.
    pub fn adjoint(&self) -> M6 {
        let mut a = M6::zeros();
        let pr = tilde(&self.pos) * self.rot;
        a.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rot);
        a.fixed_view_mut::<3, 3>(3, 3).copy_from(&self.rot);
        a.fixed_view_mut::<3, 3>(3, 0).copy_from(&pr);
        a
    }

    /// `Ad_g⁻¹ = [Rᵀ 0; −Rᵀp̃ Rᵀ]`.
    pub fn adjoint_inv(&self) -> M6 {
        let rt = self.rot.transpose();
        let mut a = M6::zeros();
        a.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
        a.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
        a.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(-(rt * tilde(&self.pos))));
        a
    }

    /// `Ad_g⁻¹ x` without forming the matrix: `[Rᵀ ω; Rᵀ(v − p × ω)]`.
    #[inline]
    pub fn adjoint_inv_mul(&self, x: &V6) -> V6 {
        let rt = self.rot.transpose();
        let w = ang(x);
        let top = rt * w;
        let bot = rt * (lin(x) - self.pos.cross(&w));
        V6::new(top[0], top[1], top[2], bot[0], bot[1], bot[2])
    }

    /// `Ad_g⁻ᵀ F = coAd_g F = [R m + p × (R f); R f]` (wrench pulled to the reference frame).
    #[inline]
    pub fn coadjoint_mul(&self, f: &V6) -> V6 {
        let rf = self.rot * lin(f);
        let top = self.rot * ang(f) + self.pos.cross(&rf);
        V6::new(top[0], top[1], top[2], rf[0], rf[1], rf[2])
    }
}

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
fn exp_with(k: &V3, nu: &V3, theta: f64, c: &ExpCoeffs) -> Pose {
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

/// Powers `ad_Ω, ad_Ω², ad_Ω³, ad_Ω⁴`.
#[inline]
pub fn ad_powers(omega: &V6) -> [M6; 4] {
    let a = ad(omega);
    let a2 = a * a;
    let a3 = a2 * a;
    let a4 = a3 * a;
    [a, a2, a3, a4]
}

/// Exponential, tangent operator and the data needed for derivatives of one Magnus step.
#[derive(Debug, Clone, Copy)]
pub struct ExpTangent {
    pub g: Pose,
    /// `T(Ω) = I + Σ_r f_r ad_Ωʳ` (spec §2.4).
    pub t: M6,
    pub coeffs: ExpCoeffs,
    /// `ad_Ωʳ`, r = 1..4.
    pub pow: [M6; 4],
    pub omega: V6,
    /// Whether `t` and `pow` are computed ([`exp_tangent_lean`] leaves them NaN, [`ExpTangent::set_lean`]
    /// stale; [`ExpTangent::t_dot`] and [`ExpTangent::d_ty`] assert it in debug builds).
    pub full: bool,
}

/// `exp(Ω̂)` and the left-trivialized tangent `T(Ω) = Σ_j ad_Ωʲ/(j+1)!` (spec §2.3–2.4).
pub fn exp_tangent(omega: &V6) -> ExpTangent {
    let k = ang(omega);
    let theta = k.norm();
    let coeffs = exp_coeffs(theta);
    let g = exp_with(&k, &lin(omega), theta, &coeffs);
    let pow = ad_powers(omega);
    let mut t = M6::identity();
    for r in 0..4 {
        t += pow[r] * coeffs.f[r];
    }
    ExpTangent {
        g,
        t,
        coeffs,
        pow,
        omega: *omega,
        full: true,
    }
}

/// [`exp_tangent`] without the powers `ad_Ωʳ` and the matrix `T` (NaN until
/// [`ExpTangent::complete`]): what a pass that only needs `exp Ω`, `T y` and `Tᵀ y`
/// ([`ExpTangent::t_mul`], [`ExpTangent::t_tr_mul`]) pays — no 6×6 products.
pub fn exp_tangent_lean(omega: &V6) -> ExpTangent {
    let nan = f64::NAN;
    let mut et = ExpTangent {
        g: Pose::identity(),
        t: M6::from_element(nan),
        coeffs: ExpCoeffs {
            a2: nan,
            a3: nan,
            f: [nan; 4],
            phi: [nan; 4],
        },
        pow: [M6::from_element(nan); 4],
        omega: *omega,
        full: false,
    };
    et.set_lean(omega);
    et
}

impl ExpTangent {
    /// Makes `self` the lean step of `omega` ([`exp_tangent_lean`]) in place: `g`, the coefficients
    /// and `Ω`, with `full = false`. `t` and `pow` keep stale values (never read while `full` is
    /// false: [`ExpTangent::complete`] recomputes them) instead of being overwritten with NaN, so a
    /// hot forward pass writes 22 numbers per step instead of moving the whole 1.5 kB struct.
    #[inline]
    pub fn set_lean(&mut self, omega: &V6) {
        let k = ang(omega);
        let theta = k.norm();
        self.coeffs = exp_coeffs(theta);
        self.g = exp_with(&k, &lin(omega), theta, &self.coeffs);
        self.omega = *omega;
        self.full = false;
    }
}

/// `T(Ω)` alone.
pub fn tangent(omega: &V6) -> M6 {
    exp_tangent(omega).t
}

impl ExpTangent {
    /// Computes `pow` and `t` of a lean step ([`exp_tangent_lean`]).
    pub fn complete(&mut self) {
        if !self.full {
            self.pow = ad_powers(&self.omega);
            let mut t = M6::identity();
            for r in 0..4 {
                t += self.pow[r] * self.coeffs.f[r];
            }
            self.t = t;
            self.full = true;
        }
    }

    /// `T y = y + Σ_r f_r ad_Ωʳ y` (by `ad` products of 6-vectors when `T` is not formed).
    #[inline]
    pub fn t_mul(&self, y: &V6) -> V6 {
        if self.full {
            return self.t * y;
        }
        let mut ay = *y;
        let mut out = *y;
        for r in 0..4 {
            ay = ad_mul(&self.omega, &ay);
            out += ay * self.coeffs.f[r];
        }
        out
    }

    /// `Tᵀ y = y + Σ_r f_r (ad_Ωᵀ)ʳ y`, `ad_Ωᵀ y = −coad_Ω y`.
    #[inline]
    pub fn t_tr_mul(&self, y: &V6) -> V6 {
        if self.full {
            return self.t.transpose() * y;
        }
        let mut ay = *y;
        let mut out = *y;
        for r in 0..4 {
            ay = -coad_mul(&self.omega, &ay);
            out += ay * self.coeffs.f[r];
        }
        out
    }

    /// Time derivative `Ṫ = Σ_r [φ_r (Ω_k·Ω̇_k) Aʳ + f_r Σ_{u=1}^{r} A^{u−1} Ȧ A^{r−u}]`, `A = ad_Ω`,
    /// `Ȧ = ad_Ω̇` (spec §2.5).
    pub fn t_dot(&self, omega_dot: &V6) -> M6 {
        debug_assert!(self.full, "t_dot needs the powers of a full step");
        let a = &self.pow[0];
        let ad_ = ad(omega_dot);
        let kk = ang(&self.omega).dot(&ang(omega_dot));
        // d(A^r) = d(A^{r-1}) A + A^{r-1} Ȧ
        let d1 = ad_;
        let d2 = d1 * a + a * ad_;
        let d3 = d2 * a + self.pow[1] * ad_;
        let d4 = d3 * a + self.pow[2] * ad_;
        let d = [d1, d2, d3, d4];
        let mut out = M6::zeros();
        for r in 0..4 {
            out += self.pow[r] * (self.coeffs.phi[r] * kk) + d[r] * self.coeffs.f[r];
        }
        out
    }

    /// `Ṫ(Ω̇) y` without forming `Ṫ`: with `w_r = d(Aʳ) y`, `w_1 = Ȧ y`,
    /// `w_r = A w_{r−1} + Ȧ A^{r−1} y` (`d(Aʳ) = A d(A^{r−1}) + Ȧ A^{r−1}`), all by `ad` products
    /// of 6-vectors: `Ṫ y = Σ_r [φ_r (Ω_k·Ω̇_k) Aʳ y + f_r w_r]` (see [`ExpTangent::t_dot`]).
    pub fn t_dot_mul(&self, omega_dot: &V6, y: &V6) -> V6 {
        let kk = ang(&self.omega).dot(&ang(omega_dot));
        let mut ay = *y; // A^{r−1} y
        let mut w = V6::zeros(); // w_{r−1}
        let mut out = V6::zeros();
        for r in 0..4 {
            w = ad_mul(&self.omega, &w) + ad_mul(omega_dot, &ay);
            ay = ad_mul(&self.omega, &ay);
            out += ay * (self.coeffs.phi[r] * kk) + w * self.coeffs.f[r];
        }
        out
    }

    /// `∂(T y)/∂Ω = Σ_r [φ_r (Aʳy) [Ω_kᵀ, 0] − f_r Σ_{u=1}^{r} A^{u−1} ad_{(A^{r−u} y)}]` (spec §2.5).
    pub fn d_ty(&self, y: &V6) -> M6 {
        debug_assert!(self.full, "d_ty needs the powers of a full step");
        let a = &self.pow[0];
        // A^{m} y for m = 0..4
        let mut ay = [*y; 5];
        for m in 1..5 {
            ay[m] = a * ay[m - 1];
        }
        let ok = ang(&self.omega);
        let mut out = M6::zeros();
        for r in 1..=4 {
            let col = ay[r] * self.coeffs.phi[r - 1];
            for c in 0..3 {
                for i in 0..6 {
                    out[(i, c)] += col[i] * ok[c];
                }
            }
            // Σ_u A^{u−1} ad(A^{r−u} y)
            let mut s = M6::zeros();
            for u in 1..=r {
                let adv = ad(&ay[r - u]);
                s += if u == 1 { adv } else { self.pow[u - 2] * adv };
            }
            out -= s * self.coeffs.f[r - 1];
        }
        out
    }

    /// `∂(Tᵀ F)/∂Ω = Σ_r (−1)ʳ [φ_r (Cʳ F)[Ω_kᵀ, 0] + f_r Σ_{u=1}^{r} C^{u−1} coadbar(C^{r−u} F)]`,
    /// `C = coad_Ω = −Aᵀ` (spec §2.5, SoRoSim's `compute_dSTdqFC`).
    ///
    /// Evaluated by grouping the double sum by `u` (`coadbar` is linear in its argument):
    /// `Σ_u C^{u−1} coadbar(v_u)`, `v_u = Σ_{r≥u} (−1)ʳ f_r C^{r−u} F`, in Horner form
    /// `coadbar(v_1) + C (coadbar(v_2) + C (coadbar(v_3) + C coadbar(v_4)))`: three 6×6 products.
    pub fn d_ttf(&self, f: &V6) -> M6 {
        let DTtf { omega, v, col } = self.d_ttf_vectors(f);
        let c1 = coad(&omega);
        let mut out = coadbar(&v[3]);
        for u in (0..3).rev() {
            out = coadbar(&v[u]) + c1 * out;
        }
        // rank-one part: col [Ω_kᵀ, 0]
        let ok = ang(&omega);
        for c in 0..3 {
            for i in 0..6 {
                out[(i, c)] += col[i] * ok[c];
            }
        }
        out
    }

    /// [`ExpTangent::d_ttf`] as its vectors, for matrix-free products ([`DTtf::mul`]). Needs only
    /// the coefficients, not the powers (works on a lean step).
    pub fn d_ttf_vectors(&self, f: &V6) -> DTtf {
        // cf[j] = Cʲ F, C = coad_Ω
        let mut cf = [*f; 5];
        for j in 1..5 {
            cf[j] = coad_mul(&self.omega, &cf[j - 1]);
        }
        let sign = |r: usize| if r.is_multiple_of(2) { 1.0 } else { -1.0 };
        let v = std::array::from_fn(|u0| {
            let u = u0 + 1;
            (u..=4).fold(V6::zeros(), |acc, r| {
                acc + cf[r - u] * (sign(r) * self.coeffs.f[r - 1])
            })
        });
        let col = (1..=4).fold(V6::zeros(), |acc, r| {
            acc + cf[r] * (sign(r) * self.coeffs.phi[r - 1])
        });
        DTtf {
            omega: self.omega,
            v,
            col,
        }
    }
}

/// The `F`-dependent vectors of [`ExpTangent::d_ttf`], for products `∂(TᵀF)/∂Ω · z` without the
/// 6×6 matrix ([`DTtf::mul`]): worth it when only a few `z` follow one `F` (a reduced model's one or
/// two coordinates per step), where forming the matrix would cost more than all the products.
#[derive(Debug, Clone, Copy)]
pub struct DTtf {
    omega: V6,
    /// `v_u = Σ_{r≥u} (−1)ʳ f_r C^{r−u} F`, u = 1..4.
    v: [V6; 4],
    /// `Σ_r (−1)ʳ φ_r Cʳ F`, the rank-one part's column.
    col: V6,
}

impl DTtf {
    /// `∂(TᵀF)/∂Ω · z = coadbar(v₁) z + C (coadbar(v₂) z + C (coadbar(v₃) z + C coadbar(v₄) z))
    /// + col (Ω_k · z_k)`, with `coadbar(v) z = coad_z v` and `C x = coad_Ω x`.
    #[inline]
    pub fn mul(&self, z: &V6) -> V6 {
        let mut out = coad_mul(z, &self.v[3]);
        for u in (0..3).rev() {
            out = coad_mul(z, &self.v[u]) + coad_mul(&self.omega, &out);
        }
        out + self.col * ang(&self.omega).dot(&ang(z))
    }
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
    use super::*;
    use approx::assert_relative_eq;

    fn v6(a: [f64; 6]) -> V6 {
        V6::from_row_slice(&a)
    }

    /// Reference matrix exponential by scaling and squaring of a Taylor series (test oracle only).
    fn expm<const N: usize>(a: &nalgebra::SMatrix<f64, N, N>) -> nalgebra::SMatrix<f64, N, N> {
        let norm = a.abs().max();
        let s = (norm.log2().ceil().max(0.0) as i32) + 4;
        let b = a / 2f64.powi(s);
        let mut term = nalgebra::SMatrix::<f64, N, N>::identity();
        let mut sum = term;
        for k in 1..30 {
            term = term * b / k as f64;
            sum += term;
        }
        for _ in 0..s {
            sum = sum * sum;
        }
        sum
    }

    /// `T(Ω)` = upper-right block of `exp([ad_Ω I; 0 0])` (spec §2.5).
    fn tangent_reference(om: &V6) -> M6 {
        let mut big = nalgebra::SMatrix::<f64, 12, 12>::zeros();
        big.fixed_view_mut::<6, 6>(0, 0).copy_from(&ad(om));
        big.fixed_view_mut::<6, 6>(0, 6).copy_from(&M6::identity());
        expm(&big).fixed_view::<6, 6>(0, 6).into_owned()
    }

    const SAMPLES: [[f64; 6]; 8] = [
        [0.3, -0.2, 0.5, 1.0, 2.0, -0.5],
        [1e-4, 2e-4, -1e-4, 1.0, 2.0, -0.5],
        [2.5, 1.0, -1.5, 0.1, 0.2, 0.3],
        [0.0, 0.0, 0.0, 0.3, -0.1, 0.2],
        [0.0099, 0.0, 0.0, 0.2, 0.0, 0.1],
        [0.0101, 0.0, 0.0, 0.2, 0.0, 0.1],
        [0.0, 0.4999, 0.0, 0.2, 0.0, 0.1],
        [0.0, 0.0, 0.5001, 0.2, 0.0, 0.1],
    ];

    #[test]
    fn ad_hat_is_lie_bracket_of_hats() {
        let a = v6([0.3, -0.7, 0.2, 1.0, -2.0, 0.4]);
        let b = v6([-0.1, 0.5, 0.9, 0.3, 0.8, -1.1]);
        let lhs = hat(&(ad(&a) * b));
        let rhs = hat(&a) * hat(&b) - hat(&b) * hat(&a);
        assert_relative_eq!(lhs, rhs, epsilon = 1e-14);
        assert_relative_eq!(ad_mul(&a, &b), ad(&a) * b, epsilon = 1e-14);
        assert_relative_eq!(ad(&a) * b, -(ad(&b) * a), epsilon = 1e-14);
        assert_relative_eq!(coad_mul(&a, &b), coad(&a) * b, epsilon = 1e-14);
        // ad_{ad_a b} = ad_a ad_b − ad_b ad_a
        assert_relative_eq!(
            ad(&(ad(&a) * b)),
            ad(&a) * ad(&b) - ad(&b) * ad(&a),
            epsilon = 1e-13
        );
    }

    #[test]
    fn coadbar_swaps_arguments_of_coad() {
        let f = v6([0.4, -1.2, 0.7, 2.0, 0.1, -0.3]);
        let a = v6([-0.5, 0.2, 0.3, 1.1, -0.6, 0.9]);
        assert_relative_eq!(coadbar(&f) * a, coad(&a) * f, epsilon = 1e-14);
    }

    #[test]
    fn adjoint_conjugates_hat_and_inverts() {
        let g = exp_se3(&v6([0.3, -0.2, 0.5, 1.0, 2.0, -0.5]));
        let xi = v6([0.1, 0.9, -0.4, 0.3, -0.2, 0.6]);
        let h = g.to_homogeneous();
        let hinv = g.inverse().to_homogeneous();
        assert_relative_eq!(
            hat(&(g.adjoint() * xi)),
            h * hat(&xi) * hinv,
            epsilon = 1e-13
        );
        assert_relative_eq!(g.inverse().adjoint(), g.adjoint_inv(), epsilon = 1e-14);
        assert_relative_eq!(
            g.adjoint() * g.adjoint_inv(),
            M6::identity(),
            epsilon = 1e-14
        );
        assert_relative_eq!(
            g.adjoint_inv_mul(&xi),
            g.adjoint_inv() * xi,
            epsilon = 1e-14
        );
        assert_relative_eq!(
            g.coadjoint_mul(&xi),
            g.adjoint_inv().transpose() * xi,
            epsilon = 1e-14
        );
        // Conjugation identities of spec §2.2.
        let a = v6([-0.5, 0.2, 0.3, 1.1, -0.6, 0.9]);
        let ai = g.adjoint_inv();
        assert_relative_eq!(ai * ad(&a) * g.adjoint(), ad(&(ai * a)), epsilon = 1e-13);
        assert_relative_eq!(
            ai.transpose() * coadbar(&xi) * ai,
            coadbar(&(ai.transpose() * xi)),
            epsilon = 1e-13
        );
    }

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
    fn tangent_matches_spec_reference_values() {
        let t = tangent(&v6([0.3, -0.2, 0.5, 1.0, 2.0, -0.5]));
        let r1 = [0.952576735, -0.2519946435, -0.0723438984, 0.0, 0.0, 0.0];
        let r4 = [
            0.2109257534,
            0.2930329888,
            1.0211389493,
            0.952576735,
            -0.2519946435,
            -0.0723438984,
        ];
        for j in 0..6 {
            assert!((t[(0, j)] - r1[j]).abs() < 1e-9);
            assert!((t[(3, j)] - r4[j]).abs() < 1e-9);
        }
        let t = tangent(&v6([1e-4, 2e-4, -1e-4, 1.0, 2.0, -0.5]));
        let r4 = [
            -1.4999999909e-4,
            0.25006666083,
            0.99997498583,
            0.99999999167,
            5.0003333083e-5,
            9.9998332833e-5,
        ];
        for j in 0..6 {
            assert!((t[(3, j)] - r4[j]).abs() < 1e-10, "T[3,{j}]");
        }
        let t = tangent(&v6([2.5, 1.0, -1.5, 0.1, 0.2, 0.3]));
        for (j, v) in [0.6644822908, 0.5736016809, -0.1767950614]
            .iter()
            .enumerate()
        {
            assert!((t[(0, j)] - v).abs() < 1e-9);
        }
    }

    #[test]
    fn exp_and_tangent_match_matrix_exponential_on_both_branches() {
        for s in SAMPLES {
            let om = v6(s);
            let g = exp_se3(&om).to_homogeneous();
            assert_relative_eq!(g, expm(&hat(&om)), epsilon = 1e-13);
            assert_relative_eq!(tangent(&om), tangent_reference(&om), epsilon = 1e-13);
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
    fn tangent_relates_to_derivative_of_exp() {
        // exp(Ω)⁻¹ d/dt exp(Ω) = (Ad⁻¹_{exp Ω} T(Ω) Ω̇)^ and Ad⁻¹_{exp Ω} T(Ω) = T(−Ω)
        let om = v6([0.4, -0.3, 0.8, 0.2, 1.0, -0.4]);
        let od = v6([0.1, 0.5, -0.2, 0.7, -0.3, 0.2]);
        let e = 1e-6;
        let gp = exp_se3(&(om + od * e)).to_homogeneous();
        let gm = exp_se3(&(om - od * e)).to_homogeneous();
        let g = exp_se3(&om);
        let lhs = g.inverse().to_homogeneous() * (gp - gm) / (2.0 * e);
        let rhs = hat(&(g.adjoint_inv() * tangent(&om) * od));
        assert_relative_eq!(lhs, rhs, epsilon = 1e-9);
        assert_relative_eq!(
            g.adjoint_inv() * tangent(&om),
            tangent(&(-om)),
            epsilon = 1e-13
        );
    }

    #[test]
    fn tangent_derivatives_match_central_differences() {
        let y = v6([0.3, -0.7, 0.2, 1.0, -0.5, 0.4]);
        let f = v6([-0.2, 0.6, 0.1, 0.8, 0.3, -0.9]);
        let od = v6([0.1, 0.5, -0.2, 0.7, -0.3, 0.2]);
        for s in SAMPLES {
            let om = v6(s);
            let et = exp_tangent(&om);
            let e = 1e-6;
            // Ṫ along Ω̇
            let fd = (tangent(&(om + od * e)) - tangent(&(om - od * e))) / (2.0 * e);
            assert_relative_eq!(et.t_dot(&od), fd, epsilon = 1e-8);
            // the lean step's products against the full matrices
            let lean = exp_tangent_lean(&om);
            assert!(!lean.full && lean.t[(0, 0)].is_nan());
            assert_relative_eq!(lean.t_mul(&y), et.t * y, epsilon = 1e-14);
            assert_relative_eq!(lean.t_tr_mul(&f), et.t.transpose() * f, epsilon = 1e-14);
            assert_relative_eq!(lean.t_dot_mul(&od, &y), et.t_dot(&od) * y, epsilon = 1e-14);
            let mut done = lean;
            done.complete();
            assert!(done.full);
            assert_relative_eq!(done.t, et.t, epsilon = 1e-15);
            assert_relative_eq!(et.t_dot_mul(&od, &y), fd * y, epsilon = 1e-8);
            assert_relative_eq!(et.t_dot_mul(&od, &y), et.t_dot(&od) * y, epsilon = 1e-14);
            // ∂(Ty)/∂Ω and ∂(TᵀF)/∂Ω column by column
            let dty = et.d_ty(&y);
            let dtf = et.d_ttf(&f);
            // the matrix-free product, also from a lean step
            let dv = lean.d_ttf_vectors(&f);
            for z in [y, od] {
                assert_relative_eq!(dv.mul(&z), dtf * z, epsilon = 1e-14);
            }
            for c in 0..6 {
                let mut dv = V6::zeros();
                dv[c] = e;
                let tp = tangent(&(om + dv));
                let tm = tangent(&(om - dv));
                let col_y = (tp * y - tm * y) / (2.0 * e);
                let col_f = (tp.transpose() * f - tm.transpose() * f) / (2.0 * e);
                assert_relative_eq!(dty.column(c).into_owned(), col_y, epsilon = 1e-8);
                assert_relative_eq!(dtf.column(c).into_owned(), col_f, epsilon = 1e-8);
            }
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
