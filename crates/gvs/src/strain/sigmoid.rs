//! An analytic nonlinear strain parameterization (gvs-spec §4.5, SoRoSim's NL-basis example): a
//! bending-y strain shaped as a sigmoid whose amplitude, steepness and centre are the coordinates,
//!
//! `Ψ₂(X̄, q) = (q₁/ℓ) σ(−q₂ (X̄ − q₃))`, `σ(z) = 1/(1 + e^{−z})`, all other components 0.
//!
//! It exercises the state-dependent path of the engine (`Ψ_q`, `Ψ̇_q`, Hessian contractions) with
//! closed-form derivatives, and is the continuum shape of the IV-B beam's curvature.

use super::{StrainEval, StrainParam};
use crate::discretize::Discretization;
use crate::lie::V6;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// Bending-y sigmoid over a single-division rod (3 coordinates).
#[derive(Debug, Clone)]
pub struct SigmoidBend {
    /// `(X̄, ℓ)` of each site.
    sites: Vec<(f64, f64)>,
}

impl SigmoidBend {
    pub fn new(disc: &Discretization) -> Self {
        SigmoidBend {
            sites: disc
                .sites
                .iter()
                .map(|s| (s.x_bar, disc.div_length[s.div]))
                .collect(),
        }
    }

    /// `(Ψ₂, ∇_q Ψ₂, ∇²_q Ψ₂)` at one site.
    fn eval_site(&self, s: usize, q: &DVector<f64>) -> (f64, Vector3<f64>, Matrix3<f64>) {
        let (xb, l) = self.sites[s];
        let (a, b, c) = (q[0], q[1], q[2]);
        let d = xb - c;
        let z = -b * d;
        let sg = 1.0 / (1.0 + (-z).exp());
        let s1 = sg * (1.0 - sg); // σ'
        let s2 = s1 * (1.0 - 2.0 * sg); // σ''
        let psi = a / l * sg;
        // ∂z/∂q = [0, −d, b]
        let grad = Vector3::new(sg / l, a / l * s1 * (-d), a / l * s1 * b);
        let h12 = s1 * (-d) / l;
        let h13 = s1 * b / l;
        let h22 = a / l * s2 * d * d;
        let h23 = a / l * (s2 * (-d) * b + s1);
        let h33 = a / l * s2 * b * b;
        let hess = Matrix3::new(0.0, h12, h13, h12, h22, h23, h13, h23, h33);
        (psi, grad, hess)
    }
}

impl StrainParam for SigmoidBend {
    fn n_dof(&self) -> usize {
        3
    }
    fn n_sites(&self) -> usize {
        self.sites.len()
    }
    fn is_linear(&self) -> bool {
        false
    }
    fn new_eval(&self) -> StrainEval {
        StrainEval::zeros(3, self.sites.len())
    }
    fn eval(&self, q: &DVector<f64>, ev: &mut StrainEval) {
        for s in 0..self.sites.len() {
            let (psi, grad, _) = self.eval_site(s, q);
            ev.psi[s] = V6::new(0.0, psi, 0.0, 0.0, 0.0, 0.0);
            for j in 0..3 {
                ev.psi_q[(1, 3 * s + j)] = grad[j];
            }
        }
    }
    fn eval_rate(&self, q: &DVector<f64>, qd: &DVector<f64>, ev: &mut StrainEval) {
        let v = Vector3::new(qd[0], qd[1], qd[2]);
        for s in 0..self.sites.len() {
            let (_, _, h) = self.eval_site(s, q);
            let r = h * v;
            for j in 0..3 {
                ev.psi_q_dot[(1, 3 * s + j)] = r[j];
            }
        }
    }
    fn add_weighted_hessian(
        &self,
        q: &DVector<f64>,
        w: &[V6],
        _ev: &mut StrainEval,
        out: &mut DMatrix<f64>,
    ) {
        for (s, ws) in w.iter().enumerate() {
            if ws[1] == 0.0 {
                continue;
            }
            let (_, _, h) = self.eval_site(s, q);
            for i in 0..3 {
                for j in 0..3 {
                    out[(i, j)] += ws[1] * h[(i, j)];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discretize::{MagnusOrder, Quadrature};
    use crate::rod::{Material, Rod};
    use crate::strain::testing::check_derivatives;

    #[test]
    fn sigmoid_derivatives_match_central_differences() {
        let rod = Rod::tapered(
            Material {
                youngs_modulus: 1e6,
                poisson_ratio: 0.5,
                density: 1000.0,
                damping: 0.0,
            },
            0.8,
            0.015,
            0.015,
        );
        let d =
            Discretization::new(&rod, &[Quadrature::Gauss { n: 8 }], MagnusOrder::Z4, &[]).unwrap();
        let p = SigmoidBend::new(&d);
        let q = DVector::from_vec(vec![1.3, 9.0, 0.4]);
        let qd = DVector::from_vec(vec![0.7, -3.0, 0.2]);
        check_derivatives(&p, &q, &qd, 1e-6);
    }
}
