//! Mini-batch Adam on the loss of eq. (15) with learning-rate reductions on plateaus and early
//! stopping on the validation loss.
//!
//! Per epoch: the training rows are shuffled (Fisher–Yates driven by `SplitMix64`), cut into batches
//! of `batch_size` rows (the last one may be smaller), and each batch takes one Adam step (`nn::adam`:
//! Kingma & Ba 2015, `m ← β₁m + (1−β₁)g`, `v ← β₂v + (1−β₂)g²`,
//! `θ ← θ − η m̂/(√v̂ + ε)`, `m̂ = m/(1−β₁ᵗ)`, `v̂ = v/(1−β₂ᵗ)`) on the gradient of
//! `(1/(B·n)) Σ‖x̂ − x‖² + (λ/n) Σ‖W‖²` (see [`crate::nn::batch`]). That is eq. (15) —
//! `‖x̂ − x‖² + λ Σ‖W‖²`, the squared norm of a whole snapshot, averaged over the batch — divided by
//! the number of features `n`: the penalty weighs against a snapshot's error, not against one
//! entry's. (Applied against the per-entry mean, λ = 1e-4 is n times stronger; on the 148-value soft
//! beam snapshots it then outweighs the reconstruction term and caps Table I's RMSE near 4 instead
//! of 0.6.) The monitored loss is the validation
//! reconstruction MSE (scaled units, no penalty; plus `β Q` with the strain-rate term of
//! `nn::rates`), or the epoch's training MSE without validation rows;
//! the weights with the lowest monitored loss are kept. After `patience` epochs without a lower
//! monitored loss the phase goes back to the best weights and continues with the rate times
//! [`LR_REDUCTION_FACTOR`], up to [`TrainOptions::lr_reductions`] times, then stops; with
//! [`TrainOptions::lr_decay`] `= f` the rate also decays exponentially, `η_e = η f^(e/E)` at epoch
//! `e` of `E` (the schedule of the JAX reference scripts). An optional fine-tuning phase ([`FineTune`]:
//! Adam with a smaller rate, or full-batch L-BFGS, which converges much further on smooth small
//! problems) restarts from the best weights and only changes the result if it lowers the monitored
//! loss. The passes and the Adam step run as pairs of tasks on rayon's current pool (the caller's, or
//! the global one: all cores unless `RAYON_NUM_THREADS` says otherwise), split by the layer sizes
//! alone ([`crate::nn::batch`]): the same seed and data give bit-identical weights whatever the
//! number of threads (`weights_do_not_depend_on_the_number_of_threads`).

use super::adam::Adam;
use super::batch::{
    backward_batch_without_penalty, dataset_mse, forward_batch, in_pool, reconstruction_mse,
    Workspace,
};
use super::lbfgs::{Buffers, Lbfgs, Objective};
use super::metric::MetricBuffers;
use super::mlp::Layer;
use super::rates::{add_rate_gradient, dataset_rate_mse, forward_rates, rate_mse, RateBuffers};
use gvs::inputs::SplitMix64;
use std::ops::ControlFlow;
use std::time::Duration;

mod options;
pub use options::{FineTune, SampleWeighting, TrainOptions};

/// Why training stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// All epochs of every phase ran.
    EpochLimit,
    /// The last phase saw `patience` epochs without improvement.
    EarlyStopping,
    /// The progress callback returned `ControlFlow::Break`.
    Interrupted,
    /// A training loss was not finite; the best weights before it are kept.
    Diverged,
    /// L-BFGS found no descent step (a stationary point to rounding).
    Converged,
}

impl StopReason {
    /// Why the last phase ended, in words (`validated`: the run had validation rows, whose loss
    /// early stopping then watches; else it watches the training loss).
    pub fn describe(self, validated: bool) -> &'static str {
        match (self, validated) {
            (StopReason::EpochLimit, _) => "at its epoch or iteration limit",
            (StopReason::EarlyStopping, true) => {
                "by early stopping (the validation loss stopped improving)"
            }
            (StopReason::EarlyStopping, false) => {
                "by early stopping (no validation rows: the training loss stopped improving)"
            }
            (StopReason::Interrupted, _) => "by an interruption (Ctrl-C)",
            (StopReason::Diverged, _) => {
                "by divergence (a loss not finite; the best weights before it are kept)"
            }
            (StopReason::Converged, _) => "at convergence (L-BFGS found no descent step)",
        }
    }
}

