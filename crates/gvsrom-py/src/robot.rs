//! `gvsrom.Robot`: a built scenario (the engine's model, loads, tensions and solver options), with
//! a reduced model attached or not, and its description (the statics are in `robot_statics`, the
//! model quantities in `robot_quantities` and `dynamics_quantities`, the runs in `simulate`).

use crate::arrays::{self, In1, Tensions};
use crate::errors::{self, invalid, scenario as err};
use crate::models::Model;
use crate::quantities::{self, WorkspaceCache};
use crate::scenario::Scenario;
use gvsrom::reduce::{self, AttachOptions};
use gvsrom::Built;
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use std::ffi::CString;
use std::path::PathBuf;
use std::sync::OnceLock;

/// A reduced model to attach: its directory, whether it may extrapolate (`--extrapolate`), and
/// its content as `load_model` read it (the manifest's hashes), which the directory must still
/// hold when a robot reads it again.
#[derive(Clone)]
pub struct Attached {
    pub dir: PathBuf,
    pub extrapolate: bool,
    pub loaded: Option<gvsrom::provenance::DirOrigin>,
}

/// A built scenario: the engine's model of the rod with its loads, tendon tensions and solver
/// options, and, if :meth:`with_model` attached one, a reduced model that replaces the scenario's
/// strain basis in statics, dynamics and every model quantity.
///
/// Made by :meth:`Scenario.build`.
///
/// Units: SI throughout. The coordinates ``q`` are the strain basis's coefficients, in strain units
/// (1/m for a torsion or bending coefficient, 1 for elongation or shear, with dimensionless basis
/// functions; a reduced model's latent coordinates are in the units of its code). A generalized
/// force is work-conjugate to ``q``: ``F · δq`` is a work [J], so each entry is in J per unit of
/// its coordinate (N·m² for a bending coefficient, N·m for an elongation one). Then
/// ``½ q̇ᵀ M q̇`` is a kinetic energy [J], ``½ δqᵀ K δq`` an elastic energy [J], ``q̇ᵀ D q̇`` a
/// dissipated power [W], and ``B`` is in m per unit of q, so that ``B u`` [J per unit of q] is a
/// generalized force for tensions ``u`` [N].
#[pyclass(module = "gvsrom", frozen)]
pub struct Robot {
    pub scenario: Scenario,
    pub built: Built,
    pub attached: Option<Attached>,
    /// The workspace of the model that runs, kept between the quantity calls.
    pub workspaces: WorkspaceCache,
    /// With a model attached, the scenario built for runs driven by an input signal (whose
    /// tensions the model checks instead of the scenario's): built on the first such run and kept,
    /// so that a control loop of short runs does not read and check the model at every call.
    signal_built: OnceLock<Built>,
    /// Each tendon's tension limit on its own (`plausibility::tension_limits`), computed at the
    /// first quantity given tensions: past it a quantity's tensions get the statics' verdict.
    tension_limits: OnceLock<Vec<f64>>,
}

/// Builds `scenario` and attaches `attached` as `gvsrom … --model DIR` does, warning in Python
/// what the command line prints as warnings.
pub fn build_with(
    py: Python<'_>,
    scenario: &Scenario,
    attached: Option<&Attached>,
    tensions_from_signal: bool,
) -> PyResult<Built> {
    let built = py
        .detach(|| attach_to(scenario, attached, tensions_from_signal))
        .map_err(errors::any)?;
    for w in built.reduced.iter().flat_map(|r| &r.warnings) {
        warn(py, w)?;
    }
    Ok(built)
}

/// [`build_with`] without Python: the scenario built, and `attached` attached to it.
fn attach_to(
    scenario: &Scenario,
    attached: Option<&Attached>,
    tensions_from_signal: bool,
) -> anyhow::Result<Built> {
    let mut built = gvsrom::build(&scenario.scenario)?;
    if let Some(a) = attached {
        let options = AttachOptions {
            extrapolate: a.extrapolate,
            tensions_from_signal,
        };
        reduce::attach_source(
            &mut built,
            &scenario.src,
            &scenario.overrides,
            &a.dir,
            options,
        )?;
        if let (Some(loaded), Some(r)) = (&a.loaded, &built.reduced) {
            if !same_content(loaded, &r.origin) {
                anyhow::bail!(
                    "model `{}`: the directory changed since `load_model` read it (it was written again): load it again to use what it holds now",
                    a.dir.display()
                );
            }
        }
    }
    Ok(built)
}

