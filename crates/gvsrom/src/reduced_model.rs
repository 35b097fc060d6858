//! Reduced-model files (`gvsrom pod … --out MODEL`, `gvsrom train … --out MODEL`): a directory
//! written through [`crate::output`] holding
//!
//! - `weights.safetensors`: the numbers, f64 little-endian, which Python opens with
//!   `safetensors.numpy.load_file`. POD: `modes` (L × K), `singular_values`. Autoencoder:
//!   `encoder.{k}.weight` (out × in, row-major), `encoder.{k}.bias`, `decoder.{k}.…`,
//!   `scaling.mean`, `scaling.scale` (`x = mean + scale ⊙ y` undoes the data scaling);
//! - `meta.json`: the kind, the point layout the model was learned on (scenario, `strain_x`, active
//!   components, HOM size), the datasets it came from (`dataset` and, for a model of several,
//!   `more_datasets`: path, hash of its `strain.npy`, rows used),
//!   the rest coordinates of the straight rod, and the training settings and results;
//! - training curves (`train_loss.npy`, `val_loss.npy`) or the POD spectrum (`singular_values.npy`,
//!   `captured_energy.npy`).
//!
//! Loading first checks every file and the metadata against the SHA-256 hashes recorded when the
//! model was written (`output::integrity`), then every tensor's name, dtype and shape against the
//! metadata: a truncated or edited file is an error naming it, never a different model. Only
//! regular files are opened ([`crate::output::read`]): a FIFO or device in place of a file is refused
//! by name, never waited on. Saved and
//! loaded models are bit-identical.

use crate::output::{Integrity, OutputError};
use rom::nn::Autoencoder;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use thiserror::Error;

mod codec;
mod weights_file;
pub use codec::{outside_range, oversized_row, row_norm, CodecError, SNAPSHOT_NORM_MARGIN};

/// The manifest format of a model directory.
pub const MODEL_FORMAT: &str = "reduced-model";
/// The weights file of a model directory.
pub const WEIGHTS_FILE: &str = "weights.safetensors";

#[derive(Debug, Error)]
pub enum ModelFileError {
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error("model `{path}`: {message}")]
    Invalid { path: PathBuf, message: String },
}

/// The strain layout a model was learned on; a scenario must match it to use the model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelLayout {
    /// Name of the scenario the dataset came from.
    pub scenario: String,
    /// Its TOML text.
    pub scenario_toml: String,
    /// Abscissae of the computational points \[m\].
    pub strain_x: Vec<f64>,
    /// Names of the active strain components, in 6-vector order.
    pub active: Vec<String>,
    /// Number of generalized coordinates of the HOM basis.
    pub hom_dof: usize,
}

impl ModelLayout {
    /// Length of one snapshot (points × active components).
    pub fn features(&self) -> usize {
        self.strain_x.len() * self.active.len()
    }
}

/// Whether two lists of point abscissae \[m\] are the same points: equal lengths and every pair
/// within 1e-12 of the larger of 1 m and the largest abscissa (rounding of the same quadrature).
pub fn same_abscissae(a: &[f64], b: &[f64]) -> bool {
    let scale = a.iter().chain(b).fold(1.0f64, |m, x| m.max(x.abs()));
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-12 * scale)
}

/// Where the training data came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DatasetRef {
    pub path: String,
    /// The SHA-256 of the `strain.npy` bytes the model was made from, as the dataset's manifest
    /// records it (16 hex digits of FNV-1a 64 in models made by earlier versions).
    pub strain_hash: String,
    /// Rows used (failed samples skipped).
    pub rows: usize,
    /// Whether its rows are one trajectory in time (a dynamic dataset) rather than independent
    /// samples; absent in models from before it was recorded, which the input coverage check
    /// (`reduce::coverage`) reads as a trajectory, the more lenient reading.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trajectory: Option<bool>,
}

/// The range of one training input over the usable samples (see `reduce::validity`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputRange {
    /// The dataset input's scenario path, e.g. `tendons.0.tension`.
    pub parameter: String,
    pub min: f64,
    pub max: f64,
}

