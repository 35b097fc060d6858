//! `gvsrom.Statics` and `gvsrom.StaticsBatch`: a statics report (`gvsrom statics --json`) as NumPy
//! arrays, one solution or many stacked.

use crate::arrays::{flat, held, shaped, vector};
use gvsrom::statics::StaticsReport;
use gvsrom::Built;
use numpy::PyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A static equilibrium (the fields of ``gvsrom statics --json``).
///
/// Attributes
/// ----------
/// scenario : str
///     The scenario's name.
/// u : numpy.ndarray, shape (n_actuators,)
///     Tendon tensions [N]: those given, and those found for tendons driven by displacement.
/// slack : numpy.ndarray of bool, shape (n_actuators,)
///     Which tendons driven by displacement are slack (``u = 0``, their path shorter than the
///     tendon paid out); all ``False`` when every tendon is driven by tension.
/// drive_iterations : int
///     Tension updates of a displacement-driven solve (0 without displacement drives).
/// q : numpy.ndarray, shape (n_dof,)
///     Generalized coordinates at equilibrium.
/// tip_position : numpy.ndarray, shape (3,)
///     Tip position in the world frame [m].
/// tip_rotation : numpy.ndarray, shape (3, 3)
///     Tip rotation matrix, section frame → world.
/// centerline_x : numpy.ndarray, shape (c,)
///     Abscissae of the centreline samples [m].
/// centerline : numpy.ndarray, shape (c, 3)
///     Centreline positions [m].
/// strain_x : numpy.ndarray, shape (p,)
///     Abscissae of the computational points [m].
/// strain : numpy.ndarray, shape (p, 6)
///     ξ at the points, ``[torsion, bend-y, bend-z, elongation, shear-y, shear-z]``.
/// strain_reference : numpy.ndarray, shape (p, 6)
///     The reference strain ξ* at the points (the unloaded rod's; ``[0, 0, 0, 1, 0, 0]`` straight).
/// tendon_paths : tuple of numpy.ndarray, each shape (m_k, 3)
///     Each tendon's thread ``r + R d(X)`` in the world frame [m], from its start to its end (at
///     its ends and at the ``centerline_x`` between them): tendons of different spans have
///     different ``m_k``. A trajectory's ``tendon_paths`` (:meth:`Robot.simulate`) is one array
///     (k, n_actuators, c, 3) at every ``centerline_x`` instead, clamped to each span (a short
///     tendon's last point repeated).
/// tendon_lengths : numpy.ndarray, shape (n_actuators,)
///     Each tendon's length [m] along its thread, ``∫ ‖t_u‖ dX`` over its span: what an encoder on
///     its actuator reads, up to a constant.
/// tendon_rest_lengths : numpy.ndarray, shape (n_actuators,)
///     The same at rest: ``tendon_rest_lengths - tendon_lengths`` is how far each is pulled in.
/// body_positions : numpy.ndarray, shape (n_bodies, 2, 3)
///     Each rigid body's section (``[:, 0]``) and centre of mass (``[:, 1]``) in the world frame
///     [m] (``[[bodies]]``; empty without).
/// iterations, load_stages, residual_evaluations, jacobian_evaluations : int
///     Solver statistics.
/// residual_norm : float
///     ``‖R(q)‖∞`` at the solution.
/// divergence : float or None
///     ``ω²`` [1/s²], the real eigenvalue ``< 0`` of ``M⁻¹ K_T``, if the equilibrium is unstable
///     (no stable one connected to the straight rod was found; a ``UserWarning`` says so too);
///     ``None`` for a stable one.
/// buckled : float or None
///     ``ω²`` [1/s²] of the equilibrium on the path from the straight rod, if that one diverged
///     (a bifurcation: a column compressed past buckling) and the rod, released along its
///     divergent mode, settled on this stable one instead; ``None`` otherwise.
/// continued : bool
///     Whether the equilibrium was reached by arc-length continuation from the straight rod (the
///     load ramp stalled, or its equilibrium diverged).
/// solve_time_s : float
///     Wall-clock time of the solve [s].
/// model_extrapolated : list of str
///     How the reduced model was used outside what it was trained on (``extrapolate=True``; the
///     ``--json``'s ``model_extrapolated``); empty inside, and without a model.
#[pyclass(module = "gvsrom", frozen, get_all)]
pub struct Statics {
    /// The scenario's name.
    pub(crate) scenario: String,
    /// Generalized coordinates n.
    pub(crate) n_dof: usize,
    /// Computational points p.
    pub(crate) n_points: usize,
    /// Tendon tensions u [N].
    pub(crate) u: Py<PyAny>,
    /// Which displacement-driven tendons are slack, `(n_actuators,)` bool.
    pub(crate) slack: Py<PyAny>,
    /// Tension updates of a displacement-driven solve.
    pub(crate) drive_iterations: usize,
    /// Generalized coordinates at equilibrium.
    pub(crate) q: Py<PyAny>,
    /// Tip position in the world frame [m].
    pub(crate) tip_position: Py<PyAny>,
    /// Tip rotation matrix, section frame → world.
    pub(crate) tip_rotation: Py<PyAny>,
    /// Abscissae of the centreline samples [m].
    pub(crate) centerline_x: Py<PyAny>,
    /// Centreline positions [m] at `centerline_x`.
    pub(crate) centerline: Py<PyAny>,
    /// Abscissae of the computational points [m].
    pub(crate) strain_x: Py<PyAny>,
    /// ξ at the points, `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`.
    pub(crate) strain: Py<PyAny>,
    /// The reference strain ξ* at the points.
    pub(crate) strain_reference: Py<PyAny>,
    /// Each tendon's thread in the world frame [m], a `(m_k, 3)` array per tendon.
    pub(crate) tendon_paths: Py<PyAny>,
    /// Each tendon's length [m] along its thread.
    pub(crate) tendon_lengths: Py<PyAny>,
    /// Each tendon's length [m] at rest.
    pub(crate) tendon_rest_lengths: Py<PyAny>,
    /// Each rigid body's section and centre of mass [m], `(n_bodies, 2, 3)`.
    pub(crate) body_positions: Py<PyAny>,
    /// Dogleg iterations over all load stages.
    pub(crate) iterations: usize,
    /// Load stages of the ramp.
    pub(crate) load_stages: usize,
    /// Residual evaluations.
    pub(crate) residual_evaluations: usize,
    /// Jacobian evaluations.
    pub(crate) jacobian_evaluations: usize,
    /// `‖R(q)‖∞` at the solution.
    pub(crate) residual_norm: f64,
    /// `ω² < 0` [1/s²] if the equilibrium diverges, else `None`.
    pub(crate) divergence: Option<f64>,
    /// `ω² < 0` [1/s²] of the diverging equilibrium the rod was released from, if it buckled.
    pub(crate) buckled: Option<f64>,
    /// Reached by arc-length continuation from the straight rod.
    pub(crate) continued: bool,
    /// Wall-clock time of the solve [s].
    pub(crate) solve_time_s: f64,
    /// How the reduced model was used outside what it was trained on (`--extrapolate`).
    pub(crate) model_extrapolated: Vec<String>,
}

