//! Full-batch L-BFGS on the loss of eq. (15), the optional final training phase.
//!
//! The objective is `f(θ) = (1/(N·n)) Σ_b ω_b ‖x̂_b − x_b‖² + λ Σ‖W‖²` over all `N` training rows
//! (`ω_b` the row weights, or 1), its
//! gradient the row-weighted sum of the batch gradients of [`crate::nn::batch`]. The direction is the
//! two-loop recursion `d = −H g` over the last `memory` pairs `s = θ⁺ − θ`, `y = g⁺ − g` (Nocedal &
//! Wright, Alg. 7.4, initial `H₀ = (sᵀy / yᵀy) I`); pairs with `sᵀy ≤ 1e-10 ‖s‖‖y‖` are skipped. The
//! step `α` backtracks from 1 (first iteration: `1/‖g‖`) by halving until the Armijo condition
//! `f(θ + α d) ≤ f(θ) + 1e-4 α gᵀd` holds; a failed search clears the memory and retries along
//! `−g`, and a second failure ends the phase. All vectors are allocated once per phase.

use super::batch::{backward_batch, forward_batch, reconstruction_mse, Workspace};
use super::mlp::Layer;
use super::rates::{add_rate_gradient, forward_rates, rate_mse, RateBuffers};

/// Flat parameter vectors (weights then biases, layer by layer) and the L-BFGS memory.
pub(crate) struct Lbfgs {
    theta: Vec<f64>,
    grad: Vec<f64>,
    trial: Vec<f64>,
    trial_grad: Vec<f64>,
    dir: Vec<f64>,
    s: Vec<Vec<f64>>,
    y: Vec<Vec<f64>>,
    rho: Vec<f64>,
    alpha: Vec<f64>,
    /// Number of stored pairs and the slot of the newest one.
    stored: usize,
    newest: usize,
    /// `(reconstruction MSE, f)` at `theta`.
    value: (f64, f64),
    first: bool,
}

/// Data of the full-batch objective.
pub(crate) struct Objective<'a> {
    pub tanh: &'a [bool],
    pub data: &'a [f64],
    pub rows: &'a [usize],
    /// The loss weight of every data row, or `None` for 1.
    pub weights: Option<&'a [f64]>,
    pub lambda: f64,
    /// The scaled strain rates of the data rows and the rate term's weight `β`, if any.
    pub rates: Option<(&'a [f64], f64)>,
}

/// The buffers an objective evaluation uses: the workspace, and the rate term's when it has one.
pub(crate) type Buffers<'b> = (&'b mut Workspace, &'b mut Option<RateBuffers>);

impl Lbfgs {
    /// Memory for `memory` pairs, started at the current `layers`.
    pub fn new(layers: &[Layer], memory: usize, obj: &Objective, ws: Buffers) -> Self {
        let len: usize = layers.iter().map(|l| l.w.len() + l.b.len()).sum();
        let memory = memory.max(1);
        let mut state = Lbfgs {
            theta: vec![0.0; len],
            grad: vec![0.0; len],
            trial: vec![0.0; len],
            trial_grad: vec![0.0; len],
            dir: vec![0.0; len],
            s: vec![vec![0.0; len]; memory],
            y: vec![vec![0.0; len]; memory],
            rho: vec![0.0; memory],
            alpha: vec![0.0; memory],
            stored: 0,
            newest: 0,
            value: (0.0, 0.0),
            first: true,
        };
        flatten(layers, &mut state.theta);
        state.value = value_and_gradient(layers, obj, ws, &mut state.grad);
        state
    }

    /// One iteration; leaves the new parameters in `layers` and returns the training reconstruction
    /// MSE there, or `None` when no descent step was found (the parameters are then unchanged).
    pub fn step(
        &mut self,
        layers: &mut [Layer],
        obj: &Objective,
        (ws, rb): Buffers,
    ) -> Option<f64> {
        self.direction();
        if !self.line_search(layers, obj, (ws, rb)) {
            self.stored = 0;
            self.direction();
            if !self.line_search(layers, obj, (ws, rb)) {
                unflatten(&self.theta, layers);
                return None;
            }
        }
        self.first = false;
        self.remember();
        Some(self.value.0)
    }

    /// `dir = −H g` by the two-loop recursion (module docs).
    fn direction(&mut self) {
        let m = self.s.len();
        self.dir
            .iter_mut()
            .zip(&self.grad)
            .for_each(|(d, g)| *d = -g);
        for i in 0..self.stored {
            let k = (self.newest + m - i) % m;
            self.alpha[k] = self.rho[k] * dot(&self.s[k], &self.dir);
            axpy(-self.alpha[k], &self.y[k], &mut self.dir);
        }
        if self.stored > 0 {
            let k = self.newest;
            let gamma = dot(&self.s[k], &self.y[k]) / dot(&self.y[k], &self.y[k]);
            self.dir.iter_mut().for_each(|d| *d *= gamma);
        }
        for i in (0..self.stored).rev() {
            let k = (self.newest + m - i) % m;
            let beta = self.rho[k] * dot(&self.y[k], &self.dir);
            axpy(self.alpha[k] - beta, &self.s[k], &mut self.dir);
        }
    }