/// The autoencoder's training record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainingMeta {
    pub hidden_layers: usize,
    pub encoder_sizes: Vec<usize>,
    pub decoder_sizes: Vec<usize>,
    pub lambda: f64,
    pub epochs: usize,
    pub batch_size: usize,
    pub learning_rate: f64,
    pub validation_fraction: f64,
    pub patience: Option<usize>,
    pub seed: u64,
    /// The loss weighting (`standardized`, `physical`, `energy`); absent in models from before the
    /// choice existed, which were trained standardized.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loss: Option<String>,
    /// Learning-rate reductions at plateaus (absent: from before they existed, none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lr_reductions: Option<usize>,
    /// The final factor of the exponential rate decay (`--lr-decay`; absent: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lr_decay: Option<f64>,
    /// Copies of the zero-strain snapshot trained with the data (absent: none, from before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zero_anchor_rows: Option<usize>,
    /// Iterations allowed to the final L-BFGS phase (absent: from before the option, 300).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lbfgs_iterations: Option<usize>,
    /// The snapshot weighting: `"uniform"` or `"relative"` (absent: from before the option,
    /// uniform).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_weighting: Option<String>,
    /// The floor of the relative weighting (absent for uniform).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relative_floor: Option<f64>,
    /// The decoder's form, `"plain"` or `"scaled"` (`rom::nn::DecoderForm`; absent: from before
    /// the option, plain).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decoder: Option<String>,
    /// The weight `β` of the strain-rate term (`rom::nn::rates`; absent: from before the option, 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_weight: Option<f64>,
    /// The weight `κ` of the kinetic-energy norm (`--kinetic-weight`; absent: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kinetic_weight: Option<f64>,
    /// Adam epochs and L-BFGS fine-tuning iterations run, together (`best_epoch` counts both).
    pub epochs_run: usize,
    /// Of `epochs_run`, the L-BFGS fine-tuning iterations (absent in models written before it
    /// was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fine_tune_iterations_run: Option<usize>,
    pub best_epoch: usize,
    pub stop: String,
    pub final_train_loss: f64,
    pub final_val_loss: Option<f64>,
    /// RMSE of the reconstruction in physical strain units (paper Table I).
    pub final_train_rmse: f64,
    pub final_val_rmse: Option<f64>,
    pub wall_time_s: f64,
}

/// `meta.json` of a model directory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelMeta {
    /// `"pod"` or `"autoencoder"`.
    pub kind: String,
    /// Number of reduced coordinates r.
    pub latent: usize,
    pub layout: ModelLayout,
    /// The dataset the model was made from (the first, if several).
    pub dataset: DatasetRef,
    /// A model made from several datasets: those after the first, in order (their rows followed
    /// the first's in training and in the anchors).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub more_datasets: Vec<DatasetRef>,
    /// Reduced coordinates where statics and dynamics start "from rest": for an autoencoder the
    /// encoding of the training snapshot closest to the straight rod (zero strain may lie off the
    /// learned manifold, e.g. under gravity).
    pub rest: Vec<f64>,
    /// Per reduced coordinate, the `[min, max]` of the training snapshots' encodings: a reduced
    /// solution far outside it is off the learned manifold and is reported as an error.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub latent_range: Vec<[f64; 2]>,
    /// The largest norm `‖x‖` of a training snapshot (its features as stored, Euclidean): an
    /// encoding refuses a snapshot more than [`SNAPSHOT_NORM_MARGIN`] times larger, which a
    /// tanh encoder would map into its training range by saturating (absent in models from before
    /// it was recorded: no such check).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub snapshot_norm_max: Option<f64>,
    /// Per training input, its range over the usable samples: `--model` refuses a scenario whose
    /// inputs lie outside (`reduce::validity`). Empty in models from before it was recorded, which
    /// are refused too.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub input_range: Vec<InputRange>,
    /// Names of the dataset inputs stored as anchors (`anchors.inputs` in the weights): the
    /// anchors near the scenario's inputs give the initial guess of a reduced statics solve.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub anchor_parameters: Vec<String>,
    /// How many anchors hold the reduced model's own statics equilibrium at their inputs (the
    /// others, the training sample's encoding): static datasets whose inputs are all tendon
    /// tensions get equilibria wherever the solve from the encoding converges inside the
    /// training encodings' range.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub anchor_equilibria: usize,
    /// POD: fraction of the snapshot energy the kept modes capture.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub captured_energy: Option<f64>,
    /// The norm of a POD (`gvsrom pod --norm`; absent in models written before it: plain). An
    /// energy POD's feature weights are stored beside its modes (`norm_weights`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pod_norm: Option<PodNorm>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub training: Option<TrainingMeta>,
    /// Largest relative part of a reconstructed training snapshot the HOM basis cannot represent,
    /// `max ‖x − Φ̄Px‖/‖x‖` (see `rom::reduced`).
    pub projection_residual: f64,
    pub crate_version: String,
    /// How the model was made ([`crate::provenance`]; absent in models from before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<crate::provenance::Provenance>,
}

