//! Tendon lengths (gvs-spec §7.6): what an actuator's encoder reads, and their derivative in `q`.
//!
//! Tendon `k`'s thread `p = r + R d(X)` has the speed `‖dp/dX‖ = ‖t_u‖`, `t_u = ν + k × d + d'`, so
//! its length is `ℓ_k = ∫ ‖t_u‖ dX` over its span, here `ℓ_k(q) = Σ_i w_{k,i} ‖t_u(X_i)‖` over its
//! points with the weights of its wrench ([`Model::tendon_weights`]). Since `∂‖t_u‖/∂ξ = [d × t; t]
//! = Φ_a`, the derivative is `∂ℓ_k/∂q = Σ_i w_{k,i} Ψ_q,iᵀ Φ_a,k(X_i)`: the column `B_k` of the
//! actuation matrix of a frictionless tendon (the virtual work of its tension, `u δℓ`). With
//! friction `B_k` weights each point by `α ≤ 1` and is no longer a gradient; `∂ℓ/∂q` is still this.

use super::{Model, Workspace};
use crate::actuation::tendon_local;
use crate::lie::V6;
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};

impl<P: StrainParam> Model<P> {
    /// The tendons' lengths `ℓ_k(q) = Σ_i w_{k,i} ‖t_u(X_i)‖` \[m\] (the module documentation), one
    /// per tendon, at `q`. A tendon is shortened by pulling it: `ℓ_k(q) < ℓ_k(rest)` as it bends
    /// the rod toward itself.
    pub fn tendon_lengths(&self, q: &DVector<f64>, ws: &mut Workspace) -> Vec<f64> {
        self.strains_at(q, ws);
        let mut out = vec![0.0; self.tendons.len()];
        self.tendon_lengths_after_forward(ws, &mut out);
        out
    }

    /// [`Self::tendon_lengths`] into `out` (one per tendon) from the strains a forward pass (or
    /// [`Self::strains_at`]) left in `ws`, allocating nothing: a trajectory's every sample and a
    /// report read them after the poses without evaluating the strains (a decoder) again.
    pub fn tendon_lengths_after_forward(&self, ws: &Workspace, out: &mut [f64]) {
        for (k, l) in out.iter_mut().enumerate().take(self.tendons.len()) {
            *l = self.tendon_length_of(k, |i| ws.xi[i]);
        }
    }

    /// The tendons' lengths \[m\] at rest, the reference strain `ξ*` (the straight, unstretched
    /// rod's `[0, 0, 0, 1, 0, 0]` unless the rod is precurved): what the lengths of
    /// [`Self::tendon_lengths`] are shortened from.
    pub fn tendon_rest_lengths(&self) -> Vec<f64> {
        (0..self.tendons.len())
            .map(|k| self.tendon_length_of(k, |i| self.xi_star(i)))
            .collect()
    }

    /// Each tendon's compliance `c_k = ℓ_k,rest / EA_k` \[m/N\]: its stretch per newton of
    /// tension, `ℓ_k,rest` from [`Self::tendon_rest_lengths`] and `EA_k` its
    /// [`crate::actuation::Tendon::axial_stiffness`] (0 for an inextensible tendon). The thread
    /// counted is its span along the rod; a free length up to the motor stretches too and folds
    /// into `EA` (the compliance of the whole line is `ℓ_total / EA`).
    pub fn tendon_compliances(&self) -> Vec<f64> {
        let rest = self.tendon_rest_lengths();
        (self.tendons.iter().zip(rest))
            .map(|(t, l)| t.axial_stiffness.map_or(0.0, |ea| l / ea))
            .collect()
    }

    /// `∂ℓ/∂q` (n × tendons): column `k` is `∇_q ℓ_k = Σ_i w_{k,i} Ψ_q,iᵀ Φ_a,k(X_i)`, the
    /// frictionless tendon's column of the actuation matrix (the module documentation). Leaves the
    /// forward pass at `q` in `ws` ([`Self::tendon_lengths_after_forward`] reads the lengths).
    pub fn tendon_length_jacobian(&self, q: &DVector<f64>, ws: &mut Workspace) -> DMatrix<f64> {
        let mut jac = DMatrix::zeros(self.n_dof(), self.n_actuators());
        let mut col = DVector::zeros(self.n_dof());
        // the strains and their tangents Ψ_q that `project` needs (as `actuation_matrix`)
        self.forward(q, ws, false);
        self.tendon_length_jacobian_after_forward(ws, &mut jac, &mut col);
        jac
    }

    /// [`Self::tendon_length_jacobian`] into `jac` (n × tendons) after a forward pass at `q`,
    /// with `col` (n) as scratch: allocates nothing.
    pub fn tendon_length_jacobian_after_forward(
        &self,
        ws: &mut Workspace,
        jac: &mut DMatrix<f64>,
        col: &mut DVector<f64>,
    ) {
        for (k, td) in self.tendons.iter().enumerate() {
            ws.y.iter_mut().for_each(|y| *y = V6::zeros());
            for (&i, &w) in self.tendon_points[k].iter().zip(&self.tendon_weights[k]) {
                if w == 0.0 {
                    continue;
                }
                let (d, dp) = td.offset_and_rate(self.disc.points[i].x);
                ws.y[i] += tendon_local(&ws.xi[i], &d, &dp).phi_a * w;
            }
            col.fill(0.0);
            self.project(ws, col);
            jac.set_column(k, col);
        }
    }

    /// `Σ_i w_{k,i} ‖t_u(X_i)‖` of tendon `k` with the strain `xi(i)` at point `i`.
    fn tendon_length_of(&self, k: usize, xi: impl Fn(usize) -> V6) -> f64 {
        let td = &self.tendons[k];
        (self.tendon_points[k].iter().zip(&self.tendon_weights[k]))
            .filter(|(_, &w)| w != 0.0)
            .map(|(&i, &w)| {
                let (d, dp) = td.offset_and_rate(self.disc.points[i].x);
                w * tendon_local(&xi(i), &d, &dp).nt
            })
            .sum()
    }
}
