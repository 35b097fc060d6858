//! Equations of motion of the GVS model (paper eq. 8, gvs-spec §6, §7.1–7.4, §7.8, §9.1):
//!
//! `M(q) q̈ + C(q, q̇) q̇ + D₁(q, q̇) + K₁(q) = B(q) u + F(q)`,
//!
//! generic over the strain parameterization (linear bases and nonlinear ones alike).
//!
//! * Velocities: `η_{i+1} = Ad⁻¹_{g_s}(η_i + S q̇)`, and with `ζ_i := J̇ˢ_i q̇` (the acceleration at
//!   `q̈ = 0`): `ζ_{i+1} = Ad⁻¹_{g_s}(ζ_i + ad_{η_i} S q̇ + Ṡ q̇)`, `Ṡ q̇ = Ṫ Ω̇ + T Ż q̇`, `Ω̇ = Z q̇`;
//!   Z4: `Ż q̇ = h/2 (Ψ̇_q1 + Ψ̇_q2) q̇ + c h² (ad_{ξ̇₁} ξ̇₂ − ad_{ξ̇₂} ξ̇₁ + ad_{ξ₁} Ψ̇_q2 q̇ − ad_{ξ₂} Ψ̇_q1 q̇)`.
//! * `M = Σ W J ᵀ Ms J` (§7.1); `C q̇ = Σ W Jᵀ (Ms ζ + coad_η Ms η)` (§7.2), obtained by adding the
//!   inertial wrenches `−W (Ms ζ + coad_η Ms η)` to the external point wrenches of the statics
//!   backward pass, so that `M q̈ = −K₁ − D₁ + F + Bu − C q̇` reuses the statics assembly.
//! * The Coriolis *matrix* `C = Σ W Jᵀ (Ms J̇ˢ + coad_η Ms J)` with SoRoSim's `J̇ˢ = J̇ + ad_η J`
//!   (recursion `J̇ˢ_{i+1} = Ad⁻¹(J̇ˢ_i + ad_{η_i} S + Ṡ)`) makes `Ṁ − 2C` skew-symmetric.

use crate::discretize::MagnusOrder;
use crate::lie::{ad_mul, coad_mul, V6};
use crate::model::{Model, PreparedLoads, Workspace, ZANNA_C};
use crate::strain::StrainParam;
use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use nalgebra::{DMatrix, DVector};
use thiserror::Error;

mod analysis;
pub(crate) mod cholesky;
mod held_modes;
mod linearize;
pub(crate) use analysis::{mass_similar, similar_modes};
pub use analysis::{Energy, Mode, SYMMETRY_TOLERANCE};
pub use cholesky::{
    cholesky_factor_in_place, cholesky_solve_factored, cholesky_solve_in_place, CHOLESKY_BLOCK,
    MASS_PIVOT_FLOOR,
};
pub use linearize::{Channel, StateSpace, LINEARIZATION_STEP};

#[derive(Debug, Clone, Error, PartialEq)]
pub enum DynamicsError {
    #[error("the mass matrix is not positive semi-definite (pivot {pivot} = {value:e}): non-finite or inconsistent inertia at this q")]
    MassNotPositiveDefinite { pivot: usize, value: f64 },
    #[error("non-finite value in the {what}")]
    NonFinite { what: &'static str },
    /// Held tendons whose constraints are dependent (two along one path, or more held tendons
    /// than a reduced model has coordinates): the constrained modes are undefined.
    #[error("the held tendons' {what} are dependent (rank {rank} of {count}): two held tendons along one path, or more held tendons than the model has coordinates")]
    DependentConstraints {
        what: &'static str,
        rank: usize,
        count: usize,
    },
    /// A tendon driven by its displacement without an axial stiffness: an inextensible one held
    /// at its length is a constraint, which the motion's equations do not impose.
    /// Channels given for a linearization that are not one per actuator.
    #[error("{got} channels given for {expected} actuators")]
    ChannelCount { expected: usize, got: usize },
    #[error("tendons[{tendon}].axial_stiffness is missing: a tendon driven by its displacement in a motion is an elastic thread whose stretch carries the motor's displacement to the rod; give its axial stiffness EA in N")]
    InextensibleDrive { tendon: usize },
}

/// Points per blocked product in [`Model::assemble_mass`].
pub const MASS_CHUNK: usize = 32;

impl<P: StrainParam> Model<P> {
    /// Forward pass with velocities: after [`Model::forward`], fills `ws.eta` (`η_i`)
    /// and `ζ_i = J̇ˢ_i q̇`.
    pub fn velocities(&self, q: &DVector<f64>, qd: &DVector<f64>, ws: &mut Workspace) {
        self.velocities_with(q, qd, None, ws);
    }

