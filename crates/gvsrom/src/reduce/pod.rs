//! `gvsrom pod DATASET --modes K --out MODEL`: proper orthogonal decomposition of a dataset's
//! strain snapshots as a linear reduced model.

use super::{
    dataset_ref, dataset_scenario, equilibrium_anchors, invalid, model_layout, projection_of,
    sample_inputs, snapshot_rows,
};
use crate::dataset::Dataset;
use crate::error::ScenarioError;
use crate::output::OutputDir;
use crate::reduced_model::{ModelMeta, ModelWeights, ReducedModel};
use rom::pod::{Pod, PodError};
use std::path::{Path, PathBuf};

/// What `gvsrom pod` reports.
pub struct PodSummary {
    pub path: PathBuf,
    pub rows: usize,
    pub features: usize,
    pub modes: usize,
    pub captured_energy: f64,
    pub singular_values: Vec<f64>,
    pub numerical_rank: usize,
    /// As [`TrainSummary::anchor_equilibria`] and [`TrainSummary::anchor_time_s`].
    pub anchor_equilibria: usize,
    pub anchor_time_s: f64,
    /// Warnings for the user (a dataset without content hashes).
    pub warnings: Vec<String>,
}

/// POD of a dataset's strain snapshots, `modes` modes, saved as a model at `out`.
pub fn pod(
    dataset: &Path,
    modes: usize,
    out: &Path,
    force: bool,
) -> Result<PodSummary, anyhow::Error> {
    let provenance = crate::provenance::Provenance::of_command();
    let ds = Dataset::load(dataset)?;
    let provenance = provenance.dataset("DATASET", dataset)?;
    let built = dataset_scenario(&ds)?;
    projection_of(&built)?; // the HOM basis must be recoverable from point strains
    let (x, rows) = snapshot_rows(&ds, "DATASET", built.model.rod.length())?;
    let features = ds.row_len();
    let dir = OutputDir::create("--out", out, crate::reduced_model::MODEL_FORMAT, force)?;
    let pod = Pod::compute(&x, features, modes).map_err(|e| pod_error(e, &ds, &x, features))?;
    let energy = pod.captured_energy();
    // anchors: each sample's POD coordinates Vᵀx, then the POD-ROM's own equilibria
    let latent = pod.encode_rows(&x);
    let latent_range = super::latent_range(&latent, modes);
    let meta = ModelMeta {
        kind: "pod".into(),
        latent: modes,
        layout: model_layout(&ds, &built),
        dataset: dataset_ref(dataset, &ds, rows),
        rest: vec![0.0; modes],
        latent_range,
        input_range: super::validity::input_ranges(&ds),
        anchor_parameters: ds.meta.parameters.clone(),
        anchor_equilibria: 0,
        captured_energy: Some(energy[modes - 1]),
        training: None,
        projection_residual: 0.0,
        crate_version: env!("CARGO_PKG_VERSION").into(),
        provenance: Some(provenance),
    };
    let mut model = ReducedModel {
        meta,
        weights: ModelWeights::Pod {
            modes: pod.modes.clone(),
            singular_values: pod.singular_values.clone(),
        },
        // written by this run: as its files will be hashed
        integrity: crate::output::Integrity::Checked,
        anchors: Some(crate::reduced_model::Anchors {
            n: rows,
            inputs: sample_inputs(&ds),
            latent,
        }),
    };
    let t_anchors = std::time::Instant::now();
    model.meta.anchor_equilibria = equilibrium_anchors(&built, &ds, &mut model)?;
    let anchor_time_s = t_anchors.elapsed().as_secs_f64();
    let path = model.save(
        dir,
        &[
            ("singular_values", &pod.singular_values),
            ("captured_energy", &energy),
        ],
    )?;
    Ok(PodSummary {
        warnings: super::dataset_warnings(&ds, dataset),
        path,
        rows,
        features,
        modes,
        captured_energy: energy[modes - 1],
        numerical_rank: pod.rank(1e-12),
        singular_values: pod.singular_values,
        anchor_equilibria: model.meta.anchor_equilibria,
        anchor_time_s,
    })
}

/// A POD error named by its cause: the number of modes, or the dataset (for a failed SVD, with the
/// largest strain value and its sample: a pathological value, not an option, makes it fail).
fn pod_error(e: PodError, ds: &Dataset, x: &[f64], features: usize) -> ScenarioError {
    match e {
        PodError::Modes { .. } => invalid("--modes", e.to_string()),
        PodError::Data(_) => invalid("DATASET", e.to_string()),
        PodError::Svd => {
            let (i, v) = x
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .map(|(i, v)| (i, *v))
                .unwrap_or((0, 0.0));
            let sample = ds.ok_rows().get(i / features.max(1)).copied().unwrap_or(0);
            invalid(
                "DATASET",
                format!(
                    "{e}: its largest strain value is {v:e} (sample {sample}); a value that large is not a strain the model can hold — check that sample"
                ),
            )
        }
    }
}
