//! `gvsrom train --init MODEL`: a training that starts from an autoencoder model's weights and
//! scaling instead of a Glorot initialisation ([`rom::nn::Autoencoder::train_on`]) — more epochs
//! for a model that was still improving or was interrupted, a fine-tuning on new snapshots of the
//! same scenario, or another loss (another `λ`) from a network found elsewhere.
//!
//! The start model fixes what its weights mean: the architecture (latent size, hidden layers), the
//! decoder form, the loss weighting (through the scaling it was trained in) and the physics of its
//! scenario. A training that asks for others is refused, naming the option; the new model records
//! its start in `provenance.model` (path and hashes). The seed and validation fraction default to
//! the start's, so that a continuation on the same data holds out the same rows ([`train_settings`]).

use super::loss::Loss;
use super::sources::Sources;
use super::validity::first_physics_difference;
use super::{attach::check_layout, invalid};
use crate::error::ScenarioError;
use crate::reduced_model::{ModelWeights, ReducedModel};
use crate::scenario::Scenario;
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
    /// The seed of its training (initialisation, split, shuffles).
    pub seed: u64,
    /// The fraction of its rows it held out for validation.
    pub validation_fraction: f64,
}

/// The settings of a training that a start model fixes or suggests, as a front-end was given
/// them: `None` where the user gave none ([`train_settings`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TrainChoices {
    pub latent: Option<usize>,
    pub hidden_layers: Option<usize>,
    pub decoder: Option<DecoderForm>,
    pub loss: Option<Loss>,
    pub seed: Option<u64>,
    pub validation_fraction: Option<f64>,
}

/// The training's options and loss: `options` with each setting of `asked` the user left open
/// taken from the start model `init`, or without one from [`TrainOptions::default`] (latent 1,
/// 7 hidden layers, the plain decoder, seed 0, a tenth held out) and [`Loss::default`]. Every
/// front-end resolves `--init` this way; `reduce::train` then refuses what the start
/// cannot be trained with.
pub fn train_settings(
    init: Option<&StartModel>,
    asked: &TrainChoices,
    options: TrainOptions,
) -> (TrainOptions, Loss) {
    let fresh = TrainOptions::default();
    let options = TrainOptions {
        latent: asked
            .latent
            .or(init.map(|s| s.latent))
            .unwrap_or(fresh.latent),
        hidden_layers: (asked.hidden_layers)
            .or(init.map(|s| s.hidden_layers))
            .unwrap_or(fresh.hidden_layers),
        decoder: (asked.decoder)
            .or(init.map(|s| s.decoder))
            .unwrap_or(fresh.decoder),
        seed: asked.seed.or(init.map(|s| s.seed)).unwrap_or(fresh.seed),
        validation_fraction: (asked.validation_fraction)
            .or(init.map(|s| s.validation_fraction))
            .unwrap_or(fresh.validation_fraction),
        ..options
    };
    let loss = asked.loss.or(init.map(|s| s.loss)).unwrap_or_default();
    (options, loss)
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
        seed: training.seed,
        validation_fraction: training.validation_fraction,
        model,
    })
}

impl StartModel {
    /// The start model's directory by its manifest's hashes as it was loaded.
    pub fn origin(&self) -> crate::provenance::DirOrigin {
        self.model
            .origin()
            .unwrap_or_else(|| crate::provenance::DirOrigin::unhashed(&self.dir))
    }

    /// The start's networks and scaling.
    pub fn autoencoder(&self) -> &Autoencoder {
        match &self.model.weights {
            ModelWeights::Autoencoder(ae) => ae,
            ModelWeights::Pod { .. } => unreachable!("start_model reads autoencoders only"),
        }
    }

    /// Checks the start against the datasets `src` (points, components, basis, and the physics of
    /// their scenario apart from the sampled inputs) and the training's `options` and `loss`: each
    /// must be the model's. A seed or validation fraction other than the start's is allowed, with
    /// a warning: on the data the start was trained on, the new validation rows would hold some
    /// of its training rows.
    pub(super) fn check(
        &self,
        src: &Sources,
        options: &TrainOptions,
        loss: Loss,
    ) -> Result<Vec<String>, ScenarioError> {
        check_layout("--init", &src.built, &self.model, &self.dir)?;
        self.check_physics(src)?;
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
        let mut warnings = vec![];
        if options.seed != self.seed || options.validation_fraction != self.validation_fraction {
            warnings.push(format!(
                "--init: the start model `{}` was trained with --seed {} and --validation-fraction {}, this training uses {} and {}: on the data the start was trained on, some of the new validation rows were its training rows, so the validation loss (and the early stopping it drives) is optimistic; leave both out to keep the start's split",
                self.dir.display(),
                self.seed,
                self.validation_fraction,
                options.seed,
                options.validation_fraction
            ));
        }
        Ok(warnings)
    }

    /// Refuses datasets whose scenario's physics differs from the start model's (inputs that
    /// either samples aside): its weights, and under the energy loss its scaling's stiffness
    /// weights, belong to its own scenario.
    fn check_physics(&self, src: &Sources) -> Result<(), ScenarioError> {
        let layout = &self.model.meta.layout;
        let own =
            Scenario::from_toml(&layout.scenario, &layout.scenario_toml, &[]).map_err(|e| {
                invalid(
                    "--init",
                    format!("the start model's recorded scenario cannot be read: {e}"),
                )
            })?;
        let meta = &src.sets[0].1.meta;
        let data = Scenario::from_toml(&meta.scenario, &meta.scenario_toml, &[])?;
        let inputs = (meta.parameters.iter())
            .chain(self.model.meta.input_range.iter().map(|r| &r.parameter))
            .map(String::as_str);
        let difference = first_physics_difference(&own, &data, inputs, |at, there, here| {
            format!("its scenario's {at} is {there}, the dataset's {here}")
        })?;
        if let Some(what) = difference {
            return Err(invalid(
                "--init",
                format!(
                    "the start model `{}` was trained on other physics: {what}; a training from a model continues it on its own scenario (train a new model for this one)",
                    self.dir.display()
                ),
            ));
        }
        Ok(())
    }
}
