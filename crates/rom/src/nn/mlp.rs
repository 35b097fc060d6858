//! A dense tanh network with a linear output layer (paper §III, "tanh activation functions").
//!
//! Layer `k` maps `h_k ∈ R^{n_k}` to `h_{k+1} = σ_k(W_k h_k + b_k)` with `σ_k = tanh` for every layer
//! but the last, whose `σ = identity`. The paper uses tanh "for all layers" but leaves the output
//! layer open; a tanh output could only produce values in (−1, 1), while a linear output together with
//! the per-feature [`crate::nn::Scaling`] lets the reconstruction reach any strain, and keeps the map
//! smooth (the hidden layers supply the nonlinearity).
//!
//! Storage: `W_k` is row-major `n_{k+1} × n_k` (element `(i, j)` at `i·n_k + j`, one row per output
//! unit), `b_k` has `n_{k+1}` values. [`Mlp::weights`], [`Mlp::biases`] and [`Mlp::new`] expose
//! exactly these vectors, so another module can save and load a network without serde.

use super::batch::{forward_rows, Workspace};
use super::NnError;
use gvs::inputs::SplitMix64;

/// One dense layer: `W` row-major `n_out × n_in`, `b` of length `n_out`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Layer {
    pub n_in: usize,
    pub n_out: usize,
    pub w: Vec<f64>,
    pub b: Vec<f64>,
}

impl Layer {
    /// Glorot/Xavier uniform initialisation: `W_ij ~ U(−a, a)`, `a = √(6 / (n_in + n_out))`, `b = 0`.
    pub fn glorot(n_in: usize, n_out: usize, rng: &mut SplitMix64) -> Self {
        let a = (6.0 / (n_in + n_out) as f64).sqrt();
        let w = (0..n_in * n_out).map(|_| rng.range(-a, a)).collect();
        Layer {
            n_in,
            n_out,
            w,
            b: vec![0.0; n_out],
        }
    }

    /// `Σ_ij W_ij²`.
    pub fn sum_squared_weights(&self) -> f64 {
        self.w.iter().map(|w| w * w).sum()
    }
}

/// A stack of dense layers, tanh on all but the last (linear) layer.
#[derive(Debug, Clone, PartialEq)]
pub struct Mlp {
    sizes: Vec<usize>,
    layers: Vec<Layer>,
}

impl Mlp {
    /// A network from its layer sizes `[n_0, …, n_L]` and, for each layer `k < L`, the row-major
    /// weights `W_k` (`n_{k+1}·n_k` values) and biases `b_k` (`n_{k+1}` values).
    ///
    /// Errors name the layer and the expected shape; all parameters must be finite.
    pub fn new(
        sizes: &[usize],
        weights: Vec<Vec<f64>>,
        biases: Vec<Vec<f64>>,
    ) -> Result<Self, NnError> {
        check_sizes(sizes)?;
        let n_layers = sizes.len() - 1;
        for (what, got) in [("weight", weights.len()), ("bias", biases.len())] {
            if got != n_layers {
                return Err(NnError::LayerCount {
                    what,
                    got,
                    expected: n_layers,
                });
            }
        }
        let mut layers = Vec::with_capacity(n_layers);
        for (k, (w, b)) in weights.into_iter().zip(biases).enumerate() {
            let (n_in, n_out) = (sizes[k], sizes[k + 1]);
            check_vector(
                k,
                "weights",
                &w,
                n_out * n_in,
                format!("{n_out} × {n_in}, row-major"),
            )?;
            check_vector(k, "biases", &b, n_out, format!("{n_out}"))?;
            layers.push(Layer { n_in, n_out, w, b });
        }
        Ok(Mlp {
            sizes: sizes.to_vec(),
            layers,
        })
    }

    /// A network with Glorot-uniform weights drawn from `rng` and zero biases.
    pub fn glorot(sizes: &[usize], rng: &mut SplitMix64) -> Result<Self, NnError> {
        check_sizes(sizes)?;
        let layers = sizes
            .windows(2)
            .map(|s| Layer::glorot(s[0], s[1], rng))
            .collect();
        Ok(Mlp {
            sizes: sizes.to_vec(),
            layers,
        })
    }

    /// Layer sizes `[n_0, …, n_L]` (input first).
    pub fn layer_sizes(&self) -> &[usize] {
        &self.sizes
    }

    /// Number of weight layers `L`.
    pub fn n_layers(&self) -> usize {
        self.layers.len()
    }

    /// Input size `n_0`.
    pub fn n_in(&self) -> usize {
        self.sizes[0]
    }

    /// Output size `n_L`.
    pub fn n_out(&self) -> usize {
        self.sizes[self.sizes.len() - 1]
    }

