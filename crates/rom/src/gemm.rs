//! Matrix products of the network passes: a safe bounds-checked wrapper of `matrixmultiply::dgemm`
//! for the mini-batches of training, and faer products for the narrow right-hand sides of one
//! evaluation (the decoder and the stacked strain basis).

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};

/// `C = A·B + β·C` for `A` (`m × k`), `B` (`k × n`), `C` (`m × n`) with explicit (row, column)
/// strides; checks that every addressed element lies inside its slice.
#[allow(clippy::too_many_arguments)]
pub(crate) fn gemm(
    (m, k, n): (usize, usize, usize),
    a: &[f64],
    (rsa, csa): (usize, usize),
    b: &[f64],
    (rsb, csb): (usize, usize),
    beta: f64,
    c: &mut [f64],
    (rsc, csc): (usize, usize),
) {
    if m == 0 || n == 0 {
        return;
    }
    let last = |rows: usize, cols: usize, rs: usize, cs: usize| {
        (rows - 1) * rs + cols.saturating_sub(1) * cs
    };
    assert!(k == 0 || (last(m, k, rsa, csa) < a.len() && last(k, n, rsb, csb) < b.len()));
    assert!(last(m, n, rsc, csc) < c.len());
    // SAFETY: the assertions above bound every element the kernel reads or writes; `c` is a unique
    // borrow and cannot alias `a` or `b`.
    unsafe {
        matrixmultiply::dgemm(
            m,
            k,
            n,
            1.0,
            a.as_ptr(),
            rsa as isize,
            csa as isize,
            b.as_ptr(),
            rsb as isize,
            csb as isize,
            beta,
            c.as_mut_ptr(),
            rsc as isize,
            csc as isize,
        );
    }
}

/// `Y = A·B` for column-major `A` (`rows × k`), `B` (`k × n`) and `Y` (`rows × n`), on faer's
/// runtime-dispatched SIMD kernels: the narrow products of one evaluation (a value and a few
/// tangents through a layer or the stacked basis), where a packing GEMM would cost more in copies
/// of `A` than in the product. Allocation-free.
pub(crate) fn mul_cols((rows, k, n): (usize, usize, usize), a: &[f64], b: &[f64], y: &mut [f64]) {
    let a = MatRef::from_column_major_slice(&a[..rows * k], rows, k);
    let b = MatRef::from_column_major_slice(&b[..k * n], k, n);
    let y = MatMut::from_column_major_slice_mut(&mut y[..rows * n], rows, n);
    matmul(y, Accum::Replace, a, b, 1.0, Par::Seq);
    gvs::cpu::clear_upper_state();
}

/// `Y = Aᵀ·B` for column-major `A` (`rows × k`), `B` (`rows × n`) and `Y` (`k × n`), as
/// [`mul_cols`].
pub(crate) fn mul_tr_cols(
    (rows, k, n): (usize, usize, usize),
    a: &[f64],
    b: &[f64],
    y: &mut [f64],
) {
    let a = MatRef::from_column_major_slice(&a[..rows * k], rows, k);
    let b = MatRef::from_column_major_slice(&b[..rows * n], rows, n);
    let y = MatMut::from_column_major_slice_mut(&mut y[..k * n], k, n);
    matmul(y, Accum::Replace, a.transpose(), b, 1.0, Par::Seq);
    gvs::cpu::clear_upper_state();
}
