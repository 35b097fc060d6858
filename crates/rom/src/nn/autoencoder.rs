//! The autoencoder of paper §III: `Ψ̄_rec = D(E(Ψ̄))` (eq. 14) trained on the loss of eq. (15).
//!
//! Architecture (paper: "the encoder halves the size at each layer, while the decoder doubles it"):
//! with `h = 2d + 1` hidden layers the sizes are
//! `n, ⌊n/2⌋', …, ⌊n/2ᵈ⌋', r, ⌊n/2ᵈ⌋', …, ⌊n/2⌋', n` where `⌊x⌋' = max(⌊x⌋, r + 1)`: sizes are
//! rounded down but a hidden layer beside the bottleneck never has fewer than `r + 1` units. For
//! n = 306, r = 1, h = 7: `306, 153, 76, 38, 1, 38, 76, 153, 306`.
//!
//! Activations: tanh on every hidden layer, linear on the encoder's last layer (the latent `z`) and on
//! the decoder's last layer (the reconstruction; see [`crate::nn::mlp`]). A linear latent does not
//! bound the reduced coordinates `q_r = z` or saturate the bottleneck's gradients; the decoder's first
//! tanh layer supplies the nonlinearity, so `D` is the same smooth tanh network either way. Both
//! halves are therefore plain [`Mlp`]s. The networks work in scaled units (see [`Scaling`]):
//! `E(x) = enc((x − μ)/s)`, `D(z) = s ⊙ dec(z) + μ`.

use super::ae_map::AeDecoderMap;
use super::batch::{dataset_mse, forward_batch, in_pool, Workspace};
use super::decoder_map::DecoderMap;
use super::metric::{MetricBuffers, RowMetric};
use super::mlp::{Layer, Mlp};
use super::train::{fit, shuffle, Problem, Progress, StopReason, TrainOptions, TrainReport};
use super::{DecoderForm, NnError, Scaling};
use gvs::inputs::SplitMix64;
use std::sync::Arc;
use std::time::Instant;

/// Encoder, decoder and the data scaling they work in.
#[derive(Debug, Clone, PartialEq)]
pub struct Autoencoder {
    encoder: Mlp,
    decoder: Mlp,
    scaling: Scaling,
    form: DecoderForm,
}

/// The deepest network accepted: far beyond what trains (tanh networks much deeper than the
/// paper's 7 hidden layers lose their gradients), and a bound on the model's size before anything
/// is allocated.
pub const MAX_HIDDEN_LAYERS: usize = 63;

/// Fewest rows a training keeps after holding out its validation rows: one snapshot defines no
/// map (the audit trained on 1 row of 200 and wrote "RMSE 0 training").
pub const MIN_TRAINING_ROWS: usize = 2;

impl Autoencoder {
    /// Layer sizes `[n, …, r, …, n]` (`hidden_layers + 2` values) of the symmetric architecture in the
    /// module docs. Errors: `latent ∉ 1..n_features`, `hidden_layers` even, zero or above
    /// [`MAX_HIDDEN_LAYERS`].
    pub fn architecture(
        n_features: usize,
        latent: usize,
        hidden_layers: usize,
    ) -> Result<Vec<usize>, NnError> {
        if latent == 0 || latent >= n_features {
            return Err(NnError::InvalidLatent { latent, n_features });
        }
        if hidden_layers.is_multiple_of(2) || hidden_layers > MAX_HIDDEN_LAYERS {
            return Err(NnError::InvalidHiddenLayers {
                value: hidden_layers,
            });
        }
        let depth = (hidden_layers - 1) / 2;
        let halves =
            (1..=depth).map(|k| (n_features >> k.min(usize::BITS as usize - 1)).max(latent + 1));
        let encoder: Vec<usize> = std::iter::once(n_features).chain(halves).collect();
        let decoder = encoder.iter().rev().copied();
        Ok(encoder
            .iter()
            .copied()
            .chain(std::iter::once(latent))
            .chain(decoder)
            .collect())
    }

    /// An autoencoder from its parts; the encoder must map `n → r`, the decoder `r → n`, and the
    /// scaling have `n` features.
    pub fn new(encoder: Mlp, decoder: Mlp, scaling: Scaling) -> Result<Self, NnError> {
        let n = encoder.n_in();
        let checks = [
            (
                "decoder input vs encoder output",
                decoder.n_in(),
                encoder.n_out(),
            ),
            ("decoder output vs encoder input", decoder.n_out(), n),
            ("scaling features vs encoder input", scaling.len(), n),
        ];
        all_match(&checks)?;
        Ok(Autoencoder {
            encoder,
            decoder,
            scaling,
            form: DecoderForm::Plain,
        })
    }

