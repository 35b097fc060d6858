//! Autoencoder strain parameterization (paper §III, eqs. 13–17): a hand-written f64 tanh MLP, its
//! training on strain snapshots (loss eq. 15, Adam), and the decoder as a [`crate::map::CoefficientMap`].
//!
//! - [`mlp`]: dense layers `h_{k+1} = tanh(W_k h_k + b_k)` with a linear last layer; plain-data access.
//! - [`scaling`]: the per-feature affine map between physical snapshots and network units.
//! - [`batch`]: batched forward/backward passes on faer's products with a reusable workspace.
//! - [`train`]: options, Adam, early stopping, the training report.
//! - [`lbfgs`]: full-batch L-BFGS, the optional final training phase.
//! - `rates`: the strain-rate term of the loss (the tangent map carries a trajectory's rates).
//! - [`autoencoder`]: the symmetric architecture, encode/decode, training entry point.
//! - [`decoder_map`]: the decoder folded with an output projection; value, Jacobian, eq. (17), Hessians.
//! - [`ae_map`]: an autoencoder's decoder map of either [`DecoderForm`].
//! - [`scaled_map`]: a map scaled by its first input, `z₁ c̃(z)` ([`DecoderForm::Scaled`]).

/// `simd_fn! { fn name(args) -> R { body } }` defines `name` whose body is compiled twice, for
/// AVX2 + FMA and for the baseline target, and runs the AVX2 build when the CPU has them (a cached
/// run-time test). The elementwise kernels of training are plain loops that the compiler vectorises;
/// without fast-math both builds round identically (`mul_add` is exactly rounded on either), so the
/// results do not depend on the path taken.
macro_rules! simd_fn {
    (
        $(#[$meta:meta])*
        $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block
    ) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn imp($($arg: $ty),*) $(-> $ret)? $body
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                unsafe fn avx2($($arg: $ty),*) $(-> $ret)? {
                    imp($($arg),*)
                }
                if std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
                {
                    // SAFETY: the CPU has AVX2 and FMA, checked just above.
                    return unsafe { avx2($($arg),*) };
                }
            }
            imp($($arg),*)
        }
    };
}

pub mod activation;
mod adam;
pub mod ae_map;
pub mod autoencoder;
pub mod batch;
pub mod decoder_map;
mod dense;
pub mod lbfgs;
pub mod metric;
pub mod mlp;
pub(crate) mod rates;
pub mod scaled_map;
pub mod scaling;
pub mod train;

pub use ae_map::AeDecoderMap;
pub use autoencoder::Autoencoder;
pub use decoder_map::DecoderMap;
pub use metric::RowMetric;
pub use mlp::Mlp;
pub use scaled_map::ScaledMap;
pub use scaling::{Scaling, Weighting};
pub use train::{
    FineTune, Progress, SampleWeighting, StopReason, TrainOptions, TrainReport, EXPLODED,
};

use thiserror::Error;

/// How the decoder network's output `y = dec(z)` (scaled units) becomes a snapshot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DecoderForm {
    /// `x̂ = s ⊙ y + μ`: the paper's decoder (eq. 14).
    #[default]
    Plain,
    /// `x̂ = z₁ (s ⊙ y + μ)`, trained with `μ = 0`: the first latent coordinate scales the
    /// snapshot, so every code with `z₁ = 0` decodes to the rest state (zero strain deviation).
    /// For families that shrink to rest as their load vanishes, e.g. IV-B's `ξ = M g(X)`: a plain
    /// smooth decoder cannot reach that apex for every `X`, and its error relative to a small
    /// snapshot grows as `1/|M|` ([`scaled_map`]).
    Scaled,
}

impl DecoderForm {
    /// The names used in options and model files: `plain`, `scaled`.
    pub const NAMES: [&'static str; 2] = ["plain", "scaled"];

    /// The name of this form ([`DecoderForm::NAMES`]).
    pub fn name(self) -> &'static str {
        match self {
            DecoderForm::Plain => "plain",
            DecoderForm::Scaled => "scaled",
        }
    }

    /// The form called `name`, or `None`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "plain" => Some(DecoderForm::Plain),
            "scaled" => Some(DecoderForm::Scaled),
            _ => None,
        }
    }
}

/// Errors of network construction, training and evaluation; each names the offending quantity.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NnError {
    #[error("an MLP needs at least 2 layer sizes (input and output), got {got}")]
    TooFewLayers { got: usize },
    #[error("layer size {index} is 0; every layer needs at least one unit")]
    ZeroLayerSize { index: usize },
    #[error("got {got} {what} vectors for {expected} layers")]
    LayerCount {
        what: &'static str,
        got: usize,
        expected: usize,
    },
    #[error("layer {layer}: {what} has {got} values, expected {expected} ({shape})")]
    LayerShape {
        layer: usize,
        what: &'static str,
        got: usize,
        expected: usize,
        shape: String,
    },
    #[error("layer {layer}: {what}[{index}] = {value} is not finite")]
    NonFiniteParameter {
        layer: usize,
        what: &'static str,
        index: usize,
        value: f64,
    },
    #[error("{what} has {got} values, expected a multiple of {expected} ({shape})")]
    DataShape {
        what: &'static str,
        got: usize,
        expected: usize,
        shape: &'static str,
    },
    #[error("the training data is empty")]
    EmptyData,
    #[error("data row {row}, feature {feature}: value {value} is not finite")]
    NonFiniteData {
        row: usize,
        feature: usize,
        value: f64,
    },
    #[error(
        "latent size {latent} must be in 1..{n_features} (fewer than the {n_features} features)"
    )]
    InvalidLatent { latent: usize, n_features: usize },
    #[error("hidden_layers = {value}: expected an odd number from 1 to {max} (1, 3, 5, 7, …; the paper's deepest has 7)", max = autoencoder::MAX_HIDDEN_LAYERS)]
    InvalidHiddenLayers { value: usize },
    #[error("invalid option {field} = {}: expected {expected}", gvs::error::fmt_value(*value))]
    InvalidOption {
        field: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error("{rows} row(s) of data: a training needs at least {least} (one snapshot defines no map)", least = autoencoder::MIN_TRAINING_ROWS)]
    TooFewRows { rows: usize },
    #[error("invalid option validation_fraction = {fraction}: it holds out {held} of the {rows} rows and leaves {left} to train on; expected a fraction that leaves at least {least} (below {most})", least = autoencoder::MIN_TRAINING_ROWS, most = (*rows as f64 - 1.0) / *rows as f64)]
    TooFewTrainingRows {
        fraction: f64,
        rows: usize,
        held: usize,
        left: usize,
    },
    #[error("scaling {what}[{index}] = {value}: expected {expected}")]
    InvalidScaling {
        what: &'static str,
        index: usize,
        value: f64,
        expected: &'static str,
    },
    #[error(
        "the training diverged at epoch {epoch}: its loss became {loss:.3e} (the initial weights' was {initial:.3e}); lower the learning rate (it was {}); no model is kept", gvs::error::fmt_value(*learning_rate)
    )]
    Diverged {
        epoch: usize,
        loss: f64,
        initial: f64,
        learning_rate: f64,
    },
    #[error(
        "the training did not lower the loss in {epochs} epochs (the initial weights' {initial:.3e} was never beaten); nothing was learned: check the learning rate and the data"
    )]
    NoProgress { epochs: usize, initial: f64 },
    #[error("{what}: {got} does not match {expected}")]
    Mismatch {
        what: &'static str,
        got: usize,
        expected: usize,
    },
}
