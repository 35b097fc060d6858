//! The decoder as the strain parameterization `c(z) = A (s ⊙ dec(z) + μ)` (paper eq. 16, projected
//! onto the HOM's basis coefficients by the caller's `A`), with the derivatives of eqs. (6), (7), (17).
//!
//! Folding: the affine output map is merged into the decoder's linear last layer once, at
//! construction: `W'_L = A diag(s) W_L`, `b'_L = A (s ⊙ b_L + μ)`, so an evaluation costs
//! `O(m·h_L)` in the last layer (m outputs) rather than `O(n·h_L)`.
//!
//! Forward mode with second-order tangents. Each layer input carries its value `h`, its Jacobian
//! `T = ∂h/∂z` (`n_k × r`) and its second derivatives `S_lj = ∂²h/∂z_l∂z_j` (`l ≤ j`, `r(r+1)/2`
//! columns); at the input `h = z`, `T = I`, `S = 0`. A layer `a = W h + b` gives `∂a = W T`,
//! `∂²a_lj = W S_lj`, and with `σ = tanh`, `σ' = 1 − σ²`, `σ'' = −2σσ'`:
//!
//! `h⁺ = σ(a)`, `T⁺_l = σ'(a) ⊙ (W T)_l`, `S⁺_lj = σ'(a) ⊙ (W S_lj) + σ''(a) ⊙ (W T)_l ⊙ (W T)_j`;
//!
//! the linear last layer gives `c = W h + b`, `C_z = W T`, `∂²c/∂z_l∂z_j = W S_lj`. [`CoefficientMap::eval`]
//! keeps the full output Hessian `H_ilj = ∂²c_i/∂z_l∂z_j` (`m·r²` values) in `scratch`; then
//! `(∂²c/∂z² ż)_il = Σ_j H_ilj ż_j` (eq. 17, the derivative of `C_z` along `ż`) and
//! `Σ_i g_i ∇²c_i` are contractions that need no further buffers, as the trait's read-only scratch
//! requires. The second-order columns cost `r(r+1)/2` extra matrix–vector products per layer (for
//! r ≤ 3 at most 1.5× the work of value + Jacobian + one directional pass). No call allocates; the
//! products are plain loops (no `dgemm`, whose packing buffers may allocate).

use super::mlp::{Layer, Mlp};
use super::{NnError, Scaling};
use crate::map::CoefficientMap;

/// A decoder network whose last layer is folded with `c = A (s ⊙ y + μ)`.
#[derive(Debug, Clone, PartialEq)]
pub struct DecoderMap {
    /// Hidden tanh layers, then the folded linear output layer (`m` outputs).
    layers: Vec<Layer>,
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
            layers,
            r: decoder.n_in(),
            m,
            widest,
        })
    }

    /// Number of tangent columns carried per unit: value, `r` first and `r(r+1)/2` second derivatives.
    fn n_cols(&self) -> usize {
        1 + self.r + self.r * (self.r + 1) / 2
    }

    /// Column of `∂²/∂z_l∂z_j` (symmetric in `l`, `j`) among [`Self::n_cols`].
    fn second_col(&self, l: usize, j: usize) -> usize {
        let (l, j) = (l.min(j), l.max(j));
        1 + self.r + j * (j + 1) / 2 + l
    }

    /// One layer on the tangent block `x` (`n_in × n_cols`, column-major) into `y` (`n_out × n_cols`).
    /// Each row of `W` is read once for all tangent columns.
    fn layer_forward(&self, layer: &Layer, tanh: bool, first: bool, x: &[f64], y: &mut [f64]) {
        let (n_in, n_out, cols) = (layer.n_in, layer.n_out, self.n_cols());
        // At the input S = 0, so W S = 0: skip those products.
        let computed = if first { 1 + self.r } else { cols };
        for i in 0..n_out {
            let w_row = &layer.w[i * n_in..(i + 1) * n_in];
            for col in 0..computed {
                y[col * n_out + i] = dot(w_row, &x[col * n_in..(col + 1) * n_in]);
            }
            for col in computed..cols {
                y[col * n_out + i] = 0.0;
            }
            y[i] += layer.b[i];
            if tanh {
                self.apply_tanh_row(y, n_out, i);
            }
        }
    }

    /// Row `i` of a pre-activation block through tanh: `S⁺ = σ' WS + σ'' (WT)_l (WT)_j`, `T⁺ = σ' WT`,
    /// `h⁺ = σ` (module docs).
    fn apply_tanh_row(&self, y: &mut [f64], ld: usize, i: usize) {
        let sigma = y[i].tanh();
        let d1 = 1.0 - sigma * sigma;
        let d2 = -2.0 * sigma * d1;
        for j in 0..self.r {
            for l in 0..=j {
                let p = self.second_col(l, j) * ld + i;
                y[p] = d1 * y[p] + d2 * y[(1 + l) * ld + i] * y[(1 + j) * ld + i];
            }
        }
        for l in 0..self.r {
            y[(1 + l) * ld + i] *= d1;
        }
        y[i] = sigma;
    }
}

/// `Σ a_i b_i` with four partial sums (lets the compiler vectorize; the order is fixed, so results
/// are repeatable).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
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

    /// `m·r²` for the output Hessian plus two tangent blocks of `widest × n_cols`.
    fn scratch_len(&self) -> usize {
        self.m * self.r * self.r + 2 * self.widest * self.n_cols()
    }

    fn eval(&self, z: &[f64], c: &mut [f64], c_z: &mut [f64], scratch: &mut [f64]) {
        let (r, m) = (self.r, self.m);
        let (hess, work) = scratch.split_at_mut(m * r * r);
        let (x, y) = work.split_at_mut(self.widest * self.n_cols());
        let cols = self.n_cols();
        x[..r * cols].iter_mut().for_each(|v| *v = 0.0);
        x[..r].copy_from_slice(z);
        for l in 0..r {
            x[(1 + l) * r + l] = 1.0;
        }
        let (mut x, mut y) = (x, y);
        let last = self.layers.len() - 1;
        for (k, layer) in self.layers.iter().enumerate() {
            self.layer_forward(layer, k < last, k == 0, x, y);
            std::mem::swap(&mut x, &mut y);
        }
        // The output block (m × n_cols) is now in `x`.
        c.copy_from_slice(&x[..m]);
        c_z.copy_from_slice(&x[m..m * (1 + r)]);
        for j in 0..r {
            for l in 0..r {
                let col = self.second_col(l, j);
                hess[(l + r * j) * m..(l + r * j + 1) * m]
                    .copy_from_slice(&x[col * m..(col + 1) * m]);
            }
        }
    }

    fn eval_rate(&self, _z: &[f64], zd: &[f64], c_z_dot: &mut [f64], scratch: &mut [f64]) {
        let (r, m) = (self.r, self.m);
        c_z_dot.iter_mut().for_each(|v| *v = 0.0);
        for l in 0..r {
            for (j, zd_j) in zd.iter().enumerate() {
                let h = &scratch[(l + r * j) * m..(l + r * j + 1) * m];
                c_z_dot[l * m..(l + 1) * m]
                    .iter_mut()
                    .zip(h)
                    .for_each(|(o, h)| *o += h * zd_j);
            }
        }
    }

    fn add_weighted_hessian(&self, _z: &[f64], g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
        let (r, m) = (self.r, self.m);
        for lj in 0..r * r {
            let h = &scratch[lj * m..(lj + 1) * m];
            out[lj] += h.iter().zip(g).map(|(h, g)| h * g).sum::<f64>();
        }
    }
}

#[cfg(test)]
mod tests;
