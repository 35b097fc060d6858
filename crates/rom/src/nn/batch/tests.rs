//! Tests of `nn::batch`.

use super::*;
use gvs::inputs::SplitMix64;

/// Total loss eq. (15) of the chain on the first `rows` samples of `H_0`.
fn total_loss(
    layers: &[Layer],
    tanh: &[bool],
    ws: &mut Workspace,
    rows: usize,
    lambda: f64,
) -> f64 {
    forward_batch(layers, tanh, ws, rows);
    let penalty: f64 = layers.iter().map(Layer::sum_squared_weights).sum();
    reconstruction_mse(ws, rows) + lambda * penalty
}

#[test]
fn gradient_matches_central_differences_on_tiny_autoencoder() {
    // 4 → 3 → 2 (linear latent) → 3 → 4 (linear output), 5 samples, random biases.
    let sizes = [4, 3, 2, 3, 4];
    let tanh = [true, false, true, false];
    let mut rng = SplitMix64::new(7);
    let mut layers = test_layers(&sizes, &mut rng);
    let (rows, lambda) = (5, 0.03);
    let mut ws = Workspace::new(&sizes, 8);
    let x: Vec<f64> = (0..rows * 4).map(|_| rng.range(-1.0, 1.0)).collect();
    ws.acts[0][..rows * 4].copy_from_slice(&x);
    forward_batch(&layers, &tanh, &mut ws, rows);
    backward_batch(&layers, &tanh, &mut ws, rows, lambda);
    let (gw, gb) = (ws.grad_w.clone(), ws.grad_b.clone());
    assert_gradient_is_central_differences(&mut layers, &gw, &gb, |layers| {
        total_loss(layers, &tanh, &mut ws, rows, lambda)
    });
}

#[test]
fn scaled_output_gradient_matches_central_differences() {
    // x̂_b = z_b1 (H_L)_b with z = H_2 (the linear latent of 4 → 3 → 2 → 3 → 4), weighted rows:
    // the loss is written here from a plain (ungated) forward pass, the product taken by hand.
    let sizes = [4, 3, 2, 3, 4];
    let tanh = [true, false, true, false];
    let mut rng = SplitMix64::new(17);
    let mut layers = test_layers(&sizes, &mut rng);
    let (rows, lambda) = (5, 0.02);
    let x: Vec<f64> = (0..rows * 4).map(|_| rng.range(-1.0, 1.0)).collect();
    let omega: Vec<f64> = (0..rows).map(|b| 0.5 + b as f64).collect();
    let index: Vec<usize> = (0..rows).collect();
    let mut plain = Workspace::new(&sizes, 8);
    let loss = |layers: &[Layer], ws: &mut Workspace| {
        ws.load_rows(&x, 4, &index, None);
        forward_batch(layers, &tanh, ws, rows);
        let mut sum = 0.0;
        for b in 0..rows {
            let z1 = ws.acts[2][b * 2];
            let y = &ws.acts[4][b * 4..(b + 1) * 4];
            let e: f64 = (0..4).map(|j| (z1 * y[j] - x[b * 4 + j]).powi(2)).sum();
            sum += omega[b] * e;
        }
        let penalty: f64 = layers.iter().map(Layer::sum_squared_weights).sum();
        sum / (rows * 4) as f64 + lambda * penalty
    };
    let mut gated = Workspace::new(&sizes, 8).gated(2);
    gated.load_rows(&x, 4, &index, Some(&omega));
    forward_batch(&layers, &tanh, &mut gated, rows);
    // the gated output is the product
    for b in 0..rows {
        for j in 0..4 {
            let expected = gated.acts[2][b * 2] * gated.pre_gate[b * 4 + j];
            assert_eq!(gated.acts[4][b * 4 + j], expected);
        }
    }
    backward_batch(&layers, &tanh, &mut gated, rows, lambda);
    let (gw, gb) = (gated.grad_w.clone(), gated.grad_b.clone());
    assert_gradient_is_central_differences(&mut layers, &gw, &gb, |layers| {
        loss(layers, &mut plain)
    });
}

