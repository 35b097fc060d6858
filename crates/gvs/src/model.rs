//! The GVS model: forward kinematics `g(X)`, geometric Jacobian `J(X)`, and the static generalized
//! forces with their analytic Jacobian — generic over the [`StrainParam`].
//!
//! **Kinematics** (gvs-spec §5.3, §6). Between consecutive points of a division
//! `Ω = h/2 (ξ₁ + ξ₂) + c h² ad_{ξ₁} ξ₂` (Z4, `c = √3/12`; Z2: `Ω = h ξ_Z`), `g_{i+1} = g_i exp(Ω̂)`,
//! `Z = ∂Ω/∂q = h/2 (Ψ_q1 + Ψ_q2) + c h² (ad_{ξ₁} Ψ_q2 − ad_{ξ₂} Ψ_q1)`, `S = T(Ω) Z`,
//! `J_{i+1} = Ad⁻¹_{g_s} (J_i + S)`.
//!
//! **Statics residual** (paper eq. 9): `R(q) = −K₁(q) + F(q) + B(q)u`. Every term is written as
//! `R = Σ_s Ψ_q,sᵀ y_s` over the strain sites `s` with a 6-vector `y_s` per site:
//! * elastic, at points: `y_i −= W_i Es_i Ψ_i` (so `K₁ = Σ W Ψ_qᵀ Es Ψ`, spec §7.3);
//! * tendons, at points: `y_i += W_i Σ_k α_k Φ_a,k u_k` (paper eq. 11, spec §7.6–7.7);
//! * external `F = Σ_i J_iᵀ w_i` by the backward pass `F̄_s = coAd_{g_s}(F̄_{s+1} + w_{s+1})`,
//!   `S_sᵀ F̄_s = Zᵀ v`, `v = Tᵀ F̄`, which lands on the Magnus sub-points as
//!   `y₁ += h/2 v + c h² coad_{ξ₂} v`, `y₂ += h/2 v − c h² coad_{ξ₁} v` (spec §8.2).
//!
//! **Jacobian**: `∂R/∂q = Σ_s Ψ_q,sᵀ ∂y_s/∂q + Σ_s Σ_a y_{s,a} ∇²Ψ_{s,a}`; the second sum is the
//! parameterization's weighted Hessian (zero for linear bases). `∂F̄/∂q` follows the backward recursion
//! of spec §8.2; the friction factor's derivative `∂α/∂q` is included, so the Jacobian is exact.

use crate::actuation::{
    smoothed_turning_angle, smoothed_turning_angle_value, tangent_jacobian, tendon_local,
    wrench_jacobian, Tendon,
};
use crate::bodies::{AttachedBody, RigidBody};
use crate::discretize::{Discretization, MagnusOrder};
use crate::error::{fmt_value, ModelError};
use crate::lie::{ad_mul, coad, coad_mul, coadbar, tilde, Pose, M6, V3, V6};
use crate::rod::{Rod, SectionProps};
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DMatrixViewMut, DVector};
// the names the test-only dense reference takes from this module besides the above
#[cfg(test)]
use {nalgebra::Matrix6xX, std::ops::AddAssign};

#[cfg(test)]
#[path = "model_dense_reference.rs"]
mod dense_reference;
#[path = "model_forces.rs"]
mod forces;
#[path = "model_kernels.rs"]
mod kernels;
#[path = "model_kinematics.rs"]
mod kinematics;
#[path = "model_loads.rs"]
mod loads;
#[path = "model_statics.rs"]
mod statics;
#[path = "model_tendons.rs"]
mod tendons;
#[path = "model_workspace.rs"]
mod workspace;

pub use kinematics::ZANNA_C;
pub use loads::{PreparedLoads, DISTRIBUTED_QUADRATURE_TOLERANCE};
pub use workspace::Workspace;
pub(crate) use workspace::{zeros6_lazy, zeros_lazy};

use kernels::{
    add_g_times, add_h_times, load_derivative, load_derivative_mul, LocalMaps, STEP_MATRIX_COLUMNS,
};

