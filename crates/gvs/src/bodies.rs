//! Rigid bodies fixed to the rod at a point: a payload or a gripper at the tip, the spacer discs a
//! tendon runs through. A body adds at its point `b` what a section adds at a quadrature point, with
//! the point's `W_i Ms_i` replaced by the body's spatial inertia `Mb` (gvs-spec §7.1, §7.2, §7.5):
//!
//! * `Mb = [I_c − m c̃ c̃, m c̃; −m c̃, m I₃]` (angular first): with `η = [ω; v]` the body twist of
//!   the section frame at `X`, the body's centre of mass `c` in that frame moves at `v − c̃ ω`, so its
//!   kinetic energy `½ m |v − c̃ω|² + ½ ωᵀ I_c ω` is `½ ηᵀ Mb η` (`I_c` the inertia tensor about the
//!   centre of mass, in the section's axes);
//! * mass matrix `M += J_bᵀ Mb J_b`; inertial wrench `w_b −= Mb η̇_b + coad_{η_b} Mb η_b`;
//! * weight `w_b = Mb Ad⁻¹_{g_b} 𝒢 = [c × f; f]`, `f = m Rᵀ g` (potential `U = −m g·(r_b + R_b c)`),
//!   whose derivative is that of a world-fixed wrench `[c × f; f]` (`[(c×f)~; f̃] δθ`, the statics
//!   kernel) plus `f × (c × δθ)` on the moment rows: `δ(c × f) = c × (f × δθ)` and Jacobi's identity.
//!
//! A body needs a computational point at its `x` (the front-ends add it to the discretization's
//! extra points, as for point loads).

use crate::error::{check_range, fmt_rounded, fmt_sci, fmt_value, ModelError};
use crate::lie::{tilde, M3, M6, V3, V6};
use nalgebra::SymmetricEigen;
use serde::{Deserialize, Serialize};

/// How far from its section a body's centre of mass, and its radius of gyration, may reach, in rod
/// lengths: a gripper or a held tool reaches a few; a thousand is a typo (`1e300`), refused
/// rather than left to a solver that cannot balance it.
pub const MAX_BODY_REACH: f64 = 1e3;

/// A rigid body fixed to the section at arc length `x` (SI units; frames of gvs-spec §1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigidBody {
    /// Arc length of the section it is fixed to \[m\].
    pub x: f64,
    /// Mass `m` \[kg\].
    pub mass: f64,
    /// Centre of mass `c` in the section frame at `x` \[m\] (x along the rod).
    pub center: [f64; 3],
    /// Inertia tensor `I_c` about the centre of mass, in the section's axes \[kg·m²\] (symmetric,
    /// with principal moments that satisfy the triangle inequality, as every solid's do).
    pub inertia: [[f64; 3]; 3],
}

impl RigidBody {
    /// A point mass `m` at the section's centroid.
    pub fn point_mass(x: f64, mass: f64) -> Self {
        RigidBody {
            x,
            mass,
            center: [0.0; 3],
            inertia: [[0.0; 3]; 3],
        }
    }

    /// The inertia tensor `I_c` as a matrix.
    pub fn inertia_matrix(&self) -> M3 {
        M3::from_fn(|a, b| self.inertia[a][b])
    }