#[test]
fn row_metric_loss_gradient_matches_central_differences() {
    // (1/(B·n)) Σ_b ω_b (‖e_b‖² + κ ‖e_b‖²_{i_b}) + λΣ‖W‖² (nn::metric; its value is checked
    // there against plain loops) on loaded rows that are data rows 7, 2, 5, 0, 3: the backward
    // pass is its gradient, and the metric changes it
    let sizes = [4, 3, 2, 3, 4];
    let tanh = [true, false, true, false];
    let mut rng = SplitMix64::new(17);
    let mut layers = test_layers(&sizes, &mut rng);
    let (rows, lambda) = (5, 0.01);
    let x: Vec<f64> = (0..8 * 4).map(|_| rng.range(-1.0, 1.0)).collect();
    let omega: Vec<f64> = (0..8).map(|_| rng.range(0.5, 2.0)).collect();
    let index = [7, 2, 5, 0, 3];
    let (metric, _) = crate::nn::metric::test_metric((4, 3, 8), 0.8, 8, &mut rng);
    let mut ws = Workspace::new(&sizes, 8).with_metric(metric);
    let total = |layers: &[Layer], ws: &mut Workspace| {
        ws.load_rows(&x, 4, &index, Some(&omega));
        total_loss(layers, &tanh, ws, rows, lambda)
    };
    total(&layers, &mut ws);
    backward_batch(&layers, &tanh, &mut ws, rows, lambda);
    let (gw, gb) = (ws.grad_w.clone(), ws.grad_b.clone());
    // without the loss evaluated first, the metric's product is computed from Δ itself: the
    // same gradient to rounding
    ws.load_rows(&x, 4, &index, Some(&omega));
    forward_batch(&layers, &tanh, &mut ws, rows);
    backward_batch(&layers, &tanh, &mut ws, rows, lambda);
    for (a, b) in ws.grad_w.iter().flatten().zip(gw.iter().flatten()) {
        assert!((a - b).abs() <= 1e-13 * (1.0 + b.abs()), "{a} vs {b}");
    }
    let mut plain = Workspace::new(&sizes, 8);
    total(&layers, &mut plain);
    backward_batch(&layers, &tanh, &mut plain, rows, lambda);
    assert!(plain.grad_w[0] != gw[0], "the metric changes the gradient");
    assert_gradient_is_central_differences(&mut layers, &gw, &gb, |layers| total(layers, &mut ws));
}

#[test]
fn row_weighted_loss_gradient_matches_central_differences() {
    // With row weights ω_b the loss is (1/(B·n)) Σ_b ω_b ‖x̂_b − x_b‖² + λΣ‖W‖², written here
    // row by row without the workspace's weighted paths; the weighted backward pass must be its
    // gradient, and weights of 1 must give the unweighted gradients bit for bit.
    let sizes = [4, 3, 2, 3, 4];
    let tanh = [true, false, true, false];
    let mut rng = SplitMix64::new(13);
    let mut layers = test_layers(&sizes, &mut rng);
    let (rows, lambda) = (6, 0.01);
    let x: Vec<f64> = (0..rows * 4).map(|_| rng.range(-1.0, 1.0)).collect();
    let omega: Vec<f64> = (0..rows).map(|b| 0.1 + 3.0 * b as f64).collect();
    let index: Vec<usize> = (0..rows).collect();
    let mut ws = Workspace::new(&sizes, 8);
    let loss = |layers: &[Layer], ws: &mut Workspace| {
        ws.load_rows(&x, 4, &index, None);
        forward_batch(layers, &tanh, ws, rows);
        let out = ws.output(rows);
        let mut sum = 0.0;
        for b in 0..rows {
            let e: f64 = (0..4)
                .map(|j| (out[b * 4 + j] - x[b * 4 + j]).powi(2))
                .sum();
            sum += omega[b] * e;
        }
        let penalty: f64 = layers.iter().map(Layer::sum_squared_weights).sum();
        sum / (rows * 4) as f64 + lambda * penalty
    };
    ws.load_rows(&x, 4, &index, Some(&omega));
    forward_batch(&layers, &tanh, &mut ws, rows);
    let weighted_mse = reconstruction_mse(&mut ws, rows);
    backward_batch(&layers, &tanh, &mut ws, rows, lambda);
    let (gw, gb) = (ws.grad_w.clone(), ws.grad_b.clone());
    let penalty: f64 = layers.iter().map(Layer::sum_squared_weights).sum();
    let direct = loss(&layers, &mut ws);
    assert!((weighted_mse + lambda * penalty - direct).abs() <= 1e-14 * direct);
    assert_gradient_is_central_differences(&mut layers, &gw, &gb, |layers| loss(layers, &mut ws));
    // weights of 1: the unweighted pass (gradients bit for bit; the loss sums per row first,
    // so to rounding)
    let ones = vec![1.0; rows];
    let mut pass = |w: Option<&[f64]>| {
        ws.load_rows(&x, 4, &index, w);
        forward_batch(&layers, &tanh, &mut ws, rows);
        let mse = reconstruction_mse(&mut ws, rows);
        backward_batch(&layers, &tanh, &mut ws, rows, lambda);
        (mse, ws.grad_w.clone(), ws.grad_b.clone())
    };
    let (weighted, unweighted) = (pass(Some(&ones)), pass(None));
    assert_eq!((&weighted.1, &weighted.2), (&unweighted.1, &unweighted.2));
    assert!((weighted.0 - unweighted.0).abs() <= 1e-15 * unweighted.0);
}