/// What follows a model's refusal of the robot's own tensions where the rest of the scenario lies
/// inside its training (a model trained on motion under tensions the preset never holds).
const TENSIONS_OUTSIDE: &str = "the model was trained for this scenario except its tensions, which a robot uses wherever no `u` is given (statics(), linearize(), modes(), the quantities, a simulation without input): set tensions inside the training inputs above before attaching it (scenario.set(\"tendons.*.tension\", u) for all, or one tendon by its index)";

/// Whether two readings of a directory found the same content (the manifest's hashes; a directory
/// without recorded hashes cannot tell, and passes).
fn same_content(a: &gvsrom::provenance::DirOrigin, b: &gvsrom::provenance::DirOrigin) -> bool {
    a.meta_sha256 == b.meta_sha256 && a.sha256 == b.sha256
}

/// How an answer of `built` at the tensions `u` used its reduced model outside its training
/// ([`gvsrom::Built::model_extrapolated`]), the tensions found for displacement drives among it
/// warned of as the command line warns of them (the attach's sentences were, when it was built).
pub fn model_extrapolated(
    py: Python<'_>,
    built: &gvsrom::Built,
    u: &[f64],
) -> PyResult<Vec<String>> {
    let all = built.model_extrapolated(u);
    let attached = built.reduced.as_ref().map_or(0, |r| r.extrapolated.len());
    for s in all.iter().skip(attached) {
        warn(py, &format!("extrapolating (--extrapolate): {s}"))?;
    }
    Ok(all)
}

/// A `UserWarning` in Python, the command line's flags spelled as keyword arguments
/// ([`errors::python_spelling`]).
pub fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    let message = errors::python_spelling(message);
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    PyErr::warn(py, &py.get_type::<PyUserWarning>(), &text, 1)
}

/// A reduced model made from equilibria only, asked for a motion, its modes or its
/// linearization, says so as a `UserWarning` (as the command line prints its `note`).
pub fn warn_motion_note(py: Python<'_>, built: &gvsrom::Built) -> PyResult<()> {
    match built.reduced.as_ref().and_then(|r| r.motion_note()) {
        Some(note) => warn(py, &note),
        None => Ok(()),
    }
}

impl Robot {
    pub fn new(py: Python<'_>, scenario: Scenario, attached: Option<Attached>) -> PyResult<Robot> {
        let built = match build_with(py, &scenario, attached.as_ref(), false) {
            // refused for the scenario's own tensions alone: say which way leads on
            Err(e)
                if attached.is_some()
                    && py
                        .detach(|| attach_to(&scenario, attached.as_ref(), true))
                        .is_ok() =>
            {
                return Err(invalid(format!("{}; {TENSIONS_OUTSIDE}", e.value(py))));
            }
            other => other?,
        };
        for w in gvsrom::build::warnings(&scenario.scenario, &built) {
            warn(py, &w)?;
        }
        Ok(Robot {
            scenario,
            built,
            attached,
            workspaces: WorkspaceCache::default(),
            signal_built: OnceLock::new(),
            tension_limits: OnceLock::new(),
        })
    }

    /// The scenario to run under an input signal: with a model attached, built (once) with the
    /// model checking the signal's tensions rather than the scenario's ([`build_with`]); else the
    /// robot's own.
    pub fn built_for_signal(&self, py: Python<'_>) -> PyResult<&Built> {
        let Some(att) = &self.attached else {
            return Ok(&self.built);
        };
        if let Some(b) = self.signal_built.get() {
            return Ok(b);
        }
        let b = build_with(py, &self.scenario, Some(att), true)?;
        Ok(self.signal_built.get_or_init(|| b))
    }

    /// [`Self::built_for_signal`] once it has been called (the robot's own before): for a thread
    /// that cannot build it.
    pub fn built_for_signal_ready(&self) -> &Built {
        match (&self.attached, self.signal_built.get()) {
            (Some(_), Some(b)) => b,
            _ => &self.built,
        }
    }

