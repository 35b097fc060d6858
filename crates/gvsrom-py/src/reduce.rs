//! Building reduced models: `gvsrom.pod(...)` and `gvsrom.train(...)` (the library's
//! [`gvsrom::reduce::pod`] and [`gvsrom::reduce::train`], `gvsrom pod` and `gvsrom train`), with
//! their `dataset` and `init` arguments.

use crate::errors;
use crate::models::{load_model, Model};
use gvsrom::reduce::TrainRequest;
use pyo3::prelude::*;
use std::path::PathBuf;

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
    #[pyo3(from_py_with = crate::arrays::whole)] modes: i128,
    out: PathBuf,
    force: bool,
    norm: &str,
) -> PyResult<Model> {
    let modes = crate::arrays::size("modes", modes, 1)?;
    let norm = gvsrom::reduce::named("norm", norm).map_err(errors::scenario)?;
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
    let one = |a: &Bound<'_, PyAny>| -> Option<PyResult<PathBuf>> {
        match a.extract::<Bound<'_, crate::datasets::Dataset>>() {
            Ok(d) => Some(d.get().unchanged_dir()),
            Err(_) => a.extract::<PathBuf>().ok().map(Ok),
        }
    };
    let refuse = |a: &Bound<'_, PyAny>| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "invalid `dataset`: got a {}; accepted: a Dataset, a dataset directory (str or os.PathLike), or a sequence of them",
            type_name(a)
        ))
    };
    if let Some(p) = one(arg) {
        return Ok(vec![p?]);
    }
    let Ok(items) = arg.try_iter() else {
        return Err(refuse(arg));
    };
    let mut paths = vec![];
    for item in items {
        let item = item?;
        paths.push(one(&item).ok_or_else(|| refuse(&item))??);
    }
    Ok(paths)
}

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
///     Hidden layers of the whole autoencoder (odd: 1, 3, 5, 7…, at most 63); default 7, or the ``init`` model's.
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
/// relative_floor : float, optional
///     The relative weighting's floor, a fraction of the largest snapshot norm in (0, 1]
///     (default 0.1); only with ``sample_weighting="relative"``.
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
// the defaults are literals, so that Python's signature shows them; tests/test_reduced.py checks
// them against `gvsrom train --help` (the library's `TrainRequest::DEFAULT`)
#[pyfunction]
#[pyo3(signature = (dataset, out, latent=None, hidden_layers=None, epochs=2000, batch_size=64, learning_rate=1e-3, lambda_=1e-4, validation_fraction=None, patience=50, lr_reductions=4, lbfgs_iterations=300, seed=None, loss=None, sample_weighting="uniform", relative_floor=None, decoder=None, rate_weight=0.0, lr_decay=None, kinetic_weight=0.0, init=None, force=false))]
#[allow(clippy::too_many_arguments)]
pub fn train(
    py: Python<'_>,
    dataset: &Bound<'_, PyAny>,
    out: PathBuf,
    #[pyo3(from_py_with = crate::arrays::whole_or_none)] latent: Option<i128>,
    #[pyo3(from_py_with = crate::arrays::whole_or_none)] hidden_layers: Option<i128>,
    #[pyo3(from_py_with = crate::arrays::whole)] epochs: i128,
    #[pyo3(from_py_with = crate::arrays::whole)] batch_size: i128,
    learning_rate: f64,
    lambda_: f64,
    validation_fraction: Option<f64>,
    #[pyo3(from_py_with = crate::arrays::whole)] patience: i128,
    #[pyo3(from_py_with = crate::arrays::whole)] lr_reductions: i128,
    #[pyo3(from_py_with = crate::arrays::whole)] lbfgs_iterations: i128,
    #[pyo3(from_py_with = crate::arrays::whole_or_none)] seed: Option<i128>,
    loss: Option<&str>,
    sample_weighting: &str,
    relative_floor: Option<f64>,
    decoder: Option<&str>,
    rate_weight: f64,
    lr_decay: Option<f64>,
    kinetic_weight: f64,
    init: Option<&Bound<'_, PyAny>>,
    force: bool,
) -> PyResult<Model> {
    use crate::arrays::{size, unsigned};
    use gvsrom::reduce::{self, TrainChoices};
    let latent = latent.map(|v| size("latent", v, 1)).transpose()?;
    let hidden_layers = hidden_layers
        .map(|v| size("hidden_layers", v, 1))
        .transpose()?;
    let seed = seed.map(|v| unsigned("seed", v)).transpose()?;
    let epochs = size("epochs", epochs, 1)?;
    let batch_size = size("batch_size", batch_size, 1)?;
    let patience = size("patience", patience, 0)?;
    let lr_reductions = size("lr_reductions", lr_reductions, 0)?;
    let lbfgs_iterations = size("lbfgs_iterations", lbfgs_iterations, 0)?;
    let init = match init {
        Some(m) => Some(reduce::start_model(&model_path(m)?).map_err(errors::any)?),
        None => None,
    };
    let request = TrainRequest {
        choices: TrainChoices {
            latent,
            hidden_layers,
            decoder: decoder
                .map(reduce::decoder_form)
                .transpose()
                .map_err(errors::scenario)?,
            loss: loss
                .map(|name| reduce::named("loss", name))
                .transpose()
                .map_err(errors::scenario)?,
            seed,
            validation_fraction,
        },
        lambda: lambda_,
        epochs,
        batch_size,
        learning_rate,
        patience,
        lr_reductions,
        lr_decay,
        lbfgs_iterations,
        sample_weighting: reduce::sample_weighting(sample_weighting, relative_floor)
            .map_err(errors::scenario)?,
        rate_weight,
    };
    let (options, loss) = request.resolve(init.as_ref());
    let dataset = dataset_paths(dataset)?;
    let mut signals = crate::interrupt::SignalPoll::new();
    let summary = py.detach(|| {
        let mut progress =
            |_epoch: usize, _train: f64, _val: Option<f64>| match signals.interrupted() {
                false => std::ops::ControlFlow::Continue(()),
                true => std::ops::ControlFlow::Break(()),
            };
        reduce::train(
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
    // a Ctrl-C first: the run it stopped may then end in an error (no epoch beat the start yet),
    // and the signal, already taken from Python's queue, would otherwise be lost
    if let Some(e) = signals.caught() {
        if let Ok(summary) = &summary {
            for w in &summary.warnings {
                let _ = crate::robot::warn(py, w);
            }
        }
        return Err(e);
    }
    let summary = summary.map_err(errors::any)?;
    for w in &summary.warnings {
        crate::robot::warn(py, w)?;
    }
    load_model(py, summary.path, false)
}
