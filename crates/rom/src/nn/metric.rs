//! A metric of each row's own on the output error: the mass-matrix (kinetic-energy) norm of the
//! error in the full model's generalized coordinates.
//!
//! An output error `e` of row `b` (physical units, `1 × n`) is the strain at the points of a
//! coefficient error `δq = e Pᵀ` (`P = Φ̄⁺`, the projection onto the full model's basis; exact for
//! every field the basis represents). The metric weighs it by the mass matrix `M_b = M(q_b)` of the
//! row's own configuration:
//!
//! `‖e‖²_b = δq M_b δqᵀ = (e C) M_b (e C)ᵀ`,  `C = diag(s) Pᵀ` (`n × m`)
//!
//! in the scaled units of training (`e = e_s ⊙ s`). For a rate error `δq̇` it is twice the kinetic
//! energy of the velocity the reduced model gets wrong, the norm in which a Lagrangian model feels
//! it; for a state error the mass-weighted size of the configuration error. A loss term
//! `(κ/(B·n)) Σ_b ω_b ‖e_b‖²_b` has the gradient `(2κ ω_b/(B·n)) (e_b C M_b) Cᵀ`: with the plain
//! term's `d_b = (2ω_b/(B·n)) e_b` already formed, `d_b ← d_b + κ (d_b C M_b) Cᵀ` adds it
//! (`MetricBuffers::add_gradient`), reusing the `e_b C M_b` of the loss just evaluated on the same
//! residual when there is one (the training loop evaluates each loss, then its gradient). Checked
//! against central differences in the tests of `batch` and `rates`.

use super::dense::{product, row_major, row_major_mut};
use super::NnError;
use faer::Accum;
use std::sync::Arc;

/// The mass matrices of every data row and the projection `Pᵀ` of a row metric (module docs), in
/// physical units; the trainer scales `Pᵀ` by the data scaling.
#[derive(Debug, Clone, PartialEq)]
pub struct RowMetric {
    n: usize,
    m: usize,
    /// `Pᵀ`, `n × m` row-major.
    p_t: Vec<f64>,
    /// `M_b`, `m × m` row-major, one after another.
    mass: Vec<f64>,
    /// `κ`, the weight of the metric's terms beside the plain ones.
    weight: f64,
}

impl RowMetric {
    /// A metric for rows of `n` values from `p_t = Pᵀ` (`n × m`, row-major: row `i` maps value
    /// `i` of a row to its coefficients), the mass matrices `mass` of every data row (`m × m`
    /// each, symmetric positive semi-definite) and the weight `κ ≥ 0`.
    pub fn new(n: usize, p_t: Vec<f64>, mass: Vec<f64>, weight: f64) -> Result<Self, NnError> {
        let bad = |field, value: f64, expected| {
            Err(NnError::InvalidOption {
                field,
                value,
                expected,
            })
        };
        if !(weight.is_finite() && weight >= 0.0) {
            return bad("metric.weight", weight, "finite and ≥ 0");
        }
        if n == 0 || p_t.is_empty() || !p_t.len().is_multiple_of(n) {
            return bad(
                "metric.projection",
                p_t.len() as f64,
                "n × m values, m ≥ 1 coefficients",
            );
        }
        let m = p_t.len() / n;
        if !mass.len().is_multiple_of(m * m) {
            return bad(
                "metric.mass",
                mass.len() as f64,
                "m × m values per data row",
            );
        }
        if let Some(v) = p_t.iter().chain(&mass).find(|v| !v.is_finite()) {
            return bad("metric", *v, "finite values");
        }
        Ok(RowMetric {
            n,
            m,
            p_t,
            mass,
            weight,
        })
    }

    /// Data rows the metric covers.
    pub fn rows(&self) -> usize {
        self.mass.len() / (self.m * self.m)
    }

    /// Values `n` of a row.
    pub fn features(&self) -> usize {
        self.n
    }

    /// Coefficients `m` of the full model.
    pub fn coefficients(&self) -> usize {
        self.m
    }