/// The numbers of a model.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelWeights {
    /// POD modes (L × K, column k = mode k) and all singular values; for a POD in a weighted norm,
    /// the feature weights `w` of that norm (the modes are then W-orthonormal and a snapshot's
    /// coordinates `Φᵀ W x`: `rom::pod`).
    Pod {
        modes: nalgebra::DMatrix<f64>,
        singular_values: Vec<f64>,
        norm_weights: Option<Vec<f64>>,
    },
    Autoencoder(Autoencoder),
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// The norm a POD is optimal in (`gvsrom pod --norm`).
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum PodNorm {
    /// The plain Euclidean norm of the point strains, every value with weight 1: the paper's POD.
    #[default]
    Plain,
    /// The strain-energy norm: each point's component weighted by its section stiffness `Σ_s,aa`,
    /// as `gvsrom train --loss energy`. Elongation and shear, small in value but stiff, weigh what
    /// they cost in elastic force; the modes are orthonormal in that norm and a snapshot's
    /// coordinates are its projection in it.
    Energy,
}

impl PodNorm {
    /// The name used on the command line and in `meta.json`.
    pub fn name(self) -> &'static str {
        match self {
            PodNorm::Plain => "plain",
            PodNorm::Energy => "energy",
        }
    }
}

/// Training samples as (inputs, reduced coordinates) pairs: initial guesses for reduced solves. The
/// coordinates are the reduced model's equilibrium at the inputs or the sample's encoding
/// ([`ModelMeta::anchor_equilibria`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Anchors {
    pub n: usize,
    /// `n × k` row-major, columns named by [`ModelMeta::anchor_parameters`].
    pub inputs: Vec<f64>,
    /// `n × r` row-major.
    pub latent: Vec<f64>,
}

/// A reduced model: its metadata and its numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedModel {
    pub meta: ModelMeta,
    pub weights: ModelWeights,
    pub anchors: Option<Anchors>,
    /// Whether its files were checked against their recorded hashes when loaded (a new model:
    /// [`Integrity::Checked`]; `Unhashed` if written before hashes were recorded).
    pub integrity: Integrity,
    /// The directory it was loaded from, as loaded; `None` for a model not read from a directory.
    pub dir: Option<ModelDir>,
}

/// What a model read from a directory keeps of it, so that nothing of it is read a second time
/// unchecked.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelDir {
    pub path: std::path::PathBuf,
    /// meta.json as it was verified: the value [`ReducedModel::meta`] was parsed from (a front-end
    /// shows it whole).
    pub meta_json: serde_json::Value,
    /// Its listed files (the training curves, the POD spectrum), each read through a check of the
    /// hash recorded for it.
    pub files: crate::output::ListedFiles,
}

impl ReducedModel {
    /// The directory it was loaded from, by its manifest's hashes as loaded (what a run's
    /// provenance records of it); `None` for a model not read from a directory.
    pub fn origin(&self) -> Option<crate::provenance::DirOrigin> {
        (self.dir.as_ref())
            .map(|d| crate::provenance::DirOrigin::of_manifest(&d.path, &d.meta_json))
    }
}

/// FNV-1a 64-bit hash, as 16 hex digits.
pub fn fnv1a64(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}
