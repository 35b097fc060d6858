//! A model directory's numbers on disk: [`ReducedModel::save`] writes the tensors as
//! `weights.safetensors` (f64 little-endian, row-major) beside `meta.json` and the curves;
//! [`ReducedModel::load`] reads them back after the directory's hashes are checked, and refuses by
//! name a tensor missing, of another dtype or shape than the metadata implies, or non-finite.
//! Saved and loaded models are bit-identical.

use super::{
    Anchors, ModelFileError, ModelMeta, ModelWeights, PodNorm, ReducedModel, MODEL_FORMAT,
    WEIGHTS_FILE,
};
use crate::npy::write_array;
use crate::output::{OutputDir, MANIFEST_KEY};
use rom::nn::{Autoencoder, DecoderForm, Mlp, Scaling};
use safetensors::tensor::{Dtype, SafeTensors, TensorView};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

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
            files,
        } = crate::output::verify_dir_meta(dir, MODEL_FORMAT).map_err(|e| match e.problem {
            // no model there (no meta.json, or not a model's): nothing was edited
            crate::output::Problem::Manifest(_) => bad(e.to_string()),
            _ => bad(format!(
                "{e}; an edited model is not the model that was trained — re-create it"
            )),
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
            serde_json::from_value(value.clone()).map_err(|e| bad(format!("meta.json: {e}")))?;
        if meta.latent == 0 || meta.rest.len() != meta.latent {
            return Err(bad(format!(
                "meta.json: latent {} with {} rest coordinates",
                meta.latent,
                meta.rest.len()
            )));
        }
        // the bytes parsed are the bytes whose hash is checked
        let bytes = files
            .read(WEIGHTS_FILE)
            .map_err(|e| bad(format!("{e}; re-create the model")))?;
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
            dir: Some(super::ModelDir {
                path: dir.to_path_buf(),
                meta_json: value,
                files,
            }),
        })
    }
}
