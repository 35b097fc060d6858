//! Datasets: `gvsrom.dataset(...)` generates one as `gvsrom dataset` does (the library's
//! [`gvsrom::dataset::run`], Ctrl-C included), `gvsrom.load_dataset(path)` reads one back
//! ([`gvsrom::dataset::Dataset::load`]) as a `Dataset` of NumPy arrays with its metadata.

use crate::arrays::{held, shaped};
use crate::errors::{self, invalid};
use crate::scenario::Scenario;
use gvsrom::dataset::{DatasetRequest, DEFAULT_CHUNK_SIZE};
use numpy::PyArray;
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::PathBuf;

/// A dataset directory read back (``gvsrom dataset`` or :func:`dataset`), its files checked
/// against their recorded hashes. Arrays are as the ``.npy`` files hold them, one row per sample.
///
/// Attributes
/// ----------
/// path : pathlib.Path
/// kind : str
///     ``"statics"`` or ``"dynamics"``.
/// scenario : str
/// parameters : list of str
///     Names of the columns of ``inputs``.
/// components : list of str
///     The active strain components stored per point, in column order.
/// inputs : numpy.ndarray, shape (N, len(parameters))
/// strain : numpy.ndarray, shape (N, n_points * len(components))
///     ``ξ − ξ*`` point-major (column ``j * len(components) + c``); NaN rows for failed samples.
/// q : numpy.ndarray, shape (N, n_dof)
///     HOM coordinates.
/// tip_position : numpy.ndarray, shape (N, 3)
///     [m]
/// tip_rotation : numpy.ndarray, shape (N, 3, 3)
/// status : numpy.ndarray of uint8, shape (N,)
///     0 ok, 1 failed, 2 not computed.
/// iterations : numpy.ndarray of int64, shape (N,)
///     The statics solver's iterations per sample (0 in a dynamic dataset: no solve).
/// residual : numpy.ndarray, shape (N,)
///     ‖R‖∞ (generalized forces) at each equilibrium; NaN where nothing was solved (failed samples, and every row
///     of a dynamic dataset: its snapshots are states of a motion, not equilibria).
/// strain_x : numpy.ndarray, shape (n_points,)
///     [m]
/// t : numpy.ndarray or None
///     Sample times [s] of a dynamic dataset.
/// tendon_lengths : numpy.ndarray or None, shape (N, n_tendons)
///     The tendons' lengths [m], what a position-controlled actuator reads (NaN rows for failed
///     samples); ``None`` for a dataset written before they were recorded (compute them with
///     ``Robot.tendon_lengths(q)``).
/// complete : bool
///     False for an interrupted dataset.
/// meta : dict
///     ``meta.json`` (manifest, scenario TOML, plan, seed, counts, failures, …).
#[pyclass(module = "gvsrom", frozen)]
pub struct Dataset {
    pub(crate) dir: PathBuf,
    /// ``"statics"`` or ``"dynamics"``.
    #[pyo3(get)]
    kind: String,
    /// The scenario's name.
    #[pyo3(get)]
    scenario: String,
    /// Names of the columns of ``inputs``.
    #[pyo3(get)]
    parameters: Vec<String>,
    /// The stored strain components, in column order within a point.
    #[pyo3(get)]
    components: Vec<String>,
    /// Generalized coordinates of the HOM.
    #[pyo3(get)]
    n_dof: usize,
    /// Computational points.
    #[pyo3(get)]
    n_points: usize,
    /// False for an interrupted dataset.
    #[pyo3(get)]
    complete: bool,
    /// The sampling plan's seed.
    #[pyo3(get)]
    seed: u64,
    /// Inputs, shape (N, len(parameters)).
    #[pyo3(get)]
    inputs: Py<PyAny>,
    /// Strain snapshots ``ξ − ξ*``, shape (N, n_points · len(components)), point-major.
    #[pyo3(get)]
    strain: Py<PyAny>,
    /// HOM coordinates, shape (N, n_dof).
    #[pyo3(get)]
    q: Py<PyAny>,
    /// Tip positions [m], shape (N, 3).
    #[pyo3(get)]
    tip_position: Py<PyAny>,
    /// Tip rotations, shape (N, 3, 3).
    #[pyo3(get)]
    tip_rotation: Py<PyAny>,
    /// 0 ok, 1 failed, 2 not computed (uint8), shape (N,).
    #[pyo3(get)]
    status: Py<PyAny>,
    /// Statics solver iterations (int64; the file holds them as uint32), shape (N,); 0 in a dynamic dataset.
    #[pyo3(get)]
    iterations: Py<PyAny>,
    /// ‖R‖∞ at the equilibria, shape (N,); NaN where nothing was solved (failed samples, every row
    /// of a dynamic dataset).
    #[pyo3(get)]
    residual: Py<PyAny>,
    /// Abscissae of the computational points [m], shape (n_points,).
    #[pyo3(get)]
    strain_x: Py<PyAny>,
    /// Sample times [s] of a dynamic dataset, else ``None``.
    #[pyo3(get)]
    t: Option<Py<PyAny>>,
    /// The tendons' lengths [m], shape (N, n_tendons); ``None`` for a dataset written before
    /// they were recorded.
    #[pyo3(get)]
    tendon_lengths: Option<Py<PyAny>>,
    /// ``meta.json`` as the loader verified it.
    pub(crate) meta_json: serde_json::Value,
}