    /// The same networks with the decoder of `form` ([`DecoderForm`]).
    pub fn with_form(self, form: DecoderForm) -> Self {
        Autoencoder { form, ..self }
    }

    /// Trains an autoencoder on row-major `data` (`rows × n_features`, one snapshot `Ψ̄` of eq. 13 per
    /// row) with the architecture, loss and optimiser described in this module and
    /// [`crate::nn::train`]. The scaling is computed from the training rows (after the seeded split).
    pub fn train(
        data: &[f64],
        n_features: usize,
        opts: &TrainOptions,
        progress: Progress,
    ) -> Result<(Self, TrainReport), NnError> {
        Self::train_with_rates(data, None, n_features, opts, progress)
    }

    /// [`Autoencoder::train`] with the strain-rate term (`nn::rates`) of weight
    /// [`TrainOptions::rate_weight`]: `rates` holds the rate of every data row (row-major, physical
    /// units per second, as `data`). The monitored (validation) loss then includes `β Q`; the
    /// reported RMSEs remain the reconstruction's.
    pub fn train_with_rates(
        data: &[f64],
        rates: Option<&[f64]>,
        n_features: usize,
        opts: &TrainOptions,
        progress: Progress,
    ) -> Result<(Self, TrainReport), NnError> {
        Self::train_with_metric(data, rates, None, n_features, opts, progress)
    }

    /// [`Autoencoder::train_with_rates`] with the reconstruction and rate errors also measured in
    /// the row metric `metric` ([`crate::nn::metric`]: the mass-matrix norm of each row's own
    /// configuration), weighted by `κ = metric.weight()` relative to the plain terms: `metric`'s
    /// scale is set so that the training rows' rates have the same mean square in both norms
    /// (so it needs the rates, `β > 0`). The loss curves include its terms; the reported RMSEs
    /// remain the reconstruction's.
    pub fn train_with_metric(
        data: &[f64],
        rates: Option<&[f64]>,
        metric: Option<Arc<RowMetric>>,
        n_features: usize,
        opts: &TrainOptions,
        progress: Progress,
    ) -> Result<(Self, TrainReport), NnError> {
        Self::fit_from(None, data, rates, metric, n_features, opts, progress)
    }

    /// Trains on, from this autoencoder's weights instead of a Glorot initialisation: more epochs
    /// of the same fit, a fine-tuning on new snapshots of the same layout, or another loss (another
    /// `λ`, say) from a network found elsewhere. The model's scaling is kept (so the loss is
    /// measured in the units the network was built in) and `opts.weighting` is not used; the
    /// architecture and decoder form of `opts` must be this model's. `opts.seed` still draws the
    /// validation split and the shuffles, as in [`Autoencoder::train_with_metric`].
    pub fn train_on(
        &self,
        data: &[f64],
        rates: Option<&[f64]>,
        metric: Option<Arc<RowMetric>>,
        opts: &TrainOptions,
        progress: Progress,
    ) -> Result<(Self, TrainReport), NnError> {
        let own_hidden = self.encoder.n_layers() + self.decoder.n_layers() - 1;
        let own_sizes: Vec<usize> = self
            .encoder
            .layer_sizes()
            .iter()
            .chain(&self.decoder.layer_sizes()[1..])
            .copied()
            .collect();
        let sizes = Self::architecture(self.n_features(), self.latent(), own_hidden)?;
        if own_sizes != sizes {
            return Err(NnError::Mismatch {
                what: "the model's units vs the paper's architecture of its latent size and depth",
                got: own_sizes.iter().sum(),
                expected: sizes.iter().sum(),
            });
        }
        let checks = [
            ("options' latent vs the model's", opts.latent, self.latent()),
            (
                "options' hidden_layers vs the model's",
                opts.hidden_layers,
                own_hidden,
            ),
            (
                "options' decoder form (0 plain, 1 scaled) vs the model's",
                opts.decoder as usize,
                self.form as usize,
            ),
        ];
        all_match(&checks)?;
        Self::fit_from(
            Some(self),
            data,
            rates,
            metric,
            self.n_features(),
            opts,
            progress,
        )
    }

