//! The NDF/BDF formulas of `ode15s`: the coefficients `γ_k`, `κ_k` and the error constants, and
//! the backward-difference table's algebra (rescaling for a new step size, interpolation).

use nalgebra::{DMatrix, DVector};

/// `γ_k = Σ_{j=1..k} 1/j`, `k = 1..5`.
pub(super) const GAMMA: [f64; 5] = [1.0, 3.0 / 2.0, 11.0 / 6.0, 25.0 / 12.0, 137.0 / 60.0];
/// The NDF coefficients `κ_k` (Shampine & Reichelt 1997, table 2.1).
const KAPPA: [f64; 5] = [-37.0 / 200.0, -1.0 / 9.0, -0.0823, -0.0415, 0.0];
/// `U_ij = (−1)^i binom(j, i)` (1-based), the difference-rescaling factor; `U = U⁻¹`.
const DIF_U: [[f64; 5]; 5] = [
    [-1.0, -2.0, -3.0, -4.0, -5.0],
    [0.0, 1.0, 3.0, 6.0, 10.0],
    [0.0, 0.0, -1.0, -4.0, -10.0],
    [0.0, 0.0, 0.0, 1.0, 5.0],
    [0.0, 0.0, 0.0, 0.0, -1.0],
];
/// `(1/((1−κ_k)γ_k), C_k = κ_k γ_k + 1/(k+1))` for `k = 1..5` (`κ = 0` for the BDFs).
pub(in super::super) fn coefficients(bdf: bool) -> ([f64; 5], [f64; 5]) {
    let mut inv_ga = [0.0; 5];
    let mut erconst = [0.0; 5];
    for k in 0..5 {
        let kappa = if bdf { 0.0 } else { KAPPA[k] };
        inv_ga[k] = 1.0 / (GAMMA[k] * (1.0 - kappa));
        erconst[k] = kappa * GAMMA[k] + 1.0 / (k as f64 + 2.0);
    }
    (inv_ga, erconst)
}

/// Re-expresses the differences `∇^1..∇^k` for the step ratio `r = h_new/h_old`:
/// `dif[:, 0..k] ← dif[:, 0..k]·(R U)`, `R_ij = Π_{m=1..i} (m − 1 − j r)/m`.
pub(in super::super) fn rescale(dif: &mut DMatrix<f64>, k: usize, r: f64) {
    let mut rm = [[0.0; 5]; 5];
    for j in 0..k {
        let mut p = 1.0;
        for (i, row) in rm.iter_mut().enumerate().take(k) {
            let m = (i + 1) as f64;
            p *= (m - 1.0 - (j + 1) as f64 * r) / m;
            row[j] = p;
        }
    }
    let mut ru = [[0.0; 5]; 5];
    for i in 0..k {
        for j in 0..k {
            ru[i][j] = (0..=j).map(|m| rm[i][m] * DIF_U[m][j]).sum();
        }
    }
    let n = dif.nrows();
    let d = dif.as_mut_slice();
    for row in 0..n {
        let mut old = [0.0; 5];
        for (m, o) in old.iter_mut().enumerate().take(k) {
            *o = d[row + m * n];
        }
        for j in 0..k {
            d[row + j * n] = (0..k).map(|m| old[m] * ru[m][j]).sum();
        }
    }
}

/// `y(tq)` from the interpolating polynomial of the step `(t_new − h, t_new]` of order `k`.
pub(in super::super) fn interpolate(
    tq: f64,
    t_new: f64,
    h: f64,
    ynew: &DVector<f64>,
    dif: &DMatrix<f64>,
    k: usize,
    out: &mut DVector<f64>,
) {
    out.copy_from(ynew);
    if tq == t_new {
        return;
    }
    let s = (tq - t_new) / h;
    let mut c = 1.0;
    for j in 0..k {
        c *= (s + j as f64) / (j + 1) as f64;
        out.axpy(c, &dif.column(j), 1.0);
    }
}
