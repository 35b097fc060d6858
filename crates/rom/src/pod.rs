//! Proper orthogonal decomposition of strain snapshots (paper Section IV, the POD-ROM baseline).
//!
//! With the snapshots as the rows of `X` (N × L, L = p·n_a point strains, eq. 13), the thin SVD
//! `X = U Σ Vᵀ` gives the POD modes as the columns of `V` (orthonormal in R^L) and the captured
//! energy of the first K modes as `Σ_{k<K} σ_k² / Σ_k σ_k²`. The snapshots are **not** centred: the
//! modes span the strain deviations themselves, so `q_r = 0` is the straight rod, as for the HOM.
//! The reduced basis on the HOM is then `Φ_s (P V_K)` (see [`crate::reduced`]), a constant linear
//! basis: `gvs::strain::LinearBasis::compose`.
//!
//! **A weighted norm** ([`Pod::compute_weighted`]): with positive feature weights `w` (`W =
//! diag(w)`, e.g. the section stiffness of each point and component: the strain-energy norm
//! `‖x‖²_W = xᵀ W x`), the SVD of `X W^{1/2} = U Σ Ṽᵀ` gives the modes `Φ = W^{-1/2} Ṽ_K`, which are
//! W-orthonormal (`Φᵀ W Φ = I`) and minimise `Σ_n ‖x_n − Φ Φᵀ W x_n‖²_W` over all K-dimensional
//! subspaces; a snapshot's coordinates are its W-orthogonal projection `Φᵀ W x`, and the captured
//! energy is measured in that norm. With `w = 1` it is the plain POD above.

use nalgebra::{DMatrix, DVector};
use thiserror::Error;

#[derive(Debug, Error, PartialEq)]
pub enum PodError {
    #[error("snapshots: {0}")]
    Data(String),
    #[error("--modes {requested}: {reason}")]
    Modes { requested: usize, reason: String },
    #[error("the SVD of the snapshot matrix did not converge")]
    Svd,
}

/// The POD of a snapshot set: all singular values, and the leading modes.
#[derive(Debug, Clone, PartialEq)]
pub struct Pod {
    /// σ_k, non-increasing (min(N, L) values).
    pub singular_values: Vec<f64>,
    /// The first K right singular vectors as columns (L × K), sign fixed so that each mode's largest
    /// entry in magnitude is positive (repeatable across platforms and runs); for a weighted POD
    /// `Φ = W^{-1/2} Ṽ_K` (module docs).
    pub modes: DMatrix<f64>,
    /// The feature weights `w` of a weighted POD (`None`: the plain norm, `w = 1`).
    pub weights: Option<Vec<f64>>,
}

impl Pod {
    /// POD of the `n_rows` snapshots stored row-major in `rows` (each of length `n_features`), keeping
    /// `modes` modes. Rows with any non-finite value are an error naming the row.
    pub fn compute(rows: &[f64], n_features: usize, modes: usize) -> Result<Pod, PodError> {
        Self::compute_in(rows, n_features, modes, None)
    }