    /// The fit of [`Autoencoder::train_with_metric`] (`start_from` None: Glorot weights and the
    /// training rows' scaling) and [`Autoencoder::train_on`] (`start_from`'s weights and scaling).
    fn fit_from(
        start_from: Option<&Autoencoder>,
        data: &[f64],
        rates: Option<&[f64]>,
        metric: Option<Arc<RowMetric>>,
        n_features: usize,
        opts: &TrainOptions,
        progress: Progress,
    ) -> Result<(Self, TrainReport), NnError> {
        let start = Instant::now();
        opts.validate()?;
        let beta = opts.rate_weight;
        match rates {
            None if beta > 0.0 => {
                return Err(NnError::InvalidOption {
                    field: "rate_weight",
                    value: beta,
                    expected: "0 without strain rates (the rate term needs the rate of every row)",
                })
            }
            Some(v) if v.len() != data.len() => {
                return Err(NnError::InvalidOption {
                    field: "rates",
                    value: v.len() as f64,
                    expected: "one rate per data value (as many values as the data)",
                })
            }
            Some(v) => {
                if let Some(bad) = v.iter().find(|r| !r.is_finite()) {
                    return Err(NnError::InvalidOption {
                        field: "rates",
                        value: *bad,
                        expected: "finite values",
                    });
                }
            }
            None => {}
        }
        let sizes = Self::architecture(n_features, opts.latent, opts.hidden_layers)?;
        let rows = check_data(data, n_features)?;
        opts.weighting.check(n_features)?;
        let mut rng = SplitMix64::new(opts.seed);
        let mut layers: Vec<Layer> = sizes
            .windows(2)
            .map(|s| Layer::glorot(s[0], s[1], &mut rng))
            .collect();
        if let Some(init) = start_from {
            layers = init
                .encoder
                .layers()
                .iter()
                .chain(init.decoder.layers())
                .cloned()
                .collect();
        }
        if rows < MIN_TRAINING_ROWS {
            return Err(NnError::TooFewRows { rows });
        }
        let (train, val) = split_rows(rows, opts.validation_fraction, &mut rng);
        if train.len() < MIN_TRAINING_ROWS {
            return Err(NnError::TooFewTrainingRows {
                fraction: opts.validation_fraction,
                rows,
                held: val.len(),
                left: train.len(),
            });
        }
        let mut scaling = match start_from {
            Some(init) => init.scaling.clone(),
            None => Scaling::from_rows(data, n_features, &train, &opts.weighting),
        };
        if opts.decoder == DecoderForm::Scaled && start_from.is_none() {
            // x̂ = z₁ s ⊙ y: no mean, so that z₁ = 0 is the rest state
            scaling = Scaling::new(vec![0.0; n_features], scaling.scale().to_vec())?;
        }
        let gate = (opts.decoder == DecoderForm::Scaled).then_some(opts.hidden_layers.div_ceil(2));
        let mut scaled = data.to_vec();
        scaling.to_scaled(&mut scaled);
        let tanh = chain_tanh_flags(opts.hidden_layers);
        let weights = opts
            .sample_weighting
            .weights(data, n_features, scaling.scale(), &train);
        // rates scale as the data's deviations: by 1/s, without the mean
        let scaled_rates: Option<Vec<f64>> = rates.filter(|_| beta > 0.0).map(|v| {
            let s = scaling.scale();
            v.iter()
                .enumerate()
                .map(|(i, v)| v / s[i % n_features])
                .collect()
        });
        let capacity = opts.batch_size.min(train.len()).max(1);
        let metric = match metric {
            Some(m) => Some(metric_buffers(
                m,
                &scaled_rates,
                scaling.scale(),
                &train,
                capacity,
            )?),
            None => None,
        };
        let problem = Problem {
            layers: &mut layers,
            tanh: &tanh,
            data: &scaled,
            train: &train,
            val: &val,
            weights: weights.as_deref(),
            gate,
            rates: scaled_rates.as_deref().map(|v| (v, beta)),
            metric: metric.as_ref(),
        };
        let outcome = fit(problem, opts, &mut rng, progress);
        // a diverged run or one that never beat its initial weights is no model
        if outcome.stop == StopReason::Diverged {
            return Err(NnError::Diverged {
                epoch: outcome.train_loss.len(),
                loss: outcome.train_loss.last().copied().unwrap_or(f64::NAN),
                initial: outcome.initial_train_loss,
                learning_rate: opts.learning_rate,
            });
        }
        if outcome.best_epoch == 0 {
            return Err(NnError::NoProgress {
                epochs: outcome.train_loss.len(),
                initial: outcome.initial_loss,
            });
        }

        let mut ws = Workspace::new(&sizes, opts.batch_size.min(rows));
        if let Some(g) = gate {
            ws = ws.gated(g);
        }
        let mut errors = |index: &[usize]| {
            let (layers, tanh, scaled, scaling, ws) = (&layers, &tanh, &scaled, &scaling, &mut ws);
            in_pool(|| {
                let mse = dataset_mse(layers, tanh, scaled, index, weights.as_deref(), ws);
                (mse, physical_rmse(layers, tanh, scaled, index, scaling, ws))
            })
        };
        let (final_train_loss, final_train_rmse) = errors(&train);
        let final_val = (!val.is_empty()).then(|| errors(&val));
        let decoder = Mlp::from_layers(layers.split_off(layers.len() / 2));
        let encoder = Mlp::from_layers(layers);
        let report = TrainReport {
            epochs_run: outcome.train_loss.len(),
            train_loss: outcome.train_loss,
            val_loss: outcome.val_loss,
            final_train_loss,
            final_val_loss: final_val.map(|e| e.0),
            final_train_rmse,
            final_val_rmse: final_val.map(|e| e.1),
            best_epoch: outcome.best_epoch,
            fine_tune_epochs_run: outcome.fine_tune_epochs_run,
            stop: outcome.stop,
            n_train: train.len(),
            n_val: val.len(),
            wall_time: start.elapsed(),
        };
        Ok((
            Autoencoder {
                encoder,
                decoder,
                scaling,
                form: opts.decoder,
            },
            report,
        ))
    }

