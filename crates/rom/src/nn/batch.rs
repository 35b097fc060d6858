//! Batched forward and backward passes of a layer chain on faer's matrix products.
//!
//! A batch of `B` samples is stored row-major, one sample per row: `H_k` is `B × n_k`. Layer `k`
//! computes `A_{k+1} = H_k W_kᵀ + 1 b_kᵀ`, `H_{k+1} = σ_k(A_{k+1})` (tanh or identity per layer).
//!
//! The loss is paper eq. (15) with the reconstruction term normalised as a mean squared error over
//! the batch and the features, on scaled data (see [`crate::nn::Scaling`]):
//!
//! `L = (1/(B·n)) Σ_b ω_b ‖x̂_b − x_b‖² + λ Σ_k ‖W_k‖²_F`   (biases are not regularised),
//!
//! where the target `x_b` is the chain's own input (an autoencoder) and `ω_b` the row's weight (1
//! unless the rows are loaded with weights: [`crate::nn::SampleWeighting`]); with a row metric
//! ([`crate::nn::metric`], `Workspace::with_metric`) each row adds `κ ‖x̂_b − x_b‖²_b`. Backpropagation:
//! `Δ_L = (2/(B·n)) diag(ω) (X̂ − X)`, `∂L/∂W_k = Δ_{k+1}ᵀ H_k + 2λ W_k`, `∂L/∂b_k = Δ_{k+1}ᵀ 1`,
//! `Δ_k = (Δ_{k+1} W_k) ⊙ σ'_{k−1}` with `σ' = 1 − H_k²` for tanh and 1 for identity.
//!
//! All buffers live in a [`Workspace`] sized once for the largest batch, so a training epoch allocates
//! nothing of its own (faer reuses its thread-local packing buffers).
//!
//! Parallelism (rayon's current pool, through `in_pool`): a layer with at least
//! `PARALLEL_MIN_MACS` multiply-adds per pass runs as two tasks — in the forward pass the two
//! halves of its output units; in the backward pass `∂L/∂W_k` beside `Δ_k` (the same work each),
//! and for the first layer the two halves of `∂L/∂W_0`'s rows. The split depends on the sizes only,
//! never on the number of threads, and every output element is computed by one task in a fixed
//! order, so results are bit-identical whatever the pool (one thread runs both tasks in turn).

use super::activation::add_bias_and_activate;
use super::dense::{product, row_major, row_major_mut};
use super::metric::{MetricBuffers, Residual};
use super::mlp::Layer;
use faer::reborrow::ReborrowMut;
use faer::{Accum, MatMut, MatRef};

/// A layer's pass runs as two parallel tasks from this many multiply-adds (rows × weights): ~10 µs
/// of work, against ~1 µs for a rayon join between running workers.
pub(crate) const PARALLEL_MIN_MACS: usize = 1 << 17;

/// Runs `f` on a worker of rayon's current pool (directly when this thread is one), so that the
/// joins inside it are cheap: from outside the pool every join would hand its work to the pool and
/// wait.
pub(crate) fn in_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| f())
}

/// Where `n` units are cut into two tasks: about half, on a multiple of 4 (the SIMD width).
fn half(n: usize) -> usize {
    n.div_ceil(2).next_multiple_of(4).min(n)
}