/// Loss curves and final errors of a training run. Losses are reconstruction mean squared errors
/// `(1/(N·n)) Σ‖x̂ − x‖²` in scaled units without the weight penalty (the curves plus `β Q` with the
/// strain-rate term, [`TrainOptions::rate_weight`]); RMSEs are in physical units,
/// `√((1/(N·n)) Σ‖x̂ − x‖²)` over all rows and features (as the paper's Table I).
#[derive(Debug, Clone, PartialEq)]
pub struct TrainReport {
    /// Per epoch: mean of the batch losses seen during the epoch (before each step).
    pub train_loss: Vec<f64>,
    /// Per epoch: validation loss after the epoch; empty without validation rows.
    pub val_loss: Vec<f64>,
    /// Training-set loss of the kept (best) weights.
    pub final_train_loss: f64,
    /// Validation-set loss of the kept weights.
    pub final_val_loss: Option<f64>,
    /// Training-set RMSE of the kept weights, physical units.
    pub final_train_rmse: f64,
    /// Validation-set RMSE of the kept weights, physical units.
    pub final_val_rmse: Option<f64>,
    /// Epoch (1-based, counted over both phases) whose weights were kept.
    pub best_epoch: usize,
    /// Epochs run in total (main + fine-tuning).
    pub epochs_run: usize,
    /// Of which in the fine-tuning phase.
    pub fine_tune_epochs_run: usize,
    pub stop: StopReason,
    pub n_train: usize,
    pub n_val: usize,
    pub wall_time: Duration,
}

/// Progress callback: `(epoch, train_loss, val_loss)` after every epoch; `Break` stops training
/// (the best weights so far are kept).
pub type Progress<'a> = &'a mut dyn FnMut(usize, f64, Option<f64>) -> ControlFlow<()>;

/// The factor applied to the Adam learning rate at each plateau ([`TrainOptions::lr_reductions`]).
pub const LR_REDUCTION_FACTOR: f64 = 0.3;
/// An epoch whose training loss exceeds the initial weights' by this factor has diverged (a loss
/// that explodes while staying finite, e.g. with a far too large learning rate).
pub const EXPLODED: f64 = 1e4;

/// Fisher–Yates shuffle driven by `rng`.
pub(crate) fn shuffle(index: &mut [usize], rng: &mut SplitMix64) {
    for i in (1..index.len()).rev() {
        let j = ((rng.uniform() * (i + 1) as f64) as usize).min(i);
        index.swap(i, j);
    }
}

/// Copies parameters between two chains of the same shape (no allocation).
fn copy_layers(dst: &mut [Layer], src: &[Layer]) {
    for (d, s) in dst.iter_mut().zip(src) {
        d.w.copy_from_slice(&s.w);
        d.b.copy_from_slice(&s.b);
    }
}

/// A chain to train on row-major scaled data.
pub(crate) struct Problem<'a> {
    pub layers: &'a mut [Layer],
    pub tanh: &'a [bool],
    pub data: &'a [f64],
    pub train: &'a [usize],
    pub val: &'a [usize],
    /// The loss weight of every data row ([`SampleWeighting`]), or `None` for 1.
    pub weights: Option<&'a [f64]>,
    /// The latent layer whose first unit scales the output ([`DecoderForm::Scaled`]), if any.
    pub gate: Option<usize>,
    /// The scaled strain rate of every data row and the weight `β` of the rate term
    /// ([`crate::nn::rates`]), or `None` for eq. (15) alone.
    pub rates: Option<(&'a [f64], f64)>,
    /// The row metric's buffers (for batches of the workspace's capacity) when the errors are also
    /// measured in it ([`crate::nn::metric`]).
    pub metric: Option<&'a MetricBuffers>,
}

/// What [`fit`] observed; the chain ends with the best weights.
pub(crate) struct FitOutcome {
    /// Training-set loss of the initial weights.
    pub initial_train_loss: f64,
    /// Monitored loss (validation, else training) of the initial weights: a kept epoch beats it.
    pub initial_loss: f64,
    pub train_loss: Vec<f64>,
    pub val_loss: Vec<f64>,
    pub best_epoch: usize,
    pub fine_tune_epochs_run: usize,
    pub stop: StopReason,
}

