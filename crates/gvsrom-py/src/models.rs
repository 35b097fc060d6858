//! Reduced models: `gvsrom.load_model(path)` and `gvsrom.pod(dataset, modes, out)` (the library's
//! `gvsrom pod`).

use crate::errors::{self, invalid};
use gvsrom::reduced_model::ReducedModel;
use pyo3::prelude::*;
use std::path::PathBuf;

/// A reduced model directory (from ``gvsrom pod``, ``gvsrom train`` or :func:`pod`), checked
/// against its recorded hashes when loaded. Pass it as ``model=`` to :meth:`Robot.statics` or to
/// :meth:`Robot.with_model`.
///
/// Attributes
/// ----------
/// path : pathlib.Path
///     The model directory.
/// kind : str
///     ``"pod"`` or ``"autoencoder"``.
/// latent : int
///     Number of reduced coordinates r.
/// extrapolate : bool
///     Whether it may be used outside its training inputs (``--extrapolate``).
#[pyclass(module = "gvsrom", frozen)]
pub struct Model {
    pub dir: PathBuf,
    /// `"pod"` or `"autoencoder"`.
    #[pyo3(get)]
    kind: String,
    /// Number of reduced coordinates r.
    #[pyo3(get)]
    latent: usize,
    /// Whether it may be used outside its training inputs (`--extrapolate`).
    #[pyo3(get)]
    pub extrapolate: bool,
}

#[pymethods]
impl Model {
    /// The model directory.
    #[getter]
    fn path(&self) -> PathBuf {
        self.dir.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(path={:?}, kind={:?}, latent={})",
            self.dir.display().to_string(),
            self.kind,
            self.latent
        )
    }
}

/// Loads a reduced model directory.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     A model directory.
/// extrapolate : bool
///     Allow using it outside its training inputs (``--extrapolate``).
///
/// Raises
/// ------
/// GvsromError
///     If it is not a model directory, or its files were edited.
#[pyfunction]
#[pyo3(signature = (path, extrapolate=false))]
pub fn load_model(py: Python<'_>, path: PathBuf, extrapolate: bool) -> PyResult<Model> {
    let m = py
        .detach(|| ReducedModel::load(&path))
        .map_err(|e| invalid(e.to_string()))?;
    Ok(Model {
        dir: path,
        kind: m.meta.kind.clone(),
        latent: m.meta.latent,
        extrapolate,
    })
}

/// POD of a dataset's strain snapshots (``gvsrom pod DATASET --modes K --out MODEL``).
///
/// Parameters
/// ----------
/// dataset : str or os.PathLike
///     A dataset directory (``gvsrom dataset``).
/// modes : int
///     POD modes kept (reduced coordinates).
/// out : str or os.PathLike
///     The new model directory.
/// force : bool
///     Replace ``out`` if it is an earlier gvsrom output.
///
/// Returns
/// -------
/// Model
///     The new model.
#[pyfunction]
#[pyo3(signature = (dataset, modes, out, force=false))]
pub fn pod(
    py: Python<'_>,
    dataset: PathBuf,
    modes: usize,
    out: PathBuf,
    force: bool,
) -> PyResult<Model> {
    let summary = py
        .detach(|| gvsrom::reduce::pod(&dataset, modes, &out, force))
        .map_err(errors::any)?;
    for w in &summary.warnings {
        crate::robot::warn(py, w)?;
    }
    load_model(py, summary.path, false)
}