/// Buffers for batches of up to `capacity` rows: activations, backpropagated errors, gradients.
#[derive(Debug, Clone)]
pub struct Workspace {
    capacity: usize,
    /// `H_k` (`capacity × n_k`, row-major) for `k = 0..=L`; `H_0` is the input batch.
    pub(crate) acts: Vec<Vec<f64>>,
    /// Two `capacity × max n_k` buffers for `Δ_k` (ping-pong).
    delta: [Vec<f64>; 2],
    /// `∂L/∂W_k`, same layout as `W_k`.
    pub(crate) grad_w: Vec<Vec<f64>>,
    /// `∂L/∂b_k`.
    pub(crate) grad_b: Vec<Vec<f64>>,
    /// The loss weight `ω_b` of each loaded row, read only when `weighted`.
    row_weight: Vec<f64>,
    /// Whether the last [`Workspace::load_rows`] loaded row weights (else every `ω_b = 1`).
    weighted: bool,
    /// A [`crate::nn::DecoderForm::Scaled`] chain: the index `g` of the latent layer `H_g`; the
    /// output is `z₁ ⊙ H_L` with `z₁` the first column of `H_g` ([`Workspace::gated`]).
    gate: Option<usize>,
    /// `H_L` before the scaling by `z₁` (gated chains only).
    pre_gate: Vec<f64>,
    /// `∂L/∂z₁ = Σ_j Δ_bj (H_L)_bj` per row (gated chains only).
    gate_grad: Vec<f64>,
    /// A metric of each row's own added to the output error ([`crate::nn::metric`]), if any.
    pub(crate) metric: Option<MetricBuffers>,
}

impl Workspace {
    /// Buffers for a chain with layer sizes `sizes = [n_0, …, n_L]` and batches of ≤ `capacity` rows.
    pub fn new(sizes: &[usize], capacity: usize) -> Self {
        let capacity = capacity.max(1);
        let widest = sizes.iter().copied().max().unwrap_or(0);
        Workspace {
            capacity,
            acts: sizes.iter().map(|&n| vec![0.0; capacity * n]).collect(),
            delta: [vec![0.0; capacity * widest], vec![0.0; capacity * widest]],
            grad_w: sizes.windows(2).map(|s| vec![0.0; s[0] * s[1]]).collect(),
            grad_b: sizes.windows(2).map(|s| vec![0.0; s[1]]).collect(),
            row_weight: vec![1.0; capacity],
            weighted: false,
            gate: None,
            pre_gate: Vec::new(),
            gate_grad: Vec::new(),
            metric: None,
        }
    }

    /// The same buffers with the row metric `metric` ([`crate::nn::metric`]) added to the output
    /// error of the reconstruction and of the rate term; `metric` must hold `capacity` rows.
    pub(crate) fn with_metric(mut self, metric: MetricBuffers) -> Self {
        debug_assert!(metric.rows.len() >= self.capacity);
        self.metric = Some(metric);
        self
    }

    /// The same buffers for a chain whose output is scaled by the first unit of its layer
    /// `H_latent` (`0 < latent < L`): `x̂_b = z_b1 (H_L)_b` (a [`crate::nn::DecoderForm::Scaled`]
    /// autoencoder).
    pub(crate) fn gated(mut self, latent: usize) -> Self {
        let n_out = self.acts[self.acts.len() - 1].len();
        assert!(
            latent > 0 && latent + 1 < self.acts.len(),
            "gate layer {latent}"
        );
        self.gate = Some(latent);
        self.pre_gate = vec![0.0; n_out];
        self.gate_grad = vec![0.0; self.capacity];
        self
    }

    /// The largest batch the buffers hold.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Copies data rows `index` (row-major data with `n` features) into the input batch `H_0`, with
    /// their loss weights `weights[i]` when given (one per data row).
    pub(crate) fn load_rows(
        &mut self,
        data: &[f64],
        n: usize,
        index: &[usize],
        weights: Option<&[f64]>,
    ) {
        for (b, &i) in index.iter().enumerate() {
            self.acts[0][b * n..(b + 1) * n].copy_from_slice(&data[i * n..(i + 1) * n]);
        }
        if let Some(m) = &mut self.metric {
            m.rows[..index.len()].copy_from_slice(index);
            m.forget(None);
        }
        self.weighted = weights.is_some();
        if let Some(w) = weights {
            for (o, &i) in self.row_weight.iter_mut().zip(index) {
                *o = w[i];
            }
        }
    }

    /// The loss weight `ω_b` of loaded row `b` (1 unless the rows were loaded with weights).
    pub(crate) fn row_weight(&self, b: usize) -> f64 {
        omega(self.weighted, &self.row_weight)(b)
    }

