//! The decoder as the strain parameterization `c(z) = A (s ⊙ dec(z) + μ)` (paper eq. 16, projected
//! onto the HOM's basis coefficients by the caller's `A`), with the derivatives of eqs. (6), (7), (17).
//!
//! Folding: the affine output map is merged into the decoder's linear last layer once, at
//! construction: `W'_L = A diag(s) W_L`, `b'_L = A (s ⊙ b_L + μ)`, so an evaluation costs
//! `O(m·h_L)` in the last layer (m outputs) rather than `O(n·h_L)`.
//!
//! With `σ = tanh`, `σ' = 1 − σ²`, `σ'' = −2σσ'`, hidden layers `h_{k+1} = σ(a_k)`,
//! `a_k = W_k h_k + b_k`, and the input tangent `T_k = ∂h_k/∂z` (`T_0 = I`):
//!
//! - [`CoefficientMap::eval`], forward mode with `r` tangents: `P_k = W_k T_k = ∂a_k/∂z`,
//!   `T_{k+1} = σ'(a_k) ⊙ P_k`; the linear last layer gives `c = W h + b`, `C_z = W T`. It keeps
//!   `σ(a_k)` and `P_k` of every hidden layer in `scratch` (`Σ_k n_k (1 + r)` values) and nothing of
//!   second order, so residual-only evaluations pay for value and Jacobian alone.
//! - [`CoefficientMap::eval_value`], `c` alone: one column per layer.
//! - [`CoefficientMap::eval_rate`], one directional pass along `ż` (eq. 17): with `Ṫ_0 = 0`,
//!   `Ṫ_{k+1} = σ'(a_k) ⊙ (W_k Ṫ_k) + σ''(a_k) ⊙ (P_k ż) ⊙ P_k` (row-wise), `Ċ_z = W_L Ṫ_L`.
//! - [`CoefficientMap::eval_motion`], second-order forward mode along `z(t)`: with `ḣ_0 = ż`,
//!   `ḧ_0 = z̈`, `ȧ_k = W_k ḣ_k`, `ä_k = W_k ḧ_k`, then `ḣ_{k+1} = σ'(a_k) ȧ_k` and
//!   `ḧ_{k+1} = σ'(a_k) ä_k + σ''(a_k) ȧ_k²` (elementwise); three columns per layer instead of
//!   `1 + r`. It stores `σ(a_k)` only.
//! - [`CoefficientMap::vjp`], reverse mode: `μ_{L−1} = W_Lᵀ g`, `μ_{k−1} = W_kᵀ (σ'(a_k) ⊙ μ_k)`,
//!   `C_zᵀ g = μ_{−1}`: one column per layer.
//! - [`CoefficientMap::add_weighted_hessian`], reverse over forward: for `φ = gᵀ c`, the linear
//!   maps have no curvature, so `∇²φ = Σ_k P_kᵀ diag(μ_k ⊙ σ''(a_k)) P_k` with the adjoints
//!   `μ_{L−1} = W_Lᵀ g`, `μ_{k−1} = W_kᵀ (σ'(a_k) ⊙ μ_k)` — `O(Σ n_k r²)`, no third-order tensor.
//!
//! The weights are kept column-major (and transposed, for the reverse passes), so every product is
//! one call of this crate's small kernels (`gemm`: value and tangents together). No call
//! allocates (`tests/decoder_map_no_alloc.rs`).

use super::mlp::{Layer, Mlp};
use super::{NnError, Scaling};
use crate::gemm::mul_cols;
use crate::map::CoefficientMap;

/// A decoder network whose last layer is folded with `c = A (s ⊙ y + μ)`.
#[derive(Debug, Clone, PartialEq)]
pub struct DecoderMap {
    /// Hidden tanh layers, then the folded linear output layer (`m` outputs).
    layers: Vec<ColLayer>,
    r: usize,
    m: usize,
    widest: usize,
}

