//! `Robot.linearize`: the equations of motion linearized for control, as `gvsrom linearize`
//! computes them ([`gvsrom::linearize`]), as NumPy arrays.

use crate::arrays::{self, matrix, vector};
use crate::dynamics_quantities::state;
use crate::errors::{self, invalid};
use crate::robot::Robot;
use gvsrom::linearize::{self, Linearization, LinearizeError};
use numpy::{Complex64, PyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;

#[pymethods]
impl Robot {
    /// The equations of motion linearized for control design, as ``gvsrom linearize`` computes
    /// them (the same numbers as its ``--json``): ``δẋ = A δx + B δu`` and ``δy = C δx`` with the
    /// state ``x = [q; q̇]``, the tendon tensions ``u`` [N] and the output ``y``, the tip position
    /// or the positions at ``outputs`` (world axes, m). ``A`` keeps every term of the dynamics
    /// (gvs-spec §9.3), the inertial ones that vanish at rest included. With a reduced model
    /// attached, its ``2r``-state linearization. About the equilibrium of a scenario that drives
    /// a tendon by its ``displacement`` through an elastic thread (``axial_stiffness``), that
    /// tendon's input is its motor's displacement [m] (the dict's ``displacement_channels``):
    /// ``A`` holds the thread's stiffness, ``B``'s column is per metre wound in.
    ///
    /// Parameters
    /// ----------
    /// u : array_like of float, optional
    ///     Tensions [N] of the operating point, one per tendon or one for all; default: the
    ///     scenario's.
    /// q : array_like of float, optional
    ///     Linearize about this state instead of the static equilibrium under ``u`` (no solve);
    ///     shape (n_dof,).
    /// qd : array_like of float, optional
    ///     The state's velocities (with ``q`` only); default zero.
    /// dt : float, optional
    ///     Also discretize with a zero-order hold of ``dt`` seconds (``--sample-time``):
    ///     ``Ad`` = e^(A dt), ``Bd`` = ∫₀^dt e^(A s) ds B, ``spectral_radius`` max |e^(λ dt)|.
    /// outputs : float or array_like of float, optional
    ///     Abscissae [m] along the rod whose world positions make ``y`` (``--output-at``), 3 rows
    ///     of ``C`` each in this order, between the computational points by the centreline's
    ///     interpolant; default: the tip.
    /// tip_orientation : bool
    ///     Also output the tip's orientation (``--output-tip-orientation``): 3 rows of ``C`` after
    ///     the positions, the tip section's small rotation in world axes [rad].
    /// tendon_lengths : bool
    ///     Also output each tendon's length [m] along its thread (``--output-tendon-lengths``),
    ///     one row of ``C`` each after the positions, for actuators under position control; the
    ///     static gain's last rows are then the tendons' compliance ``∂ℓ/∂u``.
    ///
    /// Returns
    /// -------
    /// dict
    ///     ``A`` (2n, 2n), ``B`` (2n, n_actuators), ``C`` (3k, 2n) for k outputs, ``D``
    ///     (C's rows, n_actuators) zeros (no output depends on the tensions directly), ``outputs``
    ///     (k,) their abscissae, ``output_positions`` (k, 3), ``output_tip_rotation`` (3, 3)
    ///     the tip's rotation with ``tip_orientation`` (``None`` otherwise), ``output_tendon_lengths``
    ///     (n_actuators,) with ``tendon_lengths`` (empty otherwise; ``C`` has 3k rows, 3 more
    ///     with ``tip_orientation``, then n_actuators with ``tendon_lengths``), ``x0`` (2n,) the operating
    ///     point, ``u`` (n_actuators,), ``xdot`` (2n,) ``f(x0, u)`` (≈ 0 about an equilibrium),
    ///     ``tip_position`` (3,), ``poles`` (complex, the eigenvalues of A with ``Im ≥ 0``,
    ///     conjugates once, slowest first), ``natural_frequency_hz`` and ``damping_ratio`` per pole,
    ///     ``unstable_poles`` (count, conjugates counted), ``static_gain`` (C's rows, n_actuators) [m/N]
    ///     ``−C A⁻¹ B`` about an equilibrium (``None`` about a given state), ``about``
    ///     (``"equilibrium"`` or ``"state"``), ``damping_time_s``, ``relaxation_poles``,
    ///     ``equilibrium_residual_norm`` (about an equilibrium), ``time_s`` (the linearization's
    ///     wall time), ``model_extrapolated``; with ``dt``: ``Ad`` (2n, 2n), ``Bd``
    ///     (2n, n_actuators), ``dt``, ``spectral_radius``.
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     For bad tensions or states, ``qd`` without ``q``, a massless rod, or an equilibrium
    ///     that fails (``ConvergenceError``).
    #[pyo3(signature = (u=None, q=None, qd=None, dt=None, outputs=None, tip_orientation=false, tendon_lengths=false))]
    #[allow(clippy::too_many_arguments)]
    fn linearize<'py>(
        &self,
        py: Python<'py>,
        u: Option<arrays::Tensions<'_>>,
        q: Option<arrays::In1<'_>>,
        qd: Option<arrays::In1<'_>>,
        dt: Option<f64>,
        outputs: Option<arrays::Abscissae>,
        tip_orientation: bool,
        tendon_lengths: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        if let Some(h) = dt {
            linearize::check_sample_time(h).map_err(|e| invalid(e.to_string()))?;
        }
        crate::robot::warn_motion_note(py, &self.built)?;
        let mut outputs = match &outputs {
            None => linearize::Outputs::tip(&self.built),
            Some(xs) => linearize::Outputs::at(&self.built, &xs.values)
                .map_err(|e| invalid(e.to_string()))?,
        };
        if tip_orientation {
            outputs = outputs.with_tip_orientation();
        }
        if tendon_lengths {
            outputs =
                (outputs.with_tendon_lengths(&self.built)).map_err(|e| invalid(e.to_string()))?;
        }
        let to_py = |e: LinearizeError| {
            let message = errors::chain(&e);
            match &e {
                LinearizeError::Statics(f) => errors::statics_with_message(py, f, &message),
                _ => invalid(message),
            }
        };
        let mut lin = match (&q, &qd) {
            (None, Some(_)) => {
                return Err(invalid(
                    "`qd` without `q`: give the state's `q` too, or neither to linearize about the equilibrium at rest",
                ))
            }
            (None, None) => {
                let rebuilt = self.built_at(py, u.as_ref())?;
                let built = rebuilt.as_ref().unwrap_or(&self.built);
                py.detach(|| linearize::about_equilibrium(built, &outputs))
                    .map_err(to_py)?
                    .1
            }
            (Some(q), qd) => {
                let (q, qd) = state(self, q, qd.as_ref())?;
                let u = self.quantity_tensions(py, u)?;
                py.detach(|| linearize::about_state(&self.built, &q, &qd, &u, &outputs))
                    .map_err(to_py)?
            }
        };
        if let Some(h) = dt {
            lin.discretize(h).map_err(to_py)?;
        }
        let d = report_dict(py, &lin)?;
        let extrapolated = crate::robot::model_extrapolated(py, &self.built, &lin.u)?;
        d.set_item("model_extrapolated", extrapolated)?;
        Ok(d)
    }
}

