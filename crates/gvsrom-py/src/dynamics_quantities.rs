//! The terms of the equations of motion at a given state, for the model that runs (the HOM, or the
//! reduced model attached): `M(q) q̈ + C(q, q̇) q̇ + D₁ + K₁(q) = B(q) u + F(q)` (paper eq. 8).
//! Each is one engine call (`gvs::model::Model::elastic_force`, `coriolis_force`, …); the `Robot`
//! methods of the same names convert their arguments and call these.

use crate::arrays::{self, In1};
use crate::errors::{invalid, scenario as err};
use crate::quantities::{with_model, WorkspaceCache};
use crate::robot::Robot;
use gvs::dynamics::Energy;
use gvs::loads::Loads;
use gvsrom::Built;
use nalgebra::{DMatrix, DVector};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// `K₁(q)`.
pub fn elastic_force(built: &Built, cache: &WorkspaceCache, q: &DVector<f64>) -> DVector<f64> {
    with_model!(built, cache, m, ws => m.elastic_force(q, ws))
}

/// `∂K₁/∂q`.
pub fn elastic_stiffness(built: &Built, cache: &WorkspaceCache, q: &DVector<f64>) -> DMatrix<f64> {
    with_model!(built, cache, m, ws => m.elastic_stiffness(q, ws))
}

/// `D₁ = D(q) q̇`.
pub fn damping_force(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> DVector<f64> {
    with_model!(built, cache, m, ws => m.damping_force(q, qd, ws))
}

/// `D(q)`.
pub fn damping_matrix(built: &Built, cache: &WorkspaceCache, q: &DVector<f64>) -> DMatrix<f64> {
    with_model!(built, cache, m, ws => {
        m.forward(q, ws, false);
        m.damping_matrix(ws)
    })
}

/// `F(q)` of `loads`.
pub fn external_force(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    loads: &Loads,
) -> Result<DVector<f64>, gvsrom::ScenarioError> {
    with_model!(built, cache, m, ws => {
        let prepared = m.prepare_loads(loads)?;
        Ok(m.external_force(q, &prepared, ws))
    })
}

/// `B(q)`.
pub fn actuation_matrix(built: &Built, cache: &WorkspaceCache, q: &DVector<f64>) -> DMatrix<f64> {
    with_model!(built, cache, m, ws => m.actuation_matrix(q, ws))
}

/// `C(q, q̇) q̇`.
pub fn coriolis_force(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> DVector<f64> {
    with_model!(built, cache, m, ws => m.coriolis_force(q, qd, ws))
}

/// `C(q, q̇)`.
pub fn coriolis_matrix(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> DMatrix<f64> {
    with_model!(built, cache, m, ws => m.coriolis_matrix(q, qd, ws))
}

/// `q̈ = M⁻¹ τ(q, q̇, u)` under the scenario's loads.
pub fn accelerations(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    u: &[f64],
) -> Result<DVector<f64>, String> {
    with_model!(built, cache, m, ws => {
        let loads = m.prepare_loads(&built.loads).map_err(|e| e.to_string())?;
        let mut qdd = DVector::zeros(m.n_dof());
        m.accelerations(q, qd, u, &loads, ws, &mut qdd)
            .map_err(|e| e.to_string())?;
        Ok(qdd)
    })
}

/// Kinetic, elastic and gravitational energy at `(q, q̇)` under the scenario's gravity.
pub fn energy(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> Energy {
    with_model!(built, cache, m, ws => m.energy(q, qd, &built.loads.gravity, ws))
}

/// `q` (and `q̇`) of a robot's model from array-likes, checked (length, finite; `q` inside a reduced
/// model's training encodings, [`Robot::coordinates`]).
pub fn state(
    robot: &Robot,
    q: &In1<'_>,
    qd: Option<&In1<'_>>,
) -> PyResult<(DVector<f64>, DVector<f64>)> {
    let n = robot.built.n_dof();
    let q = robot.coordinates(q)?;
    let qd = match qd {
        Some(v) => arrays::dvec("qd", v, n)?,
        None => DVector::zeros(n),
    };
    Ok((q, qd))
}

/// `values`, the quantity `what` at `(q, q̇)`, if all are finite; else a `GvsromError` naming
/// `qd`: `q` was checked as a state of the rod, so an overflow comes from velocities whose
/// products (`η ⊗ η` in `C`, `q̇ᵀ M q̇`) exceed floating point.
pub fn finite_at(what: &str, values: &[f64], qd: &DVector<f64>) -> PyResult<()> {
    match values.iter().all(|v| v.is_finite()) {
        true => Ok(()),
        false => Err(invalid(format!(
            "{what} is not finite at this state: `qd` (largest |qd| = {:e}) overflows it; accepted: velocities whose quantities are finite",
            qd.amax()
        ))),
    }
}

/// `energy` as a dict `{kinetic, elastic, gravitational, total}` [J].
pub fn energy_dict<'py>(py: Python<'py>, e: &Energy) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("kinetic", e.kinetic)?;
    d.set_item("elastic", e.elastic)?;
    d.set_item("gravitational", e.gravitational)?;
    d.set_item("total", e.total())?;
    Ok(d)
}

/// A vector as a 1-D array.
pub fn vector<'py>(py: Python<'py>, v: &DVector<f64>) -> Bound<'py, PyAny> {
    arrays::vector(py, v.as_slice())
}