impl DecoderMap {
    /// Folds `decoder` (`r → n`, scaled units), `scaling` (`n` features) and `A` (`m × n`,
    /// column-major: `A_ij` at `i + j·m`) into one map `c(z) = A (s ⊙ dec(z) + μ)`.
    /// With `A = I` (m = n) `c` is the physical reconstruction `D(z)`.
    pub fn new(decoder: &Mlp, scaling: &Scaling, a: &[f64], m: usize) -> Result<Self, NnError> {
        let n = decoder.n_out();
        if scaling.len() != n {
            return Err(NnError::Mismatch {
                what: "scaling features vs decoder outputs",
                got: scaling.len(),
                expected: n,
            });
        }
        if m == 0 || a.len() != m * n {
            return Err(NnError::DataShape {
                what: "projection A",
                got: a.len(),
                expected: n,
                shape: "m × n column-major, m ≥ 1",
            });
        }
        if let Some(index) = a.iter().position(|x| !x.is_finite()) {
            return Err(NnError::NonFiniteParameter {
                layer: decoder.n_layers(),
                what: "projection A",
                index,
                value: a[index],
            });
        }
        let mut layers = decoder.layers().to_vec();
        let last = layers.pop().ok_or(NnError::TooFewLayers { got: 1 })?;
        layers.push(fold_output_layer(&last, scaling, a, m));
        let widest = layers
            .iter()
            .map(|l| l.n_in.max(l.n_out))
            .max()
            .unwrap_or(m);
        Ok(DecoderMap {
            layers: layers.iter().map(ColLayer::of).collect(),
            r: decoder.n_in(),
            m,
            widest,
        })
    }

    /// Offset in `scratch` of hidden layer `k`'s stored `σ(a_k)` (then `P_k`, `n_k × r`).
    fn store(&self, k: usize) -> usize {
        self.layers[..k]
            .iter()
            .map(|l| l.n_out * (1 + self.r))
            .sum()
    }

    /// Columns of a work block: `1 + r` ([`CoefficientMap::eval`]) or 3 ([`CoefficientMap::eval_motion`]).
    fn work_cols(&self) -> usize {
        (1 + self.r).max(3)
    }

    /// Length of the stored part of `scratch`.
    fn stored_len(&self) -> usize {
        self.store(self.layers.len() - 1)
    }
}

/// A layer as the evaluation uses it: `W` column-major `n_out × n_in` (element `(i, j)` at
/// `i + j·n_out`, the transpose of [`Layer`]'s storage), `Wᵀ` column-major (the reverse passes:
/// a product with one column is then contiguous row updates, not dot products), `b` of `n_out`.
#[derive(Debug, Clone, PartialEq)]
struct ColLayer {
    n_in: usize,
    n_out: usize,
    w: Vec<f64>,
    wt: Vec<f64>,
    b: Vec<f64>,
}

impl ColLayer {
    fn of(l: &Layer) -> Self {
        let mut w = vec![0.0; l.n_out * l.n_in];
        for i in 0..l.n_out {
            for j in 0..l.n_in {
                w[i + j * l.n_out] = l.w[i * l.n_in + j];
            }
        }
        ColLayer {
            n_in: l.n_in,
            n_out: l.n_out,
            w,
            wt: l.w.clone(),
            b: l.b.clone(),
        }
    }
}

/// `W' = A diag(s) W`, `b' = A (s ⊙ b + μ)` for the row-major `n × h` last layer and column-major `A`.
fn fold_output_layer(last: &Layer, scaling: &Scaling, a: &[f64], m: usize) -> Layer {
    let (n, h) = (last.n_out, last.n_in);
    let (s, mu) = (scaling.scale(), scaling.mean());
    let mut w = vec![0.0; m * h];
    let mut b = vec![0.0; m];
    for j in 0..n {
        let w_row = &last.w[j * h..(j + 1) * h];
        let shifted = s[j] * last.b[j] + mu[j];
        for i in 0..m {
            let coef = a[i + j * m] * s[j];
            w[i * h..(i + 1) * h]
                .iter_mut()
                .zip(w_row)
                .for_each(|(wi, wj)| *wi += coef * wj);
            b[i] += a[i + j * m] * shifted;
        }
    }
    Layer {
        n_in: h,
        n_out: m,
        w,
        b,
    }
}

impl CoefficientMap for DecoderMap {
    fn n_in(&self) -> usize {
        self.r
    }

    fn n_out(&self) -> usize {
        self.m
    }

    /// The stored `σ(a_k)`, `P_k` of the hidden layers, plus two work blocks of
    /// `widest × max(1 + r, 3)`.
    fn scratch_len(&self) -> usize {
        self.stored_len() + 2 * self.widest * self.work_cols()
    }