    /// [`Self::velocities`], and with `qdd` the body accelerations `η̇_i = J_i q̈ + J̇ˢ_i q̇` in
    /// `ws.zeta` instead of `ζ_i`: the recursion of the module doc with `T Z q̈` added to `Ṡ q̇`.
    /// `Ω̇ = Z q̇` is formed from the site strain rates `ξ̇_s = Ψ_q,s q̇` (Z4:
    /// `Ω̇ = h/2 (ξ̇₁ + ξ̇₂) + c h² (ad_{ξ₁} ξ̇₂ − ad_{ξ₂} ξ̇₁)`), so no `Z` or `J` is needed: after a
    /// forward pass without Jacobians this costs `O(n)` per site.
    pub fn velocities_with(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: Option<&DVector<f64>>,
        ws: &mut Workspace,
    ) {
        if ws.ev.motion {
            self.velocities_from_motion(ws);
            return;
        }
        let nonlinear = !self.param.is_linear();
        if nonlinear {
            self.param.eval_rate(q, qd, &mut ws.ev);
        }
        ws.eta[0] = V6::zeros();
        ws.zeta[0] = V6::zeros();
        for i in 0..self.disc.n_points() - 1 {
            let Some(st) = self.disc.steps[i] else {
                ws.eta[i + 1] = ws.eta[i];
                ws.zeta[i + 1] = ws.zeta[i];
                continue;
            };
            let [s1, s2] = st.sites;
            let c = self.param.columns(s1);
            let qdc = qd.rows(c.start, c.len());
            let h = st.h;
            let xid1: V6 = ws.ev.psi_q_at(s1, &c) * qdc;
            let mut zd = V6::zeros(); // Ż q̇ (+ Z q̈)
            let om_dot: V6 = match self.disc.order {
                MagnusOrder::Z4 => {
                    let xid2: V6 = ws.ev.psi_q_at(s2, &c) * qdc;
                    let k = ZANNA_C * h * h;
                    zd += (ad_mul(&xid1, &xid2) - ad_mul(&xid2, &xid1)) * k;
                    if nonlinear {
                        let a1: V6 = ws.ev.psi_q_dot_at(s1, &c) * qdc;
                        let a2: V6 = ws.ev.psi_q_dot_at(s2, &c) * qdc;
                        zd += (a1 + a2) * (0.5 * h)
                            + (ad_mul(&ws.xi[s1], &a2) - ad_mul(&ws.xi[s2], &a1)) * k;
                    }
                    if let Some(qdd) = qdd {
                        let qddc = qdd.rows(c.start, c.len());
                        let b1: V6 = ws.ev.psi_q_at(s1, &c) * qddc;
                        let b2: V6 = ws.ev.psi_q_at(s2, &c) * qddc;
                        zd += (b1 + b2) * (0.5 * h)
                            + (ad_mul(&ws.xi[s1], &b2) - ad_mul(&ws.xi[s2], &b1)) * k;
                    }
                    (xid1 + xid2) * (0.5 * h)
                        + (ad_mul(&ws.xi[s1], &xid2) - ad_mul(&ws.xi[s2], &xid1)) * k
                }
                MagnusOrder::Z2 => {
                    if nonlinear {
                        let a1: V6 = ws.ev.psi_q_dot_at(s1, &c) * qdc;
                        zd += a1 * h;
                    }
                    if let Some(qdd) = qdd {
                        let b1: V6 = ws.ev.psi_q_at(s1, &c) * qdd.rows(c.start, c.len());
                        zd += b1 * h;
                    }
                    xid1 * h
                }
            };
            Self::propagate_velocity(i, &om_dot, &zd, ws);
        }
    }

    /// One step of the velocity recursion (module doc): `η_{i+1}` and `ζ_{i+1}` from `η_i`, `ζ_i`,
    /// the step's `Ω̇` and `Ż q̇ (+ Z q̈)`.
    fn propagate_velocity(i: usize, om_dot: &V6, zd: &V6, ws: &mut Workspace) {
        let et = &ws.et[i];
        let sqd = et.t_mul(om_dot);
        let sdqd = et.t_dot_mul(om_dot, om_dot) + et.t_mul(zd);
        ws.eta[i + 1] = et.g.adjoint_inv_mul(&(ws.eta[i] + sqd));
        ws.zeta[i + 1] =
            et.g.adjoint_inv_mul(&(ws.zeta[i] + ad_mul(&ws.eta[i], &sqd) + sdqd));
    }

