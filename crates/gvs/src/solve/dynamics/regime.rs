//! The rod's damping regime — how strongly its stiffest modes are damped, `ζ_max = τ ω_max / 2`
//! with `τ = min Ds/Es` and `ω_max = √λ_max(M⁻¹K)` — and the integrator it calls for when the user
//! names none (NDF for a damped rod, SDIRK4 or the A-stable NDF orders for a lightly damped one).

use super::Method;
use crate::error::ModelError;
use crate::loads::Loads;
use crate::model::Model;
use crate::solve::ode::{ErrorNorm, NdfOptions, SdirkOptions};
use crate::strain::StrainParam;
use nalgebra::DVector;

/// How strongly a rod's stiffest modes are damped, and the NDF options that suit it
/// ([`ndf_for_rod`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampingRegime {
    /// Smallest ratio `Ds/Es` over the sections and strain components \[s\]: Kelvin–Voigt damping
    /// gives a mode of frequency `ω` the damping ratio `ζ ≥ τ ω/2`.
    pub tau: f64,
    /// Highest natural frequency of the straight rod, `√λ_max(M⁻¹K)` [rad/s] (`None` when
    /// `τ = 0`: not needed).
    pub omega_max: Option<f64>,
    /// `τ ω_max / 2`: the damping ratio of the stiffest mode (0 for an undamped rod).
    pub zeta_max: f64,
}

impl DampingRegime {
    /// Lightly damped: the stiffest mode is underdamped (`ζ_max < 1`), so the NDFs of orders 3–5
    /// (not A-stable) would be limited by stability on the modes the step does not resolve.
    pub fn is_light(&self) -> bool {
        self.zeta_max < 1.0
    }
}

/// The damping regime of `model` about its rest configuration (no loads): `τ` from the section
/// matrices and, if `τ > 0`, `ω_max` by power iteration on `M⁻¹K` (`K` the elastic stiffness at
/// rest), to 0.1 %.
pub fn damping_regime<P: StrainParam>(model: &Model<P>) -> Result<DampingRegime, ModelError> {
    let tau = model.damping_time();
    if tau == 0.0 {
        return Ok(DampingRegime {
            tau,
            omega_max: None,
            zeta_max: 0.0,
        });
    }
    let n = model.n_dof();
    let q = model.param.rest_coordinates();
    let loads = model.prepare_loads(&Loads::default())?;
    let u = vec![0.0; model.n_actuators()];
    let mut ws = model.workspace();
    let z = || nalgebra::DMatrix::zeros(n, n);
    let (mut m, mut d, mut k) = (z(), z(), z());
    model.iteration_parts(&q, &u, &loads, &mut ws, &mut m, &mut d, &mut k);
    crate::dynamics::cholesky_factor_in_place(&mut m)
        .map_err(|e| ModelError::invalid("mass matrix", e.to_string()))?;
    // power iteration on M⁻¹K with the Rayleigh-like estimate ‖M⁻¹K x‖/‖x‖
    let mut x = DVector::from_fn(n, |i, _| 1.0 + 0.37 * ((i * 7919 % 101) as f64) / 101.0);
    x /= x.norm();
    let mut lambda = 0.0f64;
    for _ in 0..200 {
        let mut y = &k * &x;
        crate::dynamics::cholesky_solve_factored(&m, &mut y);
        let norm = y.norm();
        if !(norm > 0.0 && norm.is_finite()) {
            break;
        }
        let done = (norm - lambda).abs() <= 1e-3 * norm;
        lambda = norm;
        x = y / norm;
        if done {
            break;
        }
    }
    let omega = lambda.sqrt();
    Ok(DampingRegime {
        tau,
        omega_max: Some(omega),
        zeta_max: 0.5 * tau * omega,
    })
}

/// The relative tolerance [`method_for_rod`] uses on a lightly damped rod when none is given.
///
/// The error test measures a step's error against the whole (mass-weighted) state, which the first
/// mode dominates; an undamped rod never forgets the phase errors of its second and third modes,
/// which carry a few per cent and a few per mille of the tip motion. On the undamped release of
/// issue 8 (6 s, about two periods) SDIRK4 at `1e-3` leaves the tip within 0.59 % L of a tight
/// run, at `1e-4` within 0.07 % L, in 0.21 s.
pub const LIGHT_DAMPING_RTOL: f64 = 1e-4;

/// The integrator for `model` when the user names none: for a damped rod the NDF of orders ≤ 5
/// with the componentwise error test (`ode15s`) at `rtol` (default `1e-3`); for a lightly damped
/// one ([`DampingRegime::is_light`]) the L-stable SDIRK4 ([`SdirkOptions`]) with the mass-norm
/// error test at `rtol` (default [`LIGHT_DAMPING_RTOL`]). Returns the method and the regime.
pub fn method_for_rod<P: StrainParam>(
    model: &Model<P>,
    rtol: Option<f64>,
    atol: f64,
) -> Result<(Method, DampingRegime), ModelError> {
    let regime = damping_regime(model)?;
    let method = if regime.is_light() {
        Method::Sdirk(SdirkOptions {
            rtol: rtol.unwrap_or(LIGHT_DAMPING_RTOL),
            atol,
            error_norm: ErrorNorm::Mass,
            ..SdirkOptions::default()
        })
    } else {
        Method::Ndf(NdfOptions {
            rtol: rtol.unwrap_or(NdfOptions::default().rtol),
            atol,
            ..NdfOptions::default()
        })
    };
    Ok((method, regime))
}

/// `base` for a damped rod; for a lightly damped one ([`DampingRegime::is_light`]) the
/// A-stable orders only (`max_order ≤ 2`) and the mass-matrix error norm
/// ([`ErrorNorm::Mass`]), so that the unresolved high-frequency modes are damped by
/// the method instead of limiting the step. Returns the options and the regime.
pub fn ndf_for_rod<P: StrainParam>(
    model: &Model<P>,
    base: &NdfOptions,
) -> Result<(NdfOptions, DampingRegime), ModelError> {
    let regime = damping_regime(model)?;
    Ok((ndf_for_regime(base, &regime), regime))
}

/// [`ndf_for_rod`] for a known regime.
pub fn ndf_for_regime(base: &NdfOptions, regime: &DampingRegime) -> NdfOptions {
    let mut o = base.clone();
    if regime.is_light() {
        o.max_order = o.max_order.min(2);
        o.error_norm = ErrorNorm::Mass;
    }
    o
}
