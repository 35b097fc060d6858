//! Per-feature affine scaling between physical snapshots and network units.
//!
//! `y_j = (x_j − μ_j) / s_j` and back `x_j = s_j y_j + μ_j`, with `μ_j` the mean and `s_j` the
//! population standard deviation of feature `j` over the training rows. A feature with zero spread
//! (`s_j ≤ 1e-12·(1 + |μ_j|)`, e.g. a strain component the data never excites) gets `s_j = 1`, so it
//! is only centred. The network learns and its loss is measured in the scaled units `y`, which gives
//! every strain component equal weight whatever its physical magnitude.

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

    /// Mean and population standard deviation of each feature over the rows `index` of row-major
    /// `data` with `n` features (module docs for zero spread). The data must be finite.
    pub(crate) fn from_rows(data: &[f64], n: usize, index: &[usize]) -> Self {
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
        let scale = var
            .iter()
            .zip(&mean)
            .map(|(v, m)| {
                let s = (v / count).sqrt();
                if s <= 1e-12 * (1.0 + m.abs()) {
                    1.0
                } else {
                    s
                }
            })
            .collect();
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_rows_standardises_and_leaves_constant_features_unscaled() {
        // Feature 0: {1, 3} → μ = 2, s = 1; feature 1: {4, 8} → μ = 6, s = 2; feature 2 constant 5.
        let data = [1.0, 4.0, 5.0, 3.0, 8.0, 5.0];
        let s = Scaling::from_rows(&data, 3, &[0, 1]);
        assert_eq!(s.mean(), &[2.0, 6.0, 5.0]);
        assert_eq!(s.scale(), &[1.0, 2.0, 1.0]);
        let mut rows = data;
        s.to_scaled(&mut rows);
        assert_eq!(rows, [-1.0, -1.0, 0.0, 1.0, 1.0, 0.0]);
        s.to_physical(&mut rows);
        assert_eq!(rows, data);
        assert!(Scaling::new(vec![0.0], vec![0.0]).is_err());
    }
}