#[pymethods]
impl Robot {
    /// The elastic force ``K₁(q) = Σ W Ψ_qᵀ Es Ψ`` (gvs-spec §7.3): ``K q`` for the HOM's linear
    /// basis, the generalized elastic force of a reduced model. It enters the equations of motion
    /// as ``M q̈ + C q̇ + D₁ + K₁ = B u + F``.
    ///
    /// Parameters
    /// ----------
    /// q : array_like of float, shape (n_dof,)
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     Shape (n_dof,) [J per unit of q; see :class:`Robot` for the units].
    fn elastic_force<'py>(&self, py: Python<'py>, q: In1<'_>) -> PyResult<Bound<'py, PyAny>> {
        let (q, _) = state(self, &q, None)?;
        let f = py.detach(|| elastic_force(&self.built, &self.workspaces, &q));
        Ok(vector(py, &f))
    }

    /// The elastic stiffness ``K(q) = ∂K₁/∂q`` (the constant ``K`` of the HOM's linear basis; of
    /// a reduced model, its tangent), shape (n_dof, n_dof): ``½ δqᵀ K δq`` is an elastic energy
    /// [J].
    fn stiffness_matrix<'py>(&self, py: Python<'py>, q: In1<'_>) -> PyResult<Bound<'py, PyAny>> {
        let (q, _) = state(self, &q, None)?;
        let k = py.detach(|| elastic_stiffness(&self.built, &self.workspaces, &q));
        arrays::matrix(py, &k)
    }

