//! Test helpers shared by the tests of `lie`: a 6-vector from an array and the reference matrix
//! exponential (the oracle of `exp(Ω̂)` and `T(Ω)`).

use super::V6;
use nalgebra::SMatrix;

pub(super) fn v6(a: [f64; 6]) -> V6 {
    V6::from_row_slice(&a)
}

/// Reference matrix exponential by scaling and squaring of a Taylor series (test oracle only).
pub(super) fn expm<const N: usize>(a: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    let norm = a.abs().max();
    let s = (norm.log2().ceil().max(0.0) as i32) + 4;
    let b = a / 2f64.powi(s);
    let mut term = SMatrix::<f64, N, N>::identity();
    let mut sum = term;
    for k in 1..30 {
        term = term * b / k as f64;
        sum += term;
    }
    for _ in 0..s {
        sum = sum * sum;
    }
    sum
}