    /// Number of features `n` of a snapshot.
    pub fn n_features(&self) -> usize {
        self.encoder.n_in()
    }

    /// Latent size `r`.
    pub fn latent(&self) -> usize {
        self.encoder.n_out()
    }

    /// The encoder network (scaled units in, `z` out).
    pub fn encoder(&self) -> &Mlp {
        &self.encoder
    }

    /// The decoder network (`z` in, scaled units out).
    pub fn decoder(&self) -> &Mlp {
        &self.decoder
    }

    /// The data scaling.
    pub fn scaling(&self) -> &Scaling {
        &self.scaling
    }

    /// How the decoder's output becomes a snapshot.
    pub fn form(&self) -> DecoderForm {
        self.form
    }

    /// `z = E(x) = enc((x − μ)/s)` for row-major snapshots (`rows × n` → `rows × r`).
    pub fn encode(&self, x: &[f64]) -> Result<Vec<f64>, NnError> {
        check_rows(x, self.n_features(), "snapshots to encode")?;
        let mut scaled = x.to_vec();
        self.scaling.to_scaled(&mut scaled);
        self.encoder.forward(&scaled)
    }

    /// `Ψ̄ = D(z) = s ⊙ dec(z) + μ` (times `z₁` for [`DecoderForm::Scaled`]) for row-major latent
    /// points (`rows × r` → `rows × n`).
    pub fn decode(&self, z: &[f64]) -> Result<Vec<f64>, NnError> {
        let r = self.latent();
        check_rows(z, r, "latent points to decode")?;
        let mut y = self.decoder.forward(z)?;
        self.scaling.to_physical(&mut y);
        if self.form == DecoderForm::Scaled {
            for (row, z) in y.chunks_exact_mut(self.n_features()).zip(z.chunks_exact(r)) {
                row.iter_mut().for_each(|v| *v *= z[0]);
            }
        }
        Ok(y)
    }

    /// `D(E(x))` (eq. 14) for row-major snapshots.
    pub fn reconstruct(&self, x: &[f64]) -> Result<Vec<f64>, NnError> {
        self.decode(&self.encode(x)?)
    }

    /// The decoder as a [`crate::map::CoefficientMap`] `c(z) = A D(z)`: `A (s ⊙ dec(z) + μ)`, times
    /// `z₁` for [`DecoderForm::Scaled`], with `A` an `m × n` column-major matrix (see
    /// [`DecoderMap::new`]).
    pub fn decoder_map(&self, a: &[f64], m: usize) -> Result<AeDecoderMap, NnError> {
        let map = DecoderMap::new(&self.decoder, &self.scaling, a, m)?;
        Ok(AeDecoderMap::new(map, self.form))
    }
}

