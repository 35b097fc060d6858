//! Reduced models: `gvsrom.load_model(path)` and `gvsrom.pod(dataset, modes, out)` (the library's
//! `gvsrom pod`).

use crate::arrays::{shaped, vector, InDyn};
use crate::errors::{self, invalid};
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
    /// The numbers of `weights.safetensors` by name, as arrays.
    #[pyo3(get)]
    arrays: Py<PyDict>,
    /// `[min, max]` of the training encodings per reduced coordinate, shape (r, 2).
    #[pyo3(get)]
    latent_range: Py<PyAny>,
    /// Reduced coordinates of the rest state, shape (r,).
    #[pyo3(get)]
    rest: Py<PyAny>,
    /// `meta.json` as a dict.
    #[pyo3(get)]
    meta: Py<PyAny>,
    /// The model itself, for `encode` / `decode` / `reconstruct`.
    model: ReducedModel,
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
        return Err(invalid(format!(
            "`{name}` has shape {shape}; expected ({cols},) or (rows, {cols}) ({what})"
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
            .map_err(|e| invalid(e.to_string()))?;
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
    ///     Encode a snapshot whose code lies far outside the training encodings (default: the
    ///     model's own ``extrapolate``).
    ///
    /// Returns
    /// -------
    /// numpy.ndarray, shape (latent,) or (rows, latent)
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     On a wrong shape or a non-finite value, or a code far outside the training encodings
    ///     (the snapshot is unlike the training data) unless ``extrapolate``.
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
            DatasetArg::Loaded(d) => d.get().path(),
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
        })
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

/// The ``dataset`` argument of [`Model::reconstruction`]: a loaded dataset or a directory.
#[derive(FromPyObject)]
pub enum DatasetArg<'py> {
    Loaded(Bound<'py, crate::datasets::Dataset>),
    Dir(PathBuf),
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
///     Snapshots whose code lies far outside the training encodings.
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
    /// Snapshots whose code lies far outside the training encodings.
    #[pyo3(get)]
    outside: usize,
}

#[pymethods]
impl Reconstruction {
    fn __repr__(&self) -> String {
        format!(
            "Reconstruction(rows={}, rmse={:.4e}, relative={:.4e}, outside={})",
            self.rows, self.rmse, self.relative, self.outside
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
    let arrays = PyDict::new(py);
    for (name, (shape, values)) in m.arrays() {
        let a = numpy::PyArray::from_vec(py, values).reshape(shape)?;
        arrays.set_item(name, a)?;
    }
    let range: Vec<f64> = m.meta.latent_range.iter().flatten().copied().collect();
    let meta = crate::datasets::meta_json(py, &path)?;
    Ok(Model {
        kind: m.meta.kind.clone(),
        latent: m.meta.latent,
        extrapolate,
        arrays: arrays.unbind(),
        latent_range: shaped(py, range, [m.meta.latent_range.len(), 2])?.unbind(),
        rest: vector(py, &m.meta.rest).unbind(),
        meta: meta.unbind(),
        dir: path,
        model: m,
    })
}

/// POD of a dataset's strain snapshots (``gvsrom pod DATASET --modes K --out MODEL``).
///
/// Parameters
/// ----------
/// dataset : Dataset or str or os.PathLike, or a sequence of them
///     A dataset (``gvsrom dataset``, ``load_dataset``) or its directory, or several of one scenario
///     (the same points, components, sampled inputs and physics) whose snapshots are combined in
///     order.
/// modes : int
///     POD modes kept (reduced coordinates).
/// out : str or os.PathLike
///     The new model directory.
/// force : bool
///     Replace ``out`` if it is an earlier gvsrom output.
/// norm : str
///     ``"plain"`` (every strain value weighs 1: the paper's POD) or ``"energy"`` (each value weighted
///     by the section stiffness, as ``train(loss="energy")``; ``gvsrom pod --norm``).
///
/// Returns
/// -------
/// Model
///     The new model.
#[pyfunction]
#[pyo3(signature = (dataset, modes, out, force=false, norm="plain"))]
pub fn pod(
    py: Python<'_>,
    dataset: &Bound<'_, PyAny>,
    modes: usize,
    out: PathBuf,
    force: bool,
    norm: &str,
) -> PyResult<Model> {
    use gvsrom::reduce::PodNorm;
    let norm = [PodNorm::Plain, PodNorm::Energy]
        .into_iter()
        .find(|n| n.name() == norm)
        .ok_or_else(|| {
            invalid(format!(
                "invalid `norm`: `{norm}` (accepted: plain, energy)"
            ))
        })?;
    let dataset = dataset_paths(dataset)?;
    let summary = py
        .detach(|| gvsrom::reduce::pod(&dataset, modes, norm, &out, force))
        .map_err(errors::any)?;
    for w in &summary.warnings {
        crate::robot::warn(py, w)?;
    }
    load_model(py, summary.path, false)
}

/// The ``init`` argument of ``train``: a ``Model`` or its directory; a ``TypeError`` naming
/// ``init`` otherwise.
fn model_path(arg: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    if let Ok(m) = arg.extract::<PyRef<'_, Model>>() {
        return Ok(m.dir.clone());
    }
    arg.extract::<PathBuf>().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "invalid `init`: got a {}; accepted: a Model or a model directory (str or os.PathLike)",
            type_name(arg)
        ))
    })
}

