//! The generalized forces of the equations of motion one by one (paper eq. 8, gvs-spec §7):
//!
//! `M(q) q̈ + C(q, q̇) q̇ + D₁(q, q̇) + K₁(q) = B(q) u + F(q)`,
//!
//! each from the pass that assembles it in the statics residual `R = −K₁ + F + Bu` and the dynamics
//! forces `τ = R − D₁ − C q̇`, for analysis and control (the solvers assemble them together):
//! * elastic `K₁(q) = Σ W Ψ_qᵀ Es Ψ` (`= K q` for a linear basis) and its Jacobian `∂K₁/∂q`;
//! * damping `D₁ = D(q) q̇`, `D = Σ W Ψ_qᵀ Ds Ψ_q` (spec §7.4);
//! * external `F(q) = Σ_i J_iᵀ w_i` (gravity, point and distributed wrenches) by the backward pass;
//! * actuation `B(q)`: column k the generalized force of a unit tension in tendon k (friction
//!   included: `α(q)` does not depend on u, so the tendon force is `B(q) u`);
//! * Coriolis and centrifugal `C(q, q̇) q̇ = Σ W J_iᵀ (Ms ζ_i + coad_{η_i} Ms η_i)` (spec §7.2, §7.8).

use super::*;

impl<P: StrainParam> Model<P> {
    /// Loads that are all zero (no gravity, no wrenches).
    pub(crate) fn no_loads(&self) -> PreparedLoads {
        let np = self.disc.n_points();
        PreparedLoads {
            gravity: V3::zeros(),
            local: vec![V6::zeros(); np],
            global: vec![V6::zeros(); np],
        }
    }

    /// The elastic force `K₁(q) = Σ_i W_i Ψ_q,iᵀ Es_i Ψ_i` (spec §7.3), as it enters `R = −K₁ + …`:
    /// the residual's assembly with no loads and no tension.
    pub fn elastic_force(&self, q: &DVector<f64>, ws: &mut Workspace) -> DVector<f64> {
        let mut r = DVector::zeros(self.n_dof());
        let u = vec![0.0; self.n_actuators()];
        self.statics_residual(q, &u, &self.no_loads(), ws, &mut r);
        r.neg_mut();
        r
    }

    /// The tangent elastic stiffness `∂K₁/∂q` (the constant `K` of a linear basis), by the
    /// residual's analytic Jacobian with no loads and no tension.
    pub fn elastic_stiffness(&self, q: &DVector<f64>, ws: &mut Workspace) -> DMatrix<f64> {
        let n = self.n_dof();
        let mut k = DMatrix::zeros(n, n);
        let u = vec![0.0; self.n_actuators()];
        self.statics_jacobian(q, &u, &self.no_loads(), ws, &mut k);
        k.neg_mut();
        k
    }

    /// The damping force `D₁ = D(q) q̇` with `D = Σ W Ψ_qᵀ Ds Ψ_q` (spec §7.4; constant for a linear
    /// basis).
    pub fn damping_force(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        ws: &mut Workspace,
    ) -> DVector<f64> {
        self.forward(q, ws, false);
        self.damping_matrix(ws) * qd
    }

    /// The external generalized force `F(q) = Σ_i J_iᵀ w_i` of gravity and the loads (spec §7.5,
    /// §8.2): the residual's point wrenches and backward pass without the elastic and tendon terms.
    pub fn external_force(
        &self,
        q: &DVector<f64>,
        loads: &PreparedLoads,
        ws: &mut Workspace,
    ) -> DVector<f64> {
        self.forward(q, ws, false);
        self.point_wrenches(loads, ws);
        ws.y.iter_mut().for_each(|y| *y = V6::zeros());
        self.backward(ws, None);
        let mut r = DVector::zeros(self.n_dof());
        self.project(ws, &mut r);
        r
    }

    /// The actuation matrix `B(q)` (n × n_actuators): column k is the generalized force of the
    /// tendon forces at `u = e_k` (paper eq. 11, spec §7.6–7.7), so that the actuation force is
    /// `B(q) u`.
    pub fn actuation_matrix(&self, q: &DVector<f64>, ws: &mut Workspace) -> DMatrix<f64> {
        let (n, na) = (self.n_dof(), self.n_actuators());
        self.forward(q, ws, false);
        let mut b = DMatrix::zeros(n, na);
        let mut u = vec![0.0; na];
        let mut col = DVector::zeros(n);
        self.actuation_matrix_after_forward(ws, &mut b, &mut u, &mut col);
        b
    }

    /// [`Self::actuation_matrix`] into `b` (n × n_actuators) after a forward pass at `q`, with
    /// `u` (n_actuators) and `col` (n) as scratch: allocates nothing.
    pub fn actuation_matrix_after_forward(
        &self,
        ws: &mut Workspace,
        b: &mut DMatrix<f64>,
        u: &mut [f64],
        col: &mut DVector<f64>,
    ) {
        for k in 0..self.n_actuators() {
            u.fill(0.0);
            u[k] = 1.0;
            ws.y.iter_mut().for_each(|y| *y = V6::zeros());
            self.tendon_forces(u, ws, false);
            col.fill(0.0);
            self.project(ws, col);
            b.set_column(k, col);
        }
    }

    /// The Coriolis and centrifugal force `C(q, q̇) q̇ = Σ_i W_i J_iᵀ (Ms_i ζ_i + coad_{η_i} Ms_i η_i)`
    /// with `ζ_i = J̇_i q̇` (spec §7.2): the inverse dynamics at `q̈ = 0` without loads.
    pub fn coriolis_force(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        ws: &mut Workspace,
    ) -> DVector<f64> {
        let qdd = DVector::zeros(self.n_dof());
        self.inverse_dynamics(q, qd, &qdd, &self.no_loads(), ws)
    }
}
