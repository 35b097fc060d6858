//! The left-trivialized tangent operator of the exponential, `T(Ω) = Σ_j ad_Ωʲ/(j+1)!` (gvs-spec
//! §2.4–2.5): [`ExpTangent`] holds one Magnus step's `exp(Ω̂)`, `T` and the powers `ad_Ωʳ` (or, lean,
//! only what products `T y`, `Tᵀ y` need), with `Ṫ` and the Ω-derivatives `∂(T y)/∂Ω`, `∂(Tᵀ F)/∂Ω`
//! used by the Jacobians.

use super::exp::{exp_coeffs, exp_with, ExpCoeffs};
use super::{ad, ad_mul, ang, coad, coad_mul, coadbar, lin, Pose, M6, V6};

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

#[cfg(test)]
mod tests {
    use super::super::test_util::{expm, v6};
    use super::super::{exp_se3, hat};
    use super::*;
    use approx::assert_relative_eq;

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
}
