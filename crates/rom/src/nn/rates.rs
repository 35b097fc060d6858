//! The strain-rate term of the training loss: the autoencoder's tangent map must carry the
//! trajectory's rates.
//!
//! Along a trajectory `x(t)` an exact autoencoder `f = D ∘ E` keeps `f(x(t)) = x(t)`, so its
//! Jacobian carries the rate: `J_f(x) ẋ = ẋ`. Then every observed rate lies in the decoder's tangent
//! space `range(J_D)`, the space of velocities the reduced model can have. A reconstruction loss
//! alone does not ask for it: a decoder may pass through the snapshots with tangents that miss the
//! motion between them, and a Lagrangian model on that manifold gets the wrong mass and stiffness
//! along its own coordinates. The term added to eq. (15) is
//!
//! `Q = (β/(B·n)) Σ_b ω_b ‖J_f(x_b) v_b − v_b‖²`,
//!
//! with `v_b` the rate of row `b` in the scaled units of the data (rates scale by `1/s` and lose
//! no mean) and `ω_b` the row's weight. Static equilibria have `v = 0` and add nothing.
//!
//! Tangent propagation (forward mode along `v`): `T_0 = V`, `U_{k+1} = T_k W_kᵀ`,
//! `T_{k+1} = σ'_k ⊙ U_{k+1}` with `σ' = 1 − H_{k+1}²` for tanh and 1 for identity layers, so that
//! `T_L = J_f V` row by row (the activations `H_k` are those of the reconstruction's forward pass).
//! Backward, from `G_L = ∂Q/∂T_L = (2β ω/(B·n)) (T_L − V)` and no primal error above the output:
//! at a tanh layer `P = G ⊙ s` and `D = D' ⊙ s − 2 G ⊙ U ⊙ H ⊙ s` (`s = 1 − H²`; `D'` is `∂Q/∂H`),
//! at an identity layer `P = G`, `D = D'`; then `∂Q/∂W_k += Pᵀ T_k + Dᵀ H_k`, `∂Q/∂b_k += Dᵀ 1`,
//! `G_k = P W_k`, `D'_k = D W_k`. The gradient is checked against central differences in the tests.
//! With a row metric ([`crate::nn::metric`]) each row's error also counts in it,
//! `‖e_b‖² + κ ‖e_b‖²_b`, and `G_L` gains its part (`metric::MetricBuffers::add_gradient`).
//! A layer with at least `PARALLEL_MIN_MACS` multiply-adds computes `∂Q/∂W_k` beside `G_k`, `D'_k`
//! as two tasks (disjoint outputs, as in `batch`'s backward pass): the bits do not depend on the pool.

use super::batch::{Workspace, PARALLEL_MIN_MACS};
use super::dense::{product, row_major, row_major_mut};
use super::mlp::Layer;
use faer::Accum;

/// The buffers of the rate term for batches of up to `capacity` rows.
#[derive(Debug, Clone)]
pub(crate) struct RateBuffers {
    capacity: usize,
    /// `T_k` (`capacity × n_k`) for `k = 0..=L`; `T_0` is the batch of rates.
    t: Vec<Vec<f64>>,
    /// `U_k` (`capacity × n_k`) for `k = 1..=L` (index 0 unused).
    u: Vec<Vec<f64>>,
    /// Ping-pong buffers for `G` and for `D`, `capacity × max n_k` each.
    g: [Vec<f64>; 2],
    d: [Vec<f64>; 2],
}

impl RateBuffers {
    /// Buffers for a chain with layer sizes `sizes` and batches of ≤ `capacity` rows.
    pub(crate) fn new(sizes: &[usize], capacity: usize) -> Self {
        let capacity = capacity.max(1);
        let widest = sizes.iter().copied().max().unwrap_or(0);
        let per_layer = || sizes.iter().map(|&n| vec![0.0; capacity * n]).collect();
        let wide = || vec![0.0; capacity * widest];
        RateBuffers {
            capacity,
            t: per_layer(),
            u: per_layer(),
            g: [wide(), wide()],
            d: [wide(), wide()],
        }
    }

    /// Copies the rates of data rows `index` (row-major, `n` per row) into `T_0`.
    pub(crate) fn load(&mut self, rates: &[f64], n: usize, index: &[usize]) {
        debug_assert!(index.len() <= self.capacity);
        for (b, &i) in index.iter().enumerate() {
            self.t[0][b * n..(b + 1) * n].copy_from_slice(&rates[i * n..(i + 1) * n]);
        }
    }
}