    /// `W_k`, row-major `n_{k+1} × n_k`. Panics if `k ≥ n_layers()`.
    pub fn weights(&self, k: usize) -> &[f64] {
        &self.layers[k].w
    }

    /// `b_k` (`n_{k+1}` values). Panics if `k ≥ n_layers()`.
    pub fn biases(&self, k: usize) -> &[f64] {
        &self.layers[k].b
    }

    /// `Σ_k ‖W_k‖²_F`, the regularisation sum of eq. (15) (biases excluded).
    pub fn sum_squared_weights(&self) -> f64 {
        self.layers.iter().map(Layer::sum_squared_weights).sum()
    }

    /// The network applied to `rows` inputs stored row-major (`rows × n_0` values); returns
    /// `rows × n_L` values, row-major.
    pub fn forward(&self, x: &[f64]) -> Result<Vec<f64>, NnError> {
        let n_in = self.n_in();
        if !x.len().is_multiple_of(n_in) {
            return Err(NnError::DataShape {
                what: "MLP input",
                got: x.len(),
                expected: n_in,
                shape: "rows × n_in",
            });
        }
        let rows = x.len() / n_in;
        let tanh = self.tanh_flags();
        let mut ws = Workspace::new(&self.sizes, rows.clamp(1, 256));
        let mut out = vec![0.0; rows * self.n_out()];
        forward_rows(&self.layers, &tanh, x, rows, &mut ws, &mut out);
        Ok(out)
    }

    /// `true` for each tanh layer: all but the last.
    pub(crate) fn tanh_flags(&self) -> Vec<bool> {
        (0..self.layers.len())
            .map(|k| k + 1 < self.layers.len())
            .collect()
    }

    pub(crate) fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// A network from layers already known to be consistent.
    pub(crate) fn from_layers(layers: Vec<Layer>) -> Self {
        let mut sizes: Vec<usize> = layers.iter().map(|l| l.n_in).collect();
        sizes.extend(layers.last().map(|l| l.n_out));
        Mlp { sizes, layers }
    }
}

/// At least input and output, no empty layer.
fn check_sizes(sizes: &[usize]) -> Result<(), NnError> {
    if sizes.len() < 2 {
        return Err(NnError::TooFewLayers { got: sizes.len() });
    }
    match sizes.iter().position(|&n| n == 0) {
        Some(index) => Err(NnError::ZeroLayerSize { index }),
        None => Ok(()),
    }
}

/// Length `expected` and finite values.
fn check_vector(
    layer: usize,
    what: &'static str,
    v: &[f64],
    expected: usize,
    shape: String,
) -> Result<(), NnError> {
    if v.len() != expected {
        return Err(NnError::LayerShape {
            layer,
            what,
            got: v.len(),
            expected,
            shape,
        });
    }
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(NnError::NonFiniteParameter {
            layer,
            what,
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_rejects_wrong_weight_shape_naming_layer_and_shape() {
        let err = Mlp::new(
            &[3, 2, 1],
            vec![vec![0.0; 6], vec![0.0; 3]],
            vec![vec![0.0; 2], vec![0.0; 1]],
        );
        match err {
            Err(NnError::LayerShape {
                layer: 1,
                what: "weights",
                got: 3,
                expected: 2,
                shape,
            }) => {
                assert_eq!(shape, "1 × 2, row-major")
            }
            other => panic!("unexpected {other:?}"),
        }
    }

    #[test]
    fn new_round_trips_plain_data_and_forward_matches_hand_computation() {
        // h = tanh(W0 x + b0), y = W1 h + b1 with hand-picked numbers.
        let w0 = vec![0.5, -1.0, 0.25, 2.0];
        let b0 = vec![0.1, -0.2];
        let w1 = vec![1.5, -0.5];
        let b1 = vec![0.3];
        let mlp = Mlp::new(
            &[2, 2, 1],
            vec![w0.clone(), w1.clone()],
            vec![b0.clone(), b1.clone()],
        )
        .unwrap();
        assert_eq!(mlp.weights(0), &w0[..]);
        assert_eq!(mlp.biases(1), &b1[..]);
        let x = [0.7, -0.4];
        let h0 = (0.5 * 0.7 - 1.0 * -0.4 + 0.1f64).tanh();
        let h1 = (0.25 * 0.7 + 2.0 * -0.4 - 0.2f64).tanh();
        let y = 1.5 * h0 - 0.5 * h1 + 0.3;
        let out = mlp.forward(&x).unwrap();
        assert!((out[0] - y).abs() < 1e-15);
        assert!(Mlp::new(&[2, 2, 1], vec![w0, w1], vec![b0, vec![f64::NAN]]).is_err());
    }
}