    /// The scenario with tensions `u` (`--tension`), built with the model attached: for the runs
    /// whose reduced model needs its initial guess at `u`.
    pub(crate) fn rebuilt_with(
        &self,
        py: Python<'_>,
        u: Option<&[f64]>,
        attached: &Attached,
    ) -> PyResult<Built> {
        let mut scenario = self.scenario.clone();
        if let Some(u) = u {
            scenario.scenario.set_tensions(u).map_err(err)?;
        }
        build_with(py, &scenario, Some(attached), false)
    }

    /// The coordinates `q` of a model quantity: `n_dof` finite values, for a reduced model attached
    /// without `extrapolate` inside its training encodings, where its decoder answers (as
    /// `simulate(q0=…)` and `Model.decode` refuse a code far outside them; a POD model's far
    /// outside its data is answered with a `UserWarning`, as its simulation notes it), and a state
    /// of an elastic rod ([`quantities::state_violation`], as a simulation's samples are checked).
    pub(crate) fn coordinates(&self, q: &In1<'_>) -> PyResult<nalgebra::DVector<f64>> {
        let q = arrays::dvec("q", q, self.built.n_dof())?;
        let reduced = self.built.reduced.as_ref().filter(|r| !r.extrapolate);
        if let Some(v) = reduced.and_then(|r| r.range_violation(q.as_slice())) {
            return Err(invalid(format!(
                "`q`: {v}: the decoder extrapolates there and its quantities are not to be trusted; accepted: a state inside the training region, or the model attached with extrapolate=True"
            )));
        }
        // a POD basis is linear and answers everywhere: leaving its data is said, not refused
        if let Some(v) = reduced.and_then(|r| r.data_range_violation(q.as_slice())) {
            Python::attach(|py| {
                warn(
                    py,
                    &format!("`q`: {v}: the POD basis is linear and answers there, but no snapshot checked its quantities"),
                )
            })?;
        }
        if let Some(v) = quantities::state_violation(&self.built, &self.workspaces, &q) {
            return Err(invalid(format!(
                "`q` is no state of an elastic rod: {v}; accepted: a state within the bounds that end a simulation, where the model's quantities mean something"
            )));
        }
        Ok(q)
    }

    /// The scenario built again at the tensions `u` (`--tension`) with the attached model, as the
    /// command line would build it, for a result about the equilibrium under `u` (`modes`,
    /// `linearize`); `None` without `u`: this robot's own build serves.
    pub(crate) fn built_at(
        &self,
        py: Python<'_>,
        u: Option<&Tensions<'_>>,
    ) -> PyResult<Option<Built>> {
        let Some(u) = u else {
            return Ok(None);
        };
        let u = self.given_tensions(&u.values())?;
        let mut scenario = self.scenario.clone();
        scenario.scenario.set_tensions(&u).map_err(err)?;
        Ok(Some(build_with(
            py,
            &scenario,
            self.attached.as_ref(),
            false,
        )?))
    }

    /// Tensions `u` as a Python caller gives them: one for every tendon or one per tendon, each
    /// finite; errors name `u` (the library names the scenario's `tendons`).
    pub(crate) fn given_tensions(&self, u: &[f64]) -> PyResult<Vec<f64>> {
        let n = self.built.model.n_actuators();
        let u = gvsrom::scenario::tensions_for(n, u).map_err(|e| match e {
            gvsrom::error::ScenarioError::Invalid { message, .. } => {
                invalid(format!("`u`: {message}"))
            }
            other => err(other),
        })?;
        Ok(arrays::finite("u", u.into())?.as_slice().to_vec())
    }