/// Tangent pass of the first `rows` samples after [`super::batch::forward_batch`] on the same rows:
/// `T_L = J_f(x) v` for each row.
pub(crate) fn forward_rates(
    layers: &[Layer],
    tanh: &[bool],
    ws: &mut Workspace,
    rb: &mut RateBuffers,
    rows: usize,
) {
    ws.forget_metric(Some(super::metric::Residual::Rate));
    for (k, layer) in layers.iter().enumerate() {
        let (n_in, n_out) = (layer.n_in, layer.n_out);
        let (head, tail) = rb.t.split_at_mut(k + 1);
        let u = &mut rb.u[k + 1][..rows * n_out];
        product(
            row_major_mut(u, rows, n_out),
            Accum::Replace,
            row_major(&head[k], rows, n_in),
            row_major(&layer.w, n_out, n_in).transpose(),
        );
        let t = &mut tail[0][..rows * n_out];
        match tanh[k] {
            true => {
                let h = &ws.acts[k + 1][..rows * n_out];
                for ((t, u), h) in t.iter_mut().zip(u.iter()).zip(h) {
                    *t = (1.0 - h * h) * u;
                }
            }
            false => t.copy_from_slice(u),
        }
    }
}

/// `(1/(B·n)) Σ_b ω_b ‖T_L − V‖²` of the last [`forward_rates`] (without `β`).
pub(crate) fn rate_mse(ws: &mut Workspace, rb: &RateBuffers, rows: usize) -> f64 {
    let last = rb.t.len() - 1;
    let n = rb.t[last].len() / rb.capacity;
    let (y, v) = (&rb.t[last][..rows * n], &rb.t[0][..rows * n]);
    let metric = ws.rate_metric_energy(y, v, rows);
    let sum: f64 = y
        .chunks_exact(n)
        .zip(v.chunks_exact(n))
        .enumerate()
        .map(|(b, (y, v))| {
            let e: f64 = y.iter().zip(v).map(|(y, v)| (y - v) * (y - v)).sum();
            ws.row_weight(b) * e
        })
        .sum();
    (metric + sum) / (rows * n) as f64
}

/// Adds `β ∂(rate_mse)/∂θ` of the last [`forward_rates`] to `ws.grad_w`, `ws.grad_b` (module docs).
pub(crate) fn add_rate_gradient(
    layers: &[Layer],
    tanh: &[bool],
    ws: &mut Workspace,
    rb: &mut RateBuffers,
    rows: usize,
    beta: f64,
) {
    let n_layers = layers.len();
    let n = layers[n_layers - 1].n_out;
    let scale = 2.0 * beta / (rows * n) as f64;
    let RateBuffers { t, u, g, d, .. } = rb;
    let [g_cur, g_prev] = g;
    let [d_cur, d_prev] = d;
    for b in 0..rows {
        let w = scale * ws.row_weight(b);
        let (gr, y, v) = (
            &mut g_cur[b * n..(b + 1) * n],
            &t[n_layers][b * n..(b + 1) * n],
            &t[0][b * n..(b + 1) * n],
        );
        for ((g, y), v) in gr.iter_mut().zip(y).zip(v) {
            *g = w * (y - v);
        }
    }
    // the row metric's part of ∂Q/∂T_L (nn::metric)
    ws.add_rate_metric_gradient(&mut g_cur[..rows * n], rows, scale);
    d_cur[..rows * n].iter_mut().for_each(|d| *d = 0.0);
    for k in (0..n_layers).rev() {
        let layer = &layers[k];
        let (n_in, n_out) = (layer.n_in, layer.n_out);
        let m = rows * n_out;
        if tanh[k] {
            // P = G ⊙ s (in g_cur), D = D' ⊙ s − 2 G ⊙ U ⊙ H ⊙ s (in d_cur)
            let h = &ws.acts[k + 1][..m];
            let uk = &u[k + 1][..m];
            for (((g, d), h), u) in g_cur[..m].iter_mut().zip(&mut d_cur[..m]).zip(h).zip(uk) {
                let s = 1.0 - h * h;
                *d = *d * s - 2.0 * *g * u * h * s;
                *g *= s;
            }
        }
        let (p, dk) = (
            row_major(&g_cur[..m], rows, n_out),
            row_major(&d_cur[..m], rows, n_out),
        );
        let (gw, gb, h) = (&mut ws.grad_w[k], &mut ws.grad_b[k], &ws.acts[k]);
        let (tk, d_rows) = (&t[k], &d_cur[..m]);
        // ∂Q/∂W_k += Pᵀ T_k + Dᵀ H_k, ∂Q/∂b_k += Dᵀ 1
        let mut gradients = move || {
            let gw_mat = row_major_mut(gw, n_out, n_in);
            product(gw_mat, Accum::Add, p.transpose(), row_major(tk, rows, n_in));
            let gw_mat = row_major_mut(gw, n_out, n_in);
            product(gw_mat, Accum::Add, dk.transpose(), row_major(h, rows, n_in));
            for row in d_rows.chunks_exact(n_out) {
                gb.iter_mut().zip(row).for_each(|(gb, d)| *gb += d);
            }
        };
        if k > 0 {
            // G_k = P W_k, D'_k = D W_k
            let w = row_major(&layer.w, n_out, n_in);
            let (g_next, d_next) = (&mut *g_prev, &mut *d_prev);
            let mut back = move || {
                product(row_major_mut(g_next, rows, n_in), Accum::Replace, p, w);
                product(row_major_mut(d_next, rows, n_in), Accum::Replace, dk, w);
            };
            // two tasks with disjoint outputs, as `batch`'s backward pass: the same bits either way
            if rows * layer.w.len() >= PARALLEL_MIN_MACS {
                rayon::join(gradients, back);
            } else {
                gradients();
                back();
            }
            std::mem::swap(g_cur, g_prev);
            std::mem::swap(d_cur, d_prev);
        } else {
            gradients();
        }
    }
}

