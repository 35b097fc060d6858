//! The tendons' lengths at a given state, for the model that runs (the HOM, or the reduced model
//! attached): `ℓ_k(q) = ∫ ‖t_u‖ dX` over each tendon's span and its derivative `∂ℓ/∂q`
//! ([`gvs::model::Model::tendon_lengths`], gvs-spec §7.6), for a controller that commands the
//! actuators' positions rather than their tensions.

use crate::arrays::{self, In1};
use crate::dynamics_quantities::state;
use crate::quantities::{on_model, with_model, WorkspaceCache};
use crate::robot::Robot;
use gvsrom::Built;
use nalgebra::{DMatrix, DVector};
use pyo3::prelude::*;

/// `ℓ(q)`, one per tendon.
pub fn tendon_lengths(built: &Built, cache: &WorkspaceCache, q: &DVector<f64>) -> Vec<f64> {
    with_model!(built, cache, m, ws => m.tendon_lengths(q, ws))
}

/// `∂ℓ/∂q` (tendons × n).
pub fn tendon_length_jacobian(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
) -> DMatrix<f64> {
    with_model!(built, cache, m, ws => m.tendon_length_jacobian(q, ws).transpose())
}

#[pymethods]
impl Robot {
    /// Each tendon's length along its routed thread at ``q``, ``ℓ_k = ∫ ‖t_u‖ dX`` over its span
    /// (``t_u = ν + k × d + d'``, gvs-spec §7.6): what an encoder on its actuator reads, up to a
    /// constant. Pulling a tendon shortens it: :attr:`tendon_rest_lengths` ``- ℓ`` is how far it
    /// has been pulled in.
    ///
    /// Parameters
    /// ----------
    /// q : array_like of float, shape (n_dof,)
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     Shape (n_actuators,) [m].
    fn tendon_lengths<'py>(&self, py: Python<'py>, q: In1<'_>) -> PyResult<Bound<'py, PyAny>> {
        let (q, _) = state(self, &q, None)?;
        let l = py.detach(|| tendon_lengths(&self.built, &self.workspaces, &q));
        Ok(arrays::vector(py, &l))
    }

    /// The derivative of :meth:`tendon_lengths` in ``q``: row k is ``∇_q ℓ_k``. For a
    /// frictionless tendon it is the transpose of its column of :meth:`actuation_matrix` (the
    /// virtual work of its tension); with friction the actuation is attenuated along the tendon
    /// and differs. Shape (n_actuators, n_dof) [m per unit of q].
    fn tendon_length_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: In1<'_>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, _) = state(self, &q, None)?;
        let j = py.detach(|| tendon_length_jacobian(&self.built, &self.workspaces, &q));
        arrays::matrix(py, &j)
    }

    /// Each tendon's length [m] at rest (the reference strain; the straight rod's unless it is
    /// precurved), shape (n_actuators,).
    #[getter]
    fn tendon_rest_lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let l = on_model!(&self.built, m => m.tendon_rest_lengths());
        arrays::vector(py, &l)
    }
}