    /// Tensions of a model quantity: the scenario's, or `u` (one per tendon or one for all),
    /// finite, and with a reduced model attached where it answers (as `statics(u)` refuses
    /// tensions its training never came near: the model's verdict, unless attached with
    /// `extrapolate`).
    pub(crate) fn quantity_tensions(
        &self,
        py: Python<'_>,
        u: Option<Tensions<'_>>,
    ) -> PyResult<Vec<f64>> {
        let Some(u) = u else {
            // a tendon driven by displacement has no tension until a statics finds it
            if let Some(k) = self.built.displacement.iter().position(Option::is_some) {
                return Err(invalid(format!(
                    "`u`: tendons[{k}] is driven by its displacement, so this robot has no tension to use: give `u` (e.g. `robot.statics().u`, the tensions that hold the displacements)"
                )));
            }
            return Ok(self.built.u.clone());
        };
        let u = self.given_tensions(&u.values())?;
        // tensions far beyond the rod's elastic range are refused as statics refuses them (1e300
        // N gave an elastic force of inf): checked in full only past a tendon's own limit
        let limits =
            (self.tension_limits).get_or_init(|| gvsrom::plausibility::tension_limits(&self.built));
        if u.iter().zip(limits).any(|(v, lim)| v.abs() > *lim) {
            let u_abs: Vec<f64> = u.iter().map(|v| v.abs()).collect();
            gvsrom::plausibility::check(&self.built, &u_abs, 1.0).map_err(err)?;
        }
        if let (Some(r), Some(a)) = (&self.built.reduced, &self.attached) {
            if !r.extrapolate && !r.covers_tensions(&self.built.u, &u) {
                // attaching the model to the scenario at `u` gives its verdict and reasons
                self.rebuilt_with(py, Some(&u), a)?;
            }
        }
        Ok(u)
    }
}

#[pymethods]
impl Robot {
    /// The scenario's name.
    #[getter]
    fn name(&self) -> String {
        self.built.name.clone()
    }

    /// A copy of the scenario this robot was built from.
    #[getter]
    fn scenario(&self) -> Scenario {
        self.scenario.clone()
    }

    /// The attached reduced model's directory, or ``None``.
    #[getter]
    fn model(&self) -> Option<PathBuf> {
        self.attached.as_ref().map(|a| a.dir.clone())
    }

    /// Generalized coordinates n of the model that runs (the reduced model's if attached).
    #[getter]
    fn n_dof(&self) -> usize {
        self.built.n_dof()
    }

    /// Number of tendons (actuators).
    #[getter]
    fn n_actuators(&self) -> usize {
        self.built.model.n_actuators()
    }

    /// Number of computational points.
    #[getter]
    fn n_points(&self) -> usize {
        self.built.model.disc.n_points()
    }

    /// Rod length L [m].
    #[getter]
    fn length(&self) -> f64 {
        self.built.model.disc.length()
    }

