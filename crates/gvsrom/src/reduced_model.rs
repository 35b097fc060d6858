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

use crate::npy::write_array;
use crate::output::{Integrity, OutputDir, OutputError, MANIFEST_KEY};
use rom::nn::{Autoencoder, DecoderForm, Mlp, Scaling};
use safetensors::tensor::{Dtype, SafeTensors, TensorView};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

mod codec;
pub use codec::{outside_range, CodecError};

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
    pub epochs_run: usize,
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

fn f64_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn mlp_tensors(prefix: &str, mlp: &Mlp, out: &mut BTreeMap<String, (Vec<usize>, Vec<u8>)>) {
    let sizes = mlp.layer_sizes();
    for k in 0..mlp.n_layers() {
        out.insert(
            format!("{prefix}.{k}.weight"),
            (vec![sizes[k + 1], sizes[k]], f64_bytes(mlp.weights(k))),
        );
        out.insert(
            format!("{prefix}.{k}.bias"),
            (vec![sizes[k + 1]], f64_bytes(mlp.biases(k))),
        );
    }
}

/// The first tensor of the safetensors file `bytes` whose `data_offsets` end past its data,
/// described; `None` if there is none or the header cannot be read (safetensors then refuses it).
///
/// safetensors (0.8) adds the last tensor's end to the header length unchecked: offsets near 2⁶⁴
/// (tensors that fit nowhere, yet consistent with their shapes) overflow there, a panic in a build
/// with overflow checks (a wrapped sum, refused as an incomplete file, without).
fn offsets_beyond_data(bytes: &[u8]) -> Option<String> {
    let n = usize::try_from(u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?)).ok()?;
    let header = bytes.get(8..8usize.checked_add(n)?)?;
    let data = bytes.len() - 8 - n;
    let serde_json::Value::Object(tensors) = serde_json::from_slice(header).ok()? else {
        return None;
    };
    tensors.iter().find_map(|(name, info)| {
        let end = info.get("data_offsets")?.get(1)?.as_u64()?;
        (end > data as u64).then(|| {
            format!(
                "tensor `{name}` ends at byte {end} of data, but the file holds {data} data bytes"
            )
        })
    })
}

impl ReducedModel {
    fn tensors(&self) -> BTreeMap<String, (Vec<usize>, Vec<u8>)> {
        let mut t = BTreeMap::new();
        match &self.weights {
            ModelWeights::Pod {
                modes,
                singular_values,
                norm_weights,
            } => {
                // row-major L × K
                let rm: Vec<f64> = modes.transpose().iter().copied().collect();
                t.insert(
                    "modes".into(),
                    (vec![modes.nrows(), modes.ncols()], f64_bytes(&rm)),
                );
                t.insert(
                    "singular_values".into(),
                    (vec![singular_values.len()], f64_bytes(singular_values)),
                );
                if let Some(w) = norm_weights {
                    t.insert("norm_weights".into(), (vec![w.len()], f64_bytes(w)));
                }
            }
            ModelWeights::Autoencoder(ae) => {
                mlp_tensors("encoder", ae.encoder(), &mut t);
                mlp_tensors("decoder", ae.decoder(), &mut t);
                let s = ae.scaling();
                t.insert("scaling.mean".into(), (vec![s.len()], f64_bytes(s.mean())));
                t.insert(
                    "scaling.scale".into(),
                    (vec![s.len()], f64_bytes(s.scale())),
                );
            }
        }
        if let Some(a) = &self.anchors {
            let k = self.meta.anchor_parameters.len();
            t.insert(
                "anchors.inputs".into(),
                (vec![a.n, k], f64_bytes(&a.inputs)),
            );
            t.insert(
                "anchors.latent".into(),
                (vec![a.n, self.meta.latent], f64_bytes(&a.latent)),
            );
        }
        t
    }

    /// The model's numbers as named row-major arrays `name → (shape, values)`, as
    /// `weights.safetensors` stores them: POD `modes` (L × K) and `singular_values`; an
    /// autoencoder's `encoder.{k}.weight`, `encoder.{k}.bias`, `decoder.{k}.…`, `scaling.mean` and
    /// `scaling.scale`; and `anchors.inputs`, `anchors.latent` if it has anchors.
    pub fn arrays(&self) -> BTreeMap<String, (Vec<usize>, Vec<f64>)> {
        self.tensors()
            .into_iter()
            .map(|(name, (shape, bytes))| {
                let values = bytes
                    .chunks_exact(8)
                    .map(|b| f64::from_le_bytes(b.try_into().expect("8-byte chunks")))
                    .collect();
                (name, (shape, values))
            })
            .collect()
    }

