//! Tendons driven by their displacement in dynamics: elastic threads whose motors set their
//! unstretched lengths, the tension following from the stretch.
//!
//! **The law.** Channel `k` of the actuation of a displacement-driven tendon
//! ([`Actuation::displacement_driven`]) is the length `δ_k(t)` \[m\] its motor has wound in from the
//! rest length (negative pays out). The thread is a spring of compliance `c_k = ℓ_k,rest / EA_k`
//! ([`Model::tendon_compliances`]) that pulls while its path is longer than the thread and goes
//! slack otherwise:
//!
//! `u_k(q, t) = min(0, −(ℓ_k(q) − ℓ*_k(t)) / c_k)`,  `ℓ*_k = ℓ_k,rest − δ_k(t)`,
//!
//! `ℓ_k(q)` the path length of [`Model::tendon_lengths`]. At rest this is the complementarity that
//! [`crate::solve::tendon_drive`] solves with the same compliance (`g_k = ℓ_k − ℓ*_k + c_k u_k`):
//! a run settles onto that equilibrium. The thread is massless and undamped; the rod's damping
//! dissipates what it stores.
//!
//! **The iteration matrix.** `τ` holds `B(q) u`, so with `∂u_D/∂q = −C⁻¹ ∇ℓ_Dᵀ` over the taut
//! tendons the stiffness `K_T = −∂R/∂q` gains `B_D C⁻¹ ∇ℓ_Dᵀ` (`∇ℓ` of
//! [`Model::tendon_length_jacobian`], `B` of [`Model::actuation_matrix`]): symmetric positive
//! semi-definite for frictionless tendons (`B = ∇ℓ`), the spring's stiffening.
//!
//! An inextensible tendon (`c_k = 0`) driven by its displacement is a holonomic constraint, which
//! these integrators of ordinary differential equations do not impose: a run with one is refused,
//! naming the tendon's `axial_stiffness`.

use crate::error::ModelError;
use crate::inputs::Actuation;
use crate::model::{Model, Workspace};
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};

/// The tension \[N\] of a thread of compliance `c` \[m/N\] over a path of length `length` \[m\],
/// its motor having wound it in by `delta` \[m\] from its rest length `rest` \[m\]:
/// `min(0, −(ℓ − (ℓ_rest − δ))/c)` (the module documentation), negative while it pulls.
pub fn thread_tension(length: f64, rest: f64, delta: f64, c: f64) -> f64 {
    (-(length - (rest - delta)) / c).min(0.0)
}

/// An actuation whose channels `k` with `driven[k]` are displacements `δ_k(t)` \[m\] of their
/// tendons' motors, the others tensions: the wrapper that tells the dynamics so
/// ([`Actuation::displacement_driven`]).
pub struct DisplacementDriven<'a> {
    inner: &'a dyn Actuation,
    driven: Vec<bool>,
}

impl<'a> DisplacementDriven<'a> {
    /// `inner`'s channels with `driven[k]` read as displacements.
    pub fn new(inner: &'a dyn Actuation, driven: Vec<bool>) -> Self {
        Self { inner, driven }
    }
}

impl Actuation for DisplacementDriven<'_> {
    fn eval(&self, t: f64, out: &mut [f64]) {
        self.inner.eval(t, out)
    }

    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.inner.breakpoints(t0, t1)
    }

    fn validate(&self, field: &str, channels: usize) -> Result<(), ModelError> {
        if !self.driven.is_empty() && self.driven.len() != channels {
            return Err(ModelError::invalid(
                field,
                format!("{} drive flags for {channels} actuators", self.driven.len()),
            ));
        }
        self.inner.validate(field, channels)
    }

    fn observe(&self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), String> {
        self.inner.observe(t, q, qd)
    }

    fn displacement_driven(&self) -> &[bool] {
        &self.driven
    }
}

/// The displacement-driven tendons of a run and the scratch their law and stiffness need (the
/// module documentation); allocates nothing after [`TendonSprings::new`].
#[derive(Clone)]
pub(super) struct TendonSprings {
    /// The driven actuators.
    d: Vec<usize>,
    /// Their rest lengths `ℓ_k,rest` \[m\].
    rest: Vec<f64>,
    /// Their compliances `c_k` \[m/N\].
    c: Vec<f64>,
    /// Every tendon's path length at the last `q`.
    lengths: Vec<f64>,
    grad: DMatrix<f64>,
    b: DMatrix<f64>,
    unit: Vec<f64>,
    col: DVector<f64>,
}