    /// [`Self::velocities_with`] from a motion evaluation ([`StrainParam::eval_motion`] at the same
    /// `q, q̇, q̈`): the site rates `ξ̇_s` and `ξ̈ᵇ_s = Ψ̇_q,s q̇ + Ψ_q,s q̈` are given, so each step is
    /// the Magnus rate of the module doc on 6-vectors (`ξ̈ᵇ` enters `Ż q̇ + Z q̈` as the sum of the
    /// two); a call without `q̈` must follow a motion evaluation without `q̈`.
    fn velocities_from_motion(&self, ws: &mut Workspace) {
        ws.eta[0] = V6::zeros();
        ws.zeta[0] = V6::zeros();
        for i in 0..self.disc.n_points() - 1 {
            let Some(st) = self.disc.steps[i] else {
                ws.eta[i + 1] = ws.eta[i];
                ws.zeta[i + 1] = ws.zeta[i];
                continue;
            };
            let [s1, s2] = st.sites;
            let h = st.h;
            let (xid1, a1) = (ws.ev.xi_dot[s1], ws.ev.xi_acc[s1]);
            let (om_dot, zd): (V6, V6) = match self.disc.order {
                MagnusOrder::Z4 => {
                    let (xid2, a2) = (ws.ev.xi_dot[s2], ws.ev.xi_acc[s2]);
                    let k = ZANNA_C * h * h;
                    let (xi1, xi2) = (&ws.xi[s1], &ws.xi[s2]);
                    let zd = (ad_mul(&xid1, &xid2) - ad_mul(&xid2, &xid1)) * k
                        + (a1 + a2) * (0.5 * h)
                        + (ad_mul(xi1, &a2) - ad_mul(xi2, &a1)) * k;
                    let om_dot =
                        (xid1 + xid2) * (0.5 * h) + (ad_mul(xi1, &xid2) - ad_mul(xi2, &xid1)) * k;
                    (om_dot, zd)
                }
                MagnusOrder::Z2 => (xid1 * h, a1 * h),
            };
            Self::propagate_velocity(i, &om_dot, &zd, ws);
        }
    }

    /// `J̇_i q̇` (= `J̇ˢ_i q̇`) at point `i` after [`Self::velocities`]: the body acceleration at `q̈ = 0`.
    pub fn point_acceleration_bias(&self, ws: &Workspace, i: usize) -> V6 {
        ws.zeta[i]
    }

