//! The kinetic-energy metric of `gvsrom train --kinetic-weight κ` (beyond the paper): every
//! training row's mass matrix, so that the autoencoder's errors are also measured in the norm the
//! Lagrangian model feels them in (`rom::nn::metric`).
//!
//! A strain error `e` at the computational points is the coefficient error `δq = P e` of the
//! scenario's own basis (`P = Φ̄⁺`, exact for every field the basis represents); row `b`, the
//! strain `x_b` of configuration `q_b = P x_b`, weighs it by `M_b = M(q_b)` (eq. 8's mass matrix):
//! `‖e‖²_b = δqᵀ M_b δq`, twice the kinetic energy of a velocity error `δq̇`. The trainer scales
//! `κ` so that the rates of the training rows have the same mean square in this norm as in the
//! energy norm of the loss, so `κ = 1` weighs the two alike.

use crate::build::Built;
use crate::error::ScenarioError;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use rom::nn::RowMetric;

use super::invalid;

/// The metric of the row-major training `rows` (`features` values each, physical units, the
/// deviation from the reference strain) on `built`'s model with projection `p` (`m × features`)
/// and weight `weight`: `Pᵀ` and the symmetrised `M(P x_b)` of every row, in row order (the mass
/// matrices are computed in parallel; each is a pure function of its row).
pub(super) fn kinetic_metric(
    built: &Built,
    p: &DMatrix<f64>,
    rows: &[f64],
    features: usize,
    weight: f64,
) -> Result<RowMetric, ScenarioError> {
    let m = p.nrows();
    let model = &built.model;
    let mass: Vec<f64> = rows
        .par_chunks_exact(features)
        .map_init(
            || model.workspace(),
            |ws, x| {
                let q = p * DVector::from_column_slice(x);
                let mass = model.mass_matrix(&q, ws);
                // (M + Mᵀ)/2: the quadratic form's own matrix, whatever the assembly's rounding
                let sym = (&mass + mass.transpose()) * 0.5;
                sym.as_slice().to_vec()
            },
        )
        .flatten_iter()
        .collect();
    // Pᵀ row-major (features × m): element (i, j) = P[j, i], i.e. P column-major
    let p_t = p.as_slice().to_vec();
    debug_assert_eq!(p_t.len(), features * m);
    RowMetric::new(features, p_t, mass, weight)
        .map_err(|e| invalid("--kinetic-weight", e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduce::projection_of;

    #[test]
    fn the_metric_of_a_strain_rate_error_is_twice_the_kinetic_energy_of_its_coefficient_rate() {
        // On the six-tendon arm (28 coefficients, 84 point values): a configuration q and a
        // coefficient rate q̇, their point strains x = Φ̄ q and ė = Φ̄ q̇; the row of x must weigh ė
        // as q̇ᵀ M(q) q̇ with M from the engine itself.
        let built = crate::build::build(&crate::presets::load("six-tendon", &[]).unwrap()).unwrap();
        let (_, pm, p) = projection_of(&built).unwrap();
        let n = built.model.n_dof();
        let q = DVector::from_fn(n, |i, _| 0.3 * ((i as f64) * 0.7).sin());
        let qd = DVector::from_fn(n, |i, _| ((i as f64) * 1.3).cos());
        let x = &pm * &q;
        let e = &pm * &qd;
        let metric = kinetic_metric(&built, &p, x.as_slice(), x.len(), 1.0).unwrap();
        assert_eq!((metric.rows(), metric.coefficients()), (1, n));
        let mass = built.model.mass_matrix(&q, &mut built.model.workspace());
        let expected = qd.dot(&(&mass * &qd));
        let got = metric.squared_norm(0, e.as_slice());
        assert!(
            (got - expected).abs() <= 1e-10 * expected,
            "{got} against q̇ᵀ M q̇ = {expected}"
        );
    }
}