/// A rod, its discretization, a strain parameterization and its tendons.
pub struct Model<P: StrainParam> {
    pub rod: Rod,
    pub disc: Discretization,
    pub param: P,
    pub tendons: Vec<Tendon>,
    /// Base pose `g(0)`.
    pub base: Pose,
    pub(crate) props: Vec<SectionProps>,
    /// [`Model::residual_floor`], of the `props` (fixed with them at construction).
    residual_floor: f64,
    xi_star: Vec<V6>,
    tendon_points: Vec<Vec<usize>>,
    /// Per tendon, the length of its span each of its points stands for ([`tendon_weight_list`]).
    tendon_weights: Vec<Vec<f64>>,
    /// Per point: its block in the workspace's `dyp` (`∂y_i/∂q` of tendons), `usize::MAX` for the
    /// points no tendon acts on.
    dy_slot: Vec<usize>,
    k_lin: Option<DMatrix<f64>>,
    /// Rigid bodies fixed to the rod ([`crate::bodies`]).
    pub(crate) bodies: Vec<AttachedBody>,
}

impl<P: StrainParam> Model<P> {
    /// Builds a model; validates the rod, the tendons and that `param` was built on `disc`.
    pub fn new(
        rod: Rod,
        disc: Discretization,
        param: P,
        tendons: Vec<Tendon>,
    ) -> Result<Self, ModelError> {
        rod.validate()?;
        if param.n_sites() != disc.n_sites() {
            return Err(ModelError::invalid(
                "basis",
                format!(
                    "built for {} sites, the discretization has {}",
                    param.n_sites(),
                    disc.n_sites()
                ),
            ));
        }
        if param.n_dof() == 0 {
            return Err(ModelError::invalid("basis", "no generalized coordinates"));
        }
        for (k, t) in tendons.iter().enumerate() {
            t.validate(&rod, k)?;
        }
        let props = disc
            .points
            .iter()
            .map(|p| rod.divisions[p.div].props_at(rod.material_of(p.div), p.x_bar))
            .collect::<Vec<_>>();
        let xi_star = vec![V6::new(0.0, 0.0, 0.0, 1.0, 0.0, 0.0); disc.n_sites()];
        let tendon_points: Vec<Vec<usize>> = tendons
            .iter()
            .map(|t| tendon_point_list(&disc, t))
            .collect();
        for (k, (t, pts)) in tendons.iter().zip(&tendon_points).enumerate() {
            if pts.is_empty() {
                return Err(no_point_on_span(&disc, k, t));
            }
        }
        let tendon_weights: Vec<Vec<f64>> = tendons
            .iter()
            .zip(&tendon_points)
            .map(|(t, pts)| tendon_weight_list(&disc, t, pts))
            .collect();
        let mut dy_slot = vec![usize::MAX; disc.n_points()];
        let mut slots = 0;
        let weighted = tendon_points
            .iter()
            .flatten()
            .zip(tendon_weights.iter().flatten());
        for (&i, &w) in weighted {
            if dy_slot[i] == usize::MAX && w > 0.0 {
                (dy_slot[i], slots) = (slots, slots + 1);
            }
        }
        let residual_floor = (props.iter()).fold(0.0, |m: f64, p| m.max(p.es[1]).max(p.es[2]));
        let mut m = Model {
            rod,
            disc,
            param,
            tendons,
            base: Pose::identity(),
            props,
            residual_floor,
            xi_star,
            tendon_points,
            tendon_weights,
            dy_slot,
            k_lin: None,
            bodies: Vec::new(),
        };
        if m.param.is_linear() {
            m.k_lin = Some(m.stiffness_linear());
        }
        Ok(m)
    }

    pub fn with_base(mut self, base: Pose) -> Self {
        self.base = base;
        self
    }

    /// The model with the reference strain `ξ*(X) = xi_star(X, division)` at every strain site
    /// (points and Magnus sub-points; gvs-spec §3.3) instead of the straight, unstretched rod
    /// `[0, 0, 0, 1, 0, 0]`: a pre-curved (`k*`), pre-twisted or pre-stretched rod, stress-free at
    /// `q = 0`. The elastic force `Σ W Ψ_qᵀ Es (ξ − ξ*)` and every Jacobian are unchanged in `q`;
    /// the kinematics integrate `ξ = Ψ(q) + ξ*`.
    pub fn with_reference_strain(mut self, xi_star: impl Fn(f64, usize) -> V6) -> Self {
        for (s, site) in self.disc.sites.iter().enumerate() {
            self.xi_star[s] = xi_star(site.x, site.div);
        }
        self
    }

    /// The model with rigid bodies fixed to the rod ([`crate::bodies`]): each adds its inertia to
    /// the mass matrix and the inertial forces and its weight to the loads. Each body's `x` must be
    /// a computational point (an extra point of the discretization, as a point load's).
    pub fn with_bodies(mut self, bodies: Vec<RigidBody>) -> Result<Self, ModelError> {
        let length = self.disc.length();
        let mut attached = Vec::with_capacity(bodies.len());
        for (k, b) in bodies.into_iter().enumerate() {
            b.validate(k, length)?;
            let point = self.disc.point_at(b.x).ok_or_else(|| {
                ModelError::invalid(
                    format!("bodies[{k}].x"),
                    format!(
                        "X = {} m is not a computational point; add it to the discretization's extra points",
                        b.x
                    ),
                )
            })?;
            attached.push(AttachedBody::new(b, point));
        }
        self.bodies = attached;
        Ok(self)
    }

