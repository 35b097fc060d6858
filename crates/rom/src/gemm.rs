//! faer products for the narrow right-hand sides of one evaluation (the decoder and the stacked
//! strain basis); the mini-batches of training call faer directly ([`crate::nn::batch`]).

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};

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
