//! se(3) / SE(3) algebra (gvs-spec §2): `tilde`, hat, `ad`, `coad`, `coadbar` and the adjoint actions of
//! a pose. Re-exported from two submodules: `exp`, the closed-form exponential with small-angle series
//! and its logarithm; `tangent`, the left-trivialized tangent operator `T(Ω)`, `Ṫ`, and the
//! Ω-derivatives `∂(T y)/∂Ω`, `∂(Tᵀ F)/∂Ω` used by the Jacobians.
//!
//! Every 6-vector is ordered **angular first**: `ξ = [k; ν]`, `η = [ω; v]`, `F = [m; f]` (spec §1.2).
//! All operators are fixed-size and allocation-free.

use nalgebra::{Matrix3, Matrix4, Matrix6, Vector3, Vector6};

mod exp;
mod tangent;
#[cfg(test)]
mod test_util;

pub use exp::{exp_coeffs, exp_se3, log_se3, ExpCoeffs, SMALL_ANGLE};
pub use tangent::{ad_powers, exp_tangent, exp_tangent_lean, tangent, DTtf, ExpTangent};

pub type V3 = Vector3<f64>;
pub type V6 = Vector6<f64>;
pub type M3 = Matrix3<f64>;
pub type M6 = Matrix6<f64>;

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

#[cfg(test)]
mod tests {
    use super::test_util::v6;
    use super::*;
    use approx::assert_relative_eq;

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
}