    /// POD in the norm `‖x‖²_W = Σ_j w_j x_j²` (module docs): the modes are W-orthonormal and the
    /// singular values those of `X W^{1/2}`. Weights must be one per feature, finite and > 0.
    pub fn compute_weighted(
        rows: &[f64],
        n_features: usize,
        modes: usize,
        weights: &[f64],
    ) -> Result<Pod, PodError> {
        if weights.len() != n_features {
            return Err(PodError::Data(format!(
                "{} norm weights for {n_features} features",
                weights.len()
            )));
        }
        if let Some(j) = weights.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
            return Err(PodError::Data(format!(
                "norm weight {} of feature {j} (expected finite and > 0)",
                weights[j]
            )));
        }
        Self::compute_in(rows, n_features, modes, Some(weights))
    }

    fn compute_in(
        rows: &[f64],
        n_features: usize,
        modes: usize,
        weights: Option<&[f64]>,
    ) -> Result<Pod, PodError> {
        if n_features == 0 || rows.is_empty() || !rows.len().is_multiple_of(n_features) {
            return Err(PodError::Data(format!(
                "{} values do not form rows of {n_features}",
                rows.len()
            )));
        }
        let n = rows.len() / n_features;
        if let Some(i) = rows.iter().position(|v| !v.is_finite()) {
            return Err(PodError::Data(format!(
                "row {} has a non-finite value at feature {}",
                i / n_features,
                i % n_features
            )));
        }
        if rows.iter().all(|v| *v == 0.0) {
            // the SVD of a zero matrix has σ = 0 and arbitrary directions: no modes to learn
            return Err(PodError::Data(format!(
                "all {n} snapshots are zero: there is no strain to reduce (loads or tensions that do not deform the rod?)"
            )));
        }
        let rank_max = n.min(n_features);
        if modes == 0 || modes > rank_max {
            return Err(PodError::Modes {
                requested: modes,
                reason: format!(
                    "must be between 1 and min(snapshots, features) = min({n}, {n_features}) = {rank_max}"
                ),
            });
        }
        faer::set_global_parallelism(faer::Par::Seq);
        let root: Vec<f64> = match weights {
            Some(w) => w.iter().map(|w| w.sqrt()).collect(),
            None => vec![1.0; n_features],
        };
        let x = faer::Mat::<f64>::from_fn(n, n_features, |i, j| rows[i * n_features + j] * root[j]);
        let svd = x.thin_svd().map_err(|_| PodError::Svd)?;
        let s = svd.S().column_vector();
        let singular_values: Vec<f64> = (0..rank_max).map(|k| s[k]).collect();
        let v = svd.V();
        let mut m = DMatrix::from_fn(n_features, modes, |i, k| v[(i, k)] / root[i]);
        for mut col in m.column_iter_mut() {
            let imax = col.iamax();
            if col[imax] < 0.0 {
                col.neg_mut();
            }
        }
        Ok(Pod {
            singular_values,
            modes: m,
            weights: weights.map(<[f64]>::to_vec),
        })
    }

    /// Fraction of the snapshot energy `Σ σ²` captured by the first `k` modes, for k = 1..=all (a
    /// POD is never of all-zero snapshots: [`Pod::compute`] refuses them).
    pub fn captured_energy(&self) -> Vec<f64> {
        let total: f64 = self.singular_values.iter().map(|s| s * s).sum();
        let mut acc = 0.0;
        self.singular_values
            .iter()
            .map(|s| {
                acc += s * s;
                if total > 0.0 {
                    acc / total
                } else {
                    1.0
                }
            })
            .collect()
    }

    /// Number of modes with a singular value above `rel · σ_max` (the numerical rank of the data).
    pub fn rank(&self, rel: f64) -> usize {
        let smax = self.singular_values.first().copied().unwrap_or(0.0);
        self.singular_values
            .iter()
            .filter(|&&s| s > rel * smax)
            .count()
    }

    /// Projection of a snapshot onto the modes, `Vᵀ x` (`Φᵀ W x` for a weighted POD).
    pub fn encode(&self, x: &DVector<f64>) -> DVector<f64> {
        DVector::from_vec(self.encode_rows(x.as_slice()))
    }

    /// [`Pod::encode`] of the snapshots stored row-major in `rows` (each as long as a mode): their
    /// coordinates, row-major (`n_rows × K`).
    pub fn encode_rows(&self, rows: &[f64]) -> Vec<f64> {
        project_rows(&self.modes, self.weights.as_deref(), rows)
    }

    /// `V q_r`.
    pub fn decode(&self, q_r: &DVector<f64>) -> DVector<f64> {
        &self.modes * q_r
    }
}