    /// `κ Σ_b ω_b ‖y_b − x_b‖²_b` of the row metric over the first `rows` loaded rows for the rate
    /// term's residual `y − x`, or 0 without one ([`crate::nn::metric`]).
    pub(crate) fn rate_metric_energy(&mut self, y: &[f64], x: &[f64], rows: usize) -> f64 {
        let weight = omega(self.weighted, &self.row_weight);
        match self.metric.as_mut() {
            Some(m) => m.energy((y, x), rows, weight, Residual::Rate),
            None => 0.0,
        }
    }

    /// Adds the row metric's part to the rate term's output gradient `g = scale ω_b (T_L − V)`
    /// (nothing without a metric).
    pub(crate) fn add_rate_metric_gradient(&mut self, g: &mut [f64], rows: usize, scale: f64) {
        let weight = omega(self.weighted, &self.row_weight);
        if let Some(m) = self.metric.as_mut() {
            m.add_gradient(g, rows, Residual::Rate, |b| scale * weight(b));
        }
    }

    /// Forgets the metric's kept product of `residual` (`None`: both): its inputs changed.
    pub(crate) fn forget_metric(&mut self, residual: Option<Residual>) {
        if let Some(m) = self.metric.as_mut() {
            m.forget(residual);
        }
    }

    /// The chain's output `H_L` for the first `rows` samples.
    pub(crate) fn output(&self, rows: usize) -> &[f64] {
        let last = &self.acts[self.acts.len() - 1];
        &last[..rows * (last.len() / self.capacity)]
    }
}

/// `b ↦ ω_b` of loaded rows with weights `row_weight` if `weighted`, else 1.
fn omega(weighted: bool, row_weight: &[f64]) -> impl Fn(usize) -> f64 + '_ {
    move |b| if weighted { row_weight[b] } else { 1.0 }
}

/// Forward pass of the first `rows` samples of `H_0`: `H_{k+1} = σ_k(H_k W_kᵀ + 1 b_kᵀ)`.
pub(crate) fn forward_batch(layers: &[Layer], tanh: &[bool], ws: &mut Workspace, rows: usize) {
    ws.forget_metric(None);
    for (k, layer) in layers.iter().enumerate() {
        let (head, tail) = ws.acts.split_at_mut(k + 1);
        let (n_in, n_out) = (layer.n_in, layer.n_out);
        let h = row_major(&head[k], rows, n_in);
        // W_kᵀ (n_in × n_out): element (p, j) = W[j, p] at j·n_in + p.
        let w_t = row_major(&layer.w, n_out, n_in).transpose();
        let out = row_major_mut(&mut tail[0], rows, n_out);
        // output units j0.. (the columns of `out` and `w_t`, the biases `b`)
        let units = |mut out: MatMut<'_, f64>, w_t: MatRef<'_, f64>, b: &[f64]| {
            product(out.rb_mut(), Accum::Replace, h, w_t);
            add_bias_and_activate(out, b, tanh[k]);
        };
        if rows * layer.w.len() >= PARALLEL_MIN_MACS {
            let j = half(n_out);
            let (out_0, out_1) = out.split_at_col_mut(j);
            let (w_t_0, w_t_1) = w_t.split_at_col(j);
            let (b_0, b_1) = layer.b.split_at(j);
            rayon::join(|| units(out_0, w_t_0, b_0), || units(out_1, w_t_1, b_1));
        } else {
            units(out, w_t, &layer.b);
        }
    }
    if let Some(g) = ws.gate {
        // x̂_b = z_b1 (H_L)_b, keeping H_L for the backward pass
        let n = layers[layers.len() - 1].n_out;
        let r = layers[g].n_in;
        let (head, tail) = ws.acts.split_at_mut(layers.len());
        let out = &mut tail[0][..rows * n];
        ws.pre_gate[..rows * n].copy_from_slice(out);
        for (row, z) in out.chunks_exact_mut(n).zip(head[g].chunks_exact(r)) {
            row.iter_mut().for_each(|v| *v *= z[0]);
        }
    }
}

