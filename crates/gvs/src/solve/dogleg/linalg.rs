//! The dense linear algebra under the dogleg, free of trust-region logic: the LU of the Jacobian
//! (`P J₀ = L U`, partial pivoting, blocked, faer) kept across Broyden updates `J ← J + u vᵀ`, which
//! it applies by Sherman–Morrison, `J_{k+1}⁻¹ = (I − w_k v_kᵀ/σ_k) J_k⁻¹` with `w_k = J_k⁻¹u_k`,
//! `σ_k = 1 + v_kᵀw_k`; and the norms and finiteness checks of the iteration, safe from overflow and
//! underflow (MINPACK's `enorm`) and vectorized.

use crate::model::zeros_lazy;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve as lu_solve_faer};
use faer::perm::PermRef;
use faer::{MatMut, MatRef, Par};
use nalgebra::{DMatrix, DVector};

/// Broyden updates applied to a kept LU by Sherman–Morrison before `J` is refactored.
pub const MAX_SM_UPDATES: usize = 16;
/// Smallest `|σ| = |1 + vᵀJ⁻¹u|` of a Sherman–Morrison update; below it `J` is refactored.
pub const SM_MIN_SIGMA: f64 = 1e-3;

/// `P J₀ = L U` of a Jacobian `J₀` (unit lower L below the diagonal, U on and above) and the
/// Broyden updates `u_i v_iᵀ` since, as Sherman–Morrison factors `w_i = J_i⁻¹u_i`, `v_i`, `σ_i`.
pub(crate) struct Lu {
    /// `Some(nonsingular)` once `factors` holds the LU of `J₀`; `None` when `J` must be factored.
    pub(super) state: Option<bool>,
    factors: DMatrix<f64>,
    pub(super) perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
    w: DMatrix<f64>,
    v: DMatrix<f64>,
    sigma: Vec<f64>,
}

impl Lu {
    pub(crate) fn new(n: usize) -> Self {
        let par = Par::Seq;
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, par, Default::default()),
            lu_solve_faer::solve_in_place_scratch::<usize, f64>(n, 1, par),
        ]);
        Lu {
            state: None,
            factors: zeros_lazy(n, n),
            perm: vec![0; n],
            perm_inv: vec![0; n],
            mem: MemBuffer::new(req),
            w: DMatrix::zeros(n, MAX_SM_UPDATES),
            v: DMatrix::zeros(n, MAX_SM_UPDATES),
            sigma: Vec::with_capacity(MAX_SM_UPDATES),
        }
    }

    /// Factors `a` (finite) with partial pivoting; returns false when `a` is zero or a pivot is
    /// at most `n ε max|a|` (numerically singular).
    pub(crate) fn factor(&mut self, a: &DMatrix<f64>) -> bool {
        let n = a.nrows();
        self.factors.copy_from(a);
        self.sigma.clear();
        let amax = a.amax();
        let ok = if amax == 0.0 {
            n == 0
        } else {
            let m = MatMut::from_column_major_slice_mut(self.factors.as_mut_slice(), n, n);
            let stack = MemStack::new(&mut self.mem);
            let params = Default::default();
            factor::lu_in_place(
                m,
                &mut self.perm,
                &mut self.perm_inv,
                Par::Seq,
                stack,
                params,
            );
            crate::cpu::clear_upper_state();
            let tol = amax * n as f64 * f64::EPSILON;
            (0..n).all(|k| self.factors[(k, k)].abs() > tol)
        };
        self.state = Some(ok);
        ok
    }

    /// `b ← J⁻¹ b` for the current `J = J₀ + Σ u_i v_iᵀ` (nonsingular LU).
    pub(crate) fn solve(&mut self, b: &mut DVector<f64>) {
        let n = b.len();
        let lu = MatRef::from_column_major_slice(self.factors.as_slice(), n, n);
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
        let rhs = MatMut::from_column_major_slice_mut(b.as_mut_slice(), n, 1);
        let stack = MemStack::new(&mut self.mem);
        lu_solve_faer::solve_in_place(lu, lu, perm, rhs, Par::Seq, stack);
        crate::cpu::clear_upper_state();
        for (i, s) in self.sigma.iter().enumerate() {
            let c = self.v.column(i).dot(b) / s;
            b.axpy(-c, &self.w.column(i), 1.0);
        }
    }

    /// Takes the rank-1 update `J ← J + u vᵀ` into account (Sherman–Morrison) when the LU is
    /// nonsingular, fewer than [`MAX_SM_UPDATES`] are stored and `|σ| ≥ `[`SM_MIN_SIGMA`];
    /// otherwise marks `J` for refactoring. `w` is scratch.
    pub(super) fn update(&mut self, u: &DVector<f64>, v: &DVector<f64>, w: &mut DVector<f64>) {
        if self.state != Some(true) || self.sigma.len() == MAX_SM_UPDATES {
            self.state = None;
            return;
        }
        w.copy_from(u);
        self.solve(w);
        let sigma = 1.0 + v.dot(w);
        if sigma.is_nan() || sigma.abs() < SM_MIN_SIGMA || w.iter().any(|x| !x.is_finite()) {
            self.state = None;
            return;
        }
        let k = self.sigma.len();
        self.w.column_mut(k).copy_from(w);
        self.v.column_mut(k).copy_from(v);
        self.sigma.push(sigma);
    }
}