impl Dataset {
    /// Its directory, for a computation that reads it again (`pod`, `train`, `reconstruction`):
    /// refused if the directory no longer holds what `load_dataset` read (its manifest's hashes
    /// differ, or it is gone), so that a result is never computed from other data than the
    /// object's.
    pub(crate) fn unchanged_dir(&self) -> PyResult<PathBuf> {
        use gvsrom::provenance::DirOrigin;
        let now = std::fs::read(self.dir.join(gvsrom::output::MANIFEST_FILE))
            .ok()
            .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok());
        let loaded = DirOrigin::of_manifest(&self.dir, &self.meta_json);
        match now.is_some_and(|m| DirOrigin::of_manifest(&self.dir, &m) == loaded) {
            true => Ok(self.dir.clone()),
            false => Err(errors::invalid(format!(
                "dataset `{}`: the directory no longer holds what `load_dataset` read (it was written again, or removed): load it again to use what it holds now",
                self.dir.display()
            ))),
        }
    }
}

#[pymethods]
impl Dataset {
    /// The dataset directory.
    #[getter]
    pub(crate) fn path(&self) -> PathBuf {
        self.dir.clone()
    }

    /// ``meta.json`` as a dict (a new one at each access: editing it changes nothing).
    #[getter]
    fn meta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        meta_dict(py, &self.meta_json)
    }

    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.status.bind(py).len()
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Dataset(path={:?}, kind={:?}, scenario={:?}, samples={}, parameters={:?})",
            self.dir.display().to_string(),
            self.kind,
            self.scenario,
            self.__len__(py).unwrap_or(0),
            self.parameters
        )
    }
}

/// Reads a dataset directory (``gvsrom dataset`` or :func:`dataset`).
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///
/// Returns
/// -------
/// Dataset
///
/// Raises
/// ------
/// GvsromError
///     If it is not a dataset, or a file is missing, truncated or edited (naming it).
#[pyfunction]
pub fn load_dataset(py: Python<'_>, path: PathBuf) -> PyResult<Dataset> {
    let d = py
        .detach(|| gvsrom::dataset::Dataset::load(&path))
        .map_err(|e| errors::any(e.into()))?;
    let n = d.status.len();
    let m = &d.meta;
    let row = d.strain.len().checked_div(n).unwrap_or(0);
    Ok(Dataset {
        kind: m.kind.clone(),
        scenario: m.scenario.clone(),
        parameters: m.parameters.clone(),
        components: m.components.clone(),
        n_dof: m.n_dof,
        n_points: m.n_points,
        complete: m.complete,
        seed: m.seed,
        inputs: held(shaped(py, d.inputs, [n, m.parameters.len()])?)?,
        strain: held(shaped(py, d.strain, [n, row])?)?,
        q: held(shaped(py, d.q, [n, m.n_dof])?)?,
        tip_position: held(shaped(py, d.tip_position, [n, 3])?)?,
        tip_rotation: held(shaped(py, d.tip_rotation, [n, 3, 3])?)?,
        status: held(PyArray::from_vec(py, d.status).into_any())?,
        // int64 as `StaticsBatch.iterations`: the file's u32 wraps around in arithmetic
        iterations: held(
            PyArray::from_vec(py, d.iterations.iter().map(|&i| i64::from(i)).collect()).into_any(),
        )?,
        residual: held(PyArray::from_vec(py, d.residual).into_any())?,
        strain_x: held(PyArray::from_vec(py, d.strain_x).into_any())?,
        t: d.t
            .map(|t| held(PyArray::from_vec(py, t).into_any()))
            .transpose()?,
        tendon_lengths: match (d.tendon_lengths, m.n_tendons) {
            (Some(l), Some(na)) => Some(held(shaped(py, l, [n, na])?)?),
            _ => None,
        },
        meta_json: d.meta_json,
        // absolute: `pod`, `train` and `reconstruction` read the directory again, maybe after a
        // change of the working directory
        dir: std::path::absolute(&path).unwrap_or(path),
    })
}

