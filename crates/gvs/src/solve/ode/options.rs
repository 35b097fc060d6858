//! The integrators' options, tolerance bounds and work counters.

use super::{invalid, OdeError};

/// Smallest relative tolerance the adaptive integrators accept: `1e-12 ≈ 4.5e3 ε`. The error
/// estimates are differences of states that carry a round-off of a few `ε` relative to their size,
/// amplified by the Newton solves (whose convergence test asks for `rtol/2`, after one iteration
/// `rtol/20`), so below about `1e3 ε` the step control steers by round-off: the steps shrink
/// without bound or Newton never meets its test (`ode15s` floors it at `100 ε`, silently).
pub const MIN_RTOL: f64 = 1e-12;
/// Relative tolerances must be below 1: at `rtol = 1` (100 %) every step passes the error test.
pub const MAX_RTOL: f64 = 1.0;
/// Checks the tolerances of an adaptive integrator: `rtol` in [[`MIN_RTOL`], [`MAX_RTOL`]) and
/// `atol` finite and positive (`atol_field` names it in the error: `atol` or `atol_components`).
/// `atol` has the units of the state, so no floor fits every problem: a caller that knows its
/// coordinates' scale bounds it further (the CLI does for a rod's strain coordinates).
pub(in crate::solve) fn check_tolerances(
    rtol: f64,
    atol: f64,
    atol_field: &'static str,
) -> Result<(), OdeError> {
    if !(MIN_RTOL..MAX_RTOL).contains(&rtol) {
        return Err(invalid(
            "rtol",
            format!(
                "{} (accepted: a number in [{MIN_RTOL:e}, {MAX_RTOL}))",
                crate::error::fmt_value(rtol)
            ),
        ));
    }
    if !(atol > 0.0 && atol.is_finite()) {
        return Err(invalid(
            atol_field,
            format!(
                "{} (accepted: a finite number > 0)",
                crate::error::fmt_value(atol)
            ),
        ));
    }
    Ok(())
}

/// Options of [`integrate_ndf`](super::integrate_ndf).
#[derive(Debug, Clone)]
pub struct NdfOptions {
    /// Relative tolerance (default `1e-3`, as `ode15s`), in [[`MIN_RTOL`], [`MAX_RTOL`]).
    pub rtol: f64,
    /// Absolute tolerance for every component (default `1e-6`), finite and > 0.
    pub atol: f64,
    /// Per-component absolute tolerances (length `dim`); when `Some`, used instead of `atol`.
    pub atol_components: Option<Vec<f64>>,
    /// Maximum order, `1..=5` (default 5).
    pub max_order: usize,
    /// `false`: NDFs (default, κ coefficients); `true`: plain BDFs (κ = 0).
    pub bdf: bool,
    /// First step; default automatic, as `ode15s`. Only used at `t0` (restarts after breakpoints
    /// always choose their step automatically).
    pub initial_step: Option<f64>,
    /// Maximum step. The default, `f64::INFINITY`, means `0.1·|tf − t0|` (the `ode15s` default);
    /// a finite positive value is used as given.
    pub max_step: f64,
    /// Maximum number of successful steps (default 1 000 000).
    pub max_steps: usize,
    /// How local errors are measured (default componentwise, as `ode15s`; Newton corrections
    /// are measured componentwise with either).
    pub error_norm: ErrorNorm,
    /// When the second-order form renews the mass matrix of its iteration matrix (default
    /// [`MassRenewal::WhenSlow`]; the first-order form ignores it).
    pub mass_renewal: MassRenewal,
}

/// When [`integrate_ndf_second_order`](super::integrate_ndf_second_order) renews `M` in its iteration matrix `M + c D + c² K`
/// (`D`, `K` are renewed only when Newton fails with them stale).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MassRenewal {
    /// After a Newton failure, and for the step after one that contracted slower than `ρ = 0.2`:
    /// for a model whose `M` costs as much as a few residuals (the HOM: one forward pass with
    /// Jacobians on all `n` coordinates).
    #[default]
    WhenSlow,
    /// At every attempt, at the predicted configuration: for a model whose `M(q)` changes fast
    /// and costs little against the failed steps a stale one causes (a decoder's reduced model:
    /// `r ≪ n` coordinates, `M = Jᵀ Ms J` with the decoder's Jacobian inside `J`).
    EveryAttempt,
}