    /// Backtracking Armijo search along `dir`; on success `trial`, `trial_grad` hold the new point.
    fn line_search(&mut self, layers: &mut [Layer], obj: &Objective, (ws, rb): Buffers) -> bool {
        let slope = dot(&self.grad, &self.dir);
        if slope.is_nan() || slope >= 0.0 {
            return false;
        }
        let mut step = if self.first || self.stored == 0 {
            1.0 / dot(&self.grad, &self.grad).sqrt().max(1.0)
        } else {
            1.0
        };
        for _ in 0..30 {
            for ((t, x), d) in self.trial.iter_mut().zip(&self.theta).zip(&self.dir) {
                *t = x + step * d;
            }
            unflatten(&self.trial, layers);
            let value = value_and_gradient(layers, obj, (&mut *ws, &mut *rb), &mut self.trial_grad);
            if value.1.is_finite() && value.1 <= self.value.1 + 1e-4 * step * slope {
                self.value = value;
                return true;
            }
            step *= 0.5;
        }
        false
    }

    /// Stores `s = trial − θ`, `y = g_trial − g` if `sᵀy > 1e-10‖s‖‖y‖`, then moves to the trial point.
    fn remember(&mut self) {
        let m = self.s.len();
        let k = (self.newest + 1) % m;
        for i in 0..self.theta.len() {
            self.s[k][i] = self.trial[i] - self.theta[i];
            self.y[k][i] = self.trial_grad[i] - self.grad[i];
        }
        let sy = dot(&self.s[k], &self.y[k]);
        if sy > 1e-10 * dot(&self.s[k], &self.s[k]).sqrt() * dot(&self.y[k], &self.y[k]).sqrt() {
            self.rho[k] = 1.0 / sy;
            self.newest = k;
            self.stored = (self.stored + 1).min(m);
        }
        std::mem::swap(&mut self.theta, &mut self.trial);
        std::mem::swap(&mut self.grad, &mut self.trial_grad);
    }
}

/// `(reconstruction MSE [+ β Q], f)` over all training rows and `∇f` into `grad` (flat layout).
fn value_and_gradient(
    layers: &[Layer],
    obj: &Objective,
    (ws, rb): Buffers,
    grad: &mut [f64],
) -> (f64, f64) {
    let n = layers[0].n_in;
    let total = obj.rows.len().max(1) as f64;
    grad.iter_mut().for_each(|g| *g = 0.0);
    let mut mse = 0.0;
    for chunk in obj.rows.chunks(ws.capacity()) {
        let weight = chunk.len() as f64 / total;
        ws.load_rows(obj.data, n, chunk, obj.weights);
        forward_batch(layers, obj.tanh, ws, chunk.len());
        mse += weight * reconstruction_mse(ws, chunk.len());
        backward_batch(layers, obj.tanh, ws, chunk.len(), obj.lambda);
        if let (Some((v, beta)), Some(rb)) = (obj.rates, rb.as_mut()) {
            rb.load(v, n, chunk);
            forward_rates(layers, obj.tanh, ws, rb, chunk.len());
            mse += weight * beta * rate_mse(ws, rb, chunk.len());
            add_rate_gradient(layers, obj.tanh, ws, rb, chunk.len(), beta);
        }
        let flat_grads = ws
            .grad_w
            .iter()
            .zip(&ws.grad_b)
            .flat_map(|(w, b)| w.iter().chain(b));
        grad.iter_mut()
            .zip(flat_grads)
            .for_each(|(g, v)| *g += weight * v);
    }
    let penalty: f64 = layers.iter().map(Layer::sum_squared_weights).sum();
    (mse, mse + obj.lambda * penalty)
}

/// Layer parameters into one vector: `W_0, b_0, W_1, b_1, …`.
fn flatten(layers: &[Layer], flat: &mut [f64]) {
    let values = layers.iter().flat_map(|l| l.w.iter().chain(&l.b));
    flat.iter_mut().zip(values).for_each(|(f, v)| *f = *v);
}

/// The inverse of [`flatten`].
fn unflatten(flat: &[f64], layers: &mut [Layer]) {
    let values = layers
        .iter_mut()
        .flat_map(|l| l.w.iter_mut().chain(l.b.iter_mut()));
    values.zip(flat).for_each(|(v, f)| *v = *f);
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// `y ← y + a x`.
fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    y.iter_mut().zip(x).for_each(|(y, x)| *y += a * x);
}