    /// `M = Σ_i W_i J_iᵀ Ms_i J_i` into `ws.mass` (after a forward pass with Jacobians; `ws.mass`
    /// is allocated on first use), as `M = Σ_chunks Bᵀ B` with the rows `√(W_i Ms_i,a) J_i[a, :]`
    /// of [`MASS_CHUNK`] points stacked in `B` (one blocked product per chunk instead of a rank-6
    /// update per point). `J_i` is zero beyond its column bound `h_i`, so a chunk adds to the
    /// leading `h × h` block only, `h` its largest bound. `Ms` is diagonal and non-negative. The
    /// bodies add `J_bᵀ Mb J_b` ([`crate::bodies`]).
    pub fn assemble_mass(&self, ws: &mut Workspace) {
        let n = self.n_dof();
        if ws.mass.shape() != (n, n) {
            ws.mass = DMatrix::zeros(n, n);
        } else {
            ws.mass.fill(0.0);
        }
        let rows = 6 * MASS_CHUNK;
        if ws.mass_b.len() != rows * n {
            ws.mass_b = vec![0.0; rows * n];
        }
        let np = self.disc.n_points();
        let mut start = 0;
        while start < np {
            let end = (start + MASS_CHUNK).min(np);
            let h = (start..end).map(|i| ws.jac_bound(i)).max().unwrap_or(0);
            if h > 0 {
                // B (rows × h, column-major, leading dimension `rows`)
                let bounds = &ws.jac_hi[start..end];
                let b = &mut ws.mass_b[..rows * h];
                b.fill(0.0);
                for (k, i) in (start..end).enumerate() {
                    let p = &self.disc.points[i];
                    let hi = bounds[k];
                    if p.weight == 0.0 || hi == 0 {
                        continue;
                    }
                    let ms = self.props[i].ms;
                    let sq: [f64; 6] = std::array::from_fn(|a| (ms[a] * p.weight).sqrt());
                    let j = ws.jac.columns(i * n, hi);
                    for c in 0..hi {
                        let col = &mut b[c * rows + 6 * k..c * rows + 6 * k + 6];
                        for a in 0..6 {
                            col[a] = sq[a] * j[(a, c)];
                        }
                    }
                }
                let bm = MatRef::from_column_major_slice(&ws.mass_b[..rows * h], rows, h);
                let dst = MatMut::from_column_major_slice_with_stride_mut(
                    ws.mass.as_mut_slice(),
                    h,
                    h,
                    n,
                );
                matmul(dst, Accum::Add, bm.transpose(), bm, 1.0, Par::Seq);
            }
            start = end;
        }
        // each body's `J_bᵀ Mb J_b` as `Bᵀ B` with the rows `r_kᵀ J_b` (`Mb = Σ r_k r_kᵀ`)
        for b in &self.bodies {
            let h = ws.jac_bound(b.point);
            if h == 0 || b.rank == 0 {
                continue;
            }
            let rows = b.rank;
            let bm = &mut ws.mass_b[..rows * h];
            let j = ws.jac.columns(b.point * n, h);
            for c in 0..h {
                for (k, r) in b.rows[..rows].iter().enumerate() {
                    bm[c * rows + k] = r.dot(&j.column(c));
                }
            }
            let bm = MatRef::from_column_major_slice(&ws.mass_b[..rows * h], rows, h);
            let dst =
                MatMut::from_column_major_slice_with_stride_mut(ws.mass.as_mut_slice(), h, h, n);
            matmul(dst, Accum::Add, bm.transpose(), bm, 1.0, Par::Seq);
        }
        crate::cpu::clear_upper_state();
    }

    /// The smallest ratio `Ds/Es` over the sections and the strain components with `Es > 0` \[s\]
    /// (Kelvin–Voigt: `3η/E` for an incompressible material; 0 without damping).
    pub fn damping_time(&self) -> f64 {
        self.props
            .iter()
            .flat_map(|p| {
                (0..6)
                    .filter(|&a| p.es[a] > 0.0)
                    .map(move |a| p.ds[a] / p.es[a])
            })
            .fold(f64::INFINITY, f64::min)
            .clamp(0.0, f64::MAX)
    }

    /// The mass matrix `M(q)`.
    pub fn mass_matrix(&self, q: &DVector<f64>, ws: &mut Workspace) -> DMatrix<f64> {
        self.forward(q, ws, true);
        self.assemble_mass(ws);
        ws.mass.clone()
    }

    /// Generalized forces of the dynamics, `τ = −K₁ − D₁ + F + Bu − C q̇` (so that `M q̈ = τ`), into
    /// `r`; leaves `M` in `ws.mass`.
    pub fn dynamic_forces(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        r: &mut DVector<f64>,
    ) {
        self.forward(q, ws, true);
        self.velocities(q, qd, ws);
        self.assemble_mass(ws);
        self.point_wrenches(loads, ws);
        self.subtract_inertial_wrenches(ws);
        self.assemble_forces(u, Some(qd), ws, r);
    }

    /// Residual of the equations of motion `ε = M(q) q̈ − τ(q, q̇)` (paper eq. 8), for implicit
    /// integrators in second-order form, without forming `M`: the inertial wrenches
    /// `W (Ms η̇_i + coad_{η_i} Ms η_i)` with the body accelerations `η̇_i = J_i q̈ + J̇ˢ_i q̇` of
    /// [`Self::velocities_with`] join the external ones in the statics backward pass
    /// (recursive Newton–Euler, spec §7.8). Cost: one statics residual plus `O(n)` per site. A
    /// parameterization with a motion evaluation ([`StrainParam::eval_motion`]: a decoder) gives
    /// the strains and their rates without `Ψ_q`, and projects the wrenches in one reverse pass.
    #[allow(clippy::too_many_arguments)]
    pub fn dynamics_residual(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        r: &mut DVector<f64>,
    ) {
        if self.param.eval_motion(q, qd, Some(qdd), &mut ws.ev) {
            ws.ev.motion = true;
            ws.ev.psi_q_stale = true;
            self.forward_from_strains(ws, false);
        } else {
            self.forward(q, ws, false);
        }
        self.residual_after_forward(q, qd, qdd, u, loads, ws, r);
    }