    /// The bodies of another model built on the same discretization, carried to this one
    /// ([`Model::with_bodies`]).
    pub fn with_bodies_of<Q: StrainParam>(mut self, other: &Model<Q>) -> Self {
        assert_eq!(
            self.disc.n_points(),
            other.disc.n_points(),
            "bodies of a model on another discretization"
        );
        self.bodies = other.bodies.clone();
        self
    }

    /// Per body, the world positions of the section it is fixed to and of its centre of mass
    /// `r_b + R_b c` \[m\], after a forward pass in `ws`.
    pub fn body_positions<'a>(
        &'a self,
        ws: &'a Workspace,
    ) -> impl ExactSizeIterator<Item = (V3, V3)> + 'a {
        self.bodies.iter().map(|b| {
            let g = &ws.g[b.point];
            (g.pos, g.pos + g.rot * V3::from(b.body.center))
        })
    }

    /// The computational point of each rigid body, in the order of [`Model::bodies`].
    pub fn body_points(&self) -> impl ExactSizeIterator<Item = usize> + '_ {
        self.bodies.iter().map(|b| b.point)
    }

    /// The rigid bodies fixed to the rod ([`Model::with_bodies`]).
    pub fn bodies(&self) -> impl ExactSizeIterator<Item = &RigidBody> {
        self.bodies.iter().map(|b| &b.body)
    }

    /// The same model's reference strain at every site, carried to a model of another
    /// parameterization built on the same discretization ([`Model::with_reference_strain`]).
    pub fn with_reference_strain_of<Q: StrainParam>(mut self, other: &Model<Q>) -> Self {
        assert_eq!(
            self.xi_star.len(),
            other.xi_star.len(),
            "reference strain of a model on another discretization"
        );
        self.xi_star.copy_from_slice(&other.xi_star);
        self
    }

    pub fn n_dof(&self) -> usize {
        self.param.n_dof()
    }

    /// The smallest force scale of the statics convergence test \[N·m²\]: the rod's largest
    /// bending stiffness `EI`, the generalized force that bends it by about a radian. It scales
    /// with the rod as its loads' generalized forces do (`s⁴` for every length scaled by `s` and
    /// forces by `s²`), and it keeps a projection that vanishes (a decoder's spurious straight
    /// rod, a load the basis cannot hold) from asking a residual below round-off.
    pub fn residual_floor(&self) -> f64 {
        self.residual_floor
    }

    pub fn n_actuators(&self) -> usize {
        self.tendons.len()
    }

    pub fn section(&self, point: usize) -> &SectionProps {
        &self.props[point]
    }

    /// Reference strain `ξ*` at a site.
    pub fn xi_star(&self, site: usize) -> V6 {
        self.xi_star[site]
    }

    /// `K = Σ_i W_i Φ_iᵀ Es_i Φ_i` for a linear basis (spec §7.3).
    fn stiffness_linear(&self) -> DMatrix<f64> {
        let n = self.n_dof();
        let ev = self.param.new_eval();
        let mut k = DMatrix::zeros(n, n);
        for (i, p) in self.disc.points.iter().enumerate() {
            if p.weight == 0.0 {
                continue;
            }
            let c = self.param.columns(i);
            let phi = ev.psi_q_at(i, &c);
            let ephi = DMatrix::from_fn(6, c.len(), |a, j| {
                self.props[i].es[a] * p.weight * phi[(a, j)]
            });
            let mut blk = k.view_mut((c.start, c.start), (c.len(), c.len()));
            blk.gemm_tr(1.0, &phi, &ephi, 1.0);
        }
        k
    }

    /// Constant stiffness matrix of a linear parameterization.
    pub fn stiffness(&self) -> Option<&DMatrix<f64>> {
        self.k_lin.as_ref()
    }

    /// Tendon points (indices) of tendon `k`.
    pub fn tendon_points(&self, k: usize) -> &[usize] {
        &self.tendon_points[k]
    }

    /// The length \[m\] of tendon `k`'s span that each of its points ([`Model::tendon_points`])
    /// stands for: its quadrature weight `W_i` on a span of whole divisions; on a span with an end
    /// inside a division, its share of the span by the points' cells
    /// ([`Discretization::cells`]), the first point's from `X_s`, the last's to `X_e`. They sum to
    /// the span's length.
    pub fn tendon_weights(&self, k: usize) -> &[f64] {
        &self.tendon_weights[k]
    }

    /// Abscissae `[X_first, X_last]` \[m\] of tendon `k`'s first and last computational points
    /// (where [`Model::tendon_position_at`] interpolates); `None` for a tendon with no point.
    pub fn tendon_extent(&self, k: usize) -> Option<(f64, f64)> {
        let pts = &self.tendon_points[k];
        Some((
            self.disc.points[*pts.first()?].x,
            self.disc.points[*pts.last()?].x,
        ))
    }
}