#[test]
fn weighted_physical_loss_gradient_matches_central_differences() {
    // The physical weighting is applied through the scaling: the scaled MSE's gradient must be
    // the gradient of (1/(c²·B·n)) Σ_b Σ_j w_j (x̂_bj − x_bj)² with x̂ = s ⊙ chain((x − μ)/s) + μ
    // and c² = (1/n) Σ_j w_j σ_j², written here in physical units without the scaling's code.
    use crate::nn::scaling::{Scaling, Weighting};
    let sizes = [4, 3, 1, 3, 4];
    let tanh = [true, false, true, false];
    let mut rng = SplitMix64::new(11);
    let mut layers: Vec<Layer> = sizes
        .windows(2)
        .map(|s| Layer::glorot(s[0], s[1], &mut rng))
        .collect();
    let rows = 6;
    // features of very different magnitudes, as bending (≈ 10 1/m) against elongation (≈ 1e-3)
    let mag = [10.0, 3.0, 1e-3, 0.5];
    let x: Vec<f64> = (0..rows * 4)
        .map(|i| mag[i % 4] * rng.range(-1.0, 1.0))
        .collect();
    let w = vec![1.0, 2.0, 5e4, 0.3];
    let all: Vec<usize> = (0..rows).collect();
    let scaling = Scaling::from_rows(&x, 4, &all, &Weighting::Physical(w.clone()));
    let mean: Vec<f64> = (0..4)
        .map(|j| (0..rows).map(|b| x[b * 4 + j]).sum::<f64>() / rows as f64)
        .collect();
    let var: Vec<f64> = (0..4)
        .map(|j| {
            (0..rows)
                .map(|b| (x[b * 4 + j] - mean[j]).powi(2))
                .sum::<f64>()
                / rows as f64
        })
        .collect();
    let c2 = (0..4).map(|j| w[j] * var[j]).sum::<f64>() / 4.0;
    let scale: Vec<f64> = w.iter().map(|w| (c2 / w).sqrt()).collect();
    let mut y = x.clone();
    scaling.to_scaled(&mut y);
    let mut ws = Workspace::new(&sizes, 8);
    let physical_loss = |layers: &[Layer], ws: &mut Workspace| {
        for b in 0..rows {
            for j in 0..4 {
                ws.acts[0][b * 4 + j] = (x[b * 4 + j] - mean[j]) / scale[j];
            }
        }
        forward_batch(layers, &tanh, ws, rows);
        let out = ws.output(rows);
        let mut sum = 0.0;
        for b in 0..rows {
            for j in 0..4 {
                let xhat = scale[j] * out[b * 4 + j] + mean[j];
                sum += w[j] * (xhat - x[b * 4 + j]).powi(2);
            }
        }
        sum / (c2 * (rows * 4) as f64)
    };
    ws.acts[0][..rows * 4].copy_from_slice(&y);
    forward_batch(&layers, &tanh, &mut ws, rows);
    backward_batch(&layers, &tanh, &mut ws, rows, 0.0);
    let gw = ws.grad_w.clone();
    let h = 1e-6;
    for k in 0..layers.len() {
        for i in 0..gw[k].len() {
            layers[k].w[i] += h;
            let up = physical_loss(&layers, &mut ws);
            layers[k].w[i] -= 2.0 * h;
            let down = physical_loss(&layers, &mut ws);
            layers[k].w[i] += h;
            let fd = (up - down) / (2.0 * h);
            let err = (fd - gw[k][i]).abs() / gw[k][i].abs().max(1e-3);
            assert!(err <= 1e-6, "layer {k} W[{i}]: fd {fd} vs {}", gw[k][i]);
        }
    }
}