/// Curves, the best weights so far and the early-stopping counter.
struct Tracker<'p, 'q> {
    best: Vec<Layer>,
    best_loss: f64,
    since_best: usize,
    patience: Option<usize>,
    out: FitOutcome,
    progress: Progress<'p>,
    val: &'q [usize],
}

impl Tracker<'_, '_> {
    /// Records an epoch with training loss `train` (validation evaluated here); returns why to stop
    /// the phase (`Interrupted`, `Diverged` end the whole run), or `None` to continue.
    fn record(
        &mut self,
        p: &mut Problem,
        (ws, rb): Buffers,
        train: f64,
        fine: bool,
    ) -> Option<StopReason> {
        let val = (!self.val.is_empty()).then(|| monitored_loss(p, self.val, ws, rb));
        self.out.train_loss.push(train);
        self.out.val_loss.extend(val);
        self.out.fine_tune_epochs_run += usize::from(fine);
        let monitored = val.unwrap_or(train);
        let exploded = train > EXPLODED * self.out.initial_train_loss;
        if !train.is_finite() || !monitored.is_finite() || exploded {
            return Some(StopReason::Diverged);
        }
        if monitored < self.best_loss {
            (self.best_loss, self.out.best_epoch, self.since_best) =
                (monitored, self.out.train_loss.len(), 0);
            copy_layers(&mut self.best, p.layers);
        } else {
            self.since_best += 1;
        }
        if (self.progress)(self.out.train_loss.len(), train, val).is_break() {
            return Some(StopReason::Interrupted);
        }
        self.patience
            .is_some_and(|patience| self.since_best >= patience)
            .then_some(StopReason::EarlyStopping)
    }
}

/// Runs the main Adam phase and the fine-tuning phase (module docs) and leaves the best weights in
/// the chain.
pub(crate) fn fit(
    mut p: Problem,
    opts: &TrainOptions,
    rng: &mut SplitMix64,
    progress: Progress,
) -> FitOutcome {
    let sizes: Vec<usize> = p
        .layers
        .iter()
        .map(|l| l.n_in)
        .chain(p.layers.last().map(|l| l.n_out))
        .collect();
    // Batches never exceed the training rows; the validation pass reuses the same buffers.
    let mut ws = Workspace::new(&sizes, opts.batch_size.min(p.train.len()));
    if let Some(g) = p.gate {
        ws = ws.gated(g);
    }
    if let Some(m) = p.metric {
        ws = ws.with_metric(m.clone());
    }
    // eq. (15) over n: the mean squared error per entry plus λ/n Σ‖W‖² (module docs)
    let lambda = opts.lambda / sizes[0].max(1) as f64;
    let mut rb = p
        .rates
        .map(|_| RateBuffers::new(&sizes, opts.batch_size.min(p.train.len())));
    let initial_train_loss = monitored_loss(&p, p.train, &mut ws, &mut rb);
    let initial_loss = match p.val.is_empty() {
        true => initial_train_loss,
        false => monitored_loss(&p, p.val, &mut ws, &mut rb),
    };
    let mut t = Tracker {
        best: p.layers.to_vec(),
        // an epoch is kept only if it beats the initial weights
        best_loss: initial_loss,
        since_best: 0,
        patience: opts.patience,
        out: FitOutcome {
            initial_train_loss,
            initial_loss,
            train_loss: Vec::new(),
            val_loss: Vec::new(),
            best_epoch: 0,
            fine_tune_epochs_run: 0,
            stop: StopReason::EpochLimit,
        },
        progress,
        val: p.val,
    };
    let mut stop = adam_phase(
        &mut p,
        (&mut ws, &mut rb),
        &mut t,
        rng,
        (opts.epochs, opts.learning_rate, lambda, opts.lr_reductions),
        (false, opts.lr_decay),
    );
    // also when no Adam epoch beat the initial weights: the fine-tune then starts from them (a
    // start model polished before, `--init`, whose minimum Adam's first steps climb out of)
    let resumable = matches!(stop, StopReason::EpochLimit | StopReason::EarlyStopping);
    if resumable && !matches!(opts.fine_tune, FineTune::None) {
        copy_layers(p.layers, &t.best);
        t.since_best = 0;
        stop = match opts.fine_tune {
            FineTune::Adam {
                epochs,
                learning_rate_factor: f,
            } => adam_phase(
                &mut p,
                (&mut ws, &mut rb),
                &mut t,
                rng,
                (epochs, opts.learning_rate * f, lambda, opts.lr_reductions),
                (true, None),
            ),
            FineTune::Lbfgs { iterations, memory } => lbfgs_phase(
                &mut p,
                (&mut ws, &mut rb),
                &mut t,
                (iterations, memory),
                lambda,
            ),
            FineTune::None => stop,
        };
    }
    if t.out.best_epoch > 0 {
        copy_layers(p.layers, &t.best);
    }
    t.out.stop = stop;
    t.out
}