/// The norm of the NDF's error test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ErrorNorm {
    /// `max_i |e_i| / max(|y_i|, |y⁽⁰⁾_i|, atol_i/rtol)` (`ode15s`): every component to its own
    /// relative tolerance.
    #[default]
    Componentwise,
    /// Mechanical systems in second-order form only: the errors of positions and of velocities
    /// each in the norm of the mass matrix, `‖e‖_M̂ = √(eᵀ M̂ e)` with `M̂ = M·n/tr M` (unit mean
    /// diagonal, so `‖e_i‖ ≈ |e_i|` for one coordinate), relative to the same norm of the
    /// state (`atol` as a floor): the mass-weighted displacement of the cross-sections, not
    /// each coordinate. A high-frequency mode that moves little mass (shear, elongation, a
    /// coordinate at the tip) does not force the step to resolve it; with an A-stable order
    /// (`max_order ≤ 2`) the method damps it instead. The NDF's Newton test stays componentwise:
    /// the damping holds only where the corrector equation is solved, and with a mass-norm Newton
    /// test an undamped rod falling under gravity gained 164 % of its largest kinetic energy
    /// (SDIRK4 and generalized-α measure their Newton corrections in their own ways, see
    /// `one_step::Parts::newton_weighted`).
    Mass,
}

impl Default for NdfOptions {
    fn default() -> Self {
        NdfOptions {
            rtol: 1e-3,
            atol: 1e-6,
            atol_components: None,
            max_order: 5,
            bdf: false,
            initial_step: None,
            max_step: f64::INFINITY,
            max_steps: 1_000_000,
            error_norm: ErrorNorm::Componentwise,
            mass_renewal: MassRenewal::WhenSlow,
        }
    }
}

/// Options of [`integrate_fixed`](super::integrate_fixed).
#[derive(Debug, Clone)]
pub struct FixedStepOptions {
    /// Nominal step (default `1e-3`).
    pub h: f64,
    /// Newton tolerance (default `1e-8`): the iteration stops when the estimated remaining error of
    /// the iterate, `ρ/(1−ρ)·‖Δ‖` with the contraction rate `ρ` (or `‖Δ‖` itself while no rate is
    /// known), is at most `newton_tol` in the norm `max_i |Δ_i| / max(1, |y_i|)` (absolute for
    /// components below 1, relative above).
    pub newton_tol: f64,
    /// Maximum Newton iterations per attempt (default 5, at least 1; with 1, an attempt is
    /// accepted only if its first correction already meets `newton_tol`).
    pub max_newton: usize,
    /// When the second-order form ([`integrate_fixed_second_order`](super::integrate_fixed_second_order))
    /// renews `M` in its iteration matrix (default [`MassRenewal::WhenSlow`]; the first-order
    /// form ignores it).
    pub mass_renewal: MassRenewal,
    /// Whether the dynamics driver ([`crate::solve::dynamics::simulate`]) runs a mechanical system
    /// in second-order form (default `true`, with the structured Jacobian). `false` keeps the
    /// first-order form with the approximate Jacobian `[0 I; −M⁻¹K −M⁻¹D]`. The driver keeps the
    /// first-order form for a nonlinear strain parameterization whatever this says
    /// ([`crate::solve::dynamics::fixed_step_in_second_order`]): for a decoder's reduced model,
    /// whose `M(q)` is nearly singular where the decoder flattens, the second-order Newton from
    /// the linear predictor jumped to a spurious far root (IV-C2's AE-7 from rest, h = 0.01 s:
    /// left its training region at t = 0.02 s), while the first-order form stays within 1.3 mm
    /// of the adaptive run's tip over 3 s of random steps.
    pub second_order: bool,
}

impl Default for FixedStepOptions {
    fn default() -> Self {
        FixedStepOptions {
            h: 1e-3,
            newton_tol: 1e-8,
            max_newton: 5,
            mass_renewal: MassRenewal::WhenSlow,
            second_order: true,
        }
    }
}

/// Work counters of one integration.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct OdeStats {
    /// Successful steps.
    pub steps: usize,
    /// Rejected attempts (error test failures and Newton failures).
    pub failed_steps: usize,
    /// Of `failed_steps`, those whose Newton iteration did not converge (too slow, singular
    /// iteration matrix or non-finite values); the rest failed the error test.
    pub newton_failures: usize,
    /// Right-hand side evaluations (including those for finite-difference Jacobians).
    pub rhs_evals: usize,
    /// Jacobian evaluations (analytic or by finite differences).
    pub jacobian_evals: usize,
    /// LU factorizations of the iteration matrix.
    pub lu_decompositions: usize,
    /// Newton iterations (linear solves).
    pub newton_iterations: usize,
}