    fn eval(&self, z: &[f64], c: &mut [f64], c_z: &mut [f64], scratch: &mut [f64]) {
        let (r, m) = (self.r, self.m);
        let cols = 1 + r;
        let (stored, work) = scratch.split_at_mut(self.stored_len());
        let (x, y) = work.split_at_mut(self.widest * self.work_cols());
        let (mut x, mut y) = (x, y);
        // input block: value z, tangents I
        x[..r * cols].iter_mut().for_each(|v| *v = 0.0);
        x[..r].copy_from_slice(z);
        for l in 0..r {
            x[(1 + l) * r + l] = 1.0;
        }
        let last = self.layers.len() - 1;
        let mut off = 0;
        for (k, layer) in self.layers.iter().enumerate() {
            let (n_in, n_out) = (layer.n_in, layer.n_out);
            mul_cols((n_out, n_in, cols), &layer.w, x, y);
            y[..n_out]
                .iter_mut()
                .zip(&layer.b)
                .for_each(|(yi, b)| *yi += b);
            if k < last {
                let st = &mut stored[off..off + n_out * cols];
                for i in 0..n_out {
                    let sigma = super::activation::tanh(y[i]);
                    let d1 = 1.0 - sigma * sigma;
                    st[i] = sigma;
                    for l in 0..r {
                        let p = (1 + l) * n_out + i;
                        st[p] = y[p];
                        y[p] *= d1;
                    }
                    y[i] = sigma;
                }
                off += n_out * cols;
            }
            std::mem::swap(&mut x, &mut y);
        }
        c.copy_from_slice(&x[..m]);
        c_z.copy_from_slice(&x[m..m * cols]);
    }

    /// One column per layer; the stored part of `scratch` is left as it was.
    fn eval_value(&self, z: &[f64], c: &mut [f64], scratch: &mut [f64]) {
        let (_, work) = scratch.split_at_mut(self.stored_len());
        let (x, y) = work.split_at_mut(self.widest * self.work_cols());
        let (mut x, mut y) = (x, y);
        x[..self.r].copy_from_slice(z);
        let last = self.layers.len() - 1;
        for (k, layer) in self.layers.iter().enumerate() {
            let (n_in, n_out) = (layer.n_in, layer.n_out);
            mul_cols((n_out, n_in, 1), &layer.w, x, y);
            for (yi, b) in y[..n_out].iter_mut().zip(&layer.b) {
                *yi += b;
                if k < last {
                    *yi = super::activation::tanh(*yi);
                }
            }
            std::mem::swap(&mut x, &mut y);
        }
        c.copy_from_slice(&x[..self.m]);
    }

    fn eval_rate(&self, _z: &[f64], zd: &[f64], c_z_dot: &mut [f64], scratch: &mut [f64]) {
        let r = self.r;
        let (stored, work) = scratch.split_at_mut(self.stored_len());
        let (x, y) = work.split_at_mut(self.widest * self.work_cols());
        let (mut x, mut y) = (x, y);
        let last = self.layers.len() - 1;
        let mut off = 0;
        for (k, layer) in self.layers.iter().enumerate() {
            let (n_in, n_out) = (layer.n_in, layer.n_out);
            // W Ṫ_k (Ṫ_0 = 0)
            if k == 0 {
                y[..n_out * r].fill(0.0);
            } else {
                mul_cols((n_out, n_in, r), &layer.w, x, y);
            }
            if k == last {
                c_z_dot.copy_from_slice(&y[..n_out * r]);
                return;
            }
            let st = &stored[off..off + n_out * (1 + r)];
            for i in 0..n_out {
                let sigma = st[i];
                let d1 = 1.0 - sigma * sigma;
                let d2 = -2.0 * sigma * d1;
                let v: f64 = (0..r).map(|l| st[(1 + l) * n_out + i] * zd[l]).sum();
                for l in 0..r {
                    let p = l * n_out + i;
                    y[p] = d1 * y[p] + d2 * v * st[(1 + l) * n_out + i];
                }
            }
            off += n_out * (1 + r);
            std::mem::swap(&mut x, &mut y);
        }
    }