    /// `κ`.
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// `‖e‖²_b = (e Pᵀ) M_b (e Pᵀ)ᵀ` of an error `e` (`n` values, physical units) on data row `b`,
    /// without `κ`.
    pub fn squared_norm(&self, b: usize, e: &[f64]) -> f64 {
        let ones = vec![1.0; self.n];
        self.sum_of_squares(&ones, &[b], e)
    }

    /// `M_b` of data row `b`.
    fn mass_of(&self, b: usize) -> &[f64] {
        let mm = self.m * self.m;
        &self.mass[b * mm..(b + 1) * mm]
    }

    /// `Σ_b ‖e_b‖²_b` over the data rows `index` of the scaled residuals `e` (row-major, one per
    /// index) with the scaling `scale`: the mean-square sizes that set `κ`'s scale.
    pub(crate) fn sum_of_squares(&self, scale: &[f64], index: &[usize], e: &[f64]) -> f64 {
        let (n, m) = (self.n, self.m);
        let mut k = vec![0.0; m];
        let mut sum = 0.0;
        for (&b, e) in index.iter().zip(e.chunks_exact(n)) {
            k.iter_mut().for_each(|v| *v = 0.0);
            for ((e, s), p) in e.iter().zip(scale).zip(self.p_t.chunks_exact(m)) {
                k.iter_mut().zip(p).for_each(|(k, p)| *k += e * s * p);
            }
            sum += quadratic(self.mass_of(b), &k);
        }
        sum
    }
}

/// `k M kᵀ` for a row-major `m × m` matrix `M`.
fn quadratic(mass: &[f64], k: &[f64]) -> f64 {
    mass.chunks_exact(k.len())
        .zip(k)
        .map(|(row, ki)| ki * row.iter().zip(k).map(|(m, k)| m * k).sum::<f64>())
        .sum()
}

/// The residual whose `(e C) M` the buffers hold from the last [`MetricBuffers::energy`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Residual {
    /// `x̂ − x`, the reconstruction's.
    Reconstruction,
    /// `J_f v − v`, the rate term's.
    Rate,
}

/// The metric as a training workspace uses it: `C = diag(s) Pᵀ` in the data's scaling, `κ`
/// normalised ([`MetricBuffers::new`]), the data row of each loaded row and scratch for batches of
/// up to `capacity` rows.
#[derive(Debug, Clone)]
pub(crate) struct MetricBuffers {
    metric: Arc<RowMetric>,
    /// `C`, `n × m` row-major.
    c: Vec<f64>,
    /// The effective weight of the terms.
    kappa: f64,
    /// The data row of each loaded row.
    pub(crate) rows: Vec<usize>,
    /// `E` (`capacity × n`), `K = E C` and `K M` (`capacity × m`).
    e: Vec<f64>,
    k: Vec<f64>,
    km: Vec<f64>,
    /// Which residual `km` holds `(e C) M` of, until its inputs change.
    cached: Option<Residual>,
}

impl MetricBuffers {
    /// Buffers for `metric` in the scaling `scale` with the effective weight `kappa`.
    pub(crate) fn new(metric: Arc<RowMetric>, scale: &[f64], kappa: f64, capacity: usize) -> Self {
        let (n, m) = (metric.n, metric.m);
        let c: Vec<f64> = metric
            .p_t
            .chunks_exact(m)
            .zip(scale)
            .flat_map(|(p, s)| p.iter().map(move |p| s * p))
            .collect();
        MetricBuffers {
            metric,
            c,
            kappa,
            rows: vec![0; capacity],
            e: vec![0.0; capacity * n],
            k: vec![0.0; capacity * m],
            km: vec![0.0; capacity * m],
            cached: None,
        }
    }

    /// Forgets the kept product of `residual` (`None`: of both), whose inputs changed.
    pub(crate) fn forget(&mut self, residual: Option<Residual>) {
        if residual.is_none() || self.cached == residual {
            self.cached = None;
        }
    }

