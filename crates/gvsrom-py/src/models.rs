//! The `Model` class and `gvsrom.load_model(path)`: a reduced model directory read back
//! ([`ReducedModel::load`]), its arrays and metadata, and its encoder and decoder on NumPy rows.

use crate::arrays::{shaped, vector, InDyn};
use crate::errors::invalid;
use gvsrom::reduced_model::ReducedModel;
use numpy::PyArrayMethods;
use pyo3::prelude::*;
use pyo3::types::PyDict;
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
/// arrays : dict of str to numpy.ndarray
///     Its numbers as ``weights.safetensors`` stores them: POD ``modes`` (L × r) and
///     ``singular_values``; an autoencoder's ``encoder.{k}.weight``/``.bias``,
///     ``decoder.{k}.weight``/``.bias``, ``scaling.mean``, ``scaling.scale``; and
///     ``anchors.inputs``, ``anchors.latent`` if it has anchors.
/// latent_range : numpy.ndarray, shape (r, 2)
///     Per reduced coordinate, the ``[min, max]`` of the training encodings.
/// rest : numpy.ndarray, shape (r,)
///     The reduced coordinates a run starts from at rest.
/// meta : dict
///     ``meta.json`` (layout, dataset, training, input ranges, …).
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
    /// The numbers of `weights.safetensors` by name, as (read-only) arrays.
    arrays: Vec<(String, Py<PyAny>)>,
    /// `[min, max]` of the training encodings per reduced coordinate, shape (r, 2).
    #[pyo3(get)]
    latent_range: Py<PyAny>,
    /// Reduced coordinates of the rest state, shape (r,).
    #[pyo3(get)]
    rest: Py<PyAny>,
    /// The model itself, for `encode` / `decode` / `reconstruct` (and `reconstruction`).
    pub(crate) model: ReducedModel,
}

impl Model {
    /// This model to attach to a robot, with `extrapolate` (default: the model's own setting).
    pub fn attached(&self, extrapolate: Option<bool>) -> crate::robot::Attached {
        crate::robot::Attached {
            dir: self.dir.clone(),
            extrapolate: extrapolate.unwrap_or(self.extrapolate),
            loaded: self.model.origin(),
        }
    }

    /// The `model` argument of `Robot.with_model` and `Robot.statics`, to attach with
    /// `extrapolate` (default: the model's own setting): a `Model`, or a model directory (str or
    /// os.PathLike) loaded as `load_model(path)` loads it (so without `extrapolate` of its own); a
    /// `TypeError` naming `model` otherwise.
    pub(crate) fn attached_from(
        py: Python<'_>,
        model: &Bound<'_, PyAny>,
        extrapolate: Option<bool>,
    ) -> PyResult<crate::robot::Attached> {
        if let Ok(m) = model.cast::<Model>() {
            return Ok(m.get().attached(extrapolate));
        }
        match model.extract::<PathBuf>() {
            Ok(path) => Ok(load_model(py, path, false)?.attached(extrapolate)),
            Err(_) => Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "invalid `model`: got a {}; accepted: a Model or a model directory (str or os.PathLike)",
                model
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".to_string(), |n| n.to_string())
            ))),
        }
    }
}

/// The rows of a 1-D (one row) or 2-D input with `cols` columns each, row-major, and whether it was
/// 1-D; else a `GvsromError` naming `name`.
fn rows_of(name: &str, a: &InDyn<'_>, cols: usize, what: &str) -> PyResult<(Vec<f64>, bool)> {
    let v = a.as_array();
    let ok = match v.ndim() {
        1 => v.len() == cols,
        2 => v.shape()[1] == cols,
        _ => false,
    };
    if !ok {
        let dims: Vec<String> = v.shape().iter().map(usize::to_string).collect();
        let shape = match dims.len() {
            1 => format!("({},)", dims[0]),
            _ => format!("({})", dims.join(", ")),
        };
        // the strains of a result (`Statics.strain`): absolute, all six components per point
        let hint = match (name, v.shape()) {
            ("strain", [_, 6]) => "; a (points, 6) array of absolute strains, as `Statics.strain` gives them, converts to snapshot rows with `Robot.snapshot`",
            _ => "",
        };
        return Err(invalid(format!(
            "`{name}` has shape {shape}; expected ({cols},) or (rows, {cols}) ({what}){hint}"
        )));
    }
    Ok((v.iter().copied().collect(), v.ndim() == 1))
}

impl Model {
    /// `f` on the rows of `a` (1-D or 2-D, `cols` wide), its rows `out` wide, in `a`'s dimensions.
    fn map_rows<'py>(
        &self,
        py: Python<'py>,
        (name, a, cols, what): (&str, &InDyn<'_>, usize, &str),
        out: usize,
        f: impl FnOnce(&ReducedModel, &[f64]) -> Result<Vec<f64>, gvsrom::reduced_model::CodecError>
            + Send,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (x, one) = rows_of(name, a, cols, what)?;
        let y = py
            .detach(|| f(&self.model, &x))
            .map_err(|e| invalid(crate::errors::chain(&e)))?;
        if one {
            Ok(vector(py, &y))
        } else {
            let rows = y.len() / out;
            shaped(py, y, [rows, out])
        }
    }
}

