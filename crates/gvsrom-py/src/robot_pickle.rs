//! Pickling a `Robot` (for `multiprocessing`, `concurrent.futures`, `joblib`): what it was built
//! from, built again when unpickled — the scenario (pickled as `Scenario` pickles: its source
//! text and overrides), and the attached model's directory (absolute), `extrapolate` and the
//! content it was read with, so that a model directory written again in between is refused as
//! `with_model` refuses one changed since `load_model` (a model that records content hashes: every
//! one written since they were recorded). Build warnings are raised again where it is unpickled.

use crate::errors::invalid;
use crate::robot::{Attached, Robot};
use crate::scenario::Scenario;
use pyo3::prelude::*;
use std::path::PathBuf;

/// What pickling keeps of a robot: its scenario, and the attached model's directory,
/// `extrapolate` and the content it was read with (JSON of its manifest's hashes), if any.
type Parts = (Scenario, Option<PathBuf>, bool, Option<String>);

#[pymethods]
impl Robot {
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Parts)> {
        let me = slf.get();
        let restore = slf.get_type().getattr("_restore")?;
        let (dir, extrapolate, origin) = match &me.attached {
            None => (None, false, None),
            Some(a) => {
                // another process may run elsewhere: the directory as an absolute path
                let dir = std::fs::canonicalize(&a.dir).unwrap_or_else(|_| a.dir.clone());
                let origin = (a.loaded.as_ref())
                    .map(serde_json::to_string)
                    .transpose()
                    .map_err(|e| invalid(format!("cannot pickle the model's origin: {e}")))?;
                (Some(dir), a.extrapolate, origin)
            }
        };
        Ok((restore, (me.scenario.clone(), dir, extrapolate, origin)))
    }

    /// The robot `__reduce__` describes (for `pickle`; not part of the API).
    #[staticmethod]
    fn _restore(
        py: Python<'_>,
        scenario: PyRef<'_, Scenario>,
        model: Option<PathBuf>,
        extrapolate: bool,
        origin: Option<String>,
    ) -> PyResult<Robot> {
        let attached = match model {
            None => None,
            Some(dir) => {
                let loaded = (origin.as_deref())
                    .map(serde_json::from_str)
                    .transpose()
                    .map_err(|e| invalid(format!("a pickled robot's model origin: {e}")))?;
                Some(Attached {
                    dir,
                    extrapolate,
                    loaded,
                })
            }
        };
        let scenario = scenario.clone();
        Robot::new(py, scenario, attached)
    }
}
