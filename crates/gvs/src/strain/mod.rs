//! Strain parameterizations (gvs-spec §4, architecture "the one idea").
//!
//! A parameterization maps the generalized coordinates `q ∈ Rⁿ` to the strain deviation
//! `Ψ_s(q) = ξ_s(q) − ξ*_s` at every strain *site* `s` of a [`Discretization`](crate::discretize::Discretization)
//! (its computational points and Magnus sub-points), and supplies what the engine needs from it:
//!
//! | what | linear basis (Legendre, FEM-like, POD) | nonlinear (AE decoder, analytic) |
//! |---|---|---|
//! | `Ψ_s` | `Φ_s q` | `Ψ_s(q)` |
//! | `Ψ_q,s = ∂Ψ_s/∂q` (6×n) | `Φ_s` (constant) | Jacobian |
//! | `Ψ̇_q,s = (∂²Ψ_s/∂q² q̇)` (paper eq. 17) | 0 | directional second derivative |
//! | `Σ_s Σ_a w_{s,a} ∇²Ψ_{s,a}` (statics Jacobian) | 0 | contraction with per-site weights |
//!
//! Every model quantity (kinematics, M, C, K, forces) is computed by the engine from these, so a reduced
//! model keeps the Lagrangian structure by construction.

mod bases;
mod sigmoid;

pub use bases::{DivisionBasis, FemDegree, LinearBasis};
pub use sigmoid::SigmoidBend;

use crate::lie::V6;
use nalgebra::{DMatrix, DVector, Dyn, Matrix6xX, ViewStorage, U1, U6};
use std::ops::Range;

/// A view of `Ψ_q` at one site: 6 × (column range) block.
pub type SiteJacobian<'a> = nalgebra::Matrix<f64, U6, Dyn, ViewStorage<'a, f64, U6, Dyn, U1, U6>>;

/// Values of a parameterization at all sites for one `q` (and optionally `q̇`).
///
/// `psi_q` stores the 6×n blocks of all sites side by side (`6 × n·n_sites`); only the columns in
/// [`StrainParam::columns`] of a site may be non-zero and only those are read by the engine.
#[derive(Debug, Clone)]
pub struct StrainEval {
    pub n: usize,
    pub psi: Vec<V6>,
    pub psi_q: Matrix6xX<f64>,
    pub psi_q_dot: Matrix6xX<f64>,
}

impl StrainEval {
    pub fn zeros(n: usize, n_sites: usize) -> Self {
        StrainEval {
            n,
            psi: vec![V6::zeros(); n_sites],
            psi_q: Matrix6xX::zeros(n * n_sites),
            psi_q_dot: Matrix6xX::zeros(n * n_sites),
        }
    }

    /// `Ψ_q` at `site`, restricted to `cols`.
    #[inline]
    pub fn psi_q_at(&self, site: usize, cols: &Range<usize>) -> SiteJacobian<'_> {
        self.psi_q.columns(site * self.n + cols.start, cols.len())
    }

    /// `Ψ̇_q` at `site`, restricted to `cols`.
    #[inline]
    pub fn psi_q_dot_at(&self, site: usize, cols: &Range<usize>) -> SiteJacobian<'_> {
        self.psi_q_dot
            .columns(site * self.n + cols.start, cols.len())
    }
}

/// The interface between a strain parameterization and the GVS engine.
///
/// Implementations are bound to one discretization (its site list) when they are built.
pub trait StrainParam: Send + Sync {
    /// Number of generalized coordinates n.
    fn n_dof(&self) -> usize;

    /// Number of sites the parameterization was built for.
    fn n_sites(&self) -> usize;

    /// `true` if `Ψ(q) = Φ q` with constant `Φ` (then `Ψ̇_q = 0` and all Hessians vanish).
    fn is_linear(&self) -> bool;

    /// The contiguous range of coordinates that may influence the strain at `site` (the division's
    /// columns for a multi-division basis; everything for a global basis).
    fn columns(&self, site: usize) -> Range<usize> {
        let _ = site;
        0..self.n_dof()
    }

