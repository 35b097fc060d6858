//! Adam (Kingma & Ba 2015) on the weights and biases of a chain of layers:
//! `m ← β₁m + (1−β₁)g`, `v ← β₂v + (1−β₂)g²`, `θ ← θ − η m̂/(√v̂ + ε)`, `m̂ = m/(1−β₁ᵗ)`,
//! `v̂ = v/(1−β₂ᵗ)`, with `β₁ = 0.9`, `β₂ = 0.999`, `ε = 1e-8`. The weight penalty's gradient `2λW`
//! is added here, not in the backward pass ([`super::batch::backward_batch_without_penalty`]).

use super::batch::{Workspace, PARALLEL_MIN_MACS};
use super::mlp::Layer;

/// Adam moments for every weight and bias.
pub(crate) struct Adam {
    layers: Vec<Moments>,
    t: i32,
}

/// First and second moments of one layer's weights and biases.
struct Moments {
    m_w: Vec<f64>,
    v_w: Vec<f64>,
    m_b: Vec<f64>,
    v_b: Vec<f64>,
}

const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPS: f64 = 1e-8;

impl Adam {
    pub(crate) fn new(layers: &[Layer]) -> Self {
        Adam {
            layers: layers
                .iter()
                .map(|l| Moments {
                    m_w: vec![0.0; l.w.len()],
                    v_w: vec![0.0; l.w.len()],
                    m_b: vec![0.0; l.b.len()],
                    v_b: vec![0.0; l.b.len()],
                })
                .collect(),
            t: 0,
        }
    }

    /// One step `θ ← θ − η m̂/(√v̂ + ε)` on every layer with the gradients in `ws`, which lack the
    /// penalty's `2λ W` ([`super::batch::backward_batch_without_penalty`]); it is added here. Two tasks (rayon)
    /// update the layers before and after the middle of the parameters (the encoder and the decoder
    /// of an autoencoder); the update is elementwise, so the result does not depend on the split.
    pub(crate) fn step(&mut self, layers: &mut [Layer], ws: &Workspace, lr: f64, lambda: f64) {
        self.t = self.t.saturating_add(1);
        let rates = AdamRates::new(lr, self.t);
        let update = |layers: &mut [Layer], moments: &mut [Moments], k0: usize| {
            for (k, (layer, m)) in layers.iter_mut().zip(moments).enumerate() {
                let (gw, gb) = (&ws.grad_w[k0 + k], &ws.grad_b[k0 + k]);
                adam_update(
                    &mut layer.w,
                    gw,
                    &mut m.m_w,
                    &mut m.v_w,
                    rates,
                    2.0 * lambda,
                );
                adam_update(&mut layer.b, gb, &mut m.m_b, &mut m.v_b, rates, 0.0);
            }
        };
        let sizes = layers.iter().map(|l| l.w.len() + l.b.len());
        let total: usize = sizes.clone().sum();
        if total < PARALLEL_MIN_MACS / 8 {
            update(layers, &mut self.layers, 0);
            return;
        }
        // cut after the layers whose running count of parameters stays within half of them
        let mut seen = 0;
        let middle = sizes
            .take_while(|n| {
                seen += n;
                2 * seen <= total
            })
            .count()
            .max(1);
        let (first, second) = layers.split_at_mut(middle);
        let (m_first, m_second) = self.layers.split_at_mut(middle);
        rayon::join(
            || update(first, m_first, 0),
            || update(second, m_second, middle),
        );
    }
}

/// The factors of step `t`: `θ ← θ − (η/c₁) m / (√(v · (1/c₂)) + ε)` with the bias corrections
/// `c₁ = 1 − β₁ᵗ`, `c₂ = 1 − β₂ᵗ`, which is `η m̂/(√v̂ + ε)` up to rounding with one division and one
/// square root per parameter (instead of three divider operations, the bound of the update).
#[derive(Debug, Clone, Copy)]
struct AdamRates {
    lr_over_c1: f64,
    inv_c2: f64,
}

impl AdamRates {
    fn new(lr: f64, t: i32) -> Self {
        AdamRates {
            lr_over_c1: lr / (1.0 - BETA1.powi(t)),
            inv_c2: 1.0 / (1.0 - BETA2.powi(t)),
        }
    }
}

