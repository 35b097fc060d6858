//! Stiff initial-value problem integrators for `y' = f(t, y)`: a variable-step, variable-order
//! NDF/BDF method of the class of MATLAB's `ode15s` ([`integrate_ndf`]; for mechanical systems
//! `M(q) q̈ = τ` the same method with an `n × n` Newton iteration on the residual `M q̈ − τ`,
//! [`integrate_ndf_second_order`], see `corrector`), a cheap fixed-step BDF2 method for real-time
//! use ([`integrate_fixed`]), adaptive generalized-α ([`integrate_generalized_alpha`]) and an
//! adaptive L-stable SDIRK of order 4 in second-order form ([`integrate_sdirk`]).
//!
//! Reference: L. F. Shampine and M. W. Reichelt, *The MATLAB ODE Suite*, SIAM J. Sci. Comput. 18(1),
//! 1–22, 1997 (§2: the NDFs, their quasi-constant step size implementation and the step/order
//! strategy of `ode15s`).
//!
//! # The NDF method ([`integrate_ndf`])
//!
//! **Formula.** With `∇` the backward difference at the current constant step `h`, the NDF of order
//! `k` (Klopfenstein–Shampine numerical differentiation formula) is
//!
//! ```text
//!   Σ_{m=1..k} (1/m) ∇^m y_{n+1} − h f(t_{n+1}, y_{n+1}) − κ_k γ_k (y_{n+1} − y⁽⁰⁾_{n+1}) = 0,
//!   γ_k = Σ_{j=1..k} 1/j,      predictor  y⁽⁰⁾_{n+1} = Σ_{m=0..k} ∇^m y_n,
//! ```
//!
//! with `κ = (−37/200, −1/9, −0.0823, −0.0415, 0)` for `k = 1..5` (`κ = 0` gives the BDFs:
//! [`NdfOptions::bdf`]). Writing `d = y_{n+1} − y⁽⁰⁾_{n+1}` (which equals `∇^{k+1} y_{n+1}`), the
//! corrector is
//!
//! ```text
//!   d − h/((1−κ_k)γ_k) · f(t_{n+1}, y⁽⁰⁾ + d) + ψ = 0,    ψ = 1/((1−κ_k)γ_k) · Σ_{m=1..k} γ_m ∇^m y_n,
//! ```
//!
//! solved by simplified Newton, `(I − h/((1−κ_k)γ_k) J) Δ = h/((1−κ_k)γ_k) f(t_{n+1}, y⁽ⁱ⁾) − ψ − d⁽ⁱ⁾`,
//! at most 4 iterations, with the iteration matrix LU-factored once and reused for as long as `h`,
//! `k` and `J` do not change (across steps). With `ρ = ‖Δ_i‖/‖Δ_{i−1}‖` the iteration is accepted when
//! `ρ/(1−ρ)·‖Δ_i‖ ≤ rtol/2` (after one iteration using the previous rate: `≤ rtol/20`), and declared
//! too slow when `ρ > 0.9` or it cannot reach that within 4 iterations. Too slow: if `J` was not
//! evaluated at the current point `(t_n, y_n)` it is re-evaluated there, else `h ← 0.3 h`. The
//! Jacobian is thus only recomputed at the start (and after each breakpoint) and when Newton
//! converges slowly, as in `ode15s`.
//!
//! **Error estimate and norm.** The local error is estimated as `C_k ∇^{k+1} y_{n+1} = C_k d` with
//! the error constant `C_k = κ_k γ_k + 1/(k+1)`. It is measured in the **maximum norm** with the
//! weights of `ode15s`: `err = C_k · max_i |d_i| / max(|y_{n,i}|, |y⁽⁰⁾_{n+1,i}|, atol_i/rtol)` and a step
//! is accepted iff `err ≤ rtol`, i.e. iff `C_k |d_i| ≤ max(rtol·max(|y_{n,i}|, |y⁽⁰⁾_{n+1,i}|), atol_i)`
//! for every component (a max of the relative and absolute parts, not their sum).
//!
//! **Step size and order.** After a rejected step: `h ← h·max(0.1, 0.833 (rtol/err)^{1/(k+1)})`, and
//! on a first failure at `k > 1` the order drops to `k−1` if `err_{k−1} = C_{k−1}‖∇^k y_{n+1}‖`
//! allows a larger step (`h·max(0.1, 0.769 (rtol/err_{k−1})^{1/k})`, never larger than `h`); a repeated
//! failure halves `h`. After `k+2` successful steps at constant `h` and `k`, the step ratios
//! `1/(1.2 (err_k/rtol)^{1/(k+1)})`, `1/(1.3 (err_{k−1}/rtol)^{1/k})` and
//! `1/(1.4 (err_{k+1}/rtol)^{1/(k+2)})` (`err_{k+1} = C_{k+1}‖∇^{k+2} y_{n+1}‖`, each ratio at most 10) are
//! compared; the largest picks the new order, and `h` changes only if that ratio exceeds 1. The
//! step is stretched by up to 10 % to land on the end of the interval (or a breakpoint).
//!
//! **Changing h.** The differences are re-expressed for the new step `h' = r h` by
//! `[∇y]' = [∇y]·(R U)` with `R_ij = Π_{m=1..i} (m − 1 − j r)/m`, `U_ij = (−1)^i binom(j, i)`
//! (`i, j = 1..k`).
//!
//! **Dense output.** Between `t_n` and `t_{n+1}` the interpolating polynomial of the step is used:
//! `y(t_{n+1} + s h) ≈ y_{n+1} + Σ_{j=1..k} ∇^j y_{n+1} · Π_{i=1..j} (s + i − 1)/i`, `s ∈ [−1, 0]`.
//!
//! **Initial step** (as `ode15s`): `h = min(h_max, span, 1/r)`, first with
//! `r = 1.25 ‖y'/w‖_∞/√rtol` and then, for the error `½h² y''` of the first (order-1) step, with
//! `r = 1.25 √(½‖(∂f/∂t + J y')/w‖_∞ / rtol)`, `w = max(|y|, atol/rtol)`. The minimum step is
//! `16 ulp(t)`.
//!
//! # Breakpoints
//!
//! The interval is split at the breakpoints; each piece is integrated separately, stepping exactly
//! onto its end, and the next piece restarts at order 1 with a new initial step and a new Jacobian.
//! On the piece `[a, b]` the right-hand side is only evaluated at times strictly inside the piece
//! where `a`, `b` are breakpoints: a call for `t = b` is made at the largest float below `b`, and
//! for `t = a` at the smallest float above `a`. A piecewise-constant input that switches at `b`
//! (either left- or right-continuous, e.g. a zero-order hold `u(t) = u_k` for `t ∈ [t_k, t_{k+1})`)
//! is thus seen as constant on each piece.
//!
//! # The fixed-step method ([`integrate_fixed`])
//!
//! The two-step BDF with variable-coefficient form for the steps that are not of the nominal length
//! (`ω = h_n/h_{n−1}`),
//! `y_{n+1} − (1+ω)²/(1+2ω) y_n + ω²/(1+2ω) y_{n−1} = h_n (1+ω)/(1+2ω) f(t_{n+1}, y_{n+1})`
//! (`4/3, 1/3, 2/3` at `ω = 1`): second order, A- and L-stable (stiff components are damped, not
//! left ringing as with the trapezoidal rule), one implicit solve per step. It is started, and
//! restarted after every breakpoint, by one backward Euler step. See [`integrate_fixed`].
//!
//! # Failures
//!
//! A NaN or infinity from `f` (or in a Newton iterate) during a step is treated as a failed attempt
//! and the step is retried shorter (`0.3 h`); [`OdeError::NonFinite`] is returned only when that
//! is no longer possible (minimum step), so a solution that blows up or leaves the domain of `f`
//! stops with the time it reached, never silently. An [`RhsError`] stops the integration at once.
//! In every case the outputs before the time reached have been delivered.
//!
//! # Allocation
//!
//! All buffers (state vectors, difference table, Jacobian, LU factors) are allocated once per call;
//! the stepping loop does not allocate (the user's right-hand side and output callback may).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor as lu_factor, solve as lu_solve};
use faer::perm::PermRef;
use faer::{MatMut, MatRef, Par};
use nalgebra::{DMatrix, DVector};
use std::ops::ControlFlow;