    fn add_weighted_hessian(&self, _z: &[f64], g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
        let r = self.r;
        let (stored, work) = scratch.split_at_mut(self.stored_len());
        let (mu, next) = work.split_at_mut(self.widest * self.work_cols());
        let (mut mu, mut next) = (mu, next);
        let last = self.layers.len() - 1;
        // μ_{L−1} = W_Lᵀ g
        let wl = &self.layers[last];
        mul_cols((wl.n_in, wl.n_out, 1), &wl.wt, g, mu);
        for k in (0..last).rev() {
            let layer = &self.layers[k];
            let (n_in, n_out) = (layer.n_in, layer.n_out);
            let off = self.store(k);
            let st = &stored[off..off + n_out * (1 + r)];
            for i in 0..n_out {
                let sigma = st[i];
                let d1 = 1.0 - sigma * sigma;
                let q = mu[i] * (-2.0 * sigma * d1);
                if q != 0.0 {
                    // out += q P_iᵀ P_i (row i of P_k)
                    for j in 0..r {
                        let pj = q * st[(1 + j) * n_out + i];
                        for l in 0..=j {
                            let v = pj * st[(1 + l) * n_out + i];
                            out[l + r * j] += v;
                            if l != j {
                                out[j + r * l] += v;
                            }
                        }
                    }
                }
                mu[i] *= d1;
            }
            if k > 0 {
                // μ_{k−1} = W_kᵀ (σ' ⊙ μ_k)
                mul_cols((n_in, n_out, 1), &layer.wt, mu, next);
                std::mem::swap(&mut mu, &mut next);
            }
        }
    }

    fn eval_motion(
        &self,
        z: &[f64],
        zd: &[f64],
        zdd: Option<&[f64]>,
        c: &mut [f64],
        c_dot: &mut [f64],
        c_acc: &mut [f64],
        scratch: &mut [f64],
    ) {
        let (r, m) = (self.r, self.m);
        let (stored, work) = scratch.split_at_mut(self.stored_len());
        let (x, y) = work.split_at_mut(self.widest * self.work_cols());
        let (mut x, mut y) = (x, y);
        // input block [z | ż | z̈]
        x[..r].copy_from_slice(z);
        x[r..2 * r].copy_from_slice(zd);
        match zdd {
            Some(zdd) => x[2 * r..3 * r].copy_from_slice(zdd),
            None => x[2 * r..3 * r].fill(0.0),
        }
        let last = self.layers.len() - 1;
        for (k, layer) in self.layers.iter().enumerate() {
            let (n_in, n_out) = (layer.n_in, layer.n_out);
            mul_cols((n_out, n_in, 3), &layer.w, x, y);
            y[..n_out]
                .iter_mut()
                .zip(&layer.b)
                .for_each(|(yi, b)| *yi += b);
            if k < last {
                let st = &mut stored[self.store(k)..self.store(k) + n_out];
                let (v, rest) = y.split_at_mut(n_out);
                let (ad, add) = rest.split_at_mut(n_out);
                for i in 0..n_out {
                    let sigma = super::activation::tanh(v[i]);
                    let d1 = 1.0 - sigma * sigma;
                    let d2 = -2.0 * sigma * d1;
                    st[i] = sigma;
                    v[i] = sigma;
                    add[i] = d1 * add[i] + d2 * ad[i] * ad[i];
                    ad[i] *= d1;
                }
            }
            std::mem::swap(&mut x, &mut y);
        }
        c.copy_from_slice(&x[..m]);
        c_dot.copy_from_slice(&x[m..2 * m]);
        c_acc.copy_from_slice(&x[2 * m..3 * m]);
    }

    fn vjp(&self, g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
        let (stored, work) = scratch.split_at_mut(self.stored_len());
        let (mu, next) = work.split_at_mut(self.widest * self.work_cols());
        let (mut mu, mut next) = (mu, next);
        let last = self.layers.len() - 1;
        let wl = &self.layers[last];
        if last == 0 {
            mul_cols((wl.n_in, wl.n_out, 1), &wl.wt, g, out);
            return;
        }
        // μ_{L−1} = W_Lᵀ g
        mul_cols((wl.n_in, wl.n_out, 1), &wl.wt, g, mu);
        for k in (0..last).rev() {
            let layer = &self.layers[k];
            let (n_in, n_out) = (layer.n_in, layer.n_out);
            let st = &stored[self.store(k)..self.store(k) + n_out];
            for (m, &sigma) in mu[..n_out].iter_mut().zip(st) {
                *m *= 1.0 - sigma * sigma;
            }
            if k > 0 {
                mul_cols((n_in, n_out, 1), &layer.wt, mu, next);
                std::mem::swap(&mut mu, &mut next);
            } else {
                mul_cols((n_in, n_out, 1), &layer.wt, mu, out);
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests;