    /// [`Self::dynamics_residual`] and the mass matrix `M(q)` (into `ws.mass`) from one forward
    /// pass (with Jacobians, which the residual does not need but `M` does): for an integrator
    /// that renews `M` where it evaluates its first residual of a step.
    #[allow(clippy::too_many_arguments)]
    pub fn dynamics_residual_and_mass(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        r: &mut DVector<f64>,
    ) {
        self.forward(q, ws, true);
        self.assemble_mass(ws);
        // the rates by the motion evaluation where it is cheaper than `Ψ̇_q` (Ψ_q stays valid)
        ws.ev.motion = self.param.eval_motion(q, qd, Some(qdd), &mut ws.ev);
        self.residual_after_forward(q, qd, qdd, u, loads, ws, r);
    }

    /// The part of [`Self::dynamics_residual`] after the forward pass at `q`.
    #[allow(clippy::too_many_arguments)]
    fn residual_after_forward(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        r: &mut DVector<f64>,
    ) {
        self.velocities_with(q, qd, Some(qdd), ws);
        self.point_wrenches(loads, ws);
        self.subtract_inertial_wrenches(ws);
        self.assemble_forces(u, Some(qd), ws, r);
        r.neg_mut();
    }

    /// Iteration matrix of an implicit integrator in second-order form,
    /// `S = M + c_v D + c_q K_T ≈ ∂ε/∂q̈ + c_v ∂ε/∂q̇ + c_q ∂ε/∂q` for `ε` of
    /// [`Self::dynamics_residual`] when `q̇` and `q` move with `q̈` at the rates `c_v`, `c_q`
    /// (Newmark: `γ h`, `β h²`), with the tangent stiffness `K_T = −∂R/∂q` of the statics
    /// Jacobian (elastic, tendons, loads) and the damping matrix `D`; the gyroscopic and `∂M/∂q q̈`
    /// terms are dropped (they vanish at rest). Exact at an equilibrium at rest.
    #[allow(clippy::too_many_arguments)]
    pub fn iteration_parts(
        &self,
        q: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        mass: &mut DMatrix<f64>,
        damping: &mut DMatrix<f64>,
        stiffness: &mut DMatrix<f64>,
    ) {
        self.statics_jacobian(q, u, loads, ws, stiffness);
        stiffness.neg_mut();
        self.assemble_mass(ws); // J from the statics Jacobian's forward pass
        mass.copy_from(&ws.mass);
        self.damping_matrix_into(ws, damping);
    }

    /// `w_i −= W_i (Ms ζ_i + coad_{η_i} Ms η_i)`: the inertial wrenches (with `ζ_i` the body
    /// acceleration at `q̈ = 0`, or the full `η̇_i` after [`Self::velocities_with`] with `q̈`), and
    /// the bodies' `Mb ζ_b + coad_{η_b} Mb η_b` at their points.
    fn subtract_inertial_wrenches(&self, ws: &mut Workspace) {
        for (i, p) in self.disc.points.iter().enumerate() {
            if p.weight == 0.0 {
                continue;
            }
            let ms = self.props[i].ms;
            let inertial =
                ms.component_mul(&ws.zeta[i]) + coad_mul(&ws.eta[i], &ms.component_mul(&ws.eta[i]));
            ws.w[i] -= inertial * p.weight;
        }
        for b in &self.bodies {
            let (eta, zeta) = (ws.eta[b.point], ws.zeta[b.point]);
            ws.w[b.point] -= b.mb * zeta + coad_mul(&eta, &(b.mb * eta));
        }
    }