fn report_dict<'py>(py: Python<'py>, r: &Linearization) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("A", matrix(py, &r.a_matrix())?)?;
    d.set_item("B", matrix(py, &r.b_matrix())?)?;
    let c = r.c_matrix();
    d.set_item("C", matrix(py, &c)?)?;
    // no feedthrough: positions and lengths depend on the state alone
    let feedthrough = nalgebra::DMatrix::zeros(c.nrows(), r.u.len());
    d.set_item("D", matrix(py, &feedthrough)?)?;
    let x0: Vec<f64> = r.q.iter().chain(&r.qd).copied().collect();
    d.set_item("x0", vector(py, &x0))?;
    d.set_item("u", vector(py, &r.u))?;
    d.set_item("displacement_channels", r.displacement_channels.clone())?;
    d.set_item("xdot", vector(py, &r.xdot))?;
    d.set_item("tip_position", vector(py, &r.tip_position))?;
    d.set_item("outputs", vector(py, &r.outputs))?;
    let positions =
        nalgebra::DMatrix::from_fn(r.output_positions.len(), 3, |i, j| r.output_positions[i][j]);
    d.set_item("output_positions", matrix(py, &positions)?)?;
    match &r.output_tip_rotation {
        Some(rot) => {
            let m = nalgebra::DMatrix::from_fn(3, 3, |i, j| rot[i][j]);
            d.set_item("output_tip_rotation", matrix(py, &m)?)?
        }
        None => d.set_item("output_tip_rotation", py.None())?,
    }
    d.set_item(
        "output_tendon_lengths",
        vector(py, &r.output_tendon_lengths),
    )?;
    let poles: Vec<Complex64> = r.poles.iter().map(|p| Complex64::new(p.re, p.im)).collect();
    d.set_item("poles", PyArray::from_vec(py, poles))?;
    let col = |f: &dyn Fn(&linearize::Pole) -> f64| -> Vec<f64> { r.poles.iter().map(f).collect() };
    d.set_item(
        "natural_frequency_hz",
        vector(py, &col(&|p| p.natural_frequency_hz)),
    )?;
    d.set_item("damping_ratio", vector(py, &col(&|p| p.damping_ratio)))?;
    d.set_item("unstable_poles", r.unstable_poles)?;
    match r.static_gain_matrix() {
        Some(g) => d.set_item("static_gain", matrix(py, &g)?)?,
        None => d.set_item("static_gain", py.None())?,
    }
    d.set_item("about", r.about)?;
    d.set_item("damping_time_s", r.damping_time_s)?;
    d.set_item("time_s", r.time_s)?;
    d.set_item("relaxation_poles", r.relaxation_poles)?;
    d.set_item("equilibrium_residual_norm", r.equilibrium_residual_norm)?;
    if let Some(disc) = &r.discrete {
        d.set_item("Ad", matrix(py, &disc.ad_matrix())?)?;
        d.set_item("Bd", matrix(py, &disc.bd_matrix())?)?;
        d.set_item("dt", disc.sample_time_s)?;
        d.set_item("spectral_radius", disc.spectral_radius)?;
    }
    Ok(d)
}