mod corrector;
mod fixed;
mod galpha;
mod mass_norm;
mod ndf;
mod one_step;
mod sdirk;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_errors;
#[cfg(test)]
mod tests_fixed;
#[cfg(test)]
mod tests_galpha;
#[cfg(test)]
mod tests_limits;
#[cfg(test)]
mod tests_ndf_second_order;
#[cfg(test)]
mod tests_sdirk;

pub use fixed::integrate_fixed;
pub use galpha::{integrate_generalized_alpha, GeneralizedAlphaOptions, MechanicalSystem};

/// The output callback of the integrators: called with every output time and the solution there;
/// `ControlFlow::Break(reason)` stops the integration with [`OdeError::Stopped`].
pub type Output<'a> = dyn FnMut(f64, &DVector<f64>) -> ControlFlow<String> + 'a;
pub use ndf::{integrate_ndf, integrate_ndf_second_order};
pub use sdirk::{integrate_sdirk, SdirkOptions};

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
pub(super) fn check_tolerances(
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

/// An error reported by the right-hand side (or its Jacobian); it stops the integration.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
#[error("{0}")]
pub struct RhsError(pub String);

/// `y' = f(t, y)`, with an optional analytic Jacobian `∂f/∂y`.
pub trait OdeSystem {
    /// Dimension of `y`.
    fn dim(&self) -> usize;
    /// Writes `f(t, y)` into `dy` (of length [`OdeSystem::dim`]).
    fn rhs(&mut self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) -> Result<(), RhsError>;
    /// Writes `∂f/∂y` into `jac` (`dim × dim`); returns `Ok(false)` if not provided, in which case
    /// forward differences are used (column `j` with the increment
    /// `δ_j = √eps · max(|y_j|, atol_j/rtol)`). Called once per Jacobian evaluation; after an
    /// `Ok(false)` it is not called again during that integration.
    fn jacobian(
        &mut self,
        _t: f64,
        _y: &DVector<f64>,
        _jac: &mut DMatrix<f64>,
    ) -> Result<bool, RhsError> {
        Ok(false)
    }
    /// Polled before every step attempt (an atomic load's worth of work, e.g. an interrupt flag
    /// set by SIGINT/SIGTERM): `Some(reason)` stops the integration at once with
    /// [`OdeError::Stopped`] at the last accepted time, without waiting for the next output time,
    /// which tight tolerances can put out of reach. Default: never.
    fn stop_requested(&mut self) -> Option<String> {
        None
    }
}

/// Options of [`integrate_ndf`].
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
    /// How local errors (and Newton corrections) are measured (default componentwise, as
    /// `ode15s`).
    pub error_norm: ErrorNorm,
    /// When the second-order form renews the mass matrix of its iteration matrix (default
    /// [`MassRenewal::WhenSlow`]; the first-order form ignores it).
    pub mass_renewal: MassRenewal,
}