    /// `K = D C`, then `K M_b` row by row into `km`, for the first `rows` rows of `d`.
    fn project(&mut self, d: &[f64], rows: usize) {
        let (n, m) = (self.metric.n, self.metric.m);
        product(
            row_major_mut(&mut self.k[..rows * m], rows, m),
            Accum::Replace,
            row_major(&d[..rows * n], rows, n),
            row_major(&self.c, n, m),
        );
        for (b, (k, km)) in self.k[..rows * m]
            .chunks_exact(m)
            .zip(self.km[..rows * m].chunks_exact_mut(m))
            .enumerate()
        {
            // k M = Σ_j k_j M[j, :] (rows of M, axpys that vectorize; M symmetric)
            let mass = self.metric.mass_of(self.rows[b]);
            km.iter_mut().for_each(|o| *o = 0.0);
            for (row, &kj) in mass.chunks_exact(m).zip(k) {
                km.iter_mut().zip(row).for_each(|(o, mij)| *o += kj * mij);
            }
        }
    }

    /// `κ Σ_b ω_b ‖y_b − x_b‖²_b` over the first `rows` loaded rows (`ω_b = weight(b)`), keeping
    /// `(e C) M` of `residual` for its gradient.
    pub(crate) fn energy(
        &mut self,
        (y, x): (&[f64], &[f64]),
        rows: usize,
        weight: impl Fn(usize) -> f64,
        residual: Residual,
    ) -> f64 {
        let (n, m) = (self.metric.n, self.metric.m);
        let mut e = std::mem::take(&mut self.e);
        for ((e, y), x) in e[..rows * n].iter_mut().zip(y).zip(x) {
            *e = y - x;
        }
        self.project(&e, rows);
        self.e = e;
        self.cached = Some(residual);
        let sum: f64 = self.k[..rows * m]
            .chunks_exact(m)
            .zip(self.km[..rows * m].chunks_exact(m))
            .enumerate()
            .map(|(b, (k, km))| weight(b) * k.iter().zip(km).map(|(a, b)| a * b).sum::<f64>())
            .sum();
        self.kappa * sum
    }

    /// `d_b ← d_b + κ (d_b C M_b) Cᵀ` for the first `rows` rows of `d = s_b e` (module docs), `e`
    /// the `residual` and `s_b = row_scale(b)`: from the kept `(e C) M` if the last
    /// [`MetricBuffers::energy`] was of this residual and its inputs have not changed since, else
    /// from `d`.
    pub(crate) fn add_gradient(
        &mut self,
        d: &mut [f64],
        rows: usize,
        residual: Residual,
        row_scale: impl Fn(usize) -> f64,
    ) {
        let (n, m) = (self.metric.n, self.metric.m);
        let kappa = self.kappa;
        if self.cached.take() == Some(residual) {
            for (b, km) in self.km[..rows * m].chunks_exact_mut(m).enumerate() {
                let s = kappa * row_scale(b);
                km.iter_mut().for_each(|v| *v *= s);
            }
        } else {
            self.project(d, rows);
            self.km[..rows * m].iter_mut().for_each(|v| *v *= kappa);
        }
        product(
            row_major_mut(&mut d[..rows * n], rows, n),
            Accum::Add,
            row_major(&self.km[..rows * m], rows, m),
            row_major(&self.c, n, m).transpose(),
        );
    }
}