/// A meta.json value as the loader verified it (a dataset's or a model's) as a Python dict.
pub fn meta_dict<'py>(py: Python<'py>, meta: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?
        .call_method1("loads", (meta.to_string(),))
}

/// The `PATH=LO:HI` specs of a `sweep`/`grid`/`random` argument: a string, a sequence of them,
/// or a dict `{path: (lo, hi)}`.
fn specs(name: &str, value: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
    let Some(v) = value else { return Ok(vec![]) };
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(vec![s.to_str()?.to_string()]);
    }
    if let Ok(d) = v.cast::<PyDict>() {
        return d
            .iter()
            .map(|(k, range)| {
                let path: String = k.extract()?;
                let (lo, hi): (f64, f64) = range.extract().map_err(|_| {
                    invalid(format!(
                        "`{name}[{path:?}]`: expected a (lo, hi) pair of numbers"
                    ))
                })?;
                Ok(format!("{path}={lo:?}:{hi:?}"))
            })
            .collect();
    }
    v.extract::<Vec<String>>().map_err(|_| {
        invalid(format!(
            "`{name}`: expected \"PATH=LO:HI\", a list of them, or a dict {{path: (lo, hi)}}"
        ))
    })
}

/// The scenario argument of `gvsrom dataset` (a preset name or a TOML path) and the overrides
/// to apply before `set`, for a name, a path or a `Scenario`.
fn scenario_arg(value: &Bound<'_, PyAny>) -> PyResult<(String, Vec<String>)> {
    if let Ok(s) = value.cast::<Scenario>() {
        let s = s.borrow();
        if s.src.preset {
            return Ok((s.src.default_name.clone(), s.overrides.clone()));
        }
        // a file's origin is its path; text given in Python has none
        if s.src.origin == gvsrom::presets::TEXT_ORIGIN {
            return Err(invalid(
                "`scenario`: a Scenario from TOML text has no file to record in the dataset; write `scenario.to_toml()` to a file and pass its path",
            ));
        }
        return Ok((s.src.origin.clone(), s.overrides.clone()));
    }
    let path: PathBuf = value.extract().map_err(|_| {
        invalid(
            "`scenario`: expected a preset name, the path of a scenario TOML file, or a Scenario",
        )
    })?;
    Ok((path.to_string_lossy().into_owned(), vec![]))
}

// the signature's literal default (a constant would show as `...` in Python's signature)
const _: () = assert!(DEFAULT_CHUNK_SIZE == 128);

/// Options of a dynamic dataset given without `duration` (the command line's `requires`).
fn dynamic_only(duration: Option<f64>, given: &[(&str, bool)]) -> PyResult<()> {
    if duration.is_some() {
        return Ok(());
    }
    match given.iter().find(|(_, g)| *g) {
        Some((name, _)) => Err(invalid(format!(
            "`{name}` is an option of a dynamic dataset: give `duration` too"
        ))),
        None => Ok(()),
    }
}