/// The rate of epoch `e` (from 0) of `epochs` under [`TrainOptions::lr_decay`]: `η f^(e/E)`, or
/// `η` without a decay.
pub(crate) fn decayed_rate(lr: f64, decay: Option<f64>, e: usize, epochs: usize) -> f64 {
    match decay {
        Some(f) => lr * f.powf(e as f64 / epochs.max(1) as f64),
        None => lr,
    }
}

/// Up to `epochs` epochs of mini-batch Adam with a fresh optimiser state; at each of up to
/// `reductions` plateaus the best weights come back and the rate drops by [`LR_REDUCTION_FACTOR`];
/// `decay` ([`TrainOptions::lr_decay`]) lowers it epoch by epoch.
fn adam_phase(
    p: &mut Problem,
    (ws, rb): Buffers,
    t: &mut Tracker,
    rng: &mut SplitMix64,
    (epochs, lr, lambda, reductions): (usize, f64, f64, usize),
    (fine, decay): (bool, Option<f64>),
) -> StopReason {
    let mut adam = Adam::new(p.layers);
    let mut order = p.train.to_vec();
    let (mut base, mut reductions) = (lr, reductions);
    for e in 0..epochs {
        let lr = decayed_rate(base, decay, e, epochs);
        shuffle(&mut order, rng);
        let (layers, order, adam) = (&mut *p.layers, &order, &mut adam);
        let rows = (p.data, p.weights, p.rates);
        let bufs = (&mut *ws, &mut *rb);
        let train = in_pool(|| run_epoch(layers, p.tanh, rows, order, bufs, adam, (lr, lambda)));
        match t.record(p, (ws, rb), train, fine) {
            Some(StopReason::EarlyStopping) if reductions > 0 && t.out.best_epoch > 0 => {
                // a plateau: back to the best weights with a smaller step
                copy_layers(p.layers, &t.best);
                (base, reductions, t.since_best) = (base * LR_REDUCTION_FACTOR, reductions - 1, 0);
            }
            Some(stop) => return stop,
            None => {}
        }
    }
    StopReason::EpochLimit
}

/// Up to `iterations` full-batch L-BFGS iterations, each recorded as an epoch.
fn lbfgs_phase(
    p: &mut Problem,
    (ws, rb): Buffers,
    t: &mut Tracker,
    (iterations, memory): (usize, usize),
    lambda: f64,
) -> StopReason {
    let obj = Objective {
        tanh: p.tanh,
        data: p.data,
        rows: p.train,
        weights: p.weights,
        lambda,
        rates: p.rates,
    };
    let mut lbfgs = in_pool(|| Lbfgs::new(p.layers, memory, &obj, (&mut *ws, &mut *rb)));
    for _ in 0..iterations {
        let (layers, lbfgs, obj) = (&mut *p.layers, &mut lbfgs, &obj);
        let bufs = (&mut *ws, &mut *rb);
        let Some(train) = in_pool(|| lbfgs.step(layers, obj, bufs)) else {
            return StopReason::Converged;
        };
        if let Some(stop) = t.record(p, (ws, rb), train, true) {
            return stop;
        }
    }
    StopReason::EpochLimit
}

/// The scaled data rows, their loss weights (or 1) and their scaled rates with `β` (or none).
type Rows<'a> = (&'a [f64], Option<&'a [f64]>, Option<(&'a [f64], f64)>);

