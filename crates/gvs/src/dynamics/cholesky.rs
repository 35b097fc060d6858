//! The Cholesky factorization of the mass matrix `M = L Lᵀ` (blocked, with a pivot floor for the
//! semi-definite `M` of a rank-deficient nonlinear parameterization, spec §9.1) and the solves with
//! it, `M q̈ = f`.

use super::DynamicsError;
use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, Par};
use nalgebra::{DMatrix, DVector};

/// Solves `A x = b` for SPD `A` by an in-place Cholesky factorization (`A` is overwritten by `L`).
pub fn cholesky_solve_in_place(
    a: &mut DMatrix<f64>,
    b: &mut DVector<f64>,
) -> Result<(), DynamicsError> {
    cholesky_factor_in_place(a)?;
    cholesky_solve_factored(a, b);
    Ok(())
}

/// Relative floor of the Cholesky pivots of `M`, as a fraction of its largest diagonal entry.
///
/// A nonlinear parameterization can lose rank (`Ψ_q` singular, e.g. a decoder at a latent point where
/// a direction stops changing the strain; spec §9.1): `M = Σ W Jᵀ Ms J` is then only semi-definite.
/// Pivots below the floor are raised to it, which adds a tiny inertia along the lost direction
/// (where the generalized forces vanish too) instead of stopping the run. A well-posed linear basis
/// never comes near it (its pivots are > 1e-8 of the largest diagonal entry on the presets).
pub const MASS_PIVOT_FLOOR: f64 = 1e-12;

/// `A = L Lᵀ` in place (the lower triangle of `a` holds `L`; the strict upper triangle is left as
/// scratch), for symmetric positive (semi-)definite `A`: pivots below [`MASS_PIVOT_FLOOR`]
/// `· max diag(A)` are raised to it. Errors on a NaN, on a zero matrix, and on a pivot clearly
/// negative (an indefinite matrix).
///
/// Blocked, right-looking: for each block column of [`CHOLESKY_BLOCK`] columns, the diagonal block
/// is factored column by column (with the pivot floor), the panel below it solved against its
/// transpose (`A₂₁ ← A₂₁ L₁₁⁻ᵀ`) and the trailing matrix updated, `A₂₂ ← A₂₂ − A₂₁ A₂₁ᵀ`, by faer's
/// triangular solve and matrix product. (Unblocked and row-wise, the factor of a 1926-DOF mass
/// matrix took seconds.)
pub fn cholesky_factor_in_place(a: &mut DMatrix<f64>) -> Result<(), DynamicsError> {
    let n = a.nrows();
    let max_diag = (0..n).map(|j| a[(j, j)]).fold(0.0f64, f64::max);
    if n > 0 && (max_diag.is_nan() || max_diag <= 0.0) {
        return Err(DynamicsError::MassNotPositiveDefinite {
            pivot: 0,
            value: max_diag,
        });
    }
    let floor = MASS_PIVOT_FLOOR * max_diag;
    let mut j0 = 0;
    while j0 < n {
        let nb = CHOLESKY_BLOCK.min(n - j0);
        // the diagonal block, left-looking within the block (the trailing updates of the blocks
        // before it are in place)
        for j in j0..j0 + nb {
            let mut d = a[(j, j)];
            for k in j0..j {
                d -= a[(j, k)] * a[(j, k)];
            }
            // Round-off of a semi-definite matrix leaves pivots of order ε·max_diag of either sign.
            if d.is_nan() || d < -1e-8 * max_diag {
                return Err(DynamicsError::MassNotPositiveDefinite { pivot: j, value: d });
            }
            let d = d.max(floor).sqrt();
            a[(j, j)] = d;
            for i in j + 1..j0 + nb {
                let mut s = a[(i, j)];
                for k in j0..j {
                    s -= a[(i, k)] * a[(j, k)];
                }
                a[(i, j)] = s / d;
            }
        }
        let rest = n - j0 - nb;
        if rest > 0 {
            use faer::reborrow::{Reborrow, ReborrowMut};
            let full = MatMut::from_column_major_slice_mut(a.as_mut_slice(), n, n);
            let (l11, _, mut a21, a22) = full
                .submatrix_mut(j0, j0, n - j0, n - j0)
                .split_at_mut(nb, nb);
            // A₂₁ L₁₁ᵀ = A₂₁ ⇔ L₁₁ A₂₁ᵀ = A₂₁ᵀ
            faer::linalg::triangular_solve::solve_lower_triangular_in_place(
                l11.rb(),
                a21.rb_mut().transpose_mut(),
                Par::Seq,
            );
            matmul(
                a22,
                Accum::Add,
                a21.rb(),
                a21.rb().transpose(),
                -1.0,
                Par::Seq,
            );
            crate::cpu::clear_upper_state();
            if a21.rb().has_nan() {
                return Err(DynamicsError::MassNotPositiveDefinite {
                    pivot: j0 + nb,
                    value: f64::NAN,
                });
            }
        }
        j0 += nb;
    }
    Ok(())
}