/// Generates a dataset as ``gvsrom dataset`` does (same files, bit-identical for the same plan
/// and seed): the HOM solved over a sampling plan (static), or one simulation sampled (dynamic,
/// with ``duration``). Ctrl-C stops it after the chunks under way, writes the finished ones
/// (marked incomplete; ``resume=True`` continues) and raises ``KeyboardInterrupt``.
///
/// Parameters
/// ----------
/// scenario : str, os.PathLike or Scenario
///     A preset name, a scenario TOML file, or a :class:`Scenario` from a preset or a file (its
///     overrides are applied before ``set``).
/// out : str or os.PathLike
///     The new dataset directory.
/// sweep, grid, random : str, list of str or dict, optional
///     ``"PATH=LO:HI"`` specs (or ``{path: (lo, hi)}``) as ``--sweep``, ``--grid``, ``--random``:
///     an even 1-D sweep, a product grid, or uniform random values (seeded by ``seed``).
/// samples : int, optional
///     Number of samples (``--samples``).
/// seed : int, optional
///     Seed of ``random`` (and of a dynamic dataset's ``steps``/``babble``); default 0. Refused
///     with a plan that draws nothing (``sweep``, ``grid``, ``input``).
/// set : str or list of str, optional
///     ``"PATH=VALUE"`` overrides (``--set``).
/// chunk_size : int
///     Samples per chunk (part of the plan).
/// threads : int, optional
///     Worker threads (default: one per core); the files do not depend on it.
/// force : bool
///     Replace ``out`` if it is an earlier gvsrom output.
/// resume : bool
///     Continue the incomplete dataset in ``out``.
/// duration, sample_rate : float, optional
///     A dynamic dataset: simulated time [s] and samples per second [Hz].
/// input : str or os.PathLike, optional
///     Dynamic: a CSV file ``t, u_1, …`` (``--input``), linear with ``interpolate``.
/// steps : sequence of 3 floats, optional
///     Dynamic: random steps ``(lo, hi, period)``.
/// babble : sequence of 4 floats, optional
///     Dynamic: actuator babbling ``(lo, hi, hold_min, hold_max)``.
/// from_equilibrium : bool
///     Dynamic: start at the static equilibrium.
/// rtol, atol : float, optional
///     Dynamic: integrator tolerances (default as ``Robot.simulate``; atol 1e-6).
///
/// Returns
/// -------
/// Dataset
///     The new dataset, read back.
///
/// Raises
/// ------
/// GvsromError
///     For a bad plan or option (the message of ``gvsrom dataset``).
#[pyfunction]
#[pyo3(signature = (scenario, out, sweep=None, grid=None, random=None, samples=None, seed=None, set=None, chunk_size=128, threads=None, force=false, resume=false, duration=None, sample_rate=None, input=None, interpolate=false, steps=None, babble=None, from_equilibrium=false, rtol=None, atol=None))]
#[allow(clippy::too_many_arguments)]
pub fn dataset(
    py: Python<'_>,
    scenario: &Bound<'_, PyAny>,
    out: PathBuf,
    sweep: Option<&Bound<'_, PyAny>>,
    grid: Option<&Bound<'_, PyAny>>,
    random: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = crate::arrays::whole_or_none)] samples: Option<i128>,
    #[pyo3(from_py_with = crate::arrays::whole_or_none)] seed: Option<i128>,
    set: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = crate::arrays::whole)] chunk_size: i128,
    #[pyo3(from_py_with = crate::arrays::whole_or_none)] threads: Option<i128>,
    force: bool,
    resume: bool,
    #[pyo3(from_py_with = crate::arrays::real_or_none)] duration: Option<f64>,
    #[pyo3(from_py_with = crate::arrays::real_or_none)] sample_rate: Option<f64>,
    input: Option<PathBuf>,
    interpolate: bool,
    steps: Option<Vec<f64>>,
    babble: Option<Vec<f64>>,
    from_equilibrium: bool,
    rtol: Option<f64>,
    atol: Option<f64>,
) -> PyResult<Dataset> {
    use crate::arrays::{size, unsigned};
    let samples = samples.map(|v| size("samples", v, 1)).transpose()?;
    let seed = seed.map(|v| unsigned("seed", v)).transpose()?;
    let chunk_size = size("chunk_size", chunk_size, 1)?;
    let threads = threads.map(|v| size("threads", v, 1)).transpose()?;
    let (scenario, mut overrides) = scenario_arg(scenario)?;
    // the values given here, not the scenario's own (the base its plan varies)
    let given = crate::arrays::strings("set", set)?;
    overrides.extend(given.iter().cloned());
    crate::simulate_args::random_counts(steps.as_deref(), babble.as_deref())?;
    dynamic_only(
        duration,
        &[
            ("sample_rate", sample_rate.is_some()),
            ("input", input.is_some()),
            ("steps", steps.is_some()),
            ("babble", babble.is_some()),
            ("from_equilibrium", from_equilibrium),
            ("rtol", rtol.is_some()),
            ("atol", atol.is_some()),
        ],
    )?;
    if interpolate && input.is_none() {
        return Err(invalid(
            "`interpolate` applies to an `input` file: give one",
        ));
    }
    if force && resume {
        return Err(invalid(
            "`force` and `resume` exclude each other: resume continues the dataset in `out`, force replaces it",
        ));
    }
    let args = DatasetRequest {
        scenario,
        set: overrides,
        sweep: specs("sweep", sweep)?,
        grid: specs("grid", grid)?,
        random: specs("random", random)?,
        samples,
        seed,
        chunk_size,
        threads,
        out,
        force,
        resume,
        duration,
        sample_rate,
        input,
        interpolate,
        steps,
        babble,
        from_equilibrium,
        rtol,
        atol: atol.unwrap_or(gvsrom::simulate::DEFAULT_ATOL),
        stop_after_chunks: None,
    };
    gvsrom::dataset::refuse_set_varied(&given, &args).map_err(|e| errors::any(e.into()))?;
    let (outcome, caught) = crate::interrupt::run(py, |flag| gvsrom::dataset::run(&args, &flag));
    let outcome = outcome.map_err(|e| errors::any(e.into()))?;
    if let Some(message) = outcome.interruption_message() {
        return Err(PyKeyboardInterrupt::new_err(message));
    }
    if let Some(e) = caught {
        return Err(e);
    }
    for w in outcome.warnings.iter().chain(&outcome.failure_message()) {
        crate::robot::warn(py, w)?;
    }
    load_dataset(py, outcome.path)
}
