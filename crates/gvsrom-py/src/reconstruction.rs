//! `Model.reconstruction(dataset)` and its result, the `Reconstruction` class: a model's
//! reconstruction errors on a dataset (the library's [`gvsrom::reduce::reconstruction`], as
//! `gvsrom reconstruct`).

use crate::errors;
use crate::models::Model;
use pyo3::prelude::*;
use std::path::PathBuf;

#[pymethods]
impl Model {
    /// How closely the model reconstructs the solved snapshots of a dataset of its layout,
    /// ``x̂ = D(E(x))`` (``gvsrom reconstruct MODEL DATASET``): Table I's RMSE on any data, e.g. data
    /// the model was not trained on.
    ///
    /// Parameters
    /// ----------
    /// dataset : Dataset or str or os.PathLike
    ///     A dataset (``load_dataset``) or its directory, of the model's points and components.
    ///
    /// Returns
    /// -------
    /// Reconstruction
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     If the dataset has another layout (naming both) or no solved snapshot.
    fn reconstruction(&self, py: Python<'_>, dataset: DatasetArg<'_>) -> PyResult<Reconstruction> {
        let dir = match dataset {
            DatasetArg::Loaded(d) => d.get().unchanged_dir()?,
            DatasetArg::Dir(p) => p,
        };
        let r = py
            .detach(|| {
                let ds = gvsrom::dataset::Dataset::load(&dir)?;
                gvsrom::reduce::reconstruction(&self.model, &ds).map_err(anyhow::Error::from)
            })
            .map_err(errors::any)?;
        Ok(Reconstruction {
            rows: r.rows,
            rmse: r.rmse,
            relative: r.relative,
            worst: r.worst,
            largest_norm: r.largest_norm,
            outside: r.outside,
            unseen_inputs: r.unseen_inputs,
            inputs_note: r.inputs_note,
            other_physics: r.other_physics,
        })
    }
}

/// The ``dataset`` argument of [`Model::reconstruction`]: a loaded dataset or a directory.
pub enum DatasetArg<'py> {
    Loaded(Bound<'py, crate::datasets::Dataset>),
    Dir(PathBuf),
}

impl<'a, 'py> FromPyObject<'a, 'py> for DatasetArg<'py> {
    type Error = PyErr;

    /// Else a `TypeError` saying what is accepted (not pyo3's account of its enum's variants).
    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Ok(d) = ob.extract::<Bound<'py, crate::datasets::Dataset>>() {
            return Ok(DatasetArg::Loaded(d));
        }
        ob.extract::<PathBuf>().map(DatasetArg::Dir).map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "invalid `dataset`: got a {}; accepted: a Dataset or a dataset directory (str or os.PathLike)",
                ob.get_type().name().map_or("value".to_string(), |n| n.to_string())
            ))
        })
    }
}

/// A model's reconstruction errors on a dataset (``Model.reconstruction``).
///
/// Attributes
/// ----------
/// rows : int
///     Solved snapshots evaluated.
/// rmse : float
///     ``sqrt(mean (x̂ − x)²)`` over every entry of every snapshot (Table I), in strain units.
/// relative : float
///     ``‖X̂ − X‖_F / ‖X‖_F`` over the dataset.
/// worst : tuple[int, float, float] or None
///     The dataset row with the largest ``‖x̂ − x‖ / ‖x‖``, that ratio and ``‖x‖`` (None if every
///     snapshot is zero).
/// largest_norm : float
///     The largest ``‖x‖``, for scale.
/// outside : int
///     Snapshots outside the training data: their code far outside the training encodings,
///     or their norm over twice the largest training snapshot's.
/// unseen_inputs : int or None
///     Snapshots whose inputs lie outside what the model was trained on: an input outside its
///     training range, or a combination far from the training inputs (as ``model=`` refuses
///     them). None when the dataset does not sample the model's inputs (``inputs_note`` says why).
/// inputs_note : str or None
///     Why ``unseen_inputs`` is None.
/// other_physics : str or None
///     The first way the dataset's physics differs from the model's training scenario (then every
///     snapshot is an extrapolation), or None.
#[pyclass(module = "gvsrom", frozen)]
pub struct Reconstruction {
    /// Solved snapshots evaluated.
    #[pyo3(get)]
    rows: usize,
    /// ``sqrt(mean (x̂ − x)²)`` over every entry of every snapshot (Table I).
    #[pyo3(get)]
    rmse: f64,
    /// ``‖X̂ − X‖_F / ‖X‖_F`` over the dataset.
    #[pyo3(get)]
    relative: f64,
    /// ``(row, ‖x̂ − x‖ / ‖x‖, ‖x‖)`` of the worst snapshot, or None.
    #[pyo3(get)]
    worst: Option<(usize, f64, f64)>,
    /// The largest ``‖x‖`` of the snapshots.
    #[pyo3(get)]
    largest_norm: f64,
    /// Snapshots outside the training data: their code far outside the training encodings, or
    /// their norm over twice the largest training snapshot's.
    #[pyo3(get)]
    outside: usize,
    /// Snapshots whose inputs lie outside what the model was trained on, or None.
    #[pyo3(get)]
    unseen_inputs: Option<usize>,
    /// Why ``unseen_inputs`` is None.
    #[pyo3(get)]
    inputs_note: Option<String>,
    /// The first way the dataset's physics differs from the model's, or None.
    #[pyo3(get)]
    other_physics: Option<String>,
}

#[pymethods]
impl Reconstruction {
    fn __repr__(&self) -> String {
        format!(
            "Reconstruction(rows={}, rmse={}, relative={}, outside={}, unseen_inputs={})",
            self.rows,
            gvs::error::fmt_sci(self.rmse, 4),
            gvs::error::fmt_sci(self.relative, 4),
            self.outside,
            self.unseen_inputs
                .map_or("None".to_string(), |n| n.to_string())
        )
    }
}
