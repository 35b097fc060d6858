//! `gvsrom train --init MODEL`: a training that starts from an autoencoder model's weights and
//! scaling instead of a Glorot initialisation ([`rom::nn::Autoencoder::train_on`]) — more epochs
//! for a model that was still improving or was interrupted, a fine-tuning on new snapshots of the
//! same scenario, or another loss (another `λ`) from a network found elsewhere.
//!
//! The start model fixes what its weights mean: the architecture (latent size, hidden layers), the
//! decoder form and the loss weighting (through the scaling it was trained in). A training that
//! asks for others is refused, naming the option; the new model records its start in
//! `provenance.model` (path and hashes).

use super::loss::Loss;
use super::{attach::check_layout, invalid};
use crate::build::Built;
use crate::error::ScenarioError;
use crate::reduced_model::{ModelWeights, ReducedModel};
use rom::nn::{Autoencoder, DecoderForm, TrainOptions};
use std::path::{Path, PathBuf};

/// A model read as the start of a training, with the settings its weights fix.
#[derive(Debug, Clone)]
pub struct StartModel {
    pub(super) dir: PathBuf,
    /// The model read: an autoencoder (only [`start_model`] makes a `StartModel`).
    model: ReducedModel,
    /// Latent size `r`.
    pub latent: usize,
    /// Hidden layers of the whole autoencoder.
    pub hidden_layers: usize,
    pub decoder: DecoderForm,
    pub loss: Loss,
}

/// Reads `dir` (`--init`) as the start of a training: an intact autoencoder model with its
/// training record. A POD model, a damaged or edited one, or one without a record of its loss is
/// refused with the reason.
pub fn start_model(dir: &Path) -> Result<StartModel, anyhow::Error> {
    let model = ReducedModel::load(dir)?;
    let bad = |why: String| invalid("--init", format!("`{}` {why}", dir.display()));
    let ae =
        match &model.weights {
            ModelWeights::Autoencoder(ae) => ae,
            ModelWeights::Pod { .. } => return Err(bad(
                "is a POD model: a training starts from an autoencoder's weights (`gvsrom train`)"
                    .into(),
            )
            .into()),
        };
    let training = model.meta.training.as_ref().ok_or_else(|| {
        bad("records no training (meta.json has no \"training\"): re-create it".into())
    })?;
    // models from before the loss was a choice were trained standardized
    let loss = match training.loss.as_deref() {
        None => Loss::Standardized,
        Some(name) => Loss::from_name(name).ok_or_else(|| {
            bad(format!(
                "records the loss `{name}`, which this gvsrom does not know (accepted: standardized, physical, energy)"
            ))
        })?,
    };
    Ok(StartModel {
        dir: dir.to_path_buf(),
        latent: ae.latent(),
        hidden_layers: training.hidden_layers,
        decoder: ae.form(),
        loss,
        model,
    })
}

impl StartModel {
    /// The start's networks and scaling.
    pub fn autoencoder(&self) -> &Autoencoder {
        match &self.model.weights {
            ModelWeights::Autoencoder(ae) => ae,
            ModelWeights::Pod { .. } => unreachable!("start_model reads autoencoders only"),
        }
    }

    /// Checks the start against the datasets' scenario `built` (points, components, basis) and
    /// the training's `options` and `loss`: each must be the model's.
    pub(super) fn check(
        &self,
        built: &Built,
        options: &TrainOptions,
        loss: Loss,
    ) -> Result<(), ScenarioError> {
        check_layout("--init", built, &self.model, &self.dir)?;
        let differs = |option: &str, asked: String, own: String| {
            invalid(
                option,
                format!(
                    "{asked}, but the start model `{}` has {own}: a training from a model keeps its {} (leave {option} out to take the model's)",
                    self.dir.display(),
                    &option[2..]
                ),
            )
        };
        if options.latent != self.latent {
            return Err(differs(
                "--latent",
                options.latent.to_string(),
                self.latent.to_string(),
            ));
        }
        if options.hidden_layers != self.hidden_layers {
            return Err(differs(
                "--hidden-layers",
                options.hidden_layers.to_string(),
                self.hidden_layers.to_string(),
            ));
        }
        if options.decoder != self.decoder {
            return Err(differs(
                "--decoder",
                options.decoder.name().into(),
                self.decoder.name().into(),
            ));
        }
        if loss != self.loss {
            return Err(differs(
                "--loss",
                loss.name().into(),
                self.loss.name().into(),
            ));
        }
        Ok(())
    }
}
