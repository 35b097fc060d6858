//! A small linear complementarity problem: find `v ≥ 0` with `w = S v + c ≥ 0` and `vᵀw = 0`
//! (`LCP(S, c)`), by Murty's least-index principal pivoting.
//!
//! The active set `A` (the components with `v_k` free, `w_k = 0`) starts from the caller's guess;
//! each pivot solves `S_AA v_A = −c_A`, sets `v = 0` off `A`, and flips the *least* index that
//! violates its sign (`v_k < 0` in `A`, `w_k < 0` outside). For a P-matrix `S` (every principal
//! minor positive: a symmetric positive definite `S`, or one whose symmetric part is) the solution
//! exists, is unique, and the least-index rule reaches it in finitely many pivots (Murty 1974).
//! Meant for a handful of unknowns: the tendons driven by their displacement
//! ([`super::tendon_drive`]).

use nalgebra::{DMatrix, DVector};

/// Most pivots before [`solve_lcp`] gives up (a P-matrix of the sizes met here needs a few).
pub const MAX_PIVOTS: usize = 1000;

/// Why [`solve_lcp`] found no solution.
#[derive(Debug, Clone, PartialEq)]
pub enum LcpError {
    /// `S_AA` was singular for the active set `A` reached: `S` is not a P-matrix.
    Singular,
    /// [`MAX_PIVOTS`] pivots without a solution: `S` is not a P-matrix.
    Cycled,
}

/// Solves `LCP(S, c)` (the module documentation) from the active set `active` (the components
/// guessed to have `w_k = 0`); returns `v` and the active set of the solution. A component is
/// taken as violating its sign beyond `tol · (1 + ‖c‖∞)`.
pub fn solve_lcp(
    s: &DMatrix<f64>,
    c: &DVector<f64>,
    active: &[bool],
    tol: f64,
) -> Result<(DVector<f64>, Vec<bool>), LcpError> {
    let n = c.len();
    assert_eq!(s.shape(), (n, n), "S is n × n");
    assert_eq!(active.len(), n, "one guess per component");
    let mut a = active.to_vec();
    let eps = tol * (1.0 + c.amax());
    for _ in 0..MAX_PIVOTS {
        let v = solve_active(s, c, &a).ok_or(LcpError::Singular)?;
        let w = s * &v + c;
        match (0..n).find(|&k| if a[k] { v[k] < -eps } else { w[k] < -eps }) {
            Some(k) => a[k] = !a[k],
            None => {
                // the components inside the tolerance are exactly feasible
                return Ok((v.map(|x| x.max(0.0)), a));
            }
        }
    }
    Err(LcpError::Cycled)
}

/// `v` with `S_AA v_A = −c_A` on the active set and `v = 0` off it; `None` if `S_AA` is singular.
fn solve_active(s: &DMatrix<f64>, c: &DVector<f64>, a: &[bool]) -> Option<DVector<f64>> {
    let idx: Vec<usize> = (0..c.len()).filter(|&k| a[k]).collect();
    let mut v = DVector::zeros(c.len());
    if idx.is_empty() {
        return Some(v);
    }
    let m = idx.len();
    let saa = DMatrix::from_fn(m, m, |i, j| s[(idx[i], idx[j])]);
    let rhs = DVector::from_fn(m, |i, _| -c[idx[i]]);
    let va = saa.lu().solve(&rhs)?;
    if va.iter().any(|x| !x.is_finite()) {
        return None;
    }
    for (i, &k) in idx.iter().enumerate() {
        v[k] = va[i];
    }
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every solution of `LCP(S, c)` by trying all `2ⁿ` active sets.
    fn brute_force(s: &DMatrix<f64>, c: &DVector<f64>) -> Vec<DVector<f64>> {
        let n = c.len();
        (0..1usize << n)
            .filter_map(|mask| {
                let a: Vec<bool> = (0..n).map(|k| mask >> k & 1 == 1).collect();
                let v = solve_active(s, c, &a)?;
                let w = s * &v + c;
                let ok = (0..n).all(|k| v[k] >= -1e-12 && w[k] >= -1e-12);
                ok.then_some(v)
            })
            .collect()
    }

    /// A deterministic pseudo-random number in [−1, 1).
    fn rnd(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    #[test]
    fn murty_finds_the_unique_solution_of_random_p_matrix_problems() {
        let mut state = 7u64;
        for trial in 0..300 {
            let n = 1 + trial % 6;
            // S = GᵀG + 0.1 I + a skew part: its symmetric part is positive definite (a P-matrix),
            // like the sensitivity of tendons with friction
            let g = DMatrix::from_fn(n, n, |_, _| rnd(&mut state));
            let k = DMatrix::from_fn(n, n, |_, _| rnd(&mut state));
            let s = g.transpose() * &g + DMatrix::identity(n, n) * 0.1 + (&k - k.transpose()) * 0.5;
            let c = DVector::from_fn(n, |_, _| 2.0 * rnd(&mut state));
            let guess: Vec<bool> = (0..n).map(|_| rnd(&mut state) > 0.0).collect();
            let (v, a) = solve_lcp(&s, &c, &guess, 1e-12).unwrap();
            let all = brute_force(&s, &c);
            assert_eq!(all.len(), 1, "a P-matrix LCP has one solution");
            assert!(
                (&v - &all[0]).amax() < 1e-9,
                "trial {trial}: {v} vs {}",
                all[0]
            );
            let w = &s * &v + &c;
            for i in 0..n {
                assert!(v[i] >= 0.0 && w[i] >= -1e-9 && (v[i] * w[i]).abs() < 1e-9);
                assert!(!a[i] || w[i].abs() < 1e-9, "an active component has w = 0");
            }
        }
    }

    #[test]
    fn a_matrix_that_is_not_p_is_reported_not_looped_on() {
        // S = −I, c = −1: both v = 0 (w = −1 < 0) and the active set (v = −1 < 0) violate
        let s = -DMatrix::<f64>::identity(1, 1);
        let c = DVector::from_element(1, -1.0);
        assert_eq!(solve_lcp(&s, &c, &[false], 1e-12), Err(LcpError::Cycled));
        let s0 = DMatrix::<f64>::zeros(1, 1);
        assert_eq!(solve_lcp(&s0, &c, &[true], 1e-12), Err(LcpError::Singular));
    }
}
