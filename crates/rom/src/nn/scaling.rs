//! Per-feature affine scaling between physical snapshots and network units.
//!
//! `y_j = (x_j − μ_j) / s_j` and back `x_j = s_j y_j + μ_j`, with `μ_j` the mean of feature `j`
//! over the training rows. The network learns and its loss is measured in the scaled units `y`, so
//! the scale decides how much each feature's error weighs in the loss `(1/n) Σ_j (ŷ_j − y_j)²`:
//!
//! - [`Weighting::Standardize`]: `s_j = σ_j`, the population standard deviation of feature `j`. Every
//!   feature weighs the same relative to its own spread, whatever its physical magnitude; a feature
//!   with zero spread (`σ_j ≤ 1e-12·(1 + |μ_j|)`, e.g. a component the data never excites) gets
//!   `s_j = 1`, so it is only centred.
//! - [`Weighting::Physical`]`(w)`: `s_j = c/√w_j` with `c² = (1/n) Σ_j w_j σ_j²`. The scaled loss is
//!   then `(1/(c² n)) Σ_j w_j (x̂_j − x_j)²`, a weighted physical mean squared error up to the one
//!   constant `c²` (the weighted variance of the data, so that scaled features have unit mean
//!   variance). `w = 1` gives the plain physical RMSE of Table I; `w_j` = the section stiffness of
//!   feature `j`'s strain component gives the strain-energy norm `Σ (ξ̂ − ξ)ᵀ Σ_s (ξ̂ − ξ)` that the
//!   elastic force and the tip pose feel.

use super::NnError;

/// Mean `μ` and scale `s` per feature (both of length `n`, `s > 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct Scaling {
    mean: Vec<f64>,
    scale: Vec<f64>,
}

impl Scaling {
    /// A scaling from plain vectors: equal lengths, finite means, finite positive scales.
    pub fn new(mean: Vec<f64>, scale: Vec<f64>) -> Result<Self, NnError> {
        if mean.len() != scale.len() {
            return Err(NnError::Mismatch {
                what: "scaling: scale length vs mean length",
                got: scale.len(),
                expected: mean.len(),
            });
        }
        if let Some(index) = mean.iter().position(|m| !m.is_finite()) {
            return Err(NnError::InvalidScaling {
                what: "mean",
                index,
                value: mean[index],
                expected: "finite",
            });
        }
        if let Some(index) = scale.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(NnError::InvalidScaling {
                what: "scale",
                index,
                value: scale[index],
                expected: "finite and > 0",
            });
        }
        Ok(Scaling { mean, scale })
    }

    /// The identity scaling (`μ = 0`, `s = 1`) for `n` features.
    pub fn identity(n: usize) -> Self {
        Scaling {
            mean: vec![0.0; n],
            scale: vec![1.0; n],
        }
    }

    /// The scaling of `weighting` (module docs) from the rows `index` of row-major `data` with `n`
    /// features. The data must be finite and the weights checked ([`Weighting::check`]).
    pub fn from_rows(data: &[f64], n: usize, index: &[usize], weighting: &Weighting) -> Self {
        let (mean, var) = mean_and_variance(data, n, index);
        let scale = match weighting {
            Weighting::Standardize => var
                .iter()
                .zip(&mean)
                .map(|(v, m)| {
                    let s = v.sqrt();
                    if s <= 1e-12 * (1.0 + m.abs()) {
                        1.0
                    } else {
                        s
                    }
                })
                .collect(),
            Weighting::Physical(w) => {
                let c2 = w.iter().zip(&var).map(|(w, v)| w * v).sum::<f64>() / n.max(1) as f64;
                let c = if c2 > 0.0 && c2.is_finite() {
                    c2.sqrt()
                } else {
                    1.0
                };
                w.iter().map(|w| c / w.sqrt()).collect()
            }
        };
        Scaling { mean, scale }
    }

    /// Number of features `n`.
    pub fn len(&self) -> usize {
        self.mean.len()
    }

    /// `true` for zero features.
    pub fn is_empty(&self) -> bool {
        self.mean.is_empty()
    }

    /// `μ`.
    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    /// `s`.
    pub fn scale(&self) -> &[f64] {
        &self.scale
    }

    /// In place on row-major rows: `x_j ← (x_j − μ_j) / s_j`.
    pub(crate) fn to_scaled(&self, rows: &mut [f64]) {
        for row in rows.chunks_exact_mut(self.len()) {
            for ((x, m), s) in row.iter_mut().zip(&self.mean).zip(&self.scale) {
                *x = (*x - m) / s;
            }
        }
    }

    /// In place on row-major rows: `y_j ← s_j y_j + μ_j`.
    pub(crate) fn to_physical(&self, rows: &mut [f64]) {
        for row in rows.chunks_exact_mut(self.len()) {
            for ((y, m), s) in row.iter_mut().zip(&self.mean).zip(&self.scale) {
                *y = s * *y + m;
            }
        }
    }
}