/// When [`integrate_ndf_second_order`] renews `M` in its iteration matrix `M + c D + c² K`
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
    /// (`max_order ≤ 2`) the method damps it instead.
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

/// Options of [`integrate_fixed`].
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
}

impl Default for FixedStepOptions {
    fn default() -> Self {
        FixedStepOptions {
            h: 1e-3,
            newton_tol: 1e-8,
            max_newton: 5,
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

/// Why an integration stopped. Except for [`OdeError::Invalid`], every output time before
/// [`OdeError::t_reached`] has been delivered.
#[derive(Debug, Clone, thiserror::Error)]
pub enum OdeError {
    /// The error test (or Newton, for the one-step methods) failed at the smallest step the time
    /// resolution allows; the tolerances in use are named, since too tight ones are a cause.
    #[error("integration stopped at t = {t}: step size {h:e} below the minimum {h_min:e} with rtol = {rtol:e}, atol = {atol:e} (tolerances too tight for the problem, or a singularity)")]
    StepSizeUnderflow {
        t: f64,
        h: f64,
        h_min: f64,
        rtol: f64,
        /// The absolute tolerance (the smallest, for per-component tolerances).
        atol: f64,
    },
    /// Newton failed at the smallest step (the adaptive methods: its test asks for a fraction of
    /// `rtol`, so too tight tolerances are a cause, and `tolerances` names them) or after its
    /// retries (the fixed step: `tolerances` is `None`).
    #[error(
        "integration stopped at t = {t}: Newton iteration failed to converge repeatedly{}",
        tolerances.map_or(String::new(), |(rtol, atol)| format!(
            " with rtol = {rtol:e}, atol = {atol:e} (tolerances too tight for the problem, or a singularity)"
        ))
    )]
    NewtonFailure {
        t: f64,
        /// `(rtol, atol)` of an adaptive method (the smallest `atol` for per-component ones).
        tolerances: Option<(f64, f64)>,
    },
    #[error(
        "integration stopped at t = {t}: non-finite value (NaN or infinity) in the solution or the right-hand side"
    )]
    NonFinite { t: f64 },
    #[error("integration stopped at t = {t}: right-hand side failed: {source}")]
    Rhs { t: f64, source: RhsError },
    #[error("integration stopped at t = {t}: maximum number of steps {max_steps} reached")]
    TooManySteps { t: f64, max_steps: usize },
    /// The output callback asked to stop after delivering the sample at `t` (an interrupt, a full
    /// disk), or the system did ([`OdeSystem::stop_requested`]) after the step that reached `t`:
    /// not a failure of the method.
    #[error("integration stopped at t = {t}: {reason}")]
    Stopped { t: f64, reason: String },
    #[error("invalid input `{field}`: {message}")]
    Invalid {
        field: &'static str,
        message: String,
    },
}

