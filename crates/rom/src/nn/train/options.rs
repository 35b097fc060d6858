//! What a training run is asked to do ([`TrainOptions`]): eq. (15)'s λ, the Adam schedule, the
//! plateau reductions and early stopping, the sample weighting, the strain-rate term and the final
//! phase ([`FineTune`]) — the user-facing side of [`super`]'s loop, validated before it starts.

use crate::nn::scaling::Weighting;
use crate::nn::{DecoderForm, NnError};

/// Training options; [`TrainOptions::default`] gives the paper's λ and common Adam settings.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainOptions {
    /// Latent size `r` (the reduced coordinates `q_r`).
    pub latent: usize,
    /// Number of hidden layers, odd (paper: 3, 5, 7); see [`crate::nn::Autoencoder::architecture`].
    pub hidden_layers: usize,
    /// L2 weight penalty `λ` of eq. (15) (paper: 1e-4), against the squared error of a whole
    /// snapshot (module docs).
    pub lambda: f64,
    /// Maximum number of epochs of the main phase.
    pub epochs: usize,
    /// Rows per mini-batch.
    pub batch_size: usize,
    /// Adam step size `η` of the main phase.
    pub learning_rate: f64,
    /// Fraction of the rows held out for validation, in `[0, 1)`.
    pub validation_fraction: f64,
    /// Stop a phase after this many (≥ 1) epochs without a lower monitored loss; `None` never stops
    /// early.
    pub patience: Option<usize>,
    /// Learning-rate reductions of the Adam phases: after `patience` epochs without improvement the
    /// weights go back to the best ones and the rate is multiplied by [`LR_REDUCTION_FACTOR`](super::LR_REDUCTION_FACTOR), up to
    /// this many times, before the phase stops (0: stop at the first plateau).
    pub lr_reductions: usize,
    /// An exponential decay of the main Adam phase's rate: `Some(f)` runs epoch `e` (from 0) of
    /// `E = epochs` at `η_e = η f^(e/E)` (times any plateau reductions), so the last epochs run near
    /// `f η`; `f` in (0, 1]. `None`: a constant rate between plateaus.
    pub lr_decay: Option<f64>,
    /// The final phase after the main Adam phase.
    pub fine_tune: FineTune,
    /// Seed of the initialisation, the train/validation split and the shuffles.
    pub seed: u64,
    /// How each feature's error weighs in the loss (through the data scaling).
    pub weighting: Weighting,
    /// How each snapshot's error weighs in the loss.
    pub sample_weighting: SampleWeighting,
    /// How the decoder's output becomes a snapshot.
    pub decoder: DecoderForm,
    /// Weight `β` of the strain-rate term `‖J_f v − v‖²` (`nn::rates`; 0: eq. (15) alone).
    /// It needs the rate of every row ([`crate::nn::Autoencoder::train_with_rates`]).
    pub rate_weight: f64,
}

/// How each snapshot's (row's) squared error weighs in the loss of eq. (15).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum SampleWeighting {
    /// Every snapshot weighs 1: eq. (15) as the paper writes it.
    #[default]
    Uniform,
    /// Snapshot `b` weighs `ω_b ∝ 1 / max(‖x_b‖, floor · max_c ‖x_c‖)²` (norms of the snapshots
    /// themselves, the deviation from the straight rod, in the loss's feature norm), scaled to a
    /// mean of 1 over the training rows: the loss becomes the *relative* squared error of each
    /// snapshot, the measure of "strain error in % of the peak", so that small loads (which a
    /// uniform loss lets the decoder miss by as much as large ones in absolute terms) are fitted as
    /// closely as large ones. `floor` in (0, 1] bounds the weight of near-zero snapshots.
    Relative { floor: f64 },
}

impl SampleWeighting {
    /// The floor of [`SampleWeighting::Relative`] that `gvsrom train --sample-weighting relative`
    /// uses: snapshots below a tenth of the largest norm weigh as one at a tenth.
    pub const DEFAULT_FLOOR: f64 = 0.1;

    /// The weight of every row of `data` (row-major, `n` features, physical units) from its norm
    /// in the loss's feature scaling, `‖x / s‖` (not centred: the deviation from the straight rod),
    /// normalised to a mean of 1 over the rows `train`; `None` for [`SampleWeighting::Uniform`]
    /// (nothing computed).
    pub(crate) fn weights(
        &self,
        data: &[f64],
        n: usize,
        scale: &[f64],
        train: &[usize],
    ) -> Option<Vec<f64>> {
        let SampleWeighting::Relative { floor } = *self else {
            return None;
        };
        let norms: Vec<f64> = data
            .chunks_exact(n)
            .map(|x| {
                let squares = x.iter().zip(scale).map(|(x, s)| (x / s).powi(2));
                squares.sum::<f64>().sqrt()
            })
            .collect();
        let largest = norms.iter().copied().fold(0.0f64, f64::max);
        let least = (floor * largest).max(f64::MIN_POSITIVE);
        let mut w: Vec<f64> = norms.iter().map(|v| 1.0 / v.max(least).powi(2)).collect();
        let mean = train.iter().map(|&i| w[i]).sum::<f64>() / train.len().max(1) as f64;
        w.iter_mut().for_each(|v| *v /= mean);
        Some(w)
    }
}