/// Mean and population variance of each feature over the rows `index` of row-major `data`.
fn mean_and_variance(data: &[f64], n: usize, index: &[usize]) -> (Vec<f64>, Vec<f64>) {
    let count = index.len().max(1) as f64;
    let mut mean = vec![0.0; n];

    for &i in index {
        mean.iter_mut()
            .zip(&data[i * n..(i + 1) * n])
            .for_each(|(m, x)| *m += x);
    }
    mean.iter_mut().for_each(|m| *m /= count);
    let mut var = vec![0.0; n];
    for &i in index {
        for ((v, x), m) in var.iter_mut().zip(&data[i * n..(i + 1) * n]).zip(&mean) {
            *v += (x - m) * (x - m);
        }
    }
    var.iter_mut().for_each(|v| *v /= count);
    (mean, var)
}

/// How the features' errors weigh in the training loss (module docs).
#[derive(Debug, Clone, PartialEq)]
pub enum Weighting {
    /// Each feature scaled by its own standard deviation.
    Standardize,
    /// The weighted physical MSE `Σ_j w_j (x̂_j − x_j)²` (up to one constant); one weight per feature,
    /// finite and > 0.
    Physical(Vec<f64>),
}

impl Weighting {
    /// Checks the weights against the number of features `n`.
    pub fn check(&self, n: usize) -> Result<(), NnError> {
        let Weighting::Physical(w) = self else {
            return Ok(());
        };
        if w.len() != n {
            return Err(NnError::Mismatch {
                what: "loss weights: count vs features",
                got: w.len(),
                expected: n,
            });
        }
        match w.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
            Some(index) => Err(NnError::InvalidScaling {
                what: "loss weight",
                index,
                value: w[index],
                expected: "finite and > 0",
            }),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_rows_standardises_and_leaves_constant_features_unscaled() {
        // Feature 0: {1, 3} → μ = 2, s = 1; feature 1: {4, 8} → μ = 6, s = 2; feature 2 constant 5.
        let data = [1.0, 4.0, 5.0, 3.0, 8.0, 5.0];
        let s = Scaling::from_rows(&data, 3, &[0, 1], &Weighting::Standardize);
        assert_eq!(s.mean(), &[2.0, 6.0, 5.0]);
        assert_eq!(s.scale(), &[1.0, 2.0, 1.0]);
        let mut rows = data;
        s.to_scaled(&mut rows);
        assert_eq!(rows, [-1.0, -1.0, 0.0, 1.0, 1.0, 0.0]);
        s.to_physical(&mut rows);
        assert_eq!(rows, data);
        assert!(Scaling::new(vec![0.0], vec![0.0]).is_err());
    }

    #[test]
    fn physical_weighting_makes_the_scaled_mse_the_weighted_physical_mse() {
        // Feature 0: {1, 3} (σ² = 1), feature 1: {4, 8} (σ² = 4), weights (1, 4):
        // c² = (1·1 + 4·4)/2 = 8.5, s = (√8.5, √8.5/2).
        let data = [1.0, 4.0, 3.0, 8.0];
        let w = Weighting::Physical(vec![1.0, 4.0]);
        let s = Scaling::from_rows(&data, 2, &[0, 1], &w);
        let c = 8.5f64.sqrt();
        assert_eq!(s.mean(), &[2.0, 6.0]);
        assert!((s.scale()[0] - c).abs() < 1e-15 && (s.scale()[1] - c / 2.0).abs() < 1e-15);
        // an error e in physical units costs (e_j/s_j)² = w_j e_j² / c² in scaled units
        let e = [0.3, -0.7];
        let scaled: f64 = e.iter().zip(s.scale()).map(|(e, s)| (e / s).powi(2)).sum();
        let weighted: f64 = e
            .iter()
            .zip([1.0, 4.0])
            .map(|(e, w)| w * e * e)
            .sum::<f64>()
            / 8.5;
        assert!((scaled - weighted).abs() < 1e-15);
        // unit weights: one scale for all features, the data's RMS spread
        let u = Scaling::from_rows(&data, 2, &[0, 1], &Weighting::Physical(vec![1.0; 2]));
        assert_eq!(u.scale(), &[2.5f64.sqrt(); 2]);
        assert!(Weighting::Physical(vec![1.0, 0.0]).check(2).is_err());
        assert!(Weighting::Physical(vec![1.0]).check(2).is_err());
        assert!(Weighting::Physical(vec![1.0, f64::NAN]).check(2).is_err());
    }
}
