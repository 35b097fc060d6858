//! Small dense products for the narrow right-hand sides of one evaluation: a value and a few
//! tangents through a decoder layer (`≤ 84 × 42` times `≤ 9` columns) or through a tall block of
//! the stacked strain basis (`n_sites × ≤ 12`). The mini-batches of training call faer directly
//! ([`crate::nn::batch`]).
//!
//! At these sizes a general GEMM's dispatch, packing and thread-local bookkeeping cost more than
//! the arithmetic: with faer here, an IV-C2 AE-7 run spent 30 % of its time in faer's matmul
//! machinery. These kernels are plain column-major loops that LLVM vectorizes, compiled twice —
//! for the baseline target and with AVX2 + FMA enabled — and chosen once per call by a cached CPU
//! feature test. Every kernel is allocation-free; results agree with the textbook sums to rounding
//! (tests below).

/// Whether the CPU has AVX2 and FMA, for the kernels compiled with them (the standard library
/// caches the test).
#[cfg(target_arch = "x86_64")]
pub(crate) fn has_avx2_fma() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// `Y = A·B` for column-major `A` (`rows × k`), `B` (`k × n`, column stride `ldb ≥ k`) and `Y`
/// (`rows × n`).
pub(crate) fn mul_cols_strided(
    (rows, k, n): (usize, usize, usize),
    a: &[f64],
    b: &[f64],
    ldb: usize,
    y: &mut [f64],
) {
    assert!(a.len() >= rows * k && y.len() >= rows * n && ldb >= k);
    assert!(n == 0 || b.len() >= ldb * (n - 1) + k);
    #[cfg(target_arch = "x86_64")]
    {
        if has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA (checked just above), all the function requires.
            unsafe { mul_cols_avx2((rows, k, n), a, b, ldb, y) };
            return;
        }
    }
    mul_cols_body::<false>((rows, k, n), a, b, ldb, y);
}

/// `Y = A·B` for column-major `A` (`rows × k`), `B` (`k × n`) and `Y` (`rows × n`).
pub(crate) fn mul_cols(dims: (usize, usize, usize), a: &[f64], b: &[f64], y: &mut [f64]) {
    mul_cols_strided(dims, a, b, dims.1, y);
}