/// The name of `a`'s Python type, for a ``TypeError`` (``?`` if it has none).
fn type_name(a: &Bound<'_, PyAny>) -> String {
    a.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}

/// The ``dataset`` argument of ``pod`` and ``train``: a dataset (a ``Dataset`` or its directory)
/// or a sequence of them, of one scenario, whose snapshots are combined in order; a ``TypeError``
/// naming ``dataset`` otherwise.
fn dataset_paths(arg: &Bound<'_, PyAny>) -> PyResult<Vec<PathBuf>> {
    let one = |a: &Bound<'_, PyAny>| -> Option<PathBuf> {
        match a.extract::<Bound<'_, crate::datasets::Dataset>>() {
            Ok(d) => Some(d.get().path()),
            Err(_) => a.extract::<PathBuf>().ok(),
        }
    };
    let refuse = |a: &Bound<'_, PyAny>| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "invalid `dataset`: got a {}; accepted: a Dataset, a dataset directory (str or os.PathLike), or a sequence of them",
            type_name(a)
        ))
    };
    if let Some(p) = one(arg) {
        return Ok(vec![p]);
    }
    let Ok(items) = arg.try_iter() else {
        return Err(refuse(arg));
    };
    let mut paths = vec![];
    for item in items {
        let item = item?;
        paths.push(one(&item).ok_or_else(|| refuse(&item))?);
    }
    Ok(paths)
}

/// How often training looks for Ctrl-C.
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(100);

