//! State-space linearization of the equations of motion (gvs-spec §9.3): for `x = [q; q̇]` and
//! `ẋ = f(x, u) = [q̇; M(q)⁻¹ τ(q, q̇, u)]`,
//!
//! ```text
//!   δẋ = A δx + B δu,   A = ∂f/∂x = [ 0            I          ],   B = ∂f/∂u = [ 0       ]
//!                                   [ −M⁻¹ ∂ε/∂q   −M⁻¹ ∂ε/∂q̇ ]               [ M⁻¹ B(q) ]
//! ```
//!
//! with `ε(q, q̇, q̈, u) = M q̈ + C q̇ + D₁ + K₁ − F − B u` the residual of eq. (8)
//! ([`Model::dynamics_residual`]) differentiated at the current acceleration `q̈` held fixed
//! (implicit differentiation of `ε = 0`). Its parts:
//!
//! * `∂ε/∂q = −∂R/∂q + ∂(M q̈ + C q̇ + D₁)/∂q`: the static part `−∂R/∂q` (elastic, gravity, loads,
//!   tendons with friction) is the analytic statics Jacobian (§8.2); the inertial and damping part
//!   `I(q) = ε(q, q̇, q̈, 0) − ε(q, 0, 0, 0)` (no loads; the elastic force cancels exactly) by central
//!   differences in `q`. It vanishes at rest (`q̇ = 0`, `q̈ = 0`), where `A` is analytic throughout.
//! * `∂ε/∂q̇ = ∂(C q̇)/∂q̇ + D(q)`: `ε` is quadratic in `q̇` (`C q̇` quadratic, `D₁ = D q̇` linear), so
//!   its central difference is exact for any step, up to rounding.
//! * `∂ε/∂u = −B(q)`, the actuation matrix (tendon forces are linear in the tensions).
//!
//! A tendon driven by its displacement through an elastic thread
//! ([`crate::solve::dynamics::drive`]: `u_k = −(ℓ_k(q) − ℓ_k,rest + δ_k) / c_k` while taut) enters
//! with its displacement `δ_k` as the input ([`Model::linearize_equilibrium_driven`]): `∂ε/∂q`
//! gains `B_k ∇ℓ_kᵀ / c_k` (the thread's stiffness) and `B`'s column is `−M⁻¹ B_k / c_k` (a
//! metre wound in pulls `1/c_k` newtons more); a slack one's column is zero, as is its stiffness
//! (to first order its motor moves nothing).
//!
//! The analytic forward recursions of `∂η/∂q`, `∂η̇/∂q` (§9.3) would replace the `2n` residual pairs
//! of the inertial part; away from rest its difference has a relative truncation error of order
//! `h² ≈ 4e-11` (tested against differences of the accelerations).

use super::{cholesky_factor_in_place, cholesky_solve_factored, DynamicsError};
use crate::model::{Model, PreparedLoads, Workspace};
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};

/// Relative step of the central differences of the inertial part in `q`: `h_j = H (1 + |q_j|)`,
/// near `ε_mach^{1/3}`, which balances truncation (`h²`) and rounding (`ε_mach / h`).
pub const LINEARIZATION_STEP: f64 = 6e-6;

/// How an actuator's channel enters a linearization about a driven equilibrium
/// ([`Model::linearize_equilibrium_driven`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channel {
    /// Its tension \[N\].
    Tension,
    /// Its motor's displacement \[m\], through the elastic thread; `taut` unless the tendon is
    /// slack at the operating point (then its column and stiffness are zero).
    Displacement { taut: bool },
}

/// `ẋ = f(x, u)` linearized at a state: `δẋ = A δx + B δu` with `x = [q; q̇]`.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    /// `A = ∂f/∂x`, `2n × 2n`.
    pub a: DMatrix<f64>,
    /// `B = ∂f/∂u`, `2n × n_actuators`.
    pub b: DMatrix<f64>,
    /// `f(x, u) = [q̇; q̈]` at the state (zero at an equilibrium at rest).
    pub xdot: DVector<f64>,
}