#[pymethods]
impl Model {
    /// The model directory.
    #[getter]
    fn path(&self) -> PathBuf {
        self.dir.clone()
    }

    /// The numbers of ``weights.safetensors`` by name, as read-only arrays (a new dict at each
    /// access: editing it changes nothing).
    #[getter]
    fn arrays<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, a) in &self.arrays {
            d.set_item(name, a.bind(py))?;
        }
        Ok(d)
    }

    /// ``meta.json`` as a dict (a new one at each access: editing it changes nothing).
    #[getter]
    fn meta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match &self.model.dir {
            Some(dir) => crate::datasets::meta_dict(py, &dir.meta_json),
            None => Ok(py.None().into_bound(py)),
        }
    }

    /// Number of values of one snapshot: computational points × active strain components.
    #[getter]
    fn features(&self) -> usize {
        self.model.features()
    }

    /// Reduced coordinates of strain snapshots, ``q = E(x)``: POD ``Vᵀ x``, an autoencoder's
    /// encoder.
    ///
    /// Parameters
    /// ----------
    /// strain : array_like, shape (features,) or (rows, features)
    ///     Snapshots as a dataset stores them (:attr:`Dataset.strain`): ``ξ − ξ*`` of the active
    ///     components at the model's points, point-major.
    /// extrapolate : bool, optional
    ///     Encode a snapshot whose code lies far outside the training encodings, or whose norm
    ///     is over twice the largest training snapshot's (default: the model's own
    ///     ``extrapolate``).
    ///
    /// Returns
    /// -------
    /// numpy.ndarray, shape (latent,) or (rows, latent)
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     On a wrong shape or a non-finite value, or a code far outside the training encodings
    ///     or a norm over twice the largest training snapshot's (the snapshot is unlike the
    ///     training data) unless ``extrapolate``.
    #[pyo3(signature = (strain, extrapolate=None))]
    fn encode<'py>(
        &self,
        py: Python<'py>,
        strain: InDyn<'py>,
        extrapolate: Option<bool>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let e = extrapolate.unwrap_or(self.extrapolate);
        let arg = ("strain", &strain, self.model.features(), "snapshots");
        self.map_rows(py, arg, self.latent, |m, x| m.encode(x, e))
    }

    /// Strain snapshots of reduced coordinates, ``x̂ = D(q)``: POD ``V q``, an autoencoder's
    /// decoder.
    ///
    /// Parameters
    /// ----------
    /// q : array_like, shape (latent,) or (rows, latent)
    /// extrapolate : bool, optional
    ///     Decode a code far outside the training encodings, where a decoder has no data (default:
    ///     the model's own ``extrapolate``).
    ///
    /// Returns
    /// -------
    /// numpy.ndarray, shape (features,) or (rows, features)
    ///     In the layout of :attr:`Dataset.strain`.
    #[pyo3(signature = (q, extrapolate=None))]
    fn decode<'py>(
        &self,
        py: Python<'py>,
        q: InDyn<'py>,
        extrapolate: Option<bool>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let e = extrapolate.unwrap_or(self.extrapolate);
        let arg = ("q", &q, self.latent, "reduced coordinates");
        self.map_rows(py, arg, self.model.features(), |m, q| m.decode(q, e))
    }

    /// The model's reconstruction of strain snapshots, ``D(E(x))`` (Table I's ``x̂``).
    ///
    /// Parameters
    /// ----------
    /// strain : array_like, shape (features,) or (rows, features)
    /// extrapolate : bool, optional
    ///
    /// Returns
    /// -------
    /// numpy.ndarray, the shape of ``strain``
    #[pyo3(signature = (strain, extrapolate=None))]
    fn reconstruct<'py>(
        &self,
        py: Python<'py>,
        strain: InDyn<'py>,
        extrapolate: Option<bool>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let e = extrapolate.unwrap_or(self.extrapolate);
        let n = self.model.features();
        let arg = ("strain", &strain, n, "snapshots");
        self.map_rows(py, arg, n, |m, x| m.reconstruct(x, e))
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
        .map_err(|e| invalid(crate::errors::chain(&e)))?;
    let arrays = m
        .arrays()
        .into_iter()
        .map(|(name, (shape, values))| {
            let a = numpy::PyArray::from_vec(py, values).reshape(shape)?;
            Ok((name, crate::arrays::held(a.into_any())?))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let range: Vec<f64> = m.meta.latent_range.iter().flatten().copied().collect();
    Ok(Model {
        kind: m.meta.kind.clone(),
        latent: m.meta.latent,
        extrapolate,
        arrays,
        latent_range: crate::arrays::held(shaped(py, range, [m.meta.latent_range.len(), 2])?)?,
        rest: crate::arrays::held(vector(py, &m.meta.rest))?,
        // absolute: a robot reads the directory again when it attaches the model, maybe after a
        // change of the working directory
        dir: std::path::absolute(&path).unwrap_or(path),
        model: m,
    })
}