/// Trains a tanh autoencoder on a dataset's strain snapshots; its decoder becomes a nonlinear
/// reduced model (``gvsrom train DATASET … --out MODEL``, with the same defaults). Ctrl-C stops
/// training, saves the best weights so far and raises ``KeyboardInterrupt``.
///
/// Parameters
/// ----------
/// dataset : Dataset or str or os.PathLike, or a sequence of them
///     A dataset (``gvsrom dataset``, ``load_dataset``) or its directory, or several of one scenario
///     (the same points, components, sampled inputs and physics) whose snapshots are combined in
///     order.
/// out : str or os.PathLike
///     The new model directory.
/// latent : int, optional
///     Latent size r (reduced coordinates); default 1, or the ``init`` model's.
/// hidden_layers : int, optional
///     Hidden layers of the whole autoencoder (odd: 3, 5, 7…); default 7, or the ``init`` model's.
/// epochs, batch_size, learning_rate, lambda_, patience, lr_reductions, lbfgs_iterations
///     As the ``gvsrom train`` options of the same names (``lambda_`` is ``--lambda``; patience 0:
///     never stop early).
/// validation_fraction, seed : optional
///     The fraction held out for validation (default 0.1) and the seed of the initialisation,
///     split and shuffles (default 0); with ``init``, the model's, so that a continuation holds
///     out the same rows (others are allowed, with a warning).
/// loss : str, optional
///     ``"energy"`` (default), ``"physical"`` or ``"standardized"``; with ``init``, the model's.
/// sample_weighting : str
///     ``"uniform"`` (eq. 15) or ``"relative"``: each snapshot's squared error over its own
///     squared norm, so that small loads are fitted as closely as large ones.
/// relative_floor : float
///     The relative weighting's floor, a fraction of the largest snapshot norm in (0, 1].
/// decoder : str, optional
///     Default ``"plain"``, or the ``init`` model's: ``"plain"`` (the paper's, x̂ = D(z)) or ``"scaled"`` (x̂ = z₁ D(z): every code with z₁ = 0
///     decodes to the straight rod, for snapshots that shrink to rest as their load vanishes).
/// rate_weight : float
///     Weight β ≥ 0 of the strain-rate term (``--rate-weight``): the autoencoder's tangent map must
///     carry each trajectory sample's strain rate; 0 is eq. (15) alone. Needs trajectory data.
/// lr_decay : float or None
///     ``--lr-decay``: the Adam rate decays exponentially to this factor of it, in (0, 1], over
///     ``epochs``; None keeps it constant between plateaus.
/// kinetic_weight : float
///     ``--kinetic-weight``: weight κ ≥ 0 of the kinetic-energy norm (errors weighed by each
///     snapshot's mass matrix M(q)); needs ``rate_weight`` > 0. 0: none.
/// init : Model or str or os.PathLike, optional
///     ``--init``: start from this autoencoder model's weights and scaling (more epochs, or a
///     fine-tuning on new snapshots of its scenario); its latent size, hidden layers, decoder and
///     loss are kept (give none of them, or the model's).
/// force : bool
///     Replace ``out`` if it is an earlier gvsrom output.
///
/// Returns
/// -------
/// Model
///     The new model.
#[pyfunction]
#[pyo3(signature = (dataset, out, latent=None, hidden_layers=None, epochs=2000, batch_size=64, learning_rate=1e-3, lambda_=1e-4, validation_fraction=None, patience=50, lr_reductions=4, lbfgs_iterations=300, seed=None, loss=None, sample_weighting="uniform", relative_floor=0.1, decoder=None, rate_weight=0.0, lr_decay=None, kinetic_weight=0.0, init=None, force=false))]
#[allow(clippy::too_many_arguments)]
pub fn train(
    py: Python<'_>,
    dataset: &Bound<'_, PyAny>,
    out: PathBuf,
    latent: Option<usize>,
    hidden_layers: Option<usize>,
    epochs: usize,
    batch_size: usize,
    learning_rate: f64,
    lambda_: f64,
    validation_fraction: Option<f64>,
    patience: usize,
    lr_reductions: usize,
    lbfgs_iterations: usize,
    seed: Option<u64>,
    loss: Option<&str>,
    sample_weighting: &str,
    relative_floor: f64,
    decoder: Option<&str>,
    rate_weight: f64,
    lr_decay: Option<f64>,
    kinetic_weight: f64,
    init: Option<&Bound<'_, PyAny>>,
    force: bool,
) -> PyResult<Model> {
    use gvsrom::reduce::Loss;
    use rom::nn::TrainOptions;
    let init = match init {
        Some(m) => Some(gvsrom::reduce::start_model(&model_path(m)?).map_err(errors::any)?),
        None => None,
    };
    let loss = match loss {
        Some(name) => Some(Loss::from_name(name).ok_or_else(|| {
            invalid(format!(
                "invalid `loss`: `{name}` (accepted: energy, physical, standardized)"
            ))
        })?),
        None => None,
    };
    let decoder = match decoder {
        Some(name) => Some(gvsrom::reduce::decoder_form(name).map_err(errors::scenario)?),
        None => None,
    };
    let asked = gvsrom::reduce::TrainChoices {
        latent,
        hidden_layers,
        decoder,
        loss,
        seed,
        validation_fraction,
    };
    let given = TrainOptions {
        lambda: lambda_,
        epochs,
        batch_size,
        learning_rate,
        patience: (patience > 0).then_some(patience),
        lr_reductions,
        lr_decay,
        fine_tune: rom::nn::FineTune::lbfgs(lbfgs_iterations),
        sample_weighting: gvsrom::reduce::sample_weighting(sample_weighting, relative_floor)
            .map_err(errors::scenario)?,
        rate_weight,
        ..TrainOptions::default()
    };
    let (options, loss) = gvsrom::reduce::train_settings(init.as_ref(), &asked, given);
    let dataset = dataset_paths(dataset)?;
    let mut interrupt: Option<PyErr> = None;
    let summary = py.detach(|| {
        let mut last_poll = std::time::Instant::now();
        let mut progress = |_epoch: usize, _train: f64, _val: Option<f64>| {
            if last_poll.elapsed() < SIGNAL_POLL {
                return std::ops::ControlFlow::Continue(());
            }
            last_poll = std::time::Instant::now();
            match Python::attach(|py| py.check_signals()) {
                Ok(()) => std::ops::ControlFlow::Continue(()),
                Err(e) => {
                    interrupt = Some(e);
                    std::ops::ControlFlow::Break(())
                }
            }
        };
        gvsrom::reduce::train(
            &dataset,
            init.as_ref(),
            &options,
            loss,
            kinetic_weight,
            &out,
            force,
            &mut progress,
        )
    });
    let summary = summary.map_err(errors::any)?;
    for w in &summary.warnings {
        crate::robot::warn(py, w)?;
    }
    if let Some(e) = interrupt {
        return Err(e);
    }
    load_model(py, summary.path, false)
}