    /// The scenario's tendon tensions u [N]; NaN for a tendon driven by its displacement (its
    /// tension is found by ``statics()``).
    #[getter]
    fn tensions<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let u: Vec<f64> = (self.built.u.iter().zip(&self.built.displacement))
            .map(|(&u, d)| if d.is_some() { f64::NAN } else { u })
            .collect();
        arrays::vector(py, &u)
    }

    /// The displacements [m] the scenario drives its tendons by (wound in from the rest length);
    /// NaN for a tendon driven by its tension.
    #[getter]
    fn displacements<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let d: Vec<f64> = (self.built.displacement.iter())
            .map(|d| d.unwrap_or(f64::NAN))
            .collect();
        arrays::vector(py, &d)
    }

    /// Abscissae X of the computational points [m], shape ``(n_points,)``.
    #[getter]
    pub(crate) fn point_x<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let x: Vec<f64> = self.built.model.disc.points.iter().map(|p| p.x).collect();
        arrays::vector(py, &x)
    }

    /// Quadrature weights W of the computational points [m] (0 at the ends and extra points),
    /// shape ``(n_points,)``: integrals over the rod are ``Σ W_i f(X_i)``.
    #[getter]
    fn point_weights<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let w: Vec<f64> = self
            .built
            .model
            .disc
            .points
            .iter()
            .map(|p| p.weight)
            .collect();
        arrays::vector(py, &w)
    }

    /// Diagonal of the cross-section inertia ``Ms`` per unit length at each point
    /// ``[ρJ, ρI_y, ρI_z, ρA, ρA, ρA]``, shape ``(n_points, 6)``: kg·m for the first three, kg/m
    /// for the last three.
    #[getter]
    fn section_inertia<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = &self.built.model;
        let rows: Vec<[f64; 6]> = (0..m.disc.n_points())
            .map(|i| std::array::from_fn(|a| m.section(i).ms[a]))
            .collect();
        arrays::shaped(py, arrays::flat(&rows), [rows.len(), 6])
    }

    /// The computational point of each rigid body (``[[bodies]]``), shape ``(n_bodies,)``, int64:
    /// ``point_x[body_points[k]]`` is body k's ``x``.
    #[getter]
    fn body_points<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let points: Vec<i64> = self.built.model.body_points().map(|i| i as i64).collect();
        numpy::PyArray::from_vec(py, points).into_any()
    }

    /// The spatial inertia ``Mb = [I_c − m c̃c̃, m c̃; −m c̃, m I]`` of each rigid body at its
    /// section (angular first, body axes), shape ``(n_bodies, 6, 6)``: the mass matrix is
    /// ``Σ W_i J_iᵀ Ms_i J_i + Σ_b J_bᵀ Mb J_b`` with ``J_b`` the Jacobian at ``body_points[b]``.
    #[getter]
    fn body_inertia<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let bodies: Vec<[f64; 36]> = (self.built.model.bodies())
            .map(|b| {
                let mb = b.spatial_inertia();
                std::array::from_fn(|k| mb[(k / 6, k % 6)])
            })
            .collect();
        arrays::shaped(py, arrays::flat(&bodies), [bodies.len(), 6, 6])
    }

    /// Diagonal of the cross-section stiffness ``Es`` at each point
    /// ``[GJ, EI_y, EI_z, EA, GA, GA]``, shape ``(n_points, 6)``: N·m² for the first three, N
    /// for the last three.
    #[getter]
    fn section_stiffness<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = &self.built.model;
        let rows: Vec<[f64; 6]> = (0..m.disc.n_points())
            .map(|i| std::array::from_fn(|a| m.section(i).es[a]))
            .collect();
        arrays::shaped(py, arrays::flat(&rows), [rows.len(), 6])
    }

    /// The reference strain ξ* at each point, shape ``(n_points, 6)`` in the order ``[torsion,
    /// bend-y, bend-z, elongation, shear-y, shear-z]`` (1/m, then dimensionless): the unloaded
    /// rod's strain, ``[0, 0, 0, 1, 0, 0]`` unless the scenario pre-strains a division
    /// (``divisions.N.reference_strain``). ``q = 0`` is this rod; strain deviations and a
    /// dataset's ``strain`` are ``ξ − ξ*``.
    #[getter]
    fn strain_reference<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = &self.built.model;
        let rows: Vec<[f64; 6]> = (0..m.disc.n_points())
            .map(|i| std::array::from_fn(|a| m.xi_star(i)[a]))
            .collect();
        arrays::shaped(py, arrays::flat(&rows), [rows.len(), 6])
    }

    /// This scenario with a reduced model in place of its strain basis (``--model DIR``).
    ///
    /// Parameters
    /// ----------
    /// model : Model or str or os.PathLike
    ///     From :func:`load_model`, or a model directory (loaded as ``load_model(path)`` loads
    ///     it).
    /// extrapolate : bool, optional
    ///     Use the model where the scenario lies outside what it was trained on (``--extrapolate``);
    ///     the reasons are then warned about. Default: the model's own setting
    ///     (``load_model(…, extrapolate=…)``; ``False`` for a directory).
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     If the model was not learned on this scenario's points, or the scenario lies outside
    ///     its training (without ``extrapolate``); for a directory that is not a model, or whose
    ///     files were edited.
    /// TypeError
    ///     If ``model`` is neither a Model nor a path.
    #[pyo3(signature = (model, extrapolate=None))]
    fn with_model(
        &self,
        py: Python<'_>,
        model: &Bound<'_, PyAny>,
        extrapolate: Option<bool>,
    ) -> PyResult<Robot> {
        let attached = Model::attached_from(py, model, extrapolate)?;
        Robot::new(py, self.scenario.clone(), Some(attached))
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot(name={:?}, n_dof={}, n_actuators={}, length={}{})",
            self.built.name,
            self.built.n_dof(),
            self.built.model.n_actuators(),
            self.built.model.disc.length(),
            match &self.attached {
                Some(a) => format!(", model={:?}", a.dir.display().to_string()),
                None => String::new(),
            }
        )
    }
}