impl Statics {
    pub fn new(
        py: Python<'_>,
        r: &StaticsReport,
        model_extrapolated: Vec<String>,
    ) -> PyResult<Statics> {
        if let Some(w2) = r.divergence {
            crate::robot::warn(
                py,
                &format!(
                    "the equilibrium is unstable: M⁻¹K_T has the real eigenvalue ω² = {w2:.4e} 1/s² < 0, and no stable equilibrium connected to the straight rod was found (Statics.divergence)"
                ),
            )?;
        }
        Ok(Statics {
            scenario: r.scenario.clone(),
            n_dof: r.n_dof,
            n_points: r.n_points,
            u: held(vector(py, &r.u))?,
            slack: held(
                PyArray::from_vec(
                    py,
                    (0..r.u.len())
                        .map(|k| r.drives.get(k).is_some_and(|d| d.slack))
                        .collect(),
                )
                .into_any(),
            )?,
            drive_iterations: r.drive_iterations.unwrap_or(0),
            q: held(vector(py, &r.q))?,
            tip_position: held(vector(py, &r.tip_position))?,
            tip_rotation: held(shaped(py, flat(&r.tip_rotation), [3, 3])?)?,
            centerline_x: held(vector(py, &r.centerline_x))?,
            centerline: held(shaped(py, flat(&r.centerline), [r.centerline.len(), 3])?)?,
            strain_x: held(vector(py, &r.strain_x))?,
            strain: held(shaped(py, flat(&r.strain), [r.strain.len(), 6])?)?,
            strain_reference: held(shaped(
                py,
                flat(&r.strain_reference),
                [r.strain_reference.len(), 6],
            )?)?,
            tendon_paths: pyo3::types::PyTuple::new(
                py,
                r.tendon_paths
                    .iter()
                    .map(|p| held(shaped(py, flat(p), [p.len(), 3])?))
                    .collect::<PyResult<Vec<_>>>()?,
            )?
            .into_any()
            .unbind(),
            tendon_lengths: held(vector(py, &r.tendon_lengths))?,
            tendon_rest_lengths: held(vector(py, &r.tendon_rest_lengths))?,
            body_positions: held(shaped(
                py,
                (r.bodies.iter())
                    .flat_map(|b| b.section.into_iter().chain(b.center))
                    .collect(),
                [r.bodies.len(), 2, 3],
            )?)?,
            iterations: r.iterations,
            load_stages: r.load_stages,
            residual_evaluations: r.residual_evaluations,
            jacobian_evaluations: r.jacobian_evaluations,
            residual_norm: r.residual_norm,
            divergence: r.divergence,
            buckled: r.buckled,
            continued: r.continuation.is_some(),
            solve_time_s: r.solve_time_s,
            model_extrapolated,
        })
    }
}