impl<P: StrainParam> Model<P> {
    /// `∂ε/∂q` and `∂ε/∂q̇` of the residual `ε(q, q̇, q̈, u)` of eq. (8) ([`Self::dynamics_residual`])
    /// at `q̈` held fixed, into `de_dq` and `de_dqd` (`n × n`): the analytic static part, the
    /// inertial and damping part by central differences in `q` (none at rest), the exact central
    /// difference in `q̇` (module documentation). With them the iteration matrix of the NDF in
    /// second-order form would hold every term, `M + c_v ∂ε/∂q̇ + c_q ∂ε/∂q`; measured on the
    /// six-tendon babbling (10 s, seed 1, 2026-12-06) it did not pay: 2691 steps with 383 Newton
    /// failures and 110 Jacobians in 0.43 s, against 2924, 308 and 12 in 0.21 s with
    /// [`Self::iteration_parts`].
    #[allow(clippy::too_many_arguments)]
    pub fn residual_jacobians(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        de_dq: &mut DMatrix<f64>,
        de_dqd: &mut DMatrix<f64>,
    ) {
        let n = self.n_dof();
        let na = self.n_actuators();
        // ∂ε/∂q: the static part, analytic ...
        self.statics_jacobian(q, u, loads, ws, de_dq);
        de_dq.neg_mut();
        // ... and the inertial and damping part I(q), by central differences
        let none = self.no_loads();
        let zero_u = vec![0.0; na];
        let zero = DVector::zeros(n);
        let mut r1 = DVector::zeros(n);
        let mut r0 = DVector::zeros(n);
        let mut inertial = |q: &DVector<f64>, ws: &mut Workspace, out: &mut DVector<f64>| {
            self.dynamics_residual(q, qd, qdd, &zero_u, &none, ws, &mut r1);
            self.dynamics_residual(q, &zero, &zero, &zero_u, &none, ws, &mut r0);
            out.copy_from(&r1);
            *out -= &r0;
        };
        let at_rest = qd.iter().all(|v| *v == 0.0) && qdd.iter().all(|v| *v == 0.0);
        let (mut plus, mut minus) = (DVector::zeros(n), DVector::zeros(n));
        if !at_rest {
            let mut qs = q.clone();
            for j in 0..n {
                let h = LINEARIZATION_STEP * (1.0 + q[j].abs());
                qs[j] = q[j] + h;
                inertial(&qs, ws, &mut plus);
                qs[j] = q[j] - h;
                inertial(&qs, ws, &mut minus);
                qs[j] = q[j];
                plus -= &minus;
                de_dq.column_mut(j).axpy(0.5 / h, &plus, 1.0);
            }
        }
        // ∂ε/∂q̇ = ∂(C q̇)/∂q̇ + D(q): at q̇ = 0 the quadratic's derivative vanishes and it is the
        // damping matrix, from Ψ_q at q (a forward pass's parameterization evaluation) ...
        if qd.iter().all(|v| *v == 0.0) {
            self.param.eval(q, &mut ws.ev);
            ws.ev.motion = false;
            ws.ev.psi_q_stale = false;
            self.damping_matrix_into(ws, de_dqd);
            return;
        }
        // ... else exact central differences of a quadratic in q̇ (step 1 + |q̇_j|)
        let mut qds = qd.clone();
        for j in 0..n {
            let s = 1.0 + qd[j].abs();
            qds[j] = qd[j] + s;
            self.dynamics_residual(q, &qds, qdd, &zero_u, &none, ws, &mut plus);
            qds[j] = qd[j] - s;
            self.dynamics_residual(q, &qds, qdd, &zero_u, &none, ws, &mut minus);
            qds[j] = qd[j];
            plus -= &minus;
            de_dqd.column_mut(j).axpy(0.5 / s, &plus, 0.0);
        }
    }

    /// The state-space linearization of the equations of motion at `(q, q̇, u)` under `loads`
    /// (module documentation). Cost: one statics Jacobian, one mass matrix, `n` actuation columns
    /// and `6n` dynamics residuals (`2n` when `q̇ = 0`).
    pub fn linearize(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
    ) -> Result<StateSpace, DynamicsError> {
        self.linearize_holding(q, qd, u, loads, ws, false, &[])
    }

    /// [`Self::linearize`] about a static equilibrium `q` at rest, with `q̈ = 0` held in the
    /// derivatives: a solved equilibrium's residual `R` leaves `q̈ = M⁻¹R` small but not zero, and
    /// the linearization about the equilibrium is the one at the exact `q̈ = 0`, where every term is
    /// analytic (the inertial part vanishes; no differences in `q`). `ẋ` is still `f(x, u)`, so
    /// the residual stays visible. Cost: one statics Jacobian, one mass matrix and `B`.
    pub fn linearize_equilibrium(
        &self,
        q: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
    ) -> Result<StateSpace, DynamicsError> {
        let rest = DVector::zeros(self.n_dof());
        self.linearize_holding(q, &rest, u, loads, ws, true, &[])
    }

