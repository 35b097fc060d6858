//! The norm of a symmetric matrix scaled to unit mean diagonal, `‖x‖_Â = √(xᵀ Â x)` with
//! `Â = A·m/tr A`, by the Cholesky factor of `Â`: the mass norm of mechanical states
//! ([`super::ErrorNorm::Mass`], `A = M`), and the stiffness (strain-energy) norm `A = K` that the
//! Newton tests of the second-order forms add to it (see [`super::one_step::Parts::newton_weighted`]).

use crate::dynamics::cholesky_factor_in_place;
use nalgebra::{DMatrix, DVector};

/// The weight `w_K` of the stiffness norm in the Newton tests of the second-order forms with the
/// mass norm (`max(‖δ‖_M̂-test, w_K·‖δ‖_K̂-test)`, [`super::one_step::Parts::newton_weighted`]).
/// Measured on the undamped 0.5 m rod of `examples/undamped-release.toml` falling from
/// horizontal under gravity for 4 s (SDIRK4, rtol 1e-4; energy gained, of the largest kinetic
/// energy 0.261 J): without the stiffness term +40.6 %; with `w_K` = 1, 0.3, 0.1: +0.21, +0.19,
/// +0.10 %. On the undamped release of that file (6 s) the Jacobians it costs went from 50 to
/// 114, 94, 72, the tip error stayed 0.064–0.073 % L. The smallest of the three weights tried
/// is kept (smaller ones were not measured).
pub(super) const STIFFNESS_WEIGHT: f64 = 0.1;

/// `‖·‖_Â` for one half (`q` or `q̇`, `m` entries) of a mechanical state.
pub(super) struct ScaledNorm {
    /// `L` of `Â = L Lᵀ` in the lower triangle (row `i` of `Lᵀ` is the contiguous column `i` of `L`
    /// from the diagonal down; the strict upper triangle is scratch), by
    /// [`cholesky_factor_in_place`] (pivots of a semi-definite `Â` raised to its floor), or `Â`
    /// itself if it is indefinite (`chol` false).
    l: DMatrix<f64>,
    chol: bool,
    /// Evaluation count of the `A` it was made from.
    of: usize,
    /// Whether some `A` with a positive, finite trace has been set (before, `Â = I`).
    set_once: bool,
}

impl ScaledNorm {
    pub(super) fn new(m: usize) -> Self {
        ScaledNorm {
            l: DMatrix::identity(m, m),
            chol: true,
            of: usize::MAX,
            set_once: false,
        }
    }

    /// The evaluation count of the `A` in use.
    pub(super) fn of(&self) -> usize {
        self.of
    }

    /// Whether a matrix has been set (an `A` whose trace is not positive and finite is not used).
    pub(super) fn is_set(&self) -> bool {
        self.set_once
    }

    /// Sets `Â` (and its factor) from `A` if `A` changed (`count`: its evaluation count); an `A`
    /// whose trace is not positive and finite keeps the last one.
    pub(super) fn set(&mut self, mass: &DMatrix<f64>, count: usize) {
        if count == self.of {
            return;
        }
        self.of = count;
        let tr = mass.trace();
        if !(tr > 0.0 && tr.is_finite()) {
            return; // keep the last one
        }
        self.set_once = true;
        // the symmetric part (a tangent stiffness with friction or a follower load is not
        // symmetric; `xᵀAx` sees only its symmetric part), scaled
        let scale = mass.nrows() as f64 / tr;
        let symmetric = |l: &mut DMatrix<f64>| {
            for j in 0..l.ncols() {
                for i in 0..l.nrows() {
                    l[(i, j)] = 0.5 * scale * (mass[(i, j)] + mass[(j, i)]);
                }
            }
        };
        symmetric(&mut self.l);
        // the mass matrix's own (blocked) factorization: `L` in the lower triangle
        self.chol = cholesky_factor_in_place(&mut self.l).is_ok();
        if !self.chol {
            symmetric(&mut self.l);
        }
    }