impl Default for TrainOptions {
    fn default() -> Self {
        TrainOptions {
            latent: 1,
            hidden_layers: 7,
            lambda: 1e-4,
            epochs: 2000,
            batch_size: 64,
            learning_rate: 1e-3,
            validation_fraction: 0.1,
            patience: Some(50),
            lr_reductions: 4,
            lr_decay: None,
            fine_tune: FineTune::lbfgs(300),
            seed: 0,
            weighting: Weighting::Standardize,
            sample_weighting: SampleWeighting::Uniform,
            decoder: DecoderForm::Plain,
            rate_weight: 0.0,
        }
    }
}

/// Largest L2 weight penalty `λ` accepted ([`TrainOptions::lambda`]): 200 epochs on 200 IV-A
/// snapshots give an RMSE of 0.021 at the paper's 1e-4, 0.44 at 1 and 1.8 at 100 (the weights
/// pulled to 0, the snapshots' mean returned).
pub const MAX_LAMBDA: f64 = 1.0;

/// Largest Adam learning rate accepted ([`TrainOptions::learning_rate`]): 1e3 times the paper's
/// 1e-3. Adam moves each weight by about the rate per step; at 1 a 7-layer autoencoder of IV-A
/// strains already explodes by its third epoch (1e300 was accepted).
pub const MAX_LEARNING_RATE: f64 = 1.0;

impl TrainOptions {
    /// Checks the numeric options (the architecture is checked by `Autoencoder::architecture`).
    pub(crate) fn validate(&self) -> Result<(), NnError> {
        let bad = |field, value: f64, expected| {
            Err(NnError::InvalidOption {
                field,
                value,
                expected,
            })
        };
        if self.epochs == 0 {
            return bad(
                "epochs",
                0.0,
                "≥ 1 (zero epochs would keep the random initial weights)",
            );
        }
        if self.batch_size == 0 {
            return bad("batch_size", 0.0, "≥ 1");
        }
        if !(self.lambda.is_finite() && (0.0..=MAX_LAMBDA).contains(&self.lambda)) {
            return bad(
                "lambda",
                self.lambda,
                "in [0, 1] (the paper: 1e-4; at 1 the penalty already pulls the weights so far toward 0 that an IV-A autoencoder's RMSE is 20× that at 1e-4)",
            );
        }
        if !(self.learning_rate > 0.0 && self.learning_rate <= MAX_LEARNING_RATE) {
            return bad(
                "learning_rate",
                self.learning_rate,
                "in (0, 1] (the paper: 1e-3; Adam moves each weight by about the rate per step)",
            );
        }
        if !(0.0..1.0).contains(&self.validation_fraction) {
            return bad("validation_fraction", self.validation_fraction, "in [0, 1)");
        }
        if let Some(f) = self.lr_decay {
            if !(f > 0.0 && f <= 1.0) {
                return bad(
                    "lr_decay",
                    f,
                    "in (0, 1]: the rate's factor at the last epoch",
                );
            }
        }
        if let SampleWeighting::Relative { floor } = self.sample_weighting {
            if !(floor > 0.0 && floor <= 1.0) {
                return bad("sample_weighting.floor", floor, "in (0, 1]");
            }
        }
        if !(self.rate_weight.is_finite() && self.rate_weight >= 0.0) {
            return bad("rate_weight", self.rate_weight, "finite and ≥ 0");
        }
        if self.rate_weight > 0.0 && self.decoder == DecoderForm::Scaled {
            return bad(
                "rate_weight",
                self.rate_weight,
                "0 with the scaled decoder (the rate term is written for the plain one)",
            );
        }
        if self.patience == Some(0) {
            return bad("patience", 0.0, "≥ 1 epoch, or None");
        }
        if let FineTune::Adam {
            learning_rate_factor: f,
            ..
        } = self.fine_tune
        {
            if !(f > 0.0 && f <= 1.0) {
                return bad("fine_tune.learning_rate_factor", f, "in (0, 1]");
            }
        }
        Ok(())
    }
}

/// The final training phase; it starts from the best weights of the main phase and, like it, keeps
/// the weights with the lowest monitored loss, so it never makes the result worse on that loss.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FineTune {
    /// No final phase.
    None,
    /// Adam restarted (fresh moments) with `learning_rate · learning_rate_factor` for up to `epochs`.
    Adam {
        epochs: usize,
        learning_rate_factor: f64,
    },
    /// Full-batch L-BFGS ([`crate::nn::lbfgs`]) for up to `iterations`, each counted as an epoch.
    Lbfgs { iterations: usize, memory: usize },
}

impl FineTune {
    /// L-BFGS for `iterations` with a memory of 10 pairs, or no final phase for 0.
    pub fn lbfgs(iterations: usize) -> Self {
        match iterations {
            0 => FineTune::None,
            iterations => FineTune::Lbfgs {
                iterations,
                memory: 10,
            },
        }
    }

    /// The L-BFGS iterations allowed (0 for no or an Adam phase).
    pub fn lbfgs_iterations(&self) -> usize {
        match self {
            FineTune::Lbfgs { iterations, .. } => *iterations,
            _ => 0,
        }
    }
}