/// A metric for rows of `n` values over `m` coefficients with random `Pᵀ`, a random symmetric
/// positive definite mass matrix for each of `data_rows` rows (`A Aᵀ + I/2`), weight `κ`, in a
/// random scaling, for batches of up to `capacity` rows (tests of the passes). Also returns the
/// scaling.
#[cfg(test)]
pub(crate) fn test_metric(
    (n, m, data_rows): (usize, usize, usize),
    kappa: f64,
    capacity: usize,
    rng: &mut gvs::inputs::SplitMix64,
) -> (MetricBuffers, Vec<f64>) {
    let p_t: Vec<f64> = (0..n * m).map(|_| rng.range(-1.0, 1.0)).collect();
    let mut mass = Vec::with_capacity(data_rows * m * m);
    for _ in 0..data_rows {
        let a: Vec<f64> = (0..m * m).map(|_| rng.range(-1.0, 1.0)).collect();
        for i in 0..m {
            for j in 0..m {
                let aat: f64 = (0..m).map(|k| a[i * m + k] * a[j * m + k]).sum();
                mass.push(aat + if i == j { 0.5 } else { 0.0 });
            }
        }
    }
    let scale: Vec<f64> = (0..n).map(|_| rng.range(0.5, 2.0)).collect();
    let metric = Arc::new(RowMetric::new(n, p_t, mass, kappa).unwrap());
    (MetricBuffers::new(metric, &scale, kappa, capacity), scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gvs::inputs::SplitMix64;

    #[test]
    fn energy_is_the_mass_norm_of_the_coefficient_error() {
        // κ Σ_b ω_b δq_b M_{i_b} δq_bᵀ with δq_b = (e_b ⊙ s) Pᵀ, written out with plain loops; the
        // loaded rows are data rows 4, 0, 2 (each row's own mass matrix)
        let (n, m, kappa) = (5, 3, 0.7);
        let mut rng = SplitMix64::new(5);
        let (mut buffers, scale) = test_metric((n, m, 6), kappa, 4, &mut rng);
        let index = [4, 0, 2];
        buffers.rows[..3].copy_from_slice(&index);
        let y: Vec<f64> = (0..3 * n).map(|_| rng.range(-1.0, 1.0)).collect();
        let x: Vec<f64> = (0..3 * n).map(|_| rng.range(-1.0, 1.0)).collect();
        let omega = [0.5, 1.0, 2.0];
        let metric = buffers.metric.clone();
        let mut expected = 0.0;
        for (b, &row) in index.iter().enumerate() {
            let mut dq = vec![0.0; m];
            for i in 0..n {
                for (j, dq) in dq.iter_mut().enumerate() {
                    *dq += (y[b * n + i] - x[b * n + i]) * scale[i] * metric.p_t[i * m + j];
                }
            }
            let mass = metric.mass_of(row);
            let mut energy = 0.0;
            for i in 0..m {
                for j in 0..m {
                    energy += dq[i] * mass[i * m + j] * dq[j];
                }
            }
            expected += kappa * omega[b] * energy;
        }
        let got = buffers.energy((&y, &x), 3, |b| omega[b], Residual::Reconstruction);
        assert!(
            (got - expected).abs() <= 1e-13 * expected,
            "{got} vs {expected}"
        );
        // the unscaled sum of squares the trainer normalises κ with
        let e: Vec<f64> = y.iter().zip(&x).map(|(y, x)| y - x).collect();
        let plain = metric.sum_of_squares(&scale, &index, &e);
        let unweighted = buffers.energy((&y, &x), 3, |_| 1.0, Residual::Rate) / kappa;
        assert!((plain - unweighted).abs() <= 1e-13 * plain);
    }

    #[test]
    fn a_metric_of_the_wrong_shape_or_with_bad_values_is_refused_naming_it() {
        let field = |r: Result<RowMetric, NnError>| match r {
            Err(NnError::InvalidOption { field, .. }) => field,
            other => panic!("{other:?}"),
        };
        assert_eq!(
            field(RowMetric::new(2, vec![1.0; 4], vec![1.0; 4], -1.0)),
            "metric.weight"
        );
        assert_eq!(
            field(RowMetric::new(3, vec![1.0; 4], vec![1.0; 4], 1.0)),
            "metric.projection"
        );
        assert_eq!(
            field(RowMetric::new(2, vec![1.0; 4], vec![1.0; 5], 1.0)),
            "metric.mass"
        );
        assert_eq!(
            field(RowMetric::new(
                2,
                vec![1.0, f64::NAN, 0.0, 1.0],
                vec![1.0; 4],
                1.0
            )),
            "metric"
        );
        let ok = RowMetric::new(2, vec![1.0; 4], vec![1.0; 8], 1.0).unwrap();
        assert_eq!((ok.rows(), ok.coefficients(), ok.weight()), (2, 2, 1.0));
    }
}