impl TendonSprings {
    /// The springs of the actuators `driven` says (`None` if none is), refusing an inextensible
    /// tendon and a flag per actuator that does not match the model.
    pub(super) fn new<P: StrainParam>(
        model: &Model<P>,
        driven: &[bool],
    ) -> Result<Option<Self>, ModelError> {
        if !driven.iter().any(|&b| b) {
            return Ok(None);
        }
        let (n, na) = (model.n_dof(), model.n_actuators());
        if driven.len() != na {
            return Err(ModelError::invalid(
                "actuation",
                format!("{} drive flags for {na} actuators", driven.len()),
            ));
        }
        let rest = model.tendon_rest_lengths();
        let compliance = model.tendon_compliances();
        let d: Vec<usize> = (0..na).filter(|&k| driven[k]).collect();
        if let Some(&k) = d.iter().find(|&&k| compliance[k] <= 0.0) {
            return Err(ModelError::invalid(
                format!("tendons[{k}].axial_stiffness"),
                "missing: a tendon driven by its displacement in dynamics is an elastic thread whose stretch carries the motor's displacement to the rod; give its axial stiffness EA in N (e.g. 20000 for a 0.5 mm Dyneema line) — an inextensible one is a constraint the integrators do not impose",
            ));
        }
        Ok(Some(Self {
            rest: d.iter().map(|&k| rest[k]).collect(),
            c: d.iter().map(|&k| compliance[k]).collect(),
            d,
            lengths: vec![0.0; na],
            grad: DMatrix::zeros(n, na),
            b: DMatrix::zeros(n, na),
            unit: vec![0.0; na],
            col: DVector::zeros(n),
        }))
    }

    /// Replaces the displacement `u[k] = δ_k` of each driven actuator by its tension at `q`
    /// (the module documentation); `ws` is left with the strains at `q`.
    pub(super) fn tensions<P: StrainParam>(
        &mut self,
        model: &Model<P>,
        q: &DVector<f64>,
        ws: &mut Workspace,
        u: &mut [f64],
    ) {
        model.strains_at(q, ws);
        self.tensions_after_forward(model, ws, u);
    }

    /// [`Self::tensions`] from the strains already in `ws` (a forward pass at `q`).
    pub(super) fn tensions_after_forward<P: StrainParam>(
        &mut self,
        model: &Model<P>,
        ws: &Workspace,
        u: &mut [f64],
    ) {
        model.tendon_lengths_after_forward(ws, &mut self.lengths);
        for (i, &k) in self.d.iter().enumerate() {
            u[k] = thread_tension(self.lengths[k], self.rest[i], u[k], self.c[i]);
        }
    }

    /// Evaluates `∇ℓ` and `B` at `q` for the taut tendons of `u` (tensions from
    /// [`Self::tensions`] at `q`); `false`, evaluating nothing, if none is taut.
    pub(super) fn evaluate<P: StrainParam>(
        &mut self,
        model: &Model<P>,
        q: &DVector<f64>,
        u: &[f64],
        ws: &mut Workspace,
    ) -> bool {
        if !self.d.iter().any(|&k| u[k] < 0.0) {
            return false;
        }
        model.forward(q, ws, false);
        model.tendon_length_jacobian_after_forward(ws, &mut self.grad, &mut self.col);
        model.actuation_matrix_after_forward(ws, &mut self.b, &mut self.unit, &mut self.col);
        true
    }

    /// `stiffness += B_D C⁻¹ ∇ℓ_Dᵀ` over the taut tendons of `u`, after [`Self::evaluate`] at
    /// the same `q` and `u`: the springs' share of `K_T = −∂R/∂q`.
    pub(super) fn add_stiffness(&self, u: &[f64], stiffness: &mut DMatrix<f64>) {
        for (i, &k) in self.d.iter().enumerate() {
            if u[k] < 0.0 {
                stiffness.ger(
                    1.0 / self.c[i],
                    &self.b.column(k),
                    &self.grad.column(k),
                    1.0,
                );
            }
        }
    }

    /// The springs' share of the first-order Jacobian `[0 I; M⁻¹ ∂R/∂q  −M⁻¹ D]` (`2n × 2n`):
    /// its lower-left block `−= M⁻¹ B_D C⁻¹ ∇ℓ_Dᵀ`, with `mass` the Cholesky factor of `M`
    /// ([`crate::dynamics::cholesky_solve_factored`]), after [`Self::evaluate`].
    pub(super) fn add_to_first_order(
        &mut self,
        u: &[f64],
        mass: &DMatrix<f64>,
        jac: &mut DMatrix<f64>,
    ) {
        let n = self.col.len();
        for (i, &k) in self.d.iter().enumerate() {
            if u[k] < 0.0 {
                self.col.copy_from(&self.b.column(k));
                crate::dynamics::cholesky_solve_factored(mass, &mut self.col);
                jac.view_mut((n, 0), (n, n)).ger(
                    -1.0 / self.c[i],
                    &self.col,
                    &self.grad.column(k),
                    1.0,
                );
            }
        }
    }
}