    /// The damping force ``D₁ = D(q) q̇`` (Kelvin–Voigt, gvs-spec §7.4), shape (n_dof,)
    /// [J per unit of q].
    fn damping_force<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        qd: In1<'_>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd) = state(self, &q, Some(&qd))?;
        let f = py.detach(|| damping_force(&self.built, &self.workspaces, &q, &qd));
        finite_at("the damping force", f.as_slice(), &qd)?;
        Ok(vector(py, &f))
    }

    /// The damping matrix ``D(q) = Σ W Ψ_qᵀ Ds Ψ_q`` (constant for the HOM), shape
    /// (n_dof, n_dof): ``q̇ᵀ D q̇`` is the power the damping dissipates [W].
    fn damping_matrix<'py>(&self, py: Python<'py>, q: In1<'_>) -> PyResult<Bound<'py, PyAny>> {
        let (q, _) = state(self, &q, None)?;
        let d = py.detach(|| damping_matrix(&self.built, &self.workspaces, &q));
        arrays::matrix(py, &d)
    }

    /// The Coriolis and centrifugal force ``C(q, q̇) q̇ = Σ W Jᵀ (Ms J̇ q̇ + coad_η Ms η)``
    /// (gvs-spec §7.2), shape (n_dof,) [J per unit of q]. With a reduced model attached, whose
    /// strain is ``Φ c(q)``, ``J = J_HOM C_q`` and ``J̇ q̇`` holds the map's curvature: the force is
    /// ``C_qᵀ (C_HOM q̇_HOM + M_HOM Ċ_q q̇)`` at ``q̇_HOM = C_q q̇`` (``crates/rom/tests/reduced_identities.rs``).
    fn coriolis_force<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        qd: In1<'_>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd) = state(self, &q, Some(&qd))?;
        let f = py.detach(|| coriolis_force(&self.built, &self.workspaces, &q, &qd));
        finite_at("the Coriolis force", f.as_slice(), &qd)?;
        Ok(vector(py, &f))
    }

    /// The Coriolis matrix ``C(q, q̇)`` with ``Ṁ − 2C`` skew-symmetric (gvs-spec §7.2), shape
    /// (n_dof, n_dof); ``C(q, q̇) @ q̇`` is :meth:`coriolis_force` [J per unit of q].
    fn coriolis_matrix<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        qd: In1<'_>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd) = state(self, &q, Some(&qd))?;
        let c = py.detach(|| coriolis_matrix(&self.built, &self.workspaces, &q, &qd));
        finite_at("the Coriolis matrix", c.as_slice(), &qd)?;
        arrays::matrix(py, &c)
    }

    /// The external generalized force ``F(q) = Σ J_iᵀ w_i`` of gravity, the rigid bodies' weights
    /// and the scenario's point and distributed loads (gvs-spec §7.5), shape (n_dof,) [J per unit
    /// of q].
    fn external_force<'py>(&self, py: Python<'py>, q: In1<'_>) -> PyResult<Bound<'py, PyAny>> {
        let (q, _) = state(self, &q, None)?;
        let f = py
            .detach(|| external_force(&self.built, &self.workspaces, &q, &self.built.loads))
            .map_err(err)?;
        Ok(vector(py, &f))
    }

    /// The actuation matrix ``B(q)``: column k is the generalized force of a unit tension in
    /// tendon k (routing and friction included), so the tendons' force is ``B(q) @ u``. Shape
    /// (n_dof, n_actuators), in m per unit of q (a work per unit of tension).
    fn actuation_matrix<'py>(&self, py: Python<'py>, q: In1<'_>) -> PyResult<Bound<'py, PyAny>> {
        let (q, _) = state(self, &q, None)?;
        let b = py.detach(|| actuation_matrix(&self.built, &self.workspaces, &q));
        arrays::matrix(py, &b)
    }

    /// The accelerations ``q̈ = M⁻¹ (B u + F − K₁ − D₁ − C q̇)`` the integrators use (forward
    /// dynamics), shape (n_dof,), in units of q per s².
    ///
    /// Parameters
    /// ----------
    /// q, qd : array_like of float, shape (n_dof,)
    /// u : array_like of float, optional
    ///     Tensions [N], one per tendon or one for all; default: the scenario's.
    #[pyo3(signature = (q, qd, u=None))]
    fn accelerations<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        qd: In1<'_>,
        u: Option<arrays::Tensions<'_>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd) = state(self, &q, Some(&qd))?;
        let u = self.quantity_tensions(py, u)?;
        // a massless rod has no accelerations: said as `simulate`, `modes` and `linearize` say it
        gvsrom::simulate::require_mass(&self.built).map_err(crate::errors::scenario)?;
        let a = py
            .detach(|| accelerations(&self.built, &self.workspaces, &q, &qd, &u))
            // `q` was checked as a state of the rod: what fails comes from `qd`, or `u`
            .map_err(|e| {
                invalid(format!(
                    "{e}, at `qd` up to |qd| = {:e} and `u` up to |u| = {:e}",
                    qd.amax(),
                    u.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
                ))
            })?;
        finite_at("the acceleration", a.as_slice(), &qd)?;
        Ok(vector(py, &a))
    }

    /// Energies at ``(q, q̇)`` [J]: kinetic ``½ q̇ᵀ M q̇``, elastic ``½ Σ W Ψᵀ Es Ψ`` (whose
    /// gradient is :meth:`elastic_force`), gravitational ``−Σ W ρA g·r`` (and ``−m g·(r + R c)``
    /// of each rigid body), and their total.
    ///
    /// Parameters
    /// ----------
    /// u : array_like of float, shape (n_actuators,), optional
    ///     Constant tendon tensions [N]: adds their potential ``tendons = −Σ u ℓ(q)`` (ℓ the
    ///     lengths of :meth:`tendon_lengths`, whose gradient is the frictionless tendons' force
    ///     ``B u``) to the total, which a conservative run under those tensions keeps (the
    ///     ``energy_balance`` of :meth:`simulate`). Without it, no tendon term.
    ///
    /// Returns
    /// -------
    /// dict
    ///     ``kinetic``, ``elastic``, ``gravitational``, ``total`` (floats), and ``tendons`` when
    ///     ``u`` is given.
    #[pyo3(signature = (q, qd=None, u=None))]
    fn energy<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
        qd: Option<In1<'_>>,
        u: Option<arrays::Tensions<'_>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (q, qd) = state(self, &q, qd.as_ref())?;
        let u = match u {
            Some(u) => Some(self.quantity_tensions(py, Some(u))?),
            None => None,
        };
        let (e, lengths) = py.detach(|| {
            let e = energy(&self.built, &self.workspaces, &q, &qd);
            let lengths = u.as_ref().map(|_| {
                crate::tendon_quantities::tendon_lengths(&self.built, &self.workspaces, &q)
            });
            (e, lengths)
        });
        finite_at("the kinetic energy", &[e.kinetic], &qd)?;
        let d = energy_dict(py, &e)?;
        if let (Some(u), Some(lengths)) = (&u, &lengths) {
            let tendons = -(u.iter().zip(lengths)).map(|(u, l)| u * l).sum::<f64>();
            d.set_item("tendons", tendons)?;
            d.set_item("total", e.total() + tendons)?;
        }
        Ok(d)
    }
}