/// Reconstruction mean squared error `(1/(B·n)) Σ ω_b ‖x̂_b − x_b‖²` of the last forward pass (plus
/// `κ ‖x̂_b − x_b‖²_b` per row with a row metric, [`crate::nn::metric`]).
pub(crate) fn reconstruction_mse(ws: &mut Workspace, rows: usize) -> f64 {
    let n = ws.acts[0].len() / ws.capacity;
    let x = &ws.acts[0][..rows * n];
    let squares =
        |y: &[f64], x: &[f64]| -> f64 { y.iter().zip(x).map(|(y, x)| (y - x) * (y - x)).sum() };
    let y = &ws.acts[ws.acts.len() - 1][..rows * n];
    let metric = match ws.metric.as_mut() {
        Some(m) => m.energy(
            (y, x),
            rows,
            omega(ws.weighted, &ws.row_weight),
            Residual::Reconstruction,
        ),
        None => 0.0,
    };
    let sum: f64 = metric
        + match ws.weighted {
            false => squares(ws.output(rows), x),
            true => ws
                .output(rows)
                .chunks_exact(n)
                .zip(x.chunks_exact(n))
                .zip(&ws.row_weight)
                .map(|((y, x), w)| w * squares(y, x))
                .sum(),
        };
    sum / (rows * n) as f64
}

/// Gradients of eq. (15) (module docs) after [`forward_batch`] on the same `rows`, into
/// `ws.grad_w`, `ws.grad_b`.
pub(crate) fn backward_batch(
    layers: &[Layer],
    tanh: &[bool],
    ws: &mut Workspace,
    rows: usize,
    lambda: f64,
) {
    backward(layers, tanh, ws, rows, Some(lambda));
}

/// As [`backward_batch`] without the penalty: `ws.grad_w` holds `Δ_{k+1}ᵀ H_k` only, and the
/// optimiser adds `2λ W_k` (as `(2λ)·W_k`, rounding as [`backward_batch`] does) as it reads it,
/// which saves a pass over the weights and the gradients.
pub(crate) fn backward_batch_without_penalty(
    layers: &[Layer],
    tanh: &[bool],
    ws: &mut Workspace,
    rows: usize,
) {
    backward(layers, tanh, ws, rows, None);
}