    /// Accelerations `q̈ = M⁻¹ τ` (spec §9.1) by an in-place Cholesky factorization of `M`.
    pub fn accelerations(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        qdd: &mut DVector<f64>,
    ) -> Result<(), DynamicsError> {
        self.dynamic_forces(q, qd, u, loads, ws, qdd);
        cholesky_solve_in_place(&mut ws.mass, qdd)?;
        if qdd.iter().any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite {
                what: "accelerations",
            });
        }
        Ok(())
    }

    /// Inverse dynamics `ID(q, q̇, q̈) = Σ_i J_iᵀ w_i` with `w_i = W_i (Ms η̇_i + coad_{η_i} Ms η_i) − w_i^ext`,
    /// `η̇_i = J_i q̈ + J̇_i q̇` (spec §7.8), and each body's `Mb η̇_b + coad_{η_b} Mb η_b` at its
    /// point ([`crate::bodies`]); satisfies `ID = M q̈ + C q̇ − F`.
    pub fn inverse_dynamics(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        loads: &PreparedLoads,
        ws: &mut Workspace,
    ) -> DVector<f64> {
        let n = self.n_dof();
        self.forward(q, ws, true);
        self.velocities(q, qd, ws);
        self.point_wrenches(loads, ws);
        let mut id = DVector::zeros(n);
        for (i, p) in self.disc.points.iter().enumerate() {
            let j = ws.jac.columns(i * n, n);
            let mut w = -ws.w[i];
            if p.weight > 0.0 {
                let ms = self.props[i].ms;
                let eta_dot: V6 = j * qdd + ws.zeta[i];
                w += (ms.component_mul(&eta_dot)
                    + coad_mul(&ws.eta[i], &ms.component_mul(&ws.eta[i])))
                    * p.weight;
            }
            for b in self.bodies.iter().filter(|b| b.point == i) {
                let eta_dot: V6 = j * qdd + ws.zeta[i];
                w += b.mb * eta_dot + coad_mul(&ws.eta[i], &(b.mb * ws.eta[i]));
            }
            id.gemv_tr(1.0, &j, &w, 1.0);
        }
        id
    }

    /// Damping matrix `D = Σ W Ψ_qᵀ Ds Ψ_q` (spec §7.4; constant for linear bases) after a forward pass.
    pub fn damping_matrix(&self, ws: &Workspace) -> DMatrix<f64> {
        let n = self.n_dof();
        let mut d = DMatrix::zeros(n, n);
        self.damping_matrix_into(ws, &mut d);
        d
    }

    /// [`Self::damping_matrix`] into `d` (`n × n`), without allocating: `Σ_i W_i Ψ_qᵀ Ds_i Ψ_q`
    /// on each point's columns.
    pub fn damping_matrix_into(&self, ws: &Workspace, d: &mut DMatrix<f64>) {
        d.fill(0.0);
        for (i, p) in self.disc.points.iter().enumerate() {
            if p.weight == 0.0 {
                continue;
            }
            let c = self.param.columns(i);
            let psq = ws.ev.psi_q_at(i, &c);
            let wds: V6 = self.props[i].ds * p.weight;
            for b in 0..c.len() {
                let x: V6 = wds.component_mul(&psq.column(b));
                for a in 0..c.len() {
                    d[(c.start + a, c.start + b)] += psq.column(a).dot(&x);
                }
            }
        }
    }

    /// Structured approximation of the ODE Jacobian of `y' = [q̇; M⁻¹τ]` (spec §9.3):
    /// `∂f/∂y ≈ [0 I; M⁻¹ ∂R/∂q  −M⁻¹ D]`, with the exact statics Jacobian `∂R/∂q` (elastic, gravity,
    /// loads, tendons) and the damping matrix `D`; the velocity-dependent inertial terms (`∂(Cq̇)/∂y`,
    /// `∂M/∂q q̈`) are dropped. Good enough for the simplified Newton iteration of an implicit
    /// integrator and far cheaper than finite differences (one Jacobian pass instead of 2n residuals).
    pub fn ode_jacobian_approx(
        &self,
        q: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        out: &mut DMatrix<f64>,
    ) -> Result<(), DynamicsError> {
        let n = self.n_dof();
        let mut kt = DMatrix::zeros(n, n);
        self.statics_jacobian(q, u, loads, ws, &mut kt);
        self.assemble_mass(ws);
        let d = self.damping_matrix(ws);
        cholesky_factor_in_place(&mut ws.mass)?;
        out.fill(0.0);
        for j in 0..n {
            out[(j, n + j)] = 1.0;
        }
        let mut col = DVector::zeros(n);
        for j in 0..n {
            col.copy_from(&kt.column(j));
            cholesky_solve_factored(&ws.mass, &mut col);
            out.view_mut((n, j), (n, 1)).copy_from(&col);
            col.copy_from(&d.column(j));
            cholesky_solve_factored(&ws.mass, &mut col);
            out.view_mut((n, n + j), (n, 1)).copy_from(&(-&col));
        }
        Ok(())
    }
}