/// An integration that stopped before its last output time: why, and the work done until then.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{error}")]
pub struct OdeFailure {
    pub error: OdeError,
    /// The counts up to the failure (zero for errors found before the first step: invalid input).
    pub stats: OdeStats,
}

impl OdeFailure {
    /// The outcome of an integration whose work is counted in `stats`.
    pub(super) fn with(
        result: Result<(), OdeError>,
        stats: &OdeStats,
    ) -> Result<OdeStats, OdeFailure> {
        match result {
            Ok(()) => Ok(stats.clone()),
            Err(error) => Err(OdeFailure {
                error,
                stats: stats.clone(),
            }),
        }
    }
}

/// An error found before any step (invalid input, the first output): nothing counted yet.
impl From<OdeError> for OdeFailure {
    fn from(error: OdeError) -> Self {
        OdeFailure {
            error,
            stats: OdeStats::default(),
        }
    }
}

impl OdeError {
    /// The last time the solution reached (the last accepted step), `None` for invalid input.
    pub fn t_reached(&self) -> Option<f64> {
        match self {
            OdeError::StepSizeUnderflow { t, .. }
            | OdeError::NewtonFailure { t, .. }
            | OdeError::NonFinite { t }
            | OdeError::Rhs { t, .. }
            | OdeError::TooManySteps { t, .. }
            | OdeError::Stopped { t, .. } => Some(*t),
            OdeError::Invalid { .. } => None,
        }
    }
}

/// Maps a right-hand-side error to the integration error at the last accepted time `t`.
fn rhs_err(t: f64) -> impl Fn(RhsError) -> OdeError {
    move |source| OdeError::Rhs { t, source }
}

fn invalid(field: &'static str, message: impl Into<String>) -> OdeError {
    OdeError::Invalid {
        field,
        message: message.into(),
    }
}

/// The state `y = [q; q̇]` of a mechanical system with `n` coordinates (lengths checked).
fn mechanical_state(
    n: usize,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
) -> Result<DVector<f64>, OdeError> {
    if q0.len() != n || qd0.len() != n {
        return Err(invalid(
            "y0",
            format!(
                "q0 and q̇0 have {} and {} entries, the system has {n} coordinates",
                q0.len(),
                qd0.len()
            ),
        ));
    }
    let mut y0 = DVector::zeros(2 * n);
    y0.rows_mut(0, n).copy_from(q0);
    y0.rows_mut(n, n).copy_from(qd0);
    Ok(y0)
}