#[pymethods]
impl Statics {
    /// The fields as a ``dict`` (the same read-only arrays, not copies).
    pub(crate) fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("scenario", &self.scenario)?;
        d.set_item("n_dof", self.n_dof)?;
        d.set_item("n_points", self.n_points)?;
        for (k, v) in [
            ("u", &self.u),
            ("slack", &self.slack),
            ("q", &self.q),
            ("tip_position", &self.tip_position),
            ("tip_rotation", &self.tip_rotation),
            ("centerline_x", &self.centerline_x),
            ("centerline", &self.centerline),
            ("strain_x", &self.strain_x),
            ("strain", &self.strain),
            ("strain_reference", &self.strain_reference),
            ("tendon_paths", &self.tendon_paths),
            ("tendon_lengths", &self.tendon_lengths),
            ("tendon_rest_lengths", &self.tendon_rest_lengths),
            ("body_positions", &self.body_positions),
        ] {
            d.set_item(k, v.bind(py))?;
        }
        d.set_item("drive_iterations", self.drive_iterations)?;
        d.set_item("iterations", self.iterations)?;
        d.set_item("load_stages", self.load_stages)?;
        d.set_item("residual_evaluations", self.residual_evaluations)?;
        d.set_item("jacobian_evaluations", self.jacobian_evaluations)?;
        d.set_item("residual_norm", self.residual_norm)?;
        d.set_item("divergence", self.divergence)?;
        d.set_item("buckled", self.buckled)?;
        d.set_item("continued", self.continued)?;
        d.set_item("solve_time_s", self.solve_time_s)?;
        d.set_item("model_extrapolated", &self.model_extrapolated)?;
        Ok(d)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Statics(scenario={:?}, n_dof={}, tip_position={}, iterations={}, residual_norm={:.3e})",
            self.scenario,
            self.n_dof,
            self.tip_position.bind(py),
            self.iterations,
            self.residual_norm
        )
    }
}

/// Many static equilibria (:meth:`Robot.statics_batch`): the arrays below, those of
/// :class:`Statics` stacked along a first axis of length m. Of :class:`Statics`'s other fields it
/// has none (the tendon paths, body positions, drives, load stages, ``to_dict``): solve the rows
/// of interest with :meth:`Robot.statics` for those. A missing value is NaN here, where
/// :class:`Statics` gives None.
///
/// Attributes
/// ----------
/// u : numpy.ndarray, shape (m, n_actuators)
/// q : numpy.ndarray, shape (m, n_dof)
/// tip_position : numpy.ndarray, shape (m, 3)
/// tip_rotation : numpy.ndarray, shape (m, 3, 3)
/// centerline_x : numpy.ndarray, shape (c,)
/// centerline : numpy.ndarray, shape (m, c, 3)
/// strain_x : numpy.ndarray, shape (p,)
/// strain : numpy.ndarray, shape (m, p, 6)
/// tendon_lengths : numpy.ndarray, shape (m, n_actuators)
///     Each tendon's length [m] along its thread (at rest: :attr:`Robot.tendon_rest_lengths`).
/// iterations : numpy.ndarray of int64, shape (m,)
/// residual_norm : numpy.ndarray, shape (m,)
/// divergence : numpy.ndarray, shape (m,)
///     ``ω² < 0`` [1/s²] of a row whose equilibrium is unstable (no stable one connected to the
///     straight rod was found; a ``UserWarning`` names the rows), NaN for a stable one.
/// buckled : numpy.ndarray, shape (m,)
///     ``ω² < 0`` [1/s²] of the diverging equilibrium a row's rod was released from onto its
///     stable one (:attr:`Statics.buckled`), NaN for a row that did not buckle. A row
///     warm-started from a buckled neighbour starts on the buckled branch and is NaN too (its
///     equilibrium is the same; ``warm_start=False`` releases every row from straight).
/// solve_time_s : numpy.ndarray, shape (m,)
///     Each solve's own wall-clock time [s] (the solves run in parallel).
#[pyclass(module = "gvsrom", frozen, get_all)]
pub struct StaticsBatch {
    /// Tendon tensions u [N].
    pub(crate) u: Py<PyAny>,
    /// Generalized coordinates at equilibrium.
    pub(crate) q: Py<PyAny>,
    /// Tip position in the world frame [m].
    pub(crate) tip_position: Py<PyAny>,
    /// Tip rotation matrix, section frame → world.
    pub(crate) tip_rotation: Py<PyAny>,
    /// Abscissae of the centreline samples [m].
    pub(crate) centerline_x: Py<PyAny>,
    /// Centreline positions [m] at `centerline_x`.
    pub(crate) centerline: Py<PyAny>,
    /// Abscissae of the computational points [m].
    pub(crate) strain_x: Py<PyAny>,
    /// ξ at the points, `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`.
    pub(crate) strain: Py<PyAny>,
    /// Each tendon's length [m] along its thread.
    pub(crate) tendon_lengths: Py<PyAny>,
    /// Dogleg iterations over all load stages.
    pub(crate) iterations: Py<PyAny>,
    /// `‖R(q)‖∞` at the solution.
    pub(crate) residual_norm: Py<PyAny>,
    /// `ω² < 0` [1/s²] of an unstable equilibrium, NaN for a stable one.
    pub(crate) divergence: Py<PyAny>,
    /// `ω² < 0` [1/s²] of the equilibrium a buckled row left, NaN otherwise.
    pub(crate) buckled: Py<PyAny>,
    /// Wall-clock time of the solve [s].
    pub(crate) solve_time_s: Py<PyAny>,
}

