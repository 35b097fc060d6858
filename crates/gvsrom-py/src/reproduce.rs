//! `gvsrom.reproduce(study, out, quick=…)`: the paper's studies end to end, as
//! `gvsrom reproduce` runs them ([`gvsrom::reproduce::run`]), Ctrl-C included.

use crate::errors::{self, invalid};
use gvsrom::reproduce::{default_jobs, Case, Interrupted, Options, DEFAULT_NOISE};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::PathBuf;

/// The names the studies accept, for messages.
fn accepted() -> String {
    Case::EVERY
        .iter()
        .chain([&Case::All])
        .map(|c| c.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The cases named by `study`: a name or a list of names.
fn cases(study: &Bound<'_, PyAny>) -> PyResult<Vec<Case>> {
    let names: Vec<String> = match study.cast::<PyString>() {
        Ok(s) => vec![s.to_str()?.to_string()],
        Err(_) => study.extract().map_err(|_| {
            invalid(format!(
                "`study`: expected a study name or a list of them (accepted: {})",
                accepted()
            ))
        })?,
    };
    if names.is_empty() {
        return Err(invalid(format!(
            "`study`: no study given (accepted: {})",
            accepted()
        )));
    }
    names
        .iter()
        .map(|n| {
            Case::EVERY
                .into_iter()
                .chain([Case::All])
                .find(|c| c.name() == n)
                .ok_or_else(|| invalid(format!("unknown study `{n}` (accepted: {})", accepted())))
        })
        .collect()
}

// the signature's literal default (a constant would show as `...` in Python's signature)
const _: () = assert!(DEFAULT_NOISE == 0.02);

/// Reproduces the paper's studies as ``gvsrom reproduce`` does: datasets, POD and autoencoder
/// ROMs, tables beside the paper's, figures, one report directory per study and ``index.html``
/// in ``out``. A run again with the same options reuses every finished step. Ctrl-C stops at the
/// next step boundary, keeps the finished steps and raises ``KeyboardInterrupt``.
///
/// Parameters
/// ----------
/// study : str or list of str
///     ``"iv-a"``, ``"iv-b"``, ``"iv-c1"``, ``"iv-c2"``, ``"v"``, ``"noise"`` or ``"all"``.
/// out : str or os.PathLike
///     The run directory (created, or an earlier run's; the command line's default is
///     ``results``).
/// quick : bool
///     Reduced sizes: every study in minutes, the paper's trends but not its numbers.
/// jobs : int, optional
///     Worker threads (default: one per core).
/// noise : float
///     The noise study's σ relative to each strain component's RMS.
/// test_sizes : bool
///     The smallest sizes that still run every step (implies ``quick``; for tests).
///
/// Returns
/// -------
/// list of dict
///     Per study done: ``study``, ``dir`` (its report directory), ``wall_time_s``, ``steps``,
///     ``reused``.
///
/// Raises
/// ------
/// GvsromError
///     For an unknown study or a bad option (the message of ``gvsrom reproduce``).
#[pyfunction]
#[pyo3(signature = (study, out, quick=false, jobs=None, noise=0.02, test_sizes=false))]
pub fn reproduce<'py>(
    py: Python<'py>,
    study: &Bound<'py, PyAny>,
    out: PathBuf,
    quick: bool,
    #[pyo3(from_py_with = crate::arrays::whole_or_none)] jobs: Option<i128>,
    noise: f64,
    test_sizes: bool,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let jobs = jobs
        .map(|v| crate::arrays::size("jobs", v, 1))
        .transpose()?;
    let opts = Options {
        cases: cases(study)?,
        quick: quick || test_sizes,
        tiny: test_sizes,
        out,
        jobs: jobs.unwrap_or_else(default_jobs),
        noise,
    };
    let (result, caught) = crate::interrupt::run(py, |flag| {
        gvsrom::reproduce::run(&opts, flag, &mut std::io::sink())
    });
    let done = match result {
        Ok(done) => done,
        Err(e) => {
            if let Some(i) = e.downcast_ref::<Interrupted>() {
                return Err(PyKeyboardInterrupt::new_err(i.to_string()));
            }
            return Err(errors::any(e));
        }
    };
    if let Some(e) = caught {
        return Err(e);
    }
    done.iter()
        .map(|c| {
            let d = PyDict::new(py);
            d.set_item("study", c.case.name())?;
            d.set_item("dir", &c.dir)?;
            d.set_item("wall_time_s", c.wall_time_s)?;
            d.set_item("steps", c.steps)?;
            d.set_item("reused", c.reused)?;
            Ok(d)
        })
        .collect()
}