    /// The spatial inertia `Mb = [I_c − m c̃ c̃, m c̃; −m c̃, m I₃]` at the section frame (module doc).
    pub fn spatial_inertia(&self) -> M6 {
        let m = self.mass;
        let ct = tilde(&V3::from(self.center));
        let mut mb = M6::zeros();
        mb.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(self.inertia_matrix() - ct * ct * m));
        mb.fixed_view_mut::<3, 3>(0, 3).copy_from(&(ct * m));
        mb.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-ct * m));
        mb.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(M3::identity() * m));
        mb
    }

    /// Checks the body's data, naming the fields `bodies[k].…`; `length` is the rod's.
    pub fn validate(&self, k: usize, length: f64) -> Result<(), ModelError> {
        let f = |n: &str| format!("bodies[{k}].{n}");
        if crate::rod::abscissa_on(length, self.x).is_none() {
            return Err(ModelError::value(
                f("x"),
                self.x,
                format!("an abscissa in [0, {}] m", fmt_rounded(length)),
            ));
        }
        check_range(
            &f("mass"),
            self.mass,
            Some((0.0, true)),
            None,
            "a finite number >= 0 kg",
        )?;
        let reach = MAX_BODY_REACH * length;
        for (a, &c) in self.center.iter().enumerate() {
            check_range(
                &f(&format!("center[{a}]")),
                c,
                Some((-reach, true)),
                Some((reach, true)),
                &format!(
                    "an offset in m within {MAX_BODY_REACH} rod lengths of the section, each component in [-{0}, {0}]",
                    fmt_value(reach)
                ),
            )?;
        }
        for a in 0..3 {
            for b in 0..3 {
                check_range(
                    &f(&format!("inertia[{a}][{b}]")),
                    self.inertia[a][b],
                    None,
                    None,
                    "a finite number in kg*m^2",
                )?;
            }
        }
        let i = self.inertia_matrix();
        let scale = i.amax();
        for (a, b) in [(0, 1), (0, 2), (1, 2)] {
            if (i[(a, b)] - i[(b, a)]).abs() > 1e-12 * scale {
                return Err(ModelError::invalid(
                    f("inertia"),
                    format!(
                        "not symmetric: [{a}][{b}] = {} but [{b}][{a}] = {} (an inertia tensor is symmetric)",
                        fmt_value(i[(a, b)]),
                        fmt_value(i[(b, a)])
                    ),
                ));
            }
        }
        let mut p = SymmetricEigen::new(i).eigenvalues;
        p.as_mut_slice().sort_by(f64::total_cmp);
        let tol = 1e-12 * scale;
        let moments = || {
            let m: Vec<String> = p.iter().map(|v| fmt_sci(*v, 4)).collect();
            m.join(", ")
        };
        if p[0] < -tol || p[2] > p[0] + p[1] + tol {
            return Err(ModelError::invalid(
                f("inertia"),
                format!(
                    "principal moments {} kg*m^2 are not a solid's (each must be >= 0 and at most the sum of the other two)",
                    moments()
                ),
            ));
        }
        // I = ∫ r² dm: at most m (reach)² (a massless body is let through with any finite inertia:
        // a sweep of the payload's mass from 0 keeps its tensor)
        if self.mass > 0.0 && p[2] > self.mass * reach * reach * (1.0 + 1e-12) {
            return Err(ModelError::invalid(
                f("inertia"),
                format!(
                    "principal moments {} kg*m^2 for a mass of {} kg: a radius of gyration beyond {MAX_BODY_REACH} rod lengths (accepted: each <= mass * ({} m)^2)",
                    moments(),
                    fmt_value(self.mass),
                    fmt_value(reach),
                ),
            ));
        }
        Ok(())
    }
}

/// A body resolved on a discretization: its point and its inertia in the forms the passes use.
#[derive(Debug, Clone)]
pub(crate) struct AttachedBody {
    pub(crate) body: RigidBody,
    /// The computational point at `body.x`.
    pub(crate) point: usize,
    /// `Mb` ([`RigidBody::spatial_inertia`]).
    pub(crate) mb: M6,
    /// Rows `r_k` with `Mb = Σ_k r_k r_kᵀ` (from its eigenpairs; `Mb` is positive semi-definite),
    /// the non-zero ones first, `rank` of them.
    pub(crate) rows: [V6; 6],
    pub(crate) rank: usize,
}

impl AttachedBody {
    pub(crate) fn new(body: RigidBody, point: usize) -> Self {
        let mb = body.spatial_inertia();
        let eig = SymmetricEigen::new(mb);
        let top = eig.eigenvalues.amax();
        let mut rows = [V6::zeros(); 6];
        let mut rank = 0;
        for k in 0..6 {
            let l = eig.eigenvalues[k];
            if l > 1e-14 * top {
                rows[rank] = eig.eigenvectors.column(k) * l.sqrt();
                rank += 1;
            }
        }
        AttachedBody {
            body,
            point,
            mb,
            rows,
            rank,
        }
    }

    /// The weight `[c × f; f]`, `f = m Rᵀ g`, for the section's rotation transposed `rt` and the
    /// gravity `g` (module doc).
    pub(crate) fn weight(&self, rt: &M3, g: &V3) -> V6 {
        let f = rt * g * self.body.mass;
        let m = V3::from(self.body.center).cross(&f);
        V6::new(m[0], m[1], m[2], f[0], f[1], f[2])
    }