    /// `‖v‖_Â / (rtol·max(‖x‖_Â, ‖y‖_Â) + atol)`: `v` relative to the larger of two states.
    pub(super) fn relative(
        &self,
        v: &DVector<f64>,
        [x, y]: [&DVector<f64>; 2],
        (rtol, atol): (f64, f64),
    ) -> f64 {
        let s = self.half(x.as_slice()).max(self.half(y.as_slice()));
        self.half(v.as_slice()) / (rtol * s + atol)
    }

    /// `‖x‖_Â = ‖Lᵀ x‖` (`m²/2` products), or `√max(0, xᵀÂx)`.
    pub(super) fn half(&self, x: &[f64]) -> f64 {
        let m = x.len();
        let a = self.l.as_slice();
        let mut sum = 0.0;
        if self.chol {
            for i in 0..m {
                let d = dot(&a[i + i * m..(i + 1) * m], &x[i..]);
                sum += d * d;
            }
        } else {
            for (j, xj) in x.iter().enumerate() {
                sum += xj * dot(&a[j * m..(j + 1) * m], x);
            }
        }
        sum.max(0.0).sqrt()
    }
}

/// `Σ a_i b_i` with four partial sums (vectorizable).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (a4.remainder(), b4.remainder());
    let mut s = [0.0f64; 4];
    for (x, y) in a4.zip(b4) {
        for k in 0..4 {
            s[k] += x[k] * y[k];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `√(xᵀ M̂ x)` directly, `M̂ = M·m/tr M`.
    fn direct(mass: &DMatrix<f64>, x: &[f64]) -> f64 {
        let m = mass.nrows();
        let scale = m as f64 / mass.trace();
        let x = nalgebra::DVector::from_column_slice(x);
        (scale * x.dot(&(mass * &x))).max(0.0).sqrt()
    }

    #[test]
    fn the_norm_is_the_quadratic_form_of_the_scaled_mass_across_cholesky_blocks() {
        // SPD, larger than one factorization block, with entries of mixed sizes
        for m in [5, 100] {
            let b = DMatrix::from_fn(m, m, |i, j| ((i * 7 + j * 3) % 11) as f64 - 5.0);
            let mass = &b * b.transpose() + DMatrix::from_diagonal_element(m, m, 0.5);
            let mut mn = ScaledNorm::new(m);
            mn.set(&mass, 0);
            assert!(mn.chol && mn.of() == 0);
            let x: Vec<f64> = (0..m).map(|i| (i as f64 * 0.37).sin()).collect();
            let (got, want) = (mn.half(&x), direct(&mass, &x));
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "m = {m}: {got} vs {want}"
            );
        }
        // an indefinite matrix falls back to the quadratic form, clipped at zero
        let mass = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        let mut mn = ScaledNorm::new(2);
        mn.set(&mass, 1);
        assert!(!mn.chol);
        for x in [[1.0, 1.0], [1.0, -1.0]] {
            assert!((mn.half(&x) - direct(&mass, &x)).abs() < 1e-14, "{x:?}");
        }
    }

    #[test]
    fn a_non_symmetric_matrix_is_measured_by_its_symmetric_part_whichever_triangle_holds_it() {
        // a tangent stiffness with friction or a follower load: xᵀAx sees (A + Aᵀ)/2 only
        let upper = DMatrix::from_row_slice(2, 2, &[2.0, 2.0, 0.0, 2.0]);
        let lower = upper.transpose();
        let sym = (&upper + &lower) * 0.5;
        for x in [[1.0, 0.3], [0.2, -1.0], [1.0, -1.0]] {
            let norms: Vec<f64> = [&upper, &lower, &sym]
                .iter()
                .map(|a| {
                    let mut n = ScaledNorm::new(2);
                    n.set(a, 0);
                    n.half(&x)
                })
                .collect();
            let want = direct(&sym, &x);
            for got in &norms {
                assert!((got - want).abs() < 1e-14, "{x:?}: {norms:?} vs {want}");
            }
        }
    }
}