/// The coordinates `Φᵀ W x` of the row-major snapshots `rows` on the modes `Φ` (L × K) in the norm
/// of the feature weights `w` (`W = I` for `None`), row-major (`n_rows × K`): the W-orthogonal
/// projection when `Φ` is W-orthonormal (module docs).
pub fn project_rows(modes: &DMatrix<f64>, weights: Option<&[f64]>, rows: &[f64]) -> Vec<f64> {
    let l = modes.nrows();
    let w = |j: usize| weights.map_or(1.0, |w| w[j]);
    rows.chunks_exact(l)
        .flat_map(|x| {
            modes.column_iter().map(move |v| {
                let terms = v.iter().zip(x).enumerate().map(|(j, (a, b))| a * w(j) * b);
                terms.sum::<f64>()
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_rows_is_encode_of_each_row() {
        let (rows, _, _) = rank_two(5, 12);
        let pod = Pod::compute(&rows, 12, 2).unwrap();
        let all = pod.encode_rows(&rows);
        assert_eq!(all.len(), 10);
        for (i, x) in rows.chunks_exact(12).enumerate() {
            let z = pod.encode(&DVector::from_column_slice(x));
            for k in 0..2 {
                assert!((all[2 * i + k] - z[k]).abs() <= 1e-15 * (1.0 + z[k].abs()));
            }
        }
    }

    /// Rows `x(θ) = a(θ) u + b(θ) w` with orthonormal `u`, `w`: rank 2, modes span {u, w}.
    fn rank_two(n: usize, l: usize) -> (Vec<f64>, DVector<f64>, DVector<f64>) {
        let u = DVector::from_fn(l, |j, _| ((j as f64) * 0.3).sin()).normalize();
        let w0 = DVector::from_fn(l, |j, _| ((j as f64) * 0.11).cos());
        let w = (&w0 - &u * u.dot(&w0)).normalize();
        let mut rows = Vec::with_capacity(n * l);
        for i in 0..n {
            let t = i as f64 / (n - 1) as f64 * 2.0 - 1.0;
            let x = &u * (3.0 * t) + &w * (t * t);
            rows.extend(x.iter());
        }
        (rows, u, w)
    }

    #[test]
    fn pod_of_rank_two_data_finds_its_span_and_energy() {
        let (rows, u, w) = rank_two(50, 40);
        let pod = Pod::compute(&rows, 40, 2).unwrap();
        assert_eq!(pod.rank(1e-10), 2);
        let e = pod.captured_energy();
        assert!((e[1] - 1.0).abs() < 1e-14 && e[0] < 1.0);
        // orthonormal modes spanning {u, w}
        let g = pod.modes.tr_mul(&pod.modes);
        assert!((g - DMatrix::identity(2, 2)).amax() < 1e-13);
        for v in [&u, &w] {
            assert!((pod.decode(&pod.encode(v)) - v).amax() < 1e-12);
        }
        // the leading singular value: Σ (3t)² over the rows dominates
        assert!(pod.singular_values[0] > pod.singular_values[1]);
    }

    #[test]
    fn all_zero_snapshots_are_refused_rather_than_given_arbitrary_modes() {
        // σ = 0 and any direction: a review's all-zero dataset was reported as "1 mode captures
        // 1.00000000 of the snapshot energy" (0/0 read as 1)
        let e = Pod::compute(&[0.0; 12], 4, 1).unwrap_err().to_string();
        assert!(e.contains("all 3 snapshots are zero"), "{e}");
        assert!(Pod::compute_weighted(&[0.0; 12], 4, 1, &[1.0; 4]).is_err());
        // one nonzero value is data
        let mut rows = [0.0; 12];
        rows[5] = 1e-12;
        assert_eq!(Pod::compute(&rows, 4, 1).unwrap().captured_energy()[0], 1.0);
    }

    #[test]
    fn weighted_pod_keeps_the_stiff_direction_that_plain_pod_drops() {
        // Feature 0 varies by ±10 with weight 1, feature 1 by ±1 with weight 10⁴, uncorrelated (sine
        // and cosine over a period): in the plain norm the first direction carries 100× the
        // energy, in the weighted one the second 100×.
        let rows: Vec<f64> = (0..20)
            .flat_map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 20.0;
                [10.0 * a.sin(), a.cos()]
            })
            .collect();
        let plain = Pod::compute(&rows, 2, 1).unwrap();
        assert!(
            (plain.modes[(0, 0)].abs() - 1.0).abs() < 1e-9,
            "{}",
            plain.modes
        );
        let w = [1.0, 1e4];
        let pod = Pod::compute_weighted(&rows, 2, 1, &w).unwrap();
        // Φ = W^{-1/2} e₂ = (0, 1/100): W-orthonormal, the stiff direction
        assert!(pod.modes[(0, 0)].abs() < 1e-9 && (pod.modes[(1, 0)] - 0.01).abs() < 1e-12);
        // σ² of X W^{1/2}: the weighted energies Σ 10⁴ u² and Σ 100 t² of the two directions
        let (et, eu) = rows.chunks(2).fold((0.0, 0.0), |(a, b), x| {
            (a + x[0] * x[0], b + 1e4 * x[1] * x[1])
        });
        assert!((pod.singular_values[0].powi(2) - eu).abs() < 1e-9 * eu);
        assert!((pod.singular_values[1].powi(2) - et).abs() < 1e-9 * et);
        // coordinates Φᵀ W x: feature 1 times 100; decode returns the stiff part exactly
        let z = pod.encode_rows(&rows);
        for (x, z) in rows.chunks(2).zip(&z) {
            assert!((z - 100.0 * x[1]).abs() < 1e-9);
            let back = pod.decode(&DVector::from_element(1, *z));
            assert!((back[1] - x[1]).abs() < 1e-12 && back[0].abs() < 1e-9);
        }
    }

    #[test]
    fn weighted_pod_modes_are_w_orthonormal_and_unit_weights_give_the_plain_pod() {
        let (rows, _, _) = rank_two(30, 12);
        let w: Vec<f64> = (0..12).map(|j| 1.0 + (j * j) as f64).collect();
        let pod = Pod::compute_weighted(&rows, 12, 2, &w).unwrap();
        let wd = DMatrix::from_diagonal(&DVector::from_column_slice(&w));
        let g = pod.modes.transpose() * &wd * &pod.modes;
        assert!((g - DMatrix::identity(2, 2)).amax() < 1e-12);
        // rank-two data are reproduced exactly by the W-projection as by the plain one
        let z = pod.encode_rows(&rows);
        for (x, z) in rows.chunks(12).zip(z.chunks(2)) {
            let back = pod.decode(&DVector::from_column_slice(z));
            let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!((back - DVector::from_column_slice(x)).amax() < 1e-12 * scale);
        }
        let ones = Pod::compute_weighted(&rows, 12, 2, &[1.0; 12]).unwrap();
        let plain = Pod::compute(&rows, 12, 2).unwrap();
        assert!((ones.modes - plain.modes).amax() < 1e-14);
        assert_eq!(ones.singular_values, plain.singular_values);
        for bad in [vec![1.0; 11], vec![0.0; 12], vec![f64::NAN; 12]] {
            assert!(Pod::compute_weighted(&rows, 12, 2, &bad).is_err());
        }
    }

    #[test]
    fn bad_snapshots_and_mode_counts_are_named() {
        let (mut rows, _, _) = rank_two(5, 4);
        assert!(Pod::compute(&rows, 4, 5)
            .unwrap_err()
            .to_string()
            .contains("min(5, 4) = 4"));
        assert!(Pod::compute(&rows, 3, 1).is_err());
        rows[9] = f64::NAN;
        let e = Pod::compute(&rows, 4, 1).unwrap_err().to_string();
        assert!(e.contains("row 2") && e.contains("feature 1"), "{e}");
    }
}