    /// `E = f̃ c̃`: the weight's moment derivative beyond the world-fixed kernel, `f × (c × δθ) = E δθ`.
    pub(crate) fn weight_offset_derivative(&self, rt: &M3, g: &V3) -> M3 {
        let f = rt * g * self.body.mass;
        tilde(&f) * tilde(&V3::from(self.body.center))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body() -> RigidBody {
        RigidBody {
            x: 0.2,
            mass: 0.3,
            center: [0.02, -0.01, 0.005],
            inertia: [[2e-4, 1e-5, 0.0], [1e-5, 1.5e-4, -2e-5], [0.0, -2e-5, 1e-4]],
        }
    }

    #[test]
    fn spatial_inertia_gives_the_kinetic_energy_of_the_centre_of_mass_and_the_spin() {
        let b = body();
        let (w, v) = (V3::new(0.3, -1.2, 0.7), V3::new(-0.4, 0.1, 2.0));
        let vc = v + w.cross(&V3::from(b.center));
        let t = 0.5 * b.mass * vc.norm_squared() + 0.5 * w.dot(&(b.inertia_matrix() * w));
        let eta = V6::new(w[0], w[1], w[2], v[0], v[1], v[2]);
        let tb = 0.5 * eta.dot(&(b.spatial_inertia() * eta));
        assert!((t - tb).abs() < 1e-15, "{t} vs {tb}");
    }

    #[test]
    fn factor_rows_rebuild_the_spatial_inertia_also_for_a_point_mass() {
        for b in [body(), RigidBody::point_mass(0.1, 2.0)] {
            let a = AttachedBody::new(b, 3);
            let sum: M6 = a.rows[..a.rank].iter().map(|r| r * r.transpose()).sum();
            assert!(
                (sum - a.mb).amax() < 1e-14 * a.mb.amax(),
                "{sum} vs {}",
                a.mb
            );
        }
        assert_eq!(
            AttachedBody::new(RigidBody::point_mass(0.1, 2.0), 0).rank,
            3
        );
    }

    #[test]
    fn weight_offset_derivative_matches_finite_differences_of_the_moment() {
        let a = AttachedBody::new(body(), 1);
        let g = V3::new(0.0, 0.0, -9.81);
        let r = nalgebra::Rotation3::from_scaled_axis(V3::new(0.3, -0.5, 0.2)).into_inner();
        let w0 = a.weight(&r.transpose(), &g);
        let e = a.weight_offset_derivative(&r.transpose(), &g);
        let h = 1e-7;
        for k in 0..3 {
            let mut d = V3::zeros();
            d[k] = h;
            // R → R exp(δθ̃): a body-frame rotation, as δθ = J_ang δq
            let rp = r * nalgebra::Rotation3::from_scaled_axis(d).into_inner();
            let dw = (a.weight(&rp.transpose(), &g) - w0) / h;
            let mw = V3::new(w0[0], w0[1], w0[2]);
            let fw = V3::new(w0[3], w0[4], w0[5]);
            // the kernel's part (world-fixed [m; f]) plus E
            let expected_m = mw.cross(&d) / h + e * d / h;
            let expected_f = fw.cross(&d) / h;
            for c in 0..3 {
                // forward differences, second-order terms: ~h |f| |c| ≈ 6e-9 on the moment,
                // ~h |f| / 2 ≈ 1.5e-7 on the force (|f| = 2.9 N)
                assert!(
                    (dw[c] - expected_m[c]).abs() < 1e-7,
                    "moment {k} {c}: {dw} vs {expected_m}"
                );
                assert!((dw[3 + c] - expected_f[c]).abs() < 1e-6, "force {k} {c}");
            }
        }
    }

    #[test]
    fn validate_names_the_field_and_refuses_an_impossible_inertia() {
        let mut b = body();
        b.inertia = [[1.0, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]];
        let e = b.validate(2, 1.0).unwrap_err().to_string();
        assert!(
            e.contains("bodies[2].inertia") && e.contains("not a solid"),
            "{e}"
        );
        let mut b = body();
        b.inertia[0][1] = 3e-5;
        let e = b.validate(0, 1.0).unwrap_err().to_string();
        assert!(e.contains("not symmetric"), "{e}");
        let mut b = body();
        b.mass = -1.0;
        let e = b.validate(0, 1.0).unwrap_err().to_string();
        assert!(e.contains("bodies[0].mass") && e.contains(">= 0 kg"), "{e}");
        let mut b = body();
        b.x = 1.5;
        assert!(b
            .validate(0, 1.0)
            .unwrap_err()
            .to_string()
            .contains("bodies[0].x"));
        assert!(body().validate(0, 1.0).is_ok());
        // a typo's reach: a centre 1e300 m away, an inertia of 1e300 kg m²
        let mut b = body();
        b.center[2] = 1e300;
        let e = b.validate(0, 1.0).unwrap_err().to_string();
        assert!(
            e.contains("bodies[0].center[2]") && e.contains("within 1000 rod lengths"),
            "{e}"
        );
        let mut b = body();
        b.inertia = [[1e300, 0.0, 0.0], [0.0, 1e300, 0.0], [0.0, 0.0, 1e300]];
        let e = b.validate(0, 1.0).unwrap_err().to_string();
        assert!(
            e.contains("radius of gyration beyond 1000 rod lengths"),
            "{e}"
        );
        // a sweep of the mass from 0 keeps its tensor
        let mut b = body();
        b.mass = 0.0;
        assert!(b.validate(0, 1.0).is_ok());
        // a long tool held at its end: centre 10 rod lengths out, gyration radius of that order
        let mut b = body();
        b.center = [10.0, 0.0, 0.0];
        b.inertia = [[1e-4, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]];
        assert!(b.validate(0, 1.0).is_ok());
    }
}
