//! Row-major views of flat buffers and the single-threaded matrix product the passes use.

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};

/// The first `rows × cols` values of `s` as a row-major matrix.
pub(crate) fn row_major(s: &[f64], rows: usize, cols: usize) -> MatRef<'_, f64> {
    MatRef::from_row_major_slice(&s[..rows * cols], rows, cols)
}

/// The first `rows × cols` values of `s` as a mutable row-major matrix.
pub(crate) fn row_major_mut(s: &mut [f64], rows: usize, cols: usize) -> MatMut<'_, f64> {
    MatMut::from_row_major_slice_mut(&mut s[..rows * cols], rows, cols)
}

/// `C = A·B` (`Accum::Replace`) or `C += A·B` (`Accum::Add`) on this thread.
pub(crate) fn product(c: MatMut<'_, f64>, accum: Accum, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    matmul(c, accum, a, b, 1.0, Par::Seq);
    // faer leaves the upper vector registers dirty; the baseline SSE code after it would pay
    gvs::cpu::clear_upper_state();
}