    /// Allocates an evaluation buffer. Linear bases store their constant `Φ` in it here.
    fn new_eval(&self) -> StrainEval;

    /// Fills `ev.psi` (and, for nonlinear parameterizations, `ev.psi_q`) at `q`.
    fn eval(&self, q: &DVector<f64>, ev: &mut StrainEval);

    /// Fills `ev.psi_q_dot = (∂²Ψ/∂q² q̇)` at `(q, q̇)` (paper eq. 17). Linear bases: nothing to do.
    fn eval_rate(&self, q: &DVector<f64>, qd: &DVector<f64>, ev: &mut StrainEval);

    /// `out += Σ_s Σ_a w[s]_a ∇²_q Ψ_{s,a}(q)` (n×n, symmetric); `w` has one 6-vector per site and
    /// zero vectors may be skipped. Linear bases: nothing to add.
    fn add_weighted_hessian(&self, q: &DVector<f64>, w: &[V6], out: &mut DMatrix<f64>);
}

#[cfg(test)]
pub(crate) mod test_support {
    use super::*;

    /// Checks `psi_q`, `psi_q_dot` and the weighted Hessian of `p` against central differences at `q`.
    pub fn check_derivatives<P: StrainParam>(p: &P, q: &DVector<f64>, qd: &DVector<f64>, tol: f64) {
        let n = p.n_dof();
        let ns = p.n_sites();
        let mut ev = p.new_eval();
        p.eval(q, &mut ev);
        p.eval_rate(q, qd, &mut ev);
        let h = 1e-6;
        let mut ep = p.new_eval();
        let mut em = p.new_eval();
        // Ψ_q columns
        for j in 0..n {
            let mut qp = q.clone();
            qp[j] += h;
            let mut qm = q.clone();
            qm[j] -= h;
            p.eval(&qp, &mut ep);
            p.eval(&qm, &mut em);
            for s in 0..ns {
                let fd = (ep.psi[s] - em.psi[s]) / (2.0 * h);
                let an = ev.psi_q.column(s * n + j);
                for a in 0..6 {
                    assert!(
                        (fd[a] - an[a]).abs() < tol,
                        "Psi_q site {s} row {a} col {j}: {} vs {}",
                        an[a],
                        fd[a]
                    );
                }
            }
        }
        // Ψ̇_q = d/dε Ψ_q(q + ε q̇)
        p.eval(&(q + qd * h), &mut ep);
        p.eval(&(q - qd * h), &mut em);
        let fd = (&ep.psi_q - &em.psi_q) / (2.0 * h);
        assert!((&fd - &ev.psi_q_dot).abs().max() < tol, "Psi_q_dot vs FD");
        // weighted Hessian: ∂/∂q (Σ_s Ψ_q,sᵀ w_s)
        let w: Vec<V6> = (0..ns)
            .map(|s| V6::from_fn(|a, _| ((s * 7 + a * 3) % 5) as f64 - 2.0))
            .collect();
        let g = |e: &StrainEval| {
            let mut out = DVector::zeros(n);
            for s in 0..ns {
                out += e.psi_q.columns(s * n, n).transpose() * w[s];
            }
            out
        };
        let mut hess = DMatrix::zeros(n, n);
        p.add_weighted_hessian(q, &w, &mut hess);
        for j in 0..n {
            let mut qp = q.clone();
            qp[j] += h;
            let mut qm = q.clone();
            qm[j] -= h;
            p.eval(&qp, &mut ep);
            p.eval(&qm, &mut em);
            let col = (g(&ep) - g(&em)) / (2.0 * h);
            for i in 0..n {
                assert!(
                    (col[i] - hess[(i, j)]).abs() < tol * 10.0,
                    "H[{i},{j}]: {} vs {}",
                    hess[(i, j)],
                    col[i]
                );
            }
        }
    }
}
