//! The statics of a rod as a [`ParametrizedSystem`] in the load factor λ — `R(q, λ) = R(q; 0) +
//! λ G(q)`, `∂R/∂λ = G(q)` exactly (the parent module's doc) — and [`follow_statics`], which
//! follows it from the straight rod at λ = 0 to the full load at λ = 1.

use super::{
    follow, ContinuationError, ContinuationOptions, ContinuationReport, ParametrizedSystem,
};
use crate::error::ModelError;
use crate::loads::Loads;
use crate::model::{Model, PreparedLoads, Workspace};
use crate::solve::dogleg::DoglegOptions;
use crate::solve::StopCheck;
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};

/// The statics residual along the load ramp: `R(q, λ) = R(q; 0) + λ G(q)`, `∂R/∂λ = G(q) =
/// R(q; 1) − R(q; 0)` (module doc), two residual evaluations per call; `∂R/∂q` analytic at the
/// scaled loads `λ·loads`, `λu`.
pub struct StaticsPath<'a, 'm, P: StrainParam> {
    model: &'m Model<P>,
    ws: &'a mut Workspace,
    u: Vec<f64>,
    u_scaled: Vec<f64>,
    no_u: Vec<f64>,
    full: PreparedLoads,
    none: PreparedLoads,
    scaled: PreparedLoads,
    r0: DVector<f64>,
    /// Where `ws` holds the last forward pass, for the Jacobian to reuse.
    at: Option<DVector<f64>>,
    /// Model residual and Jacobian evaluations so far.
    pub residual_evaluations: usize,
    pub jacobian_evaluations: usize,
    /// Polled before every step ([`ParametrizedSystem::stop_requested`]).
    stop: &'a StopCheck<'a>,
}

impl<'a, 'm, P: StrainParam> StaticsPath<'a, 'm, P> {
    pub fn new(
        model: &'m Model<P>,
        ws: &'a mut Workspace,
        u: &[f64],
        loads: &Loads,
        stop: &'a StopCheck<'a>,
    ) -> Result<Self, ModelError> {
        let full = model.prepare_loads(loads)?;
        let mut none = full.clone();
        none.scale_from(&full, 0.0);
        Ok(StaticsPath {
            model,
            ws,
            u: u.to_vec(),
            u_scaled: u.to_vec(),
            no_u: vec![0.0; u.len()],
            scaled: full.clone(),
            full,
            none,
            r0: DVector::zeros(model.n_dof()),
            at: None,
            residual_evaluations: 0,
            jacobian_evaluations: 0,
            stop,
        })
    }
}

impl<P: StrainParam> ParametrizedSystem for StaticsPath<'_, '_, P> {
    fn dim(&self) -> usize {
        self.model.n_dof()
    }
    fn residual(
        &mut self,
        x: &DVector<f64>,
        lambda: f64,
        r: &mut DVector<f64>,
        r_lambda: &mut DVector<f64>,
    ) -> f64 {
        let m = self.model;
        m.statics_residual(x, &self.no_u, &self.none, self.ws, &mut self.r0);
        m.statics_residual(x, &self.u, &self.full, self.ws, r_lambda);
        *r_lambda -= &self.r0;
        r.copy_from(&self.r0);
        r.axpy(lambda, r_lambda, 1.0);
        self.residual_evaluations += 2;
        self.at = Some(x.clone());
        // the statics scale max(‖K₁‖∞, ‖F + Bu‖∞, EI_max) at λ (`Model::statics_residual`)
        (self.r0.amax().max(lambda.abs() * r_lambda.amax())).max(m.residual_floor())
    }
    fn jacobian(&mut self, x: &DVector<f64>, lambda: f64, jac: &mut DMatrix<f64>) {
        self.scaled.scale_from(&self.full, lambda);
        for (s, u) in self.u_scaled.iter_mut().zip(&self.u) {
            *s = lambda * u;
        }
        let m = self.model;
        if self.at.as_ref() == Some(x) {
            m.statics_jacobian_after_forward(x, &self.u_scaled, &self.scaled, self.ws, jac);
        } else {
            m.statics_jacobian(x, &self.u_scaled, &self.scaled, self.ws, jac);
        }
        self.at = None;
        self.jacobian_evaluations += 1;
    }
    fn stop_requested(&mut self) -> Option<String> {
        (self.stop)()
    }
}

/// Follows the statics of `model` under `u`, `loads` from the straight rod
/// ([`StrainParam::rest_coordinates`], the equilibrium at λ = 0) to λ = 1, landing with the dogleg
/// options `landing`, polling `stop` before every step. Returns the report and the model's residual
/// and Jacobian evaluations.
pub fn follow_statics<P: StrainParam>(
    model: &Model<P>,
    ws: &mut Workspace,
    u: &[f64],
    loads: &Loads,
    landing: &DoglegOptions,
    stop: &StopCheck<'_>,
) -> Result<(ContinuationReport, usize, usize), ContinuationError> {
    let opts = ContinuationOptions {
        corrector_ftol: landing
            .ftol
            .max(ContinuationOptions::default().corrector_ftol),
        landing: landing.clone(),
        ..ContinuationOptions::default()
    };
    let mut sys = StaticsPath::new(model, ws, u, loads, stop)?;
    let rep = follow(&mut sys, &model.param.rest_coordinates(), 0.0, &opts)?;
    Ok((rep, sys.residual_evaluations, sys.jacobian_evaluations))
}
