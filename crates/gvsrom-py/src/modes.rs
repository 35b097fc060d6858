//! `Robot.modes`: natural frequencies and mode shapes about the static equilibrium, as
//! `gvsrom modes` computes them ([`gvsrom::modes::compute`]), as NumPy arrays.

use crate::arrays::{self, shaped, vector};
use crate::errors;
use crate::robot::Robot;
use gvsrom::modes::{self, ModesError, ModesReport};
use pyo3::prelude::*;
use pyo3::types::PyDict;

#[pymethods]
impl Robot {
    /// Natural frequencies and mode shapes linearized about the static equilibrium, as
    /// ``gvsrom modes`` computes them (the same numbers as its ``--json``): ``(K_T − ω² M) φ = 0``
    /// with the tangent stiffness ``K_T = −∂R/∂q`` (elastic, loads and tendons), undamped, shapes
    /// mass-normalized (``φᵀ M φ = 1``). With a reduced model attached, its modes.
    ///
    /// Parameters
    /// ----------
    /// count : int
    ///     How many of the lowest modes to describe (≥ 1; more than n_dof gives all).
    /// u : array_like of float, optional
    ///     Tensions [N] of the equilibrium (``--tension``), one per tendon or one for all; default:
    ///     the scenario's.
    ///
    /// Returns
    /// -------
    /// dict
    ///     ``frequency_hz`` (k,), ``period_s`` (k,) (``inf`` at 0 Hz), ``omega_squared`` (k,)
    ///     [1/s²] (negative: unstable), ``shape`` (k, n_dof), ``strain`` (k, n_points, 6) the
    ///     modal strain per unit modal coordinate, ``strain_energy_share`` (k, 6),
    ///     ``dominant_strain`` (list of k names), ``tip_displacement`` and ``tip_rotation``
    ///     (k, 3) world axes per unit modal coordinate (``tip_rotation`` a small-rotation vector
    ///     [rad], not the (3, 3) matrix of a statics or a trajectory), ``centerline_x`` (c,) and ``centerline`` (c, 3) the equilibrium's
    ///     centreline, ``centerline_shape`` (k, c, 3) its displacement per unit modal coordinate
    ///     (world axes), ``all_frequencies_hz`` (n_dof,; one fewer per inextensible held
    ///     tendon), ``q0`` (n_dof,), ``u`` (the tensions, those found for displacement drives),
    ///     ``held_tendons`` (list of int: the taut tendons driven by displacement, held by their
    ///     locked motors), ``held_by_threads`` (list of int: those of them held through an
    ///     elastic thread, ``axial_stiffness``, a spring rather than a constraint),
    ///     ``strain_x`` (n_points,), ``equilibrium_tip_position`` (3,),
    ///     ``equilibrium_residual_norm``, ``model_extrapolated`` (list of str: how the reduced
    ///     model was used outside its training, ``extrapolate=True``; empty otherwise).
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     For a count < 1, bad tensions, or an equilibrium that fails (``ConvergenceError``).
    #[pyo3(signature = (count=10, u=None))]
    fn modes<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = arrays::whole)] count: i128,
        u: Option<arrays::Tensions<'_>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let rebuilt = self.built_at(py, u.as_ref())?;
        let built = rebuilt.as_ref().unwrap_or(&self.built);
        crate::robot::warn_motion_note(py, built)?;
        let (count, _clipped) = modes::parse_count(Some(&count.to_string()), built.n_dof())
            .map_err(|e| errors::any(e.into()))?;
        let (_, report) = py.detach(|| modes::compute(built, count)).map_err(|e| {
            let message = errors::chain(&e);
            match &e {
                ModesError::Statics(f) => errors::statics_with_message(py, f, &message),
                _ => errors::invalid(message),
            }
        })?;
        let d = report_dict(py, &report)?;
        let extrapolated = crate::robot::model_extrapolated(py, built, &report.u)?;
        d.set_item("model_extrapolated", extrapolated)?;
        Ok(d)
    }
}

fn report_dict<'py>(py: Python<'py>, r: &ModesReport) -> PyResult<Bound<'py, PyDict>> {
    let k = r.modes.len();
    let n = r.n_dof;
    let p = r.strain_x.len();
    let col =
        |f: &dyn Fn(&modes::ModeReport) -> f64| -> Vec<f64> { r.modes.iter().map(f).collect() };
    let rows = |f: &dyn Fn(&modes::ModeReport) -> Vec<f64>| -> Vec<f64> {
        r.modes.iter().flat_map(f).collect()
    };
    let d = PyDict::new(py);
    d.set_item("frequency_hz", vector(py, &col(&|m| m.frequency_hz)))?;
    d.set_item(
        "period_s",
        vector(py, &col(&|m| m.period_s.unwrap_or(f64::INFINITY))),
    )?;
    d.set_item("omega_squared", vector(py, &col(&|m| m.omega_squared)))?;
    d.set_item("shape", shaped(py, rows(&|m| m.shape.clone()), [k, n])?)?;
    d.set_item(
        "strain",
        shaped(py, rows(&|m| arrays::flat(&m.strain)), [k, p, 6])?,
    )?;
    d.set_item(
        "strain_energy_share",
        shaped(py, rows(&|m| m.strain_energy_share.to_vec()), [k, 6])?,
    )?;
    let dominant: Vec<&str> = r.modes.iter().map(|m| m.dominant_strain).collect();
    d.set_item("dominant_strain", dominant)?;
    d.set_item(
        "tip_displacement",
        shaped(py, rows(&|m| m.tip_displacement.to_vec()), [k, 3])?,
    )?;
    d.set_item(
        "tip_rotation",
        shaped(py, rows(&|m| m.tip_rotation.to_vec()), [k, 3])?,
    )?;
    let c = r.centerline_x.len();
    d.set_item("centerline_x", vector(py, &r.centerline_x))?;
    d.set_item(
        "centerline",
        shaped(py, arrays::flat(&r.centerline), [c, 3])?,
    )?;
    d.set_item(
        "centerline_shape",
        shaped(py, rows(&|m| arrays::flat(&m.centerline_shape)), [k, c, 3])?,
    )?;
    d.set_item("all_frequencies_hz", vector(py, &r.all_frequencies_hz))?;
    d.set_item("q0", vector(py, &r.q0))?;
    d.set_item("u", vector(py, &r.u))?;
    d.set_item("held_tendons", r.held_tendons.clone())?;
    d.set_item("held_by_threads", r.held_by_threads.clone())?;
    d.set_item("strain_x", vector(py, &r.strain_x))?;
    d.set_item(
        "equilibrium_tip_position",
        vector(py, &r.equilibrium_tip_position),
    )?;
    d.set_item("equilibrium_residual_norm", r.equilibrium_residual_norm)?;
    Ok(d)
}