/// The row metric's training buffers: `C = diag(s) Pᵀ` and `κ` scaled so that the training rows'
/// scaled rates have the same mean square in the metric as in the plain norm (module docs of
/// [`Autoencoder::train_with_metric`]).
fn metric_buffers(
    metric: Arc<RowMetric>,
    scaled_rates: &Option<Vec<f64>>,
    scale: &[f64],
    train: &[usize],
    capacity: usize,
) -> Result<MetricBuffers, NnError> {
    let n = scale.len();
    let bad = |field, value: f64, expected| {
        Err(NnError::InvalidOption {
            field,
            value,
            expected,
        })
    };
    let Some(v) = scaled_rates else {
        return bad(
            "metric",
            metric.weight(),
            "no metric without strain rates and a rate weight β > 0 (its scale is set on the rates)",
        );
    };
    if metric.features() != n {
        return bad(
            "metric.projection",
            metric.features() as f64,
            "as many values per row as the data",
        );
    }
    if metric.rows() * n != v.len() {
        return bad(
            "metric.mass",
            metric.rows() as f64,
            "one mass matrix per data row",
        );
    }
    let mut rows_rates = Vec::with_capacity(train.len() * n);
    train
        .iter()
        .for_each(|&i| rows_rates.extend_from_slice(&v[i * n..(i + 1) * n]));
    let plain: f64 = rows_rates.iter().map(|v| v * v).sum();
    let in_metric = metric.sum_of_squares(scale, train, &rows_rates);
    if !(plain > 0.0 && in_metric > 0.0 && in_metric.is_finite()) {
        return bad(
            "metric",
            in_metric,
            "a positive size of the training rows' rates in the metric (moving data, mass matrices that are not zero)",
        );
    }
    let kappa = metric.weight() * plain / in_metric;
    Ok(MetricBuffers::new(metric, scale, kappa, capacity))
}

/// Number of rows of row-major `data` with `n` features; rejects empty, ragged and non-finite data.
fn check_data(data: &[f64], n: usize) -> Result<usize, NnError> {
    if data.is_empty() {
        return Err(NnError::EmptyData);
    }
    check_rows(data, n, "training data")?;
    match data.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(NnError::NonFiniteData {
            row: i / n,
            feature: i % n,
            value: data[i],
        }),
        None => Ok(data.len() / n),
    }
}

/// `x.len()` is a multiple of `n`.
fn check_rows(x: &[f64], n: usize, what: &'static str) -> Result<(), NnError> {
    if n == 0 || !x.len().is_multiple_of(n) {
        return Err(NnError::DataShape {
            what,
            got: x.len(),
            expected: n,
            shape: "rows × features, row-major",
        });
    }
    Ok(())
}

/// Seeded split of `0..rows` into (training, validation) rows, `⌊rows·fraction⌋` validation rows
/// but at least one training row.
fn split_rows(rows: usize, fraction: f64, rng: &mut SplitMix64) -> (Vec<usize>, Vec<usize>) {
    let mut index: Vec<usize> = (0..rows).collect();
    shuffle(&mut index, rng);
    let n_val = ((rows as f64 * fraction) as usize).min(rows - 1);
    let train = index.split_off(n_val);
    (train, index)
}

/// Tanh flags of the whole chain: each half has `(h + 1)/2` layers, the last one linear.
fn chain_tanh_flags(hidden_layers: usize) -> Vec<bool> {
    let half = hidden_layers.div_ceil(2);
    let flags: Vec<bool> = (0..half).map(|k| k + 1 < half).collect();
    flags.iter().chain(&flags).copied().collect()
}

/// `√((1/(N·n)) Σ_b Σ_j (s_j (ŷ_bj − y_bj))²)`: the RMSE in physical units from scaled data.
fn physical_rmse(
    layers: &[Layer],
    tanh: &[bool],
    scaled: &[f64],
    index: &[usize],
    scaling: &Scaling,
    ws: &mut Workspace,
) -> f64 {
    let n = scaling.len();
    let mut sum = 0.0;
    for chunk in index.chunks(ws.capacity()) {
        ws.load_rows(scaled, n, chunk, None);
        forward_batch(layers, tanh, ws, chunk.len());
        let (x, y) = (&ws.acts[0][..chunk.len() * n], ws.output(chunk.len()));
        for (xr, yr) in x.chunks_exact(n).zip(y.chunks_exact(n)) {
            sum += xr
                .iter()
                .zip(yr)
                .zip(scaling.scale())
                .map(|((x, y), s)| (s * (y - x)).powi(2))
                .sum::<f64>();
        }
    }
    (sum / (index.len() * n).max(1) as f64).sqrt()
}

/// The first `(what, got, expected)` of `checks` whose counts differ, as [`NnError::Mismatch`].
fn all_match(checks: &[(&'static str, usize, usize)]) -> Result<(), NnError> {
    match checks.iter().find(|(_, got, expected)| got != expected) {
        Some(&(what, got, expected)) => Err(NnError::Mismatch {
            what,
            got,
            expected,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests;