fn backward(layers: &[Layer], tanh: &[bool], ws: &mut Workspace, rows: usize, lambda: Option<f64>) {
    let n_layers = layers.len();
    let n = layers[n_layers - 1].n_out;
    let scale = 2.0 / (rows * n) as f64;
    let Workspace {
        acts,
        delta: [d_cur, d_prev],
        grad_w,
        grad_b,
        row_weight,
        weighted,
        gate,
        pre_gate,
        gate_grad,
        metric,
        ..
    } = ws;
    let (d, y, x) = (
        &mut d_cur[..rows * n],
        &acts[n_layers][..rows * n],
        &acts[0][..rows * n],
    );
    match weighted {
        false => output_delta(d, y, x, scale),
        true => {
            let rows = d
                .chunks_exact_mut(n)
                .zip(y.chunks_exact(n))
                .zip(x.chunks_exact(n));
            for (((d, y), x), w) in rows.zip(row_weight.iter()) {
                output_delta(d, y, x, scale * w);
            }
        }
    }
    if let Some(m) = metric {
        // the row metric's part of ∂L/∂x̂ (nn::metric)
        let weight = omega(*weighted, row_weight);
        m.add_gradient(
            &mut d_cur[..rows * n],
            rows,
            Residual::Reconstruction,
            |b| scale * weight(b),
        );
    }
    if let Some(g) = *gate {
        // x̂ = z₁ y: ∂L/∂z₁ = Σ_j Δ_j y_j, ∂L/∂y = z₁ Δ
        let r = layers[g].n_in;
        let rows_of = d_cur[..rows * n].chunks_exact_mut(n);
        let pre = pre_gate[..rows * n].chunks_exact(n);
        for (((d, y), z), gz) in rows_of
            .zip(pre)
            .zip(acts[g].chunks_exact(r))
            .zip(gate_grad.iter_mut())
        {
            *gz = d.iter().zip(y).map(|(d, y)| d * y).sum();
            d.iter_mut().for_each(|d| *d *= z[0]);
        }
    }
    if tanh[n_layers - 1] {
        apply_tanh_derivative(&mut d_cur[..rows * n], &acts[n_layers][..rows * n]);
    }
    for k in (0..n_layers).rev() {
        let layer = &layers[k];
        let (n_in, n_out) = (layer.n_in, layer.n_out);
        let (delta, h) = (&d_cur[..rows * n_out], &acts[k][..rows * n_in]);
        // rows j0.. of ∂L/∂W_k = Δᵀ H_k + 2λ W_k (into `gw`) and of ∂L/∂b_k = Δᵀ 1 (into `gb`)
        let gradients = |gw: &mut [f64], gb: &mut [f64], j0: usize| {
            let units = gb.len();
            if let Some(lambda) = lambda {
                let w = &layer.w[j0 * n_in..(j0 + units) * n_in];
                for (g, w) in gw.iter_mut().zip(w) {
                    *g = 2.0 * lambda * w;
                }
            }
            let accum = if lambda.is_some() {
                Accum::Add
            } else {
                Accum::Replace
            };
            let delta_t = row_major(delta, rows, n_out).transpose().subrows(j0, units);
            product(
                row_major_mut(gw, units, n_in),
                accum,
                delta_t,
                row_major(h, rows, n_in),
            );
            column_sums(delta, n_out, j0, gb);
        };
        // Δ_k = (Δ_{k+1} W_k) ⊙ σ'_{k−1}(H_k)
        let back = |d_prev: &mut [f64]| {
            product(
                row_major_mut(d_prev, rows, n_in),
                Accum::Replace,
                row_major(delta, rows, n_out),
                row_major(&layer.w, n_out, n_in),
            );
            if tanh[k - 1] {
                apply_tanh_derivative(&mut d_prev[..rows * n_in], h);
            }
        };
        let (gw, gb) = (&mut grad_w[k][..], &mut grad_b[k][..]);
        let parallel = rows * layer.w.len() >= PARALLEL_MIN_MACS;
        if k > 0 {
            if parallel {
                rayon::join(|| gradients(gw, gb, 0), || back(d_prev));
            } else {
                gradients(gw, gb, 0);
                back(d_prev);
            }
            if *gate == Some(k) {
                // the latent layer is linear: add ∂L/∂z₁ of the output's scaling
                debug_assert!(!tanh[k - 1]);
                for (d, gz) in d_prev.chunks_exact_mut(n_in).zip(&gate_grad[..rows]) {
                    d[0] += gz;
                }
            }
            std::mem::swap(d_cur, d_prev);
        } else if parallel {
            let j = half(n_out);
            let (gw_0, gw_1) = gw.split_at_mut(j * n_in);
            let (gb_0, gb_1) = gb.split_at_mut(j);
            rayon::join(|| gradients(gw_0, gb_0, 0), || gradients(gw_1, gb_1, j));
        } else {
            gradients(gw, gb, 0);
        }
    }
}

simd_fn! {
    /// `d = scale · (y − x)`, the loss gradient with respect to the output.
    fn output_delta(d: &mut [f64], y: &[f64], x: &[f64], scale: f64) {
        for (d, (y, x)) in d.iter_mut().zip(y.iter().zip(x)) {
            *d = scale * (y - x);
        }
    }
}

simd_fn! {
    /// `d ← d ⊙ (1 − h²)`, the tanh derivative expressed through its output `h = tanh(a)`.
    fn apply_tanh_derivative(d: &mut [f64], h: &[f64]) {
        d.iter_mut().zip(h).for_each(|(d, h)| *d *= 1.0 - h * h);
    }
}

simd_fn! {
    /// `out_j = Σ_b m[b, j0 + j]` for a row-major `B × n` matrix `m`.
    fn column_sums(m: &[f64], n: usize, j0: usize, out: &mut [f64]) {
        out.iter_mut().for_each(|o| *o = 0.0);
        for row in m.chunks_exact(n) {
            out.iter_mut().zip(&row[j0..]).for_each(|(o, v)| *o += v);
        }
    }
}