/// `Y (+)= Aᵀ·B` for column-major `A` (`rows × k`), `B` (`rows × n`) and `Y` (`k × n`): replaces
/// `Y` unless `accumulate`.
pub(crate) fn mul_tr_cols_into(
    (rows, k, n): (usize, usize, usize),
    a: &[f64],
    b: &[f64],
    y: &mut [f64],
    accumulate: bool,
) {
    assert!(a.len() >= rows * k && b.len() >= rows * n && y.len() >= k * n);
    #[cfg(target_arch = "x86_64")]
    {
        if has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA (checked just above), all the function requires.
            unsafe { mul_tr_cols_avx2((rows, k, n), a, b, y, accumulate) };
            return;
        }
    }
    mul_tr_cols_body::<false>((rows, k, n), a, b, y, accumulate);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn mul_cols_avx2(dims: (usize, usize, usize), a: &[f64], b: &[f64], ldb: usize, y: &mut [f64]) {
    mul_cols_body::<true>(dims, a, b, ldb, y);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn mul_tr_cols_avx2(
    dims: (usize, usize, usize),
    a: &[f64],
    b: &[f64],
    y: &mut [f64],
    accumulate: bool,
) {
    mul_tr_cols_body::<true>(dims, a, b, y, accumulate);
}

/// Register-blocked: `Y` in tiles of `8 × 4` (eight AVX2 accumulators held in registers over the
/// whole `l` sweep), the rows left over in tiles of 4, 2 and 1, the columns left over (1–3) in one
/// narrower block.
#[inline(always)]
fn mul_cols_body<const FMA: bool>(
    (rows, k, n): (usize, usize, usize),
    a: &[f64],
    b: &[f64],
    ldb: usize,
    y: &mut [f64],
) {
    let mut jb = 0;
    while jb + 4 <= n {
        col_block::<4, FMA>((rows, k), a, &b[jb * ldb..], ldb, &mut y[jb * rows..]);
        jb += 4;
    }
    if jb == n {
        return;
    }
    let (b, y) = (&b[jb * ldb..], &mut y[jb * rows..]);
    match n - jb {
        3 => col_block::<3, FMA>((rows, k), a, b, ldb, y),
        2 => col_block::<2, FMA>((rows, k), a, b, ldb, y),
        1 => col_block::<1, FMA>((rows, k), a, b, ldb, y),
        _ => {}
    }
}

/// `NR` columns of `Y = A·B`, rows in tiles of 8, then 4, 2, 1.
#[inline(always)]
fn col_block<const NR: usize, const FMA: bool>(
    (rows, k): (usize, usize),
    a: &[f64],
    b: &[f64],
    ldb: usize,
    y: &mut [f64],
) {
    let mut ib = 0;
    while ib + 8 <= rows {
        tile::<8, NR, FMA>((rows, k), ib, a, b, ldb, y);
        ib += 8;
    }
    if ib + 4 <= rows {
        tile::<4, NR, FMA>((rows, k), ib, a, b, ldb, y);
        ib += 4;
    }
    if ib + 2 <= rows {
        tile::<2, NR, FMA>((rows, k), ib, a, b, ldb, y);
        ib += 2;
    }
    if ib < rows {
        tile::<1, NR, FMA>((rows, k), ib, a, b, ldb, y);
    }
}

/// Rows `ib .. ib + MR` of `NR` columns of `Y`, accumulated in a fixed-size array (registers).
#[inline(always)]
fn tile<const MR: usize, const NR: usize, const FMA: bool>(
    (rows, k): (usize, usize),
    ib: usize,
    a: &[f64],
    b: &[f64],
    ldb: usize,
    y: &mut [f64],
) {
    let mut acc = [[0.0f64; MR]; NR];
    for l in 0..k {
        let al: &[f64; MR] = a[l * rows + ib..l * rows + ib + MR].try_into().unwrap();
        for (jj, col) in acc.iter_mut().enumerate() {
            let s = b[l + jj * ldb];
            for (v, &x) in col.iter_mut().zip(al) {
                *v = madd::<FMA>(x, s, *v);
            }
        }
    }
    for (jj, col) in acc.iter().enumerate() {
        y[jj * rows + ib..jj * rows + ib + MR].copy_from_slice(col);
    }
}

/// `x·s + v`, fused if `FMA`.
#[inline(always)]
pub(crate) fn madd<const FMA: bool>(x: f64, s: f64, v: f64) -> f64 {
    if FMA {
        x.mul_add(s, v)
    } else {
        x * s + v
    }
}

/// `Y[l, j] = A[:, l] · B[:, j]` with four partial sums (a vectorizable dot product).
#[inline(always)]
fn mul_tr_cols_body<const FMA: bool>(
    (rows, k, n): (usize, usize, usize),
    a: &[f64],
    b: &[f64],
    y: &mut [f64],
    accumulate: bool,
) {
    for j in 0..n {
        let bj = &b[j * rows..(j + 1) * rows];
        for l in 0..k {
            let al = &a[l * rows..(l + 1) * rows];
            let mut acc = [0.0f64; 4];
            let (ac, ar) = al.split_at(rows - rows % 4);
            let (bc, br) = bj.split_at(rows - rows % 4);
            for (x, z) in ac.chunks_exact(4).zip(bc.chunks_exact(4)) {
                for t in 0..4 {
                    acc[t] = madd::<FMA>(x[t], z[t], acc[t]);
                }
            }
            let mut s = (acc[0] + acc[2]) + (acc[1] + acc[3]);
            for (x, z) in ar.iter().zip(br) {
                s += x * z;
            }
            let out = &mut y[l + j * k];
            *out = if accumulate { *out + s } else { s };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic, irregular fill (no two entries alike, signs mixed).
    fn fill(len: usize, seed: f64) -> Vec<f64> {
        (0..len)
            .map(|i| ((i as f64 + 1.0) * seed).sin() * (1.0 + (i % 7) as f64))
            .collect()
    }

    #[test]
    fn small_products_match_the_textbook_sums_at_every_shape_the_models_use() {
        for &(rows, k, n) in &[
            (1, 1, 1),
            (14, 5, 8),
            (10, 7, 8),
            (21, 10, 7),
            (42, 21, 9),
            (28, 42, 8),
            (84, 42, 3),
            (19, 3, 4),
            (7, 2, 2),
            (3, 2, 1),
        ] {
            let ldb = k + 3;
            let a = fill(rows * k, 0.37);
            let b = fill(ldb * n, 1.13);
            let mut y = vec![f64::NAN; rows * n];
            mul_cols_strided((rows, k, n), &a, &b, ldb, &mut y);
            let mut yt = vec![f64::NAN; k * n];
            let bt = fill(rows * n, 0.71);
            mul_tr_cols_into((rows, k, n), &a, &bt, &mut yt, false);
            for j in 0..n {
                for i in 0..rows {
                    let want: f64 = (0..k).map(|l| a[i + l * rows] * b[l + j * ldb]).sum();
                    assert!((y[i + j * rows] - want).abs() <= 1e-13 * (1.0 + want.abs()));
                }
                for l in 0..k {
                    let want: f64 = (0..rows).map(|i| a[i + l * rows] * bt[i + j * rows]).sum();
                    assert!((yt[l + j * k] - want).abs() <= 1e-13 * (1.0 + want.abs()));
                }
            }
            // accumulate adds to what is there
            let mut acc = vec![1.0; k * n];
            mul_tr_cols_into((rows, k, n), &a, &bt, &mut acc, true);
            for (s, t) in acc.iter().zip(&yt) {
                assert!((s - (t + 1.0)).abs() <= 1e-13 * (1.0 + t.abs()));
            }
        }
    }

    #[test]
    fn the_baseline_kernel_agrees_with_the_dispatched_one() {
        let (rows, k, n) = (42, 21, 8);
        let a = fill(rows * k, 0.91);
        let b = fill(k * n, 0.19);
        let mut y1 = vec![0.0; rows * n];
        let mut y2 = vec![0.0; rows * n];
        mul_cols((rows, k, n), &a, &b, &mut y1);
        mul_cols_body::<false>((rows, k, n), &a, &b, k, &mut y2);
        for (p, q) in y1.iter().zip(&y2) {
            assert!((p - q).abs() <= 1e-13 * (1.0 + q.abs()));
        }
    }
}