/// `(1/(N·n)) Σ ω ‖J_f v − v‖²` over the data rows `index`, in workspace-sized chunks.
pub(crate) fn dataset_rate_mse(
    layers: &[Layer],
    tanh: &[bool],
    (data, rates): (&[f64], &[f64]),
    index: &[usize],
    weights: Option<&[f64]>,
    ws: &mut Workspace,
    rb: &mut RateBuffers,
) -> f64 {
    let n = layers[0].n_in;
    let mut sum = 0.0;
    for chunk in index.chunks(ws.capacity()) {
        ws.load_rows(data, n, chunk, weights);
        super::batch::forward_batch(layers, tanh, ws, chunk.len());
        rb.load(rates, n, chunk);
        forward_rates(layers, tanh, ws, rb, chunk.len());
        sum += rate_mse(ws, rb, chunk.len()) * chunk.len() as f64;
    }
    sum / index.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::batch::{assert_gradient_is_central_differences, forward_batch, test_layers};
    use gvs::inputs::SplitMix64;

    /// `β Q` of the chain on the rows loaded in `ws`, `rb`.
    fn loss(
        layers: &[Layer],
        tanh: &[bool],
        ws: &mut Workspace,
        rb: &mut RateBuffers,
        rows: usize,
        beta: f64,
    ) -> f64 {
        forward_batch(layers, tanh, ws, rows);
        forward_rates(layers, tanh, ws, rb, rows);
        beta * rate_mse(ws, rb, rows)
    }

    #[test]
    fn tangent_pass_is_the_directional_derivative_of_the_chain() {
        // T_L = J_f v against central differences (f(x + h v) − f(x − h v)) / 2h
        let sizes = [6, 4, 2, 4, 6];
        let tanh = [true, false, true, false];
        let mut rng = SplitMix64::new(11);
        let layers = test_layers(&sizes, &mut rng);
        let rows = 3;
        let x: Vec<f64> = (0..rows * 6).map(|_| rng.range(-1.0, 1.0)).collect();
        let v: Vec<f64> = (0..rows * 6).map(|_| rng.range(-2.0, 2.0)).collect();
        let mut ws = Workspace::new(&sizes, rows);
        let mut rb = RateBuffers::new(&sizes, rows);
        let index: Vec<usize> = (0..rows).collect();
        ws.load_rows(&x, 6, &index, None);
        forward_batch(&layers, &tanh, &mut ws, rows);
        rb.load(&v, 6, &index);
        forward_rates(&layers, &tanh, &mut ws, &mut rb, rows);
        let jv = rb.t[4][..rows * 6].to_vec();
        let h = 1e-6;
        let shifted = |sign: f64, ws: &mut Workspace| {
            let xs: Vec<f64> = x.iter().zip(&v).map(|(x, v)| x + sign * h * v).collect();
            ws.load_rows(&xs, 6, &index, None);
            forward_batch(&layers, &tanh, ws, rows);
            ws.output(rows).to_vec()
        };
        let (plus, minus) = (shifted(1.0, &mut ws), shifted(-1.0, &mut ws));
        for i in 0..rows * 6 {
            let fd = (plus[i] - minus[i]) / (2.0 * h);
            assert!(
                (jv[i] - fd).abs() <= 1e-8 * (1.0 + fd.abs()),
                "{i}: {} vs {fd}",
                jv[i]
            );
        }
    }

    #[test]
    fn rate_gradient_matches_central_differences() {
        let sizes = [5, 4, 2, 4, 5];
        let tanh = [true, false, true, false];
        let mut rng = SplitMix64::new(3);
        let mut layers = test_layers(&sizes, &mut rng);
        let (rows, beta) = (4, 0.7);
        let x: Vec<f64> = (0..rows * 5).map(|_| rng.range(-1.0, 1.0)).collect();
        let v: Vec<f64> = (0..rows * 5).map(|_| rng.range(-3.0, 3.0)).collect();
        let weights: Vec<f64> = (0..rows).map(|_| rng.range(0.5, 2.0)).collect();
        let index: Vec<usize> = (0..rows).collect();
        let mut ws = Workspace::new(&sizes, rows);
        let mut rb = RateBuffers::new(&sizes, rows);
        ws.load_rows(&x, 5, &index, Some(&weights));
        rb.load(&v, 5, &index);
        loss(&layers, &tanh, &mut ws, &mut rb, rows, beta);
        for (gw, gb) in ws.grad_w.iter_mut().zip(ws.grad_b.iter_mut()) {
            gw.iter_mut().chain(gb.iter_mut()).for_each(|g| *g = 0.0);
        }
        add_rate_gradient(&layers, &tanh, &mut ws, &mut rb, rows, beta);
        let (gw, gb) = (ws.grad_w.clone(), ws.grad_b.clone());
        assert_gradient_is_central_differences(&mut layers, &gw, &gb, |layers| {
            loss(layers, &tanh, &mut ws, &mut rb, rows, beta)
        });
    }

    #[test]
    fn rate_gradient_with_a_row_metric_matches_central_differences() {
        // β (1/(B·n)) Σ_b ω_b (‖e_b‖² + κ ‖e_b‖²_{i_b}), e_b = J_f(x_b) v_b − v_b, on loaded rows
        // that are data rows 6, 1, 4, 2 (nn::metric)
        let sizes = [5, 4, 2, 4, 5];
        let tanh = [true, false, true, false];
        let mut rng = SplitMix64::new(19);
        let mut layers = test_layers(&sizes, &mut rng);
        let (rows, beta) = (4, 0.7);
        let x: Vec<f64> = (0..7 * 5).map(|_| rng.range(-1.0, 1.0)).collect();
        let v: Vec<f64> = (0..7 * 5).map(|_| rng.range(-3.0, 3.0)).collect();
        let weights: Vec<f64> = (0..7).map(|_| rng.range(0.5, 2.0)).collect();
        let index = [6, 1, 4, 2];
        let (metric, _) = crate::nn::metric::test_metric((5, 3, 7), 1.3, rows, &mut rng);
        let mut ws = Workspace::new(&sizes, rows).with_metric(metric);
        let mut rb = RateBuffers::new(&sizes, rows);
        ws.load_rows(&x, 5, &index, Some(&weights));
        rb.load(&v, 5, &index);
        let with_metric = loss(&layers, &tanh, &mut ws, &mut rb, rows, beta);
        for (gw, gb) in ws.grad_w.iter_mut().zip(ws.grad_b.iter_mut()) {
            gw.iter_mut().chain(gb.iter_mut()).for_each(|g| *g = 0.0);
        }
        add_rate_gradient(&layers, &tanh, &mut ws, &mut rb, rows, beta);
        let (gw, gb) = (ws.grad_w.clone(), ws.grad_b.clone());
        // without the loss evaluated first (the tangent pass forgets the kept product), the same
        // gradient to rounding
        forward_rates(&layers, &tanh, &mut ws, &mut rb, rows);
        for (gw, gb) in ws.grad_w.iter_mut().zip(ws.grad_b.iter_mut()) {
            gw.iter_mut().chain(gb.iter_mut()).for_each(|g| *g = 0.0);
        }
        add_rate_gradient(&layers, &tanh, &mut ws, &mut rb, rows, beta);
        for (a, b) in ws.grad_w.iter().flatten().zip(gw.iter().flatten()) {
            assert!((a - b).abs() <= 1e-13 * (1.0 + b.abs()), "{a} vs {b}");
        }
        let mut plain = Workspace::new(&sizes, rows);
        plain.load_rows(&x, 5, &index, Some(&weights));
        let without = loss(&layers, &tanh, &mut plain, &mut rb, rows, beta);
        assert!(with_metric > without, "{with_metric} vs {without}");
        rb.load(&v, 5, &index);
        assert_gradient_is_central_differences(&mut layers, &gw, &gb, |layers| {
            loss(layers, &tanh, &mut ws, &mut rb, rows, beta)
        });
    }
}
