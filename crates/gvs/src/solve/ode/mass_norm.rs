//! The mass-matrix norm of mechanical states ([`super::ErrorNorm::Mass`]): `‖x‖_M̂ = √(xᵀ M̂ x)` with
//! `M̂ = M·m/tr M` (unit mean diagonal), by the Cholesky factor of `M̂`.

use nalgebra::DMatrix;

/// `‖·‖_M̂` for one half (`q` or `q̇`, `m` entries) of a mechanical state.
pub(super) struct MassNorm {
    /// `L` of `M̂ = L Lᵀ` (row `i` of `Lᵀ` is the contiguous column `i` of `L` from the diagonal
    /// down), or `M̂` itself if it is not positive definite (`chol` false).
    l: DMatrix<f64>,
    chol: bool,
    /// Evaluation count of the `M` it was made from.
    of: usize,
}

impl MassNorm {
    pub(super) fn new(m: usize) -> Self {
        MassNorm {
            l: DMatrix::identity(m, m),
            chol: true,
            of: usize::MAX,
        }
    }

    /// The evaluation count of the `M` in use.
    pub(super) fn of(&self) -> usize {
        self.of
    }

    /// Sets `M̂` (and its factor) from `M` if `M` changed (`count`: its evaluation count).
    pub(super) fn set(&mut self, mass: &DMatrix<f64>, count: usize) {
        if count == self.of {
            return;
        }
        self.of = count;
        let tr = mass.trace();
        if !(tr > 0.0 && tr.is_finite()) {
            return; // keep the last one
        }
        self.l.copy_from(mass);
        self.l *= mass.nrows() as f64 / tr;
        self.chol = cholesky_upper_in_place(&mut self.l);
        if self.chol {
            self.l.transpose_mut();
        } else {
            self.l.copy_from(mass);
            self.l *= mass.nrows() as f64 / tr;
        }
    }

    /// `‖x‖_M̂ = ‖Lᵀ x‖` (`m²/2` products), or `√max(0, xᵀM̂x)`.
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

/// `A = RᵀR` in place (upper triangle `R`, lower triangle zeroed) for a symmetric positive
/// definite `A`; `false` (with `A` overwritten) if it is not.
fn cholesky_upper_in_place(a: &mut DMatrix<f64>) -> bool {
    let m = a.nrows();
    let s = a.as_mut_slice();
    for j in 0..m {
        // R_ij = (A_ij − Σ_{k<i} R_ki R_kj) / R_ii for i < j; R_jj = √(A_jj − Σ_k R_kj²)
        for i in 0..j {
            let mut v = s[i + j * m];
            for k in 0..i {
                v -= s[k + i * m] * s[k + j * m];
            }
            s[i + j * m] = v / s[i + i * m];
        }
        let mut d = s[j + j * m];
        for k in 0..j {
            d -= s[k + j * m] * s[k + j * m];
        }
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        s[j + j * m] = d.sqrt();
        for i in j + 1..m {
            s[i + j * m] = 0.0;
        }
    }
    true
}