    /// Writes the weights, the curves in `extra` (name → 1-D values, as `.npy`) and `meta.json`
    /// into `out` and commits it.
    pub fn save(
        &self,
        mut out: OutputDir,
        extra: &[(&str, &[f64])],
    ) -> Result<PathBuf, ModelFileError> {
        let tensors = self.tensors();
        let views: Vec<(String, TensorView<'_>)> = tensors
            .iter()
            .map(|(k, (shape, data))| {
                TensorView::new(Dtype::F64, shape.clone(), data).map(|v| (k.clone(), v))
            })
            .collect::<Result<_, _>>()
            .map_err(|e| {
                out.io_error("encode the weights", std::io::Error::other(e.to_string()))
            })?;
        let bytes = safetensors::serialize(views, None).map_err(|e| {
            out.io_error("encode the weights", std::io::Error::other(e.to_string()))
        })?;
        out.write_file(WEIGHTS_FILE, |w| std::io::Write::write_all(w, &bytes))
            .map_err(|e| out.io_error("write weights.safetensors", e))?;
        for (name, values) in extra {
            let file = format!("{name}.npy");
            write_array(&mut out, &file, &[values.len()], values)
                .map_err(|e| out.io_error(&format!("write {file}"), e))?;
        }
        Ok(out.commit(&self.meta)?)
    }

    /// Reads and checks a model directory.
    pub fn load(dir: &Path) -> Result<ReducedModel, ModelFileError> {
        let bad = |message: String| ModelFileError::Invalid {
            path: dir.to_path_buf(),
            message,
        };
        // every listed file and the metadata as written, before anything is parsed
        let crate::output::Verified {
            integrity,
            meta: value,
        } = crate::output::verify_dir_meta(dir, MODEL_FORMAT).map_err(|e| {
            bad(format!(
                "{e}; an edited model is not the model that was trained — re-create it"
            ))
        })?;
        let format = value
            .get(MANIFEST_KEY)
            .and_then(|m| m.get("format"))
            .and_then(|f| f.as_str());
        if format != Some(MODEL_FORMAT) {
            return Err(bad(format!(
                "not a gvsrom reduced model (meta.json format {}, expected \"{MODEL_FORMAT}\")",
                format.map_or("missing".to_string(), |f| format!("\"{f}\""))
            )));
        }
        let meta: ModelMeta =
            serde_json::from_value(value).map_err(|e| bad(format!("meta.json: {e}")))?;
        if meta.latent == 0 || meta.rest.len() != meta.latent {
            return Err(bad(format!(
                "meta.json: latent {} with {} rest coordinates",
                meta.latent,
                meta.rest.len()
            )));
        }
        let bytes = crate::output::read_regular(&dir.join(WEIGHTS_FILE))
            .map_err(|e| bad(format!("cannot read {WEIGHTS_FILE}: {e}")))?;
        if let Some(message) = offsets_beyond_data(&bytes) {
            return Err(bad(format!("{WEIGHTS_FILE} is damaged: {message}")));
        }
        let st = SafeTensors::deserialize(&bytes)
            .map_err(|e| bad(format!("{WEIGHTS_FILE} is damaged: {e}")))?;
        let get = |name: &str, shape: &[usize]| -> Result<Vec<f64>, ModelFileError> {
            let t = st
                .tensor(name)
                .map_err(|_| bad(format!("{WEIGHTS_FILE}: tensor `{name}` is missing")))?;
            if t.dtype() != Dtype::F64 || t.shape() != shape {
                return Err(bad(format!(
                    "{WEIGHTS_FILE}: tensor `{name}` is {:?} {:?}, expected F64 {shape:?}",
                    t.dtype(),
                    t.shape()
                )));
            }
            let values: Vec<f64> = t
                .data()
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("chunks of 8")))
                .collect();
            // modes, singular values, weights, scalings and anchors are all finite when written
            if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(bad(format!(
                    "{WEIGHTS_FILE}: tensor `{name}` holds {v} at index {i} (expected finite values)"
                )));
            }
            Ok(values)
        };
        let features = meta.layout.features();
        let weights = match meta.kind.as_str() {
            "pod" => {
                let rm = get("modes", &[features, meta.latent])?;
                let n_sv = st
                    .tensor("singular_values")
                    .map(|t| t.shape().first().copied().unwrap_or(0))
                    .unwrap_or(0);
                let singular_values = get("singular_values", &[n_sv])?;
                let norm_weights = match meta.pod_norm.unwrap_or_default() {
                    PodNorm::Plain if st.tensor("norm_weights").is_ok() => {
                        return Err(bad(format!(
                            "{WEIGHTS_FILE}: tensor `norm_weights` in a POD whose meta.json records the plain norm (`pod_norm`): the files do not belong together"
                        )));
                    }
                    PodNorm::Plain => None,
                    PodNorm::Energy => {
                        let w = get("norm_weights", &[features])?;
                        if let Some((j, v)) = w.iter().enumerate().find(|(_, v)| **v <= 0.0) {
                            return Err(bad(format!(
                                "{WEIGHTS_FILE}: tensor `norm_weights` holds {v} at index {j} (expected > 0)"
                            )));
                        }
                        Some(w)
                    }
                };
                ModelWeights::Pod {
                    modes: nalgebra::DMatrix::from_row_slice(features, meta.latent, &rm),
                    singular_values,
                    norm_weights,
                }
            }
            "autoencoder" => {
                let tr = meta
                    .training
                    .as_ref()
                    .ok_or_else(|| bad("meta.json: autoencoder without `training`".into()))?;
                let mlp = |prefix: &str, sizes: &[usize]| -> Result<Mlp, ModelFileError> {
                    let mut ws = vec![];
                    let mut bs = vec![];
                    for k in 0..sizes.len().saturating_sub(1) {
                        ws.push(get(
                            &format!("{prefix}.{k}.weight"),
                            &[sizes[k + 1], sizes[k]],
                        )?);
                        bs.push(get(&format!("{prefix}.{k}.bias"), &[sizes[k + 1]])?);
                    }
                    Mlp::new(sizes, ws, bs).map_err(|e| bad(format!("{prefix}: {e}")))
                };
                let encoder = mlp("encoder", &tr.encoder_sizes)?;
                let decoder = mlp("decoder", &tr.decoder_sizes)?;
                let scaling = Scaling::new(
                    get("scaling.mean", &[features])?,
                    get("scaling.scale", &[features])?,
                )
                .map_err(|e| bad(format!("scaling: {e}")))?;
                let form = match tr.decoder.as_deref() {
                    None => DecoderForm::Plain,
                    Some(name) => DecoderForm::from_name(name).ok_or_else(|| {
                        bad(format!(
                            "meta.json: training.decoder is \"{name}\" (expected one of {:?})",
                            DecoderForm::NAMES
                        ))
                    })?,
                };
                let ae = Autoencoder::new(encoder, decoder, scaling)
                    .map_err(|e| bad(e.to_string()))?
                    .with_form(form);
                if ae.n_features() != features || ae.latent() != meta.latent {
                    return Err(bad(format!(
                        "the network maps {} features to {} coordinates, meta.json says {features} and {}",
                        ae.n_features(),
                        ae.latent(),
                        meta.latent
                    )));
                }
                ModelWeights::Autoencoder(ae)
            }
            other => {
                return Err(bad(format!(
                    "meta.json: unknown kind \"{other}\" (expected \"pod\" or \"autoencoder\")"
                )))
            }
        };
        let anchors = match st.tensor("anchors.latent") {
            Ok(t) => {
                let n = t.shape().first().copied().unwrap_or(0);
                let k = meta.anchor_parameters.len();
                Some(Anchors {
                    n,
                    inputs: get("anchors.inputs", &[n, k])?,
                    latent: get("anchors.latent", &[n, meta.latent])?,
                })
            }
            Err(_) => None,
        };
        if !meta.latent_range.is_empty() && meta.latent_range.len() != meta.latent {
            return Err(bad(format!(
                "meta.json: {} latent ranges for {} coordinates",
                meta.latent_range.len(),
                meta.latent
            )));
        }
        Ok(ReducedModel {
            meta,
            weights,
            anchors,
            integrity,
        })
    }
}