/// Columns per block of [`cholesky_factor_in_place`].
pub const CHOLESKY_BLOCK: usize = 48;

/// Solves `L Lᵀ x = b` in place with the factor from [`cholesky_factor_in_place`] (by columns of
/// `L`: contiguous in memory).
pub fn cholesky_solve_factored(a: &DMatrix<f64>, b: &mut DVector<f64>) {
    let n = a.nrows();
    let l = a.as_slice();
    let x = b.as_mut_slice();
    // L y = b: y_k = b_k / L_kk, then b_i −= L_ik y_k below
    for k in 0..n {
        let col = &l[k * n..(k + 1) * n];
        let yk = x[k] / col[k];
        x[k] = yk;
        for (xi, lik) in x[k + 1..].iter_mut().zip(&col[k + 1..]) {
            *xi -= lik * yk;
        }
    }
    // Lᵀ x = y: x_i = (y_i − Σ_{k>i} L_ki x_k) / L_ii
    for i in (0..n).rev() {
        let col = &l[i * n..(i + 1) * n];
        let s: f64 = col[i + 1..]
            .iter()
            .zip(&x[i + 1..])
            .map(|(a, b)| a * b)
            .sum();
        x[i] = (x[i] - s) / col[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `L` of `A = L Lᵀ` by the textbook (unblocked) recurrences.
    fn cholesky_reference(a: &DMatrix<f64>) -> DMatrix<f64> {
        let n = a.nrows();
        let mut l = DMatrix::zeros(n, n);
        for j in 0..n {
            let d = a[(j, j)] - (0..j).map(|k| l[(j, k)] * l[(j, k)]).sum::<f64>();
            l[(j, j)] = d.sqrt();
            for i in j + 1..n {
                let s = a[(i, j)] - (0..j).map(|k| l[(i, k)] * l[(j, k)]).sum::<f64>();
                l[(i, j)] = s / l[(j, j)];
            }
        }
        l
    }

    #[test]
    fn blocked_cholesky_and_solve_match_the_textbook_recurrences_across_blocks() {
        // sizes below, at and across block boundaries
        for n in [
            1,
            7,
            CHOLESKY_BLOCK,
            CHOLESKY_BLOCK + 1,
            3 * CHOLESKY_BLOCK + 5,
        ] {
            let g = DMatrix::from_fn(n, n, |i, j| ((i * 31 + j * 17) % 23) as f64 / 23.0 - 0.5);
            let a = &g * g.transpose() + DMatrix::identity(n, n) * (n as f64);
            let mut f = a.clone();
            cholesky_factor_in_place(&mut f).unwrap();
            let l = f.lower_triangle();
            let l_ref = cholesky_reference(&a);
            let err = (&l - &l_ref).amax() / l_ref.amax();
            assert!(err < 1e-13, "n = {n}: L off by {err:e}");
            let x_true = DVector::from_fn(n, |i, _| (i as f64 * 0.37).sin());
            let mut x = &a * &x_true;
            cholesky_solve_factored(&f, &mut x);
            let err = (&x - &x_true).amax();
            assert!(err < 1e-12, "n = {n}: solution off by {err:e}");
        }
        // an indefinite matrix is refused in a later block too
        let n = 2 * CHOLESKY_BLOCK + 3;
        let mut a = DMatrix::identity(n, n);
        a[(n - 2, n - 1)] = 2.0;
        a[(n - 1, n - 2)] = 2.0;
        assert!(matches!(
            cholesky_factor_in_place(&mut a),
            Err(DynamicsError::MassNotPositiveDefinite { pivot, .. }) if pivot == n - 1
        ));
    }

    #[test]
    fn cholesky_of_a_semi_definite_mass_regularizes_and_of_an_indefinite_one_fails() {
        // M = v vᵀ + diag(0, 0, 0): rank 1; b in its range
        let v = DVector::from_vec(vec![1.0, 2.0, -1.0]);
        let mut m = &v * v.transpose();
        let mut b = &v * 3.0;
        cholesky_solve_in_place(&mut m, &mut b).unwrap();
        assert!(b.iter().all(|x| x.is_finite()));
        let m0 = &v * v.transpose();
        assert!(
            (&m0 * &b - &v * 3.0).amax() < 1e-6,
            "M x = b within the floor"
        );
        // SPD: exact
        let mut a = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 3.0]);
        let mut x = DVector::from_vec(vec![1.0, 2.0]);
        cholesky_solve_in_place(&mut a, &mut x).unwrap();
        assert!((x[0] - 1.0 / 11.0).abs() < 1e-15 && (x[1] - 7.0 / 11.0).abs() < 1e-15);
        // indefinite and NaN
        let mut ind = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(cholesky_factor_in_place(&mut ind).is_err());
        let mut nan = DMatrix::from_row_slice(1, 1, &[f64::NAN]);
        assert!(cholesky_factor_in_place(&mut nan).is_err());
    }
}
