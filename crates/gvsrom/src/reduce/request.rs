//! A training as every front-end is given it: `gvsrom train`'s options and `gvsrom.train`'s
//! arguments, with their one set of defaults ([`TrainRequest::DEFAULT`]) and their one reading
//! into the network's [`TrainOptions`] and the [`Loss`] ([`TrainRequest::resolve`]). A front-end
//! parses its own syntax into a `TrainRequest` and holds no other training logic; names given as
//! text are read by [`named`] (enumerations), [`super::sample_weighting`] and
//! [`super::decoder_form`], whose errors name the option and what it accepts.

use super::loss::Loss;
use super::start::{train_settings, StartModel, TrainChoices};
use crate::error::ScenarioError;
use rom::nn::{FineTune, SampleWeighting, TrainOptions};

/// The options of a training as the user gives them (`gvsrom train --…`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrainRequest {
    /// What a start model (`--init`) fixes or suggests: `None` where the user gave none.
    pub choices: TrainChoices,
    /// `--lambda`: the L2 weight penalty `λ` of eq. (15).
    pub lambda: f64,
    /// `--epochs`: the main Adam phase's epochs at most.
    pub epochs: usize,
    /// `--batch-size`: rows per mini-batch.
    pub batch_size: usize,
    /// `--learning-rate`: Adam's step size `η`.
    pub learning_rate: f64,
    /// `--patience`: epochs without improvement before a rate reduction or the end of a phase;
    /// 0 never stops early.
    pub patience: usize,
    /// `--lr-reductions`: rate reductions at plateaus before a phase stops.
    pub lr_reductions: usize,
    /// `--lr-decay`: the rate decays exponentially to this factor of it over `epochs`, in (0, 1];
    /// `None` keeps it constant between plateaus.
    pub lr_decay: Option<f64>,
    /// `--lbfgs-iterations`: the final L-BFGS phase's iterations; 0 runs none.
    pub lbfgs_iterations: usize,
    /// `--sample-weighting` and `--relative-floor` ([`super::sample_weighting`]).
    pub sample_weighting: SampleWeighting,
    /// `--rate-weight`: the weight `β ≥ 0` of the strain-rate term (0: eq. (15) alone).
    pub rate_weight: f64,
}

impl TrainRequest {
    /// The defaults of `gvsrom train` and `gvsrom.train`: 2000 Adam epochs of 64 rows at 1e-3,
    /// `λ` = 1e-4 (the paper's), a plateau patience of 50 epochs with 4 rate reductions, 300 L-BFGS
    /// iterations, every snapshot weighing alike, no strain-rate term; the architecture, loss,
    /// seed and split as [`train_settings`] resolves them.
    pub const DEFAULT: TrainRequest = TrainRequest {
        choices: TrainChoices {
            latent: None,
            hidden_layers: None,
            decoder: None,
            loss: None,
            seed: None,
            validation_fraction: None,
        },
        lambda: 1e-4,
        epochs: 2000,
        batch_size: 64,
        learning_rate: 1e-3,
        patience: 50,
        lr_reductions: 4,
        lr_decay: None,
        lbfgs_iterations: 300,
        sample_weighting: SampleWeighting::Uniform,
        rate_weight: 0.0,
    };

    /// The network's options and the loss of this request, with what the user left open taken
    /// from the start model `init` or the defaults ([`train_settings`]). The numbers are checked
    /// by the training itself, which names the option at fault.
    pub fn resolve(&self, init: Option<&StartModel>) -> (TrainOptions, Loss) {
        let given = TrainOptions {
            lambda: self.lambda,
            epochs: self.epochs,
            batch_size: self.batch_size,
            learning_rate: self.learning_rate,
            patience: (self.patience > 0).then_some(self.patience),
            lr_reductions: self.lr_reductions,
            lr_decay: self.lr_decay,
            fine_tune: FineTune::lbfgs(self.lbfgs_iterations),
            sample_weighting: self.sample_weighting,
            rate_weight: self.rate_weight,
            ..TrainOptions::default()
        };
        train_settings(init, &self.choices, given)
    }
}

impl Default for TrainRequest {
    fn default() -> Self {
        TrainRequest::DEFAULT
    }
}

/// The value of the enumeration `T` whose command-line name is `name`, given as option `field`;
/// an error naming the field, the value and every accepted name otherwise (`--loss`, `--norm` and
/// their Python arguments alike).
pub fn named<T: clap::ValueEnum>(field: &str, name: &str) -> Result<T, ScenarioError> {
    T::from_str(name, false).map_err(|_| {
        let accepted: Vec<String> = T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value())
            .map(|p| p.get_name().to_string())
            .collect();
        ScenarioError::invalid(
            field,
            format!("`{name}` (accepted: {})", accepted.join(", ")),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduce::PodNorm;

    #[test]
    fn the_default_request_is_the_networks_default_training() {
        // the front-ends' defaults must be the library's: a default request changes nothing but
        // the loss weighting (set by `reduce::train` from the loss)
        let (options, loss) = TrainRequest::DEFAULT.resolve(None);
        let fresh = TrainOptions::default();
        assert_eq!(options, fresh);
        assert_eq!(loss, Loss::Energy);
    }

    #[test]
    fn patience_zero_never_stops_early_and_no_lbfgs_iterations_runs_no_fine_tuning() {
        let r = TrainRequest {
            patience: 0,
            lbfgs_iterations: 0,
            ..TrainRequest::DEFAULT
        };
        let (options, _) = r.resolve(None);
        assert_eq!(options.patience, None);
        assert_eq!(options.fine_tune, FineTune::None);
        let r = TrainRequest {
            patience: 7,
            lbfgs_iterations: 12,
            ..TrainRequest::DEFAULT
        };
        let (options, _) = r.resolve(None);
        assert_eq!(options.patience, Some(7));
        assert_eq!(options.fine_tune.lbfgs_iterations(), 12);
    }

    #[test]
    fn a_name_outside_an_enumeration_is_refused_naming_the_field_and_every_accepted_name() {
        assert_eq!(named::<PodNorm>("norm", "energy").unwrap(), PodNorm::Energy);
        assert_eq!(named::<Loss>("--loss", "physical").unwrap(), Loss::Physical);
        let e = named::<PodNorm>("norm", "kinetic").unwrap_err().to_string();
        assert_eq!(e, "invalid `norm`: `kinetic` (accepted: plain, energy)");
        let e = named::<Loss>("loss", "Energy").unwrap_err().to_string();
        assert_eq!(
            e,
            "invalid `loss`: `Energy` (accepted: standardized, physical, energy)"
        );
    }
}