/// Euclidean norm without spurious overflow or underflow (like MINPACK's `enorm`): the plain
/// `√Σx²` when that sum is safely inside the normal range, otherwise rescaled by `max|x|`.
pub(super) fn norm2(v: impl Iterator<Item = f64> + Clone) -> f64 {
    let s = v.clone().fold(0.0_f64, |s, x| s + x * x);
    if s.is_finite() && s > f64::MIN_POSITIVE / f64::EPSILON {
        return s.sqrt();
    }
    let m = v.clone().fold(0.0_f64, |m, x| m.max(x.abs()));
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    m * v.map(|x| (x / m).powi(2)).sum::<f64>().sqrt()
}

/// Whether every entry is finite: `Σ 0·x` is 0, or NaN if some `x` is infinite or NaN (eight
/// independent partial sums, so the pass over an n × n Jacobian vectorizes).
pub(super) fn all_finite(v: &[f64]) -> bool {
    let mut acc = [0.0f64; 8];
    let chunks = v.chunks_exact(8);
    let rest = chunks.remainder();
    for c in chunks {
        for l in 0..8 {
            acc[l] += c[l] * 0.0;
        }
    }
    acc.iter().sum::<f64>() == 0.0 && rest.iter().all(|x| x.is_finite())
}

/// [`norm2`] of a contiguous column: the sum of squares by eight independent partial sums (it
/// vectorizes), the rescaled [`norm2`] when that sum leaves the safe range.
pub(super) fn column_norm(v: &[f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let chunks = v.chunks_exact(8);
    let rest = chunks.remainder();
    for c in chunks {
        for l in 0..8 {
            acc[l] += c[l] * c[l];
        }
    }
    let s = acc.iter().sum::<f64>() + rest.iter().map(|x| x * x).sum::<f64>();
    if s.is_finite() && s > f64::MIN_POSITIVE / f64::EPSILON {
        s.sqrt()
    } else {
        norm2(v.iter().copied())
    }
}

/// `‖D v‖₂`.
pub(super) fn scaled_norm(diag: &DVector<f64>, v: &DVector<f64>) -> f64 {
    norm2(diag.iter().zip(v.iter()).map(|(d, x)| d * x))
}

#[cfg(test)]
mod tests {
    use super::*;

    type V = DVector<f64>;

    #[test]
    fn sherman_morrison_updates_solve_like_a_refactored_jacobian() {
        // J₀ (non-symmetric, needs pivoting) and three rank-1 updates: the kept LU with the
        // updates solves like the LU of J₀ + Σ u vᵀ, to round-off.
        let n = 7;
        let j0 = DMatrix::from_fn(n, n, |i, j| {
            ((i * 5 + j * 3) % 7) as f64 - 3.0 + 0.1 * i as f64
        });
        let mut lu = Lu::new(n);
        assert!(lu.factor(&j0));
        let mut j = j0.clone();
        let mut w = V::zeros(n);
        for k in 0..3 {
            let u = V::from_fn(n, |i, _| ((i + 2 * k) % 3) as f64 - 0.7);
            let v = V::from_fn(n, |i, _| 0.2 * ((i * k + 1) % 4) as f64);
            j.ger(1.0, &u, &v, 1.0);
            lu.update(&u, &v, &mut w);
            assert_eq!(lu.state, Some(true), "update {k} kept");
        }
        let b = V::from_fn(n, |i, _| 1.0 + i as f64);
        let mut x = b.clone();
        lu.solve(&mut x);
        let mut fresh = Lu::new(n);
        assert!(fresh.factor(&j));
        let mut y = b.clone();
        fresh.solve(&mut y);
        assert!((&x - &y).amax() <= 1e-12 * y.amax(), "{x} vs {y}");
        assert!((&j * &x - &b).amax() <= 1e-12 * b.amax());
        // an update that makes J singular (σ = 0) is not applied: J is refactored instead
        let u = -j.column(0).into_owned();
        let e0 = V::from_fn(n, |i, _| if i == 0 { 1.0 } else { 0.0 });
        lu.update(&u, &e0, &mut w);
        assert_eq!(lu.state, None);
        j.ger(1.0, &u, &e0, 1.0);
        assert!(!lu.factor(&j), "a zero column is singular");
    }
}
