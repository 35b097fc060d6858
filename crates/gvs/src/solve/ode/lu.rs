//! The iteration matrices' LU factorization.

use super::OdeStats;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor as lu_factor, solve as lu_solve};
use faer::perm::PermRef;
use faer::{MatMut, MatRef, Par};
use nalgebra::{DMatrix, DVector};

/// LU factorization with partial pivoting (faer, blocked) of an iteration matrix, in place
/// (allocation-free after construction).
pub(super) struct Lu {
    pub(super) a: DMatrix<f64>,
    pub(super) perm: Vec<usize>,
    pub(super) perm_inv: Vec<usize>,
    pub(super) mem: MemBuffer,
}

impl Lu {
    pub(super) fn new(n: usize) -> Self {
        let par = Par::Seq;
        let req = StackReq::any_of(&[
            lu_factor::lu_in_place_scratch::<usize, f64>(n, n, par, Default::default()),
            lu_solve::solve_in_place_scratch::<usize, f64>(n, 1, par),
        ]);
        Lu {
            a: DMatrix::zeros(n, n),
            perm: vec![0; n],
            perm_inv: vec![0; n],
            mem: MemBuffer::new(req),
        }
    }

    /// Factors `I − c·jac`; `false` if it is singular or not finite.
    pub(super) fn factor(&mut self, c: f64, jac: &DMatrix<f64>, stats: &mut OdeStats) -> bool {
        let n = self.perm.len();
        self.factor_with(stats, |a| {
            for (dst, src) in a.iter_mut().zip(jac.iter()) {
                *dst = -c * src;
            }
            for i in 0..n {
                a[(i, i)] += 1.0;
            }
        })
    }

    /// Factors the matrix `fill` writes (into an `n × n` buffer); `false` if it is singular
    /// (a zero pivot) or not finite.
    pub(super) fn factor_with(
        &mut self,
        stats: &mut OdeStats,
        fill: impl FnOnce(&mut DMatrix<f64>),
    ) -> bool {
        stats.lu_decompositions += 1;
        let n = self.perm.len();
        fill(&mut self.a);
        if !self.a.iter().all(|x| x.is_finite()) {
            return false;
        }
        let m = MatMut::from_column_major_slice_mut(self.a.as_mut_slice(), n, n);
        lu_factor::lu_in_place(
            m,
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        crate::cpu::clear_upper_state();
        (0..n).all(|k| {
            let p = self.a[(k, k)];
            p != 0.0 && p.is_finite()
        })
    }

    /// Solves `A x = b` in place with the last successful factorization.
    pub(super) fn solve(&mut self, b: &mut DVector<f64>) {
        let n = self.perm.len();
        let lu = MatRef::from_column_major_slice(self.a.as_slice(), n, n);
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
        let rhs = MatMut::from_column_major_slice_mut(b.as_mut_slice(), n, 1);
        lu_solve::solve_in_place(lu, lu, perm, rhs, Par::Seq, MemStack::new(&mut self.mem));
        crate::cpu::clear_upper_state();
    }
}