/// One pass over the rows in `order`, one Adam step per batch; returns the mean batch loss (with
/// the rate term's `β Q` when the problem has rates).
fn run_epoch(
    layers: &mut [Layer],
    tanh: &[bool],
    (data, weights, rates): Rows,
    order: &[usize],
    (ws, rb): Buffers,
    adam: &mut Adam,
    (lr, lambda): (f64, f64),
) -> f64 {
    let n = layers[0].n_in;
    let mut sum = 0.0;
    for batch in order.chunks(ws.capacity()) {
        ws.load_rows(data, n, batch, weights);
        forward_batch(layers, tanh, ws, batch.len());
        sum += reconstruction_mse(ws, batch.len()) * batch.len() as f64;
        backward_batch_without_penalty(layers, tanh, ws, batch.len());
        if let (Some((v, beta)), Some(rb)) = (rates, rb.as_mut()) {
            rb.load(v, n, batch);
            forward_rates(layers, tanh, ws, rb, batch.len());
            sum += beta * rate_mse(ws, rb, batch.len()) * batch.len() as f64;
            add_rate_gradient(layers, tanh, ws, rb, batch.len(), beta);
        }
        adam.step(layers, ws, lr, lambda);
    }
    sum / order.len().max(1) as f64
}

/// The monitored loss over the data rows `index`: the reconstruction MSE, plus `β Q` of the rate
/// term when the problem has rates ([`crate::nn::rates`]).
fn monitored_loss(
    p: &Problem,
    index: &[usize],
    ws: &mut Workspace,
    rb: &mut Option<RateBuffers>,
) -> f64 {
    let layers = &*p.layers;
    let mse = in_pool(|| dataset_mse(layers, p.tanh, p.data, index, p.weights, ws));
    match (p.rates, rb.as_mut()) {
        (Some((v, beta)), Some(rb)) => {
            let data = (p.data, v);
            mse + beta
                * in_pool(|| dataset_rate_mse(layers, p.tanh, data, index, p.weights, ws, rb))
        }
        _ => mse,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::NnError;

    #[test]
    fn decayed_rate_falls_geometrically_to_its_final_factor() {
        // η f^(e/E): η at the first epoch, η √f halfway, a constant ratio f^(1/E) between epochs
        let (lr, f, epochs) = (2e-3, 0.04, 10);
        assert_eq!(decayed_rate(lr, Some(f), 0, epochs), lr);
        assert!((decayed_rate(lr, Some(f), 5, epochs) - lr * 0.2).abs() <= 1e-15);
        assert!((decayed_rate(lr, Some(f), epochs, epochs) - lr * f).abs() <= 1e-17);
        let ratio = f.powf(0.1);
        for e in 0..epochs {
            let (a, b) = (
                decayed_rate(lr, Some(f), e, epochs),
                decayed_rate(lr, Some(f), e + 1, epochs),
            );
            assert!((b / a - ratio).abs() <= 1e-12, "epoch {e}: {a} → {b}");
        }
        assert_eq!(decayed_rate(lr, None, 7, epochs), lr);
        for bad in [0.0, -0.5, 1.5, f64::NAN] {
            let opts = TrainOptions {
                lr_decay: Some(bad),
                ..TrainOptions::default()
            };
            assert!(
                matches!(
                    opts.validate(),
                    Err(NnError::InvalidOption {
                        field: "lr_decay",
                        ..
                    })
                ),
                "{bad}"
            );
        }
    }

    #[test]
    fn relative_sample_weights_are_inverse_squared_norms_floored_with_mean_one() {
        // norms 1, 2, 0 (the straight rod) and 10, floor 0.2: the least norm is 2, so the weights
        // are 1/4, 1/4, 1/4, 1/100 before the mean over the training rows {0, 1, 3} is made 1.
        // (one feature of scale 2: the norms are |x| / 2)
        let w = SampleWeighting::Relative { floor: 0.2 }
            .weights(&[2.0, -4.0, 0.0, 20.0], 1, &[2.0], &[0, 1, 3])
            .unwrap();
        let mean = (0.25 + 0.25 + 0.01) / 3.0;
        let expected = [0.25 / mean, 0.25 / mean, 0.25 / mean, 0.01 / mean];
        for (a, b) in w.iter().zip(expected) {
            assert!((a - b).abs() <= 1e-15 * b, "{w:?} vs {expected:?}");
        }
        assert!(SampleWeighting::Uniform
            .weights(&[1.0], 1, &[1.0], &[0])
            .is_none());
        let bad = TrainOptions {
            sample_weighting: SampleWeighting::Relative { floor: 0.0 },
            ..TrainOptions::default()
        };
        assert!(matches!(
            bad.validate(),
            Err(NnError::InvalidOption {
                field: "sample_weighting.floor",
                ..
            })
        ));
    }
}
