//! `gvsrom.compare(reference, run)`: a trajectory measured against a reference one, as `gvsrom
//! compare` measures it ([`gvsrom::compare::run`]).

use crate::errors::{self, invalid};
use pyo3::prelude::*;
use std::path::PathBuf;

/// Measures a trajectory against a reference one of the same scenario, input and sample times, as
/// ``gvsrom compare`` does: e.g. a reduced model's run (``simulate(out=…)`` with a model
/// attached) against the full model's. Both are run directories (``Robot.simulate(…, out=…)`` or
/// ``gvsrom simulate --out``); nothing is written.
///
/// Parameters
/// ----------
/// reference : str or os.PathLike
///     The reference run's directory (e.g. the full model's).
/// run : str or os.PathLike
///     The run to measure (e.g. a reduced model's).
/// allow_different : bool
///     Compare them even if their scenario, physics, input or duration differ (or their
///     ``meta.json`` cannot tell); the result's ``differ`` and ``unknown`` then say how. Without
///     it such runs are refused, since one does not approximate the other.
///
/// Returns
/// -------
/// dict
///     What ``gvsrom compare --json`` writes: ``reference`` and ``run`` (each run's directory,
///     scenario, sizes, samples, wall time), ``comparison`` (``samples``; the tip errors in % of
///     the length: ``tip_mean``, ``tip_max``, ``tip_max_t``, ``tip_end``, ``tip_start``; the
///     strain errors; the tendons' length errors in mm), ``speed_ratio`` (the run's simulated
///     time per wall time over the reference's, ``None`` if it cannot be told), ``differ``,
///     ``unknown``, ``warnings`` (a run written before gvsrom recorded content hashes, also
///     raised as a ``UserWarning``) and ``provenance`` (both runs' hashes).
///
/// Raises
/// ------
/// GvsromError
///     For a directory that is not a trajectory (or was edited since it was written), runs that
///     differ (unless ``allow_different``), or runs without common samples.
#[pyfunction]
#[pyo3(signature = (reference, run, allow_different=false))]
pub fn compare<'py>(
    py: Python<'py>,
    reference: PathBuf,
    run: PathBuf,
    allow_different: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (text, warnings) = py
        .detach(|| -> anyhow::Result<(String, Vec<String>)> {
            let compared = gvsrom::compare::run(&reference, &run, allow_different)?;
            Ok((
                serde_json::to_string(&compared.report()?)?,
                compared.warnings,
            ))
        })
        .map_err(errors::any)?;
    for w in &warnings {
        crate::robot::warn(py, w)?;
    }
    let json = py.import("json").map_err(|e| invalid(e.to_string()))?;
    let report = json.call_method1("loads", (text,))?;
    // how the runs differ, named as Python names them (`reference`, `run`, `allow_different`)
    for key in ["differ", "unknown", "warnings"] {
        let spelled: Vec<String> = (report.get_item(key)?.extract::<Vec<String>>()?.iter())
            .map(|s| errors::python_spelling(s))
            .collect();
        report.set_item(key, spelled)?;
    }
    Ok(report)
}