impl StaticsBatch {
    pub fn new(py: Python<'_>, rs: &[StaticsReport], built: &Built) -> PyResult<StaticsBatch> {
        let m = rs.len();
        let cat = |f: &dyn Fn(&StaticsReport) -> Vec<f64>| -> Vec<f64> {
            rs.iter().flat_map(f).collect()
        };
        let na = built.model.n_actuators();
        let n = built.n_dof();
        let x: Vec<f64> = built.model.disc.points.iter().map(|p| p.x).collect();
        let c = gvsrom::statics::centerline_abscissae(
            built.model.disc.length(),
            built.centerline_points,
        );
        let iterations: Vec<i64> = rs.iter().map(|r| r.iterations as i64).collect();
        let divergence: Vec<f64> = rs
            .iter()
            .map(|r| r.divergence.unwrap_or(f64::NAN))
            .collect();
        let unstable: Vec<String> = (divergence.iter().enumerate())
            .filter(|(_, w2)| !w2.is_nan())
            .map(|(k, _)| k.to_string())
            .collect();
        if !unstable.is_empty() {
            crate::robot::warn(
                py,
                &format!(
                    "the equilibria of rows [{}] are unstable (M⁻¹K_T has a real ω² < 0) and no stable one connected to the straight rod was found (StaticsBatch.divergence)",
                    unstable.join(", ")
                ),
            )?;
        }
        Ok(StaticsBatch {
            u: held(shaped(py, cat(&|r| r.u.clone()), [m, na])?)?,
            q: held(shaped(py, cat(&|r| r.q.clone()), [m, n])?)?,
            tip_position: held(shaped(py, cat(&|r| r.tip_position.to_vec()), [m, 3])?)?,
            tip_rotation: held(shaped(py, cat(&|r| flat(&r.tip_rotation)), [m, 3, 3])?)?,
            centerline_x: held(vector(py, &c))?,
            centerline: held(shaped(py, cat(&|r| flat(&r.centerline)), [m, c.len(), 3])?)?,
            strain_x: held(vector(py, &x))?,
            strain: held(shaped(py, cat(&|r| flat(&r.strain)), [m, x.len(), 6])?)?,
            tendon_lengths: held(shaped(py, cat(&|r| r.tendon_lengths.clone()), [m, na])?)?,
            iterations: held(PyArray::from_vec(py, iterations).into_any())?,
            residual_norm: held(vector(
                py,
                &rs.iter().map(|r| r.residual_norm).collect::<Vec<_>>(),
            ))?,
            divergence: held(vector(py, &divergence))?,
            buckled: held(vector(
                py,
                &rs.iter()
                    .map(|r| r.buckled.unwrap_or(f64::NAN))
                    .collect::<Vec<_>>(),
            ))?,
            solve_time_s: held(vector(
                py,
                &rs.iter().map(|r| r.solve_time_s).collect::<Vec<_>>(),
            ))?,
        })
    }
}

#[pymethods]
impl StaticsBatch {
    /// Number of equilibria m.
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.q.bind(py).len()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("StaticsBatch(m={})", self.__len__(py)?))
    }
}