simd_fn! {
    /// Elementwise Adam update ([`AdamRates`]) on the gradient `g + two_lambda·θ` (the penalty's
    /// term, summed as [`crate::nn::batch::backward_batch`] does).
    fn adam_update(
        theta: &mut [f64],
        g: &[f64],
        m: &mut [f64],
        v: &mut [f64],
        rates: AdamRates,
        two_lambda: f64,
    ) {
        let AdamRates { lr_over_c1, inv_c2 } = rates;
        for (((theta, g), m), v) in theta.iter_mut().zip(g).zip(m.iter_mut()).zip(v.iter_mut()) {
            let g = two_lambda * *theta + g;
            *m = BETA1 * *m + (1.0 - BETA1) * g;
            *v = BETA2 * *v + (1.0 - BETA2) * g * g;
            *theta -= lr_over_c1 * *m / ((*v * inv_c2).sqrt() + EPS);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::batch::{
        backward_batch, backward_batch_without_penalty, forward_batch, test_layers,
    };
    use gvs::inputs::SplitMix64;

    #[test]
    fn adam_step_adds_the_penalty_as_backward_batch_does() {
        // Two Adam steps with the penalty added in the update equal, bit for bit, the update on the
        // full gradient of `backward_batch`; and the textbook update to rounding.
        let sizes = [9, 5, 2, 5, 9];
        let tanh = [true, false, true, false];
        let mut rng = SplitMix64::new(5);
        let mut layers = test_layers(&sizes, &mut rng);
        let (rows, lambda, lr) = (7, 0.02, 1e-2);
        let x: Vec<f64> = (0..rows * 9).map(|_| rng.range(-1.0, 1.0)).collect();
        let mut ws = Workspace::new(&sizes, rows);
        let mut reference = layers.clone();
        let mut m: Vec<Vec<f64>> = layers.iter().map(|l| vec![0.0; l.w.len()]).collect();
        let mut v = m.clone();
        let mut mb: Vec<Vec<f64>> = layers.iter().map(|l| vec![0.0; l.b.len()]).collect();
        let mut vb = mb.clone();
        let mut adam = Adam::new(&layers);
        let mut textbook = layers.clone();
        let (mut m_t, mut v_t) = (m.clone(), v.clone());
        for t in 1..=2 {
            ws.acts[0][..rows * 9].copy_from_slice(&x);
            forward_batch(&reference, &tanh, &mut ws, rows);
            backward_batch(&reference, &tanh, &mut ws, rows, lambda);
            let (c1, c2) = (1.0 - BETA1.powi(t), 1.0 - BETA2.powi(t));
            let AdamRates { lr_over_c1, inv_c2 } = AdamRates::new(lr, t);
            for (k, layer) in textbook.iter_mut().enumerate() {
                let (theta, g) = (&mut layer.w, &ws.grad_w[k]);
                let (m, v) = (&mut m_t[k], &mut v_t[k]);
                for i in 0..theta.len() {
                    m[i] = BETA1 * m[i] + (1.0 - BETA1) * g[i];
                    v[i] = BETA2 * v[i] + (1.0 - BETA2) * g[i] * g[i];
                    theta[i] -= lr * (m[i] / c1) / ((v[i] / c2).sqrt() + EPS);
                }
            }
            for (k, layer) in reference.iter_mut().enumerate() {
                for (theta, g, m, v) in [
                    (&mut layer.w, &ws.grad_w[k], &mut m[k], &mut v[k]),
                    (&mut layer.b, &ws.grad_b[k], &mut mb[k], &mut vb[k]),
                ] {
                    for i in 0..theta.len() {
                        m[i] = BETA1 * m[i] + (1.0 - BETA1) * g[i];
                        v[i] = BETA2 * v[i] + (1.0 - BETA2) * g[i] * g[i];
                        theta[i] -= lr_over_c1 * m[i] / ((v[i] * inv_c2).sqrt() + EPS);
                    }
                }
            }
            ws.acts[0][..rows * 9].copy_from_slice(&x);
            forward_batch(&layers, &tanh, &mut ws, rows);
            backward_batch_without_penalty(&layers, &tanh, &mut ws, rows);
            adam.step(&mut layers, &ws, lr, lambda);
            assert_eq!(layers, reference, "step {t}");
            for (a, b) in layers.iter().zip(&textbook) {
                for (a, b) in a.w.iter().zip(&b.w) {
                    assert!(
                        (a - b).abs() <= 1e-15 * (b.abs() + lr),
                        "step {t}: {a} vs {b}"
                    );
                }
            }
        }
    }
}