/// Applies the chain to `rows` row-major inputs `x` in chunks of the workspace capacity, writing the
/// row-major outputs to `out`.
pub(crate) fn forward_rows(
    layers: &[Layer],
    tanh: &[bool],
    x: &[f64],
    rows: usize,
    ws: &mut Workspace,
    out: &mut [f64],
) {
    let weights: usize = layers.iter().map(|l| l.w.len()).sum();
    if rows * weights >= PARALLEL_MIN_MACS && rayon::current_thread_index().is_none() {
        return in_pool(|| forward_rows(layers, tanh, x, rows, ws, out));
    }
    let n_in = layers[0].n_in;
    let n_out = layers[layers.len() - 1].n_out;
    let mut start = 0;
    while start < rows {
        let count = ws.capacity.min(rows - start);
        ws.acts[0][..count * n_in].copy_from_slice(&x[start * n_in..(start + count) * n_in]);
        forward_batch(layers, tanh, ws, count);
        out[start * n_out..(start + count) * n_out].copy_from_slice(ws.output(count));
        start += count;
    }
}

/// Mean reconstruction error `(1/(N·n)) Σ ω ‖x̂ − x‖²` of an autoencoder chain over the data rows
/// `index` (row-major data with `n` features; `ω = weights[row]`, or 1), evaluated in
/// workspace-sized chunks.
pub(crate) fn dataset_mse(
    layers: &[Layer],
    tanh: &[bool],
    data: &[f64],
    index: &[usize],
    weights: Option<&[f64]>,
    ws: &mut Workspace,
) -> f64 {
    let n = layers[0].n_in;
    let mut sum = 0.0;
    for chunk in index.chunks(ws.capacity) {
        ws.load_rows(data, n, chunk, weights);
        forward_batch(layers, tanh, ws, chunk.len());
        sum += reconstruction_mse(ws, chunk.len()) * chunk.len() as f64;
    }
    sum / index.len().max(1) as f64
}

/// Checks the gradients `gw`, `gb` of every weight and bias of `layers` against central
/// differences of `loss` (h = 1e-5: truncation O(h²) ≈ 1e-10, rounding ≈ 1e-16/h ≈ 1e-11),
/// relative to max(|g|, 1e-3), within 1e-6.
#[cfg(test)]
pub(crate) fn assert_gradient_is_central_differences(
    layers: &mut [Layer],
    gw: &[Vec<f64>],
    gb: &[Vec<f64>],
    mut loss: impl FnMut(&[Layer]) -> f64,
) {
    let h = 1e-5;
    for k in 0..layers.len() {
        for (is_w, grad) in [(true, &gw[k]), (false, &gb[k])] {
            for i in 0..grad.len() {
                let probe = |delta: f64, layers: &mut [Layer]| match is_w {
                    true => layers[k].w[i] += delta,
                    false => layers[k].b[i] += delta,
                };
                probe(h, layers);
                let up = loss(layers);
                probe(-2.0 * h, layers);
                let down = loss(layers);
                probe(h, layers);
                let fd = (up - down) / (2.0 * h);
                let err = (fd - grad[i]).abs() / grad[i].abs().max(1e-3);
                assert!(
                    err <= 1e-6,
                    "layer {k} {} [{i}]: fd {fd} vs {}",
                    if is_w { "W" } else { "b" },
                    grad[i]
                );
            }
        }
    }
}

/// Glorot weights and random biases in [−0.5, 0.5) for the layers of `sizes` (tests of the passes
/// and of the optimiser: non-zero biases exercise their gradients).
#[cfg(test)]
pub(crate) fn test_layers(sizes: &[usize], rng: &mut gvs::inputs::SplitMix64) -> Vec<Layer> {
    let mut layers: Vec<Layer> = sizes
        .windows(2)
        .map(|s| Layer::glorot(s[0], s[1], rng))
        .collect();
    layers
        .iter_mut()
        .flat_map(|l| l.b.iter_mut())
        .for_each(|b| *b = rng.range(-0.5, 0.5));
    layers
}

#[cfg(test)]
mod tests;