/// The length of tendon `t`'s span `[X_s, X_e]` each of its points `pts` stands for, the weight
/// of its wrench `Φ_a α u` in `B(q) u` (gvs-spec §7.6) and of its speed in the tendon's length.
///
/// A span made of whole divisions (the spec's tendon domain) takes the quadrature weights `W_i`,
/// as the stiffness does. A span with an end inside a division is partitioned among its points at
/// the boundaries of their cells ([`Discretization::cells`]), the first point's share starting at
/// `X_s` and the last's ending at `X_e`: the weights then sum to `X_e − X_s` wherever the ends fall.
/// With `W_i` the points inside the span carried up to a point's weight more or less than its
/// length: a tendon ending at 0.1 m inside a 0.25 m division of 33 Gauss points turned the tip by
/// 0.012217 rad instead of the closed form's 0.012732 (4 % off).
fn tendon_weight_list(disc: &Discretization, t: &Tendon, pts: &[usize]) -> Vec<f64> {
    let tol = 1e-12 * disc.length().max(1.0);
    let on_boundary = |x: f64| {
        (x - disc.length()).abs() <= tol || disc.div_start.iter().any(|&s| (x - s).abs() <= tol)
    };
    if on_boundary(t.x_start) && on_boundary(t.x_end) {
        return pts.iter().map(|&i| disc.points[i].weight).collect();
    }
    let cells = disc.cells();
    let m = pts.len();
    (0..m)
        .map(|j| {
            let lo = match j {
                0 => t.x_start,
                _ => cells[pts[j]].0.clamp(t.x_start, t.x_end),
            };
            let hi = match j + 1 {
                e if e == m => t.x_end,
                _ => cells[pts[j + 1]].0.clamp(t.x_start, t.x_end),
            };
            (hi - lo).max(0.0)
        })
        .collect()
}

/// The error of tendon `k` whose span holds no computational point: it would act on nothing (its
/// load and length would be lost silently). Names the points on either side of it.
fn no_point_on_span(disc: &Discretization, k: usize, t: &Tendon) -> ModelError {
    let xs: Vec<f64> = disc.points.iter().map(|p| p.x).collect();
    let below = xs.iter().rev().find(|&&x| x < t.x_start).copied();
    let above = xs.iter().find(|&&x| x > t.x_end).copied();
    let around = match (below, above) {
        (Some(a), Some(b)) => format!("between the points at X = {a:.6} and {b:.6} m"),
        _ => "between two points".to_string(),
    };
    ModelError::invalid(
        format!("tendons[{k}].x_end"),
        format!(
            "{} m: the span [{}, {}] m lies {around} and holds none, so the tendon would act on nothing; accepted: a span that holds a computational point (longer, or with more points: more Gauss points, or a division junction inside it)",
            fmt_value(t.x_end),
            fmt_value(t.x_start),
            fmt_value(t.x_end),
        ),
    )
}

/// The computational points on a tendon's span. At a termination (or start) on a division junction
/// the duplicated point on the far side is excluded; junctions inside the span keep both points so
/// that the tangent kink counts in the friction angle.
fn tendon_point_list(disc: &Discretization, t: &Tendon) -> Vec<usize> {
    let tol = 1e-12 * disc.length().max(1.0);
    let pts = &disc.points;
    (0..pts.len())
        .filter(|&i| {
            let x = pts[i].x;
            if x < t.x_start - tol || x > t.x_end + tol {
                return false;
            }
            if (x - t.x_end).abs() <= tol && i > 0 && (pts[i - 1].x - x).abs() <= tol {
                return false;
            }
            if (x - t.x_start).abs() <= tol && i + 1 < pts.len() && (pts[i + 1].x - x).abs() <= tol
            {
                return false;
            }
            true
        })
        .collect()
}
