//! `gvsrom pod DATASET… --modes K --out MODEL`: proper orthogonal decomposition of the strain
//! snapshots of one or more datasets as a linear reduced model.

use super::sources::Sources;
use super::{equilibrium_anchors, invalid, model_layout, projection_of};
use crate::error::ScenarioError;
use crate::output::OutputDir;
use crate::reduced_model::{ModelMeta, ModelWeights, PodNorm, ReducedModel};
use rom::pod::{Pod, PodError};
use std::path::{Path, PathBuf};

/// What `gvsrom pod` reports.
pub struct PodSummary {
    pub path: PathBuf,
    pub rows: usize,
    /// Each dataset and its usable rows, in order (the rows are `rows` in all).
    pub datasets: Vec<(PathBuf, usize)>,
    pub features: usize,
    pub modes: usize,
    /// The norm of the POD, in which `captured_energy` is measured.
    pub norm: PodNorm,
    pub captured_energy: f64,
    pub singular_values: Vec<f64>,
    pub numerical_rank: usize,
    /// As `TrainSummary::anchor_equilibria` and `TrainSummary::anchor_time_s`.
    pub anchor_equilibria: usize,
    pub anchor_time_s: f64,
    /// Warnings for the user (a dataset without content hashes).
    pub warnings: Vec<String>,
}

/// The relative singular value `σ_k / σ₁` below which a mode counts as round-off (the printed
/// numerical rank).
pub const ROUND_OFF_RANK: f64 = 1e-12;

/// POD of the strain snapshots of `datasets` (one, or several of one scenario: their rows in
/// order) in the norm `norm`, `modes` modes, saved as a model at `out`.
pub fn pod<P: AsRef<Path>>(
    datasets: &[P],
    modes: usize,
    norm: PodNorm,
    out: &Path,
    force: bool,
) -> Result<PodSummary, anyhow::Error> {
    super::refuse_input_overlap(out, datasets, None)?;
    let provenance = crate::provenance::Provenance::of_command();
    let src = Sources::load(datasets)?;
    let provenance = src.record(provenance);
    let built = &src.built;
    super::at_most_the_full_models_dof("--modes", modes, built)?;
    let most = built.n_dof().min(src.rows());
    if modes > most {
        return Err(super::invalid(
            "--modes",
            format!(
                "{modes}: an integer in [1, {most}] (at most the full model's {} DOF and the {} snapshots)",
                built.n_dof(),
                src.rows()
            ),
        )
        .into());
    }
    // the HOM basis must be recoverable from point strains
    let (layout, _, _) = projection_of(built)?;
    let (x, rows, features) = (&src.x, src.rows(), src.features);
    let dir = OutputDir::create("--out", out, crate::reduced_model::MODEL_FORMAT, force)?;
    let pod = match norm {
        PodNorm::Plain => Pod::compute(x, features, modes),
        PodNorm::Energy => Pod::compute_weighted(
            x,
            features,
            modes,
            &super::stiffness_weights(built, &layout),
        ),
    }
    .map_err(|e| pod_error(e, &src))?;
    let energy = pod.captured_energy();
    // anchors: each sample's POD coordinates Vᵀx, then the POD-ROM's own equilibria
    let latent = pod.encode_rows(x);
    let latent_range = super::latent_range(&latent, modes);
    let refs = src.refs();
    let meta = ModelMeta {
        kind: "pod".into(),
        latent: modes,
        layout: model_layout(src.first(), built),
        dataset: refs.0,
        more_datasets: refs.1,
        rest: vec![0.0; modes],
        latent_range,
        snapshot_norm_max: Some(super::largest_norm(x, features)),
        input_range: src.input_ranges(),
        anchor_parameters: src.first().meta.parameters.clone(),
        anchor_equilibria: 0,
        captured_energy: Some(energy[modes - 1]),
        pod_norm: Some(norm),
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
            norm_weights: pod.weights.clone(),
        },
        // written by this run: as its files will be hashed
        integrity: crate::output::Integrity::Checked,
        dir: None,
        anchors: Some(crate::reduced_model::Anchors {
            n: rows,
            inputs: src.sample_inputs(),
            latent,
        }),
    };
    let t_anchors = std::time::Instant::now();
    if let Some(ds) = src.all_static() {
        model.meta.anchor_equilibria = equilibrium_anchors(built, ds, &mut model)?;
    }
    let anchor_time_s = t_anchors.elapsed().as_secs_f64();
    let path = model.save(
        dir,
        &[
            ("singular_values", &pod.singular_values),
            ("captured_energy", &energy),
        ],
    )?;
    let mut warnings = src.warnings();
    let rank = pod.rank(ROUND_OFF_RANK);
    if modes > rank {
        warnings.push(format!(
            "--modes {modes} exceeds the data's numerical rank {rank}: modes {}–{modes} have σ/σ₁ below {ROUND_OFF_RANK:e} (σ{modes} = {:.3e}, σ₁ = {:.3e}), directions set by the solver's tolerance and round-off rather than by the snapshots; the ROM still projects the full model onto them, but they are not the data's",
            rank + 1,
            pod.singular_values.get(modes - 1).copied().unwrap_or(0.0),
            pod.singular_values.first().copied().unwrap_or(0.0),
        ));
    }
    Ok(PodSummary {
        warnings,
        datasets: src.listing(),
        path,
        rows,
        features,
        modes,
        norm,
        captured_energy: energy[modes - 1],
        numerical_rank: rank,
        singular_values: pod.singular_values,
        anchor_equilibria: model.meta.anchor_equilibria,
        anchor_time_s,
    })
}

/// A POD error named by its cause: the number of modes, or the dataset (for a failed SVD, with the
/// largest strain value and its sample: a pathological value, not an option, makes it fail).
fn pod_error(e: PodError, src: &Sources) -> ScenarioError {
    let (x, features) = (&src.x, src.features);
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
            let (dir, sample) = src.origin_of(i / features.max(1));
            invalid(
                "DATASET",
                format!(
                    "{e}: the largest strain value is {v:e} (sample {sample} of `{}`); a value that large is not a strain the model can hold — check that sample",
                    dir.display()
                ),
            )
        }
    }
}