    /// [`Self::linearize_equilibrium`] with some tendons driven by their displacement through
    /// their elastic threads (module documentation): `channels[k]` says how actuator `k` enters,
    /// `u` holds every tension at the equilibrium (those the displacements need included). The
    /// input of a displacement channel is `δ_k` \[m\]. A displacement channel of a tendon
    /// without an axial stiffness is [`DynamicsError::InextensibleDrive`].
    pub fn linearize_equilibrium_driven(
        &self,
        q: &DVector<f64>,
        u: &[f64],
        channels: &[Channel],
        loads: &PreparedLoads,
        ws: &mut Workspace,
    ) -> Result<StateSpace, DynamicsError> {
        let rest = DVector::zeros(self.n_dof());
        self.linearize_holding(q, &rest, u, loads, ws, true, channels)
    }

    #[allow(clippy::too_many_arguments)]
    fn linearize_holding(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        still: bool,
        channels: &[Channel],
    ) -> Result<StateSpace, DynamicsError> {
        let n = self.n_dof();
        let na = self.n_actuators();
        let mut qdd = DVector::zeros(n);
        self.accelerations(q, qd, u, loads, ws, &mut qdd)?;
        let held = if still {
            DVector::zeros(n)
        } else {
            qdd.clone()
        };
        let mut de_dq = DMatrix::zeros(n, n);
        let mut de_dqd = DMatrix::zeros(n, n);
        self.residual_jacobians(q, qd, &held, u, loads, ws, &mut de_dq, &mut de_dqd);

        let mut actuation = self.actuation_matrix(q, ws);
        // displacement channels: the threads' stiffness in ∂ε/∂q, and B's column per metre
        if !channels.is_empty() && channels.len() != na {
            return Err(DynamicsError::ChannelCount {
                expected: na,
                got: channels.len(),
            });
        }
        if channels.iter().any(|c| *c != Channel::Tension) {
            let compliance = self.tendon_compliances();
            let grad = self.tendon_length_jacobian(q, ws);
            for (k, channel) in channels.iter().enumerate() {
                let Channel::Displacement { taut } = *channel else {
                    continue;
                };
                if compliance[k] <= 0.0 {
                    return Err(DynamicsError::InextensibleDrive { tendon: k });
                }
                if taut {
                    de_dq.ger(
                        1.0 / compliance[k],
                        &actuation.column(k),
                        &grad.column(k),
                        1.0,
                    );
                    actuation.column_mut(k).scale_mut(-1.0 / compliance[k]);
                } else {
                    actuation.column_mut(k).fill(0.0);
                }
            }
        }
        let mut mass = self.mass_matrix(q, ws);
        cholesky_factor_in_place(&mut mass)?;

        let mut a = DMatrix::zeros(2 * n, 2 * n);
        let mut b = DMatrix::zeros(2 * n, na);
        for j in 0..n {
            a[(j, n + j)] = 1.0;
        }
        let mut col = DVector::zeros(n);
        for j in 0..n {
            col.copy_from(&de_dq.column(j));
            cholesky_solve_factored(&mass, &mut col);
            a.view_mut((n, j), (n, 1)).copy_from(&(-&col));
            col.copy_from(&de_dqd.column(j));
            cholesky_solve_factored(&mass, &mut col);
            a.view_mut((n, n + j), (n, 1)).copy_from(&(-&col));
        }
        for k in 0..na {
            col.copy_from(&actuation.column(k));
            cholesky_solve_factored(&mass, &mut col);
            b.view_mut((n, k), (n, 1)).copy_from(&col);
        }
        if a.iter().chain(b.iter()).any(|v| !v.is_finite()) {
            return Err(DynamicsError::NonFinite {
                what: "state-space linearization",
            });
        }
        let mut xdot = DVector::zeros(2 * n);
        xdot.rows_mut(0, n).copy_from(qd);
        xdot.rows_mut(n, n).copy_from(&qdd);
        Ok(StateSpace { a, b, xdot })
    }
}