/// Smallest float above `x` (for finite `x`; `f64::next_up` needs Rust 1.86).
fn next_up(x: f64) -> f64 {
    if !x.is_finite() {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let b = x.to_bits();
    f64::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

/// Largest float below `x` (for finite `x`).
fn next_down(x: f64) -> f64 {
    -next_up(-x)
}

/// Spacing of the floats at `x` (`eps(x)` of MATLAB).
fn ulp(x: f64) -> f64 {
    let a = x.abs();
    next_up(a) - a
}

/// Checks the arguments shared by both integrators; returns the piece boundaries
/// `[t0, b_1, …, b_m, tf]` (breakpoints outside `(t0, tf)` dropped, duplicates and breakpoints within
/// 64 ulp of a neighbour merged).
fn check_common(
    dim: usize,
    t0: f64,
    y0: &DVector<f64>,
    t_out: &[f64],
    breakpoints: &[f64],
) -> Result<Vec<f64>, OdeError> {
    if dim == 0 {
        return Err(invalid("system", "the system has dimension 0"));
    }
    if y0.len() != dim {
        return Err(invalid(
            "y0",
            format!("{} entries, the system has dimension {dim}", y0.len()),
        ));
    }
    if !t0.is_finite() {
        return Err(invalid("t0", format!("must be finite, got {t0}")));
    }
    if let Some(i) = y0.iter().position(|v| !v.is_finite()) {
        return Err(invalid(
            "y0",
            format!("entry {i} is not finite ({})", y0[i]),
        ));
    }
    let Some(&tf) = t_out.last() else {
        return Err(invalid("t_out", "at least one output time is required"));
    };
    for (i, &t) in t_out.iter().enumerate() {
        if !t.is_finite() {
            return Err(invalid("t_out", format!("entry {i} is not finite ({t})")));
        }
        if t < t0 {
            return Err(invalid(
                "t_out",
                format!("entry {i} = {t} is before t0 = {t0}"),
            ));
        }
        if i > 0 && t <= t_out[i - 1] {
            return Err(invalid(
                "t_out",
                format!(
                    "not strictly ascending at entry {i} ({} then {t})",
                    t_out[i - 1]
                ),
            ));
        }
    }
    let mut bounds = vec![t0];
    for (i, &b) in breakpoints.iter().enumerate() {
        if !b.is_finite() {
            return Err(invalid(
                "breakpoints",
                format!("entry {i} is not finite ({b})"),
            ));
        }
        if i > 0 && b < breakpoints[i - 1] {
            return Err(invalid(
                "breakpoints",
                format!(
                    "not ascending at entry {i} ({} then {b})",
                    breakpoints[i - 1]
                ),
            ));
        }
        let last = *bounds.last().unwrap_or(&t0);
        let gap = 64.0 * ulp(b.abs().max(last.abs()).max(tf.abs()));
        if b > last + gap && b < tf - gap {
            bounds.push(b);
        }
    }
    if tf > t0 {
        bounds.push(tf);
    }
    Ok(bounds)
}

/// The system with evaluation counters, finiteness checks and the time convention of a piece.
struct Counted<'a, S: OdeSystem> {
    sys: &'a mut S,
    stats: OdeStats,
    /// `None` until the first Jacobian request; then whether `sys.jacobian` provides it.
    analytic: Option<bool>,
    /// Evaluation times of the current piece.
    clamp: Clamp,
}

/// Evaluation times are clamped to `[lo, hi]`: the open piece when its ends are breakpoints.
#[derive(Debug, Clone, Copy)]
struct Clamp {
    lo: f64,
    hi: f64,
}

impl Default for Clamp {
    fn default() -> Self {
        Clamp {
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
        }
    }
}

impl Clamp {
    /// The piece `[a, b]`: evaluation times are kept strictly inside where an end is a breakpoint.
    fn piece(a: f64, a_is_break: bool, b: f64, b_is_break: bool) -> Self {
        Clamp {
            lo: if a_is_break {
                next_up(a)
            } else {
                f64::NEG_INFINITY
            },
            hi: if b_is_break {
                next_down(b)
            } else {
                f64::INFINITY
            },
        }
    }

    fn apply(&self, t: f64) -> f64 {
        t.max(self.lo).min(self.hi)
    }
}

impl<'a, S: OdeSystem> Counted<'a, S> {
    fn new(sys: &'a mut S) -> Self {
        Counted {
            sys,
            stats: OdeStats::default(),
            analytic: None,
            clamp: Clamp::default(),
        }
    }

    fn clamp(&self, t: f64) -> f64 {
        self.clamp.apply(t)
    }

    /// `dy = f(t, y)`; `Ok(false)` if `dy` is not finite. `t_acc` is the last accepted time (for errors).
    fn f(
        &mut self,
        t_acc: f64,
        t: f64,
        y: &DVector<f64>,
        dy: &mut DVector<f64>,
    ) -> Result<bool, OdeError> {
        self.stats.rhs_evals += 1;
        let te = self.clamp(t);
        let n = y.len();
        self.sys
            .rhs(te, y, dy)
            .map_err(|source| OdeError::Rhs { t: t_acc, source })?;
        if dy.len() != n {
            let message = format!(
                "the right-hand side has {} entries, the system has dimension {n}",
                dy.len()
            );
            return Err(OdeError::Rhs {
                t: t_acc,
                source: RhsError(message),
            });
        }
        Ok(dy.iter().all(|v| v.is_finite()))
    }

    /// `jac = ∂f/∂y (t, y)`, analytic or by forward differences (`thresh_j = atol_j/rtol`);
    /// `Ok(false)` if the result (or `f(t, y)`) is not finite.
    fn jacobian(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        thresh: &DVector<f64>,
        jac: &mut DMatrix<f64>,
        jw: &mut JacWork,
    ) -> Result<bool, OdeError> {
        self.stats.jacobian_evals += 1;
        let te = self.clamp(t);
        if self.analytic != Some(false) {
            let given = self
                .sys
                .jacobian(te, y, jac)
                .map_err(|source| OdeError::Rhs { t, source })?;
            self.analytic = Some(given);
            if given && jac.shape() != (y.len(), y.len()) {
                let message = format!(
                    "the Jacobian is {:?}, the system has dimension {}",
                    jac.shape(),
                    y.len()
                );
                return Err(OdeError::Rhs {
                    t,
                    source: RhsError(message),
                });
            }
            if given {
                return Ok(jac.iter().all(|v| v.is_finite()));
            }
        }
        if jac.shape() != (y.len(), y.len()) {
            *jac = DMatrix::zeros(y.len(), y.len()); // only if `jacobian` resized it and declined
        }
        if !self.f(t, t, y, &mut jw.f0)? {
            return Ok(false);
        }
        let sqrt_eps = f64::EPSILON.sqrt();
        jw.ydel.copy_from(y);
        for j in 0..y.len() {
            let yj = y[j];
            let mut del = sqrt_eps * yj.abs().max(thresh[j]);
            if del == 0.0 || !del.is_finite() {
                del = sqrt_eps;
            }
            if yj < 0.0 {
                del = -del;
            }
            jw.ydel[j] = yj + del;
            let del = jw.ydel[j] - yj; // the increment actually representable
            let ok = self.f(t, t, &jw.ydel, &mut jw.fdel)?;
            jw.ydel[j] = yj;
            if !ok {
                return Ok(false);
            }
            let inv = 1.0 / del;
            for i in 0..y.len() {
                jac[(i, j)] = (jw.fdel[i] - jw.f0[i]) * inv;
            }
        }
        Ok(jac.iter().all(|v| v.is_finite()))
    }
}

/// Buffers of the finite-difference Jacobian.
struct JacWork {
    f0: DVector<f64>,
    ydel: DVector<f64>,
    fdel: DVector<f64>,
}

impl JacWork {
    fn new(n: usize) -> Self {
        JacWork {
            f0: DVector::zeros(n),
            ydel: DVector::zeros(n),
            fdel: DVector::zeros(n),
        }
    }
}

/// LU factorization with partial pivoting (faer, blocked) of an iteration matrix, in place
/// (allocation-free after construction).
struct Lu {
    a: DMatrix<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
}

impl Lu {
    fn new(n: usize) -> Self {
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
    fn factor(&mut self, c: f64, jac: &DMatrix<f64>, stats: &mut OdeStats) -> bool {
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
    fn factor_with(&mut self, stats: &mut OdeStats, fill: impl FnOnce(&mut DMatrix<f64>)) -> bool {
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
    fn solve(&mut self, b: &mut DVector<f64>) {
        let n = self.perm.len();
        let lu = MatRef::from_column_major_slice(self.a.as_slice(), n, n);
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
        let rhs = MatMut::from_column_major_slice_mut(b.as_mut_slice(), n, 1);
        lu_solve::solve_in_place(lu, lu, perm, rhs, Par::Seq, MemStack::new(&mut self.mem));
        crate::cpu::clear_upper_state();
    }
}

/// `max_i |v_i w_i|`, NaN if any term is NaN.
fn wnorm(v: &DVector<f64>, w: &DVector<f64>) -> f64 {
    let mut m = 0.0f64;
    for (a, b) in v.iter().zip(w.iter()) {
        let x = (a * b).abs();
        if x.is_nan() {
            return f64::NAN;
        }
        if x > m {
            m = x;
        }
    }
    m
}

/// Delivers the outputs `t_out[*next..]` that are `≤ t_new`, computing each with `value`.
fn deliver(
    t_out: &[f64],
    next: &mut usize,
    t_new: f64,
    buf: &mut DVector<f64>,
    output: &mut Output<'_>,
    mut value: impl FnMut(f64, &mut DVector<f64>),
) -> Result<(), OdeError> {
    while *next < t_out.len() && t_out[*next] <= t_new {
        let t = t_out[*next];
        value(t, buf);
        *next += 1;
        if let ControlFlow::Break(reason) = output(t, buf) {
            return Err(OdeError::Stopped { t, reason });
        }
    }
    Ok(())
}
