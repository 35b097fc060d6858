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
//! at most 4 iterations (8 with the mass-norm error test), with the iteration matrix LU-factored
//! once and reused for as long as `h`, `k` and `J` do not change (across steps). With
//! `ρ = ‖Δ_i‖/‖Δ_{i−1}‖` (in the componentwise norm below, whichever norm the error test uses: see
//! [`ErrorNorm::Mass`]) the iteration is accepted when
//! `ρ/(1−ρ)·‖Δ_i‖ ≤ rtol/2` (after one iteration using the previous rate: `≤ rtol/20`), and declared
//! too slow when `ρ > 0.9` or it cannot reach that within those iterations. Too slow: if `J` was not
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
//! restarted after every breakpoint, by one backward Euler step. See [`integrate_fixed`]; a
//! mechanical system runs it in second-order form with the NDF's corrector
//! ([`integrate_fixed_second_order`]: the same discrete solution, an `n × n` Newton iteration with
//! `M` renewed where it contracts slowly).
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

use nalgebra::{DMatrix, DVector};
use std::ops::ControlFlow;

mod corrector;
mod counted;
mod error;
mod fixed;
mod galpha;
mod lu;
mod ndf;
mod one_step;
mod options;
mod scaled_norm;
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

use counted::{Clamp, Counted, JacWork};
use error::{invalid, rhs_err};
use lu::Lu;

pub use error::{OdeError, OdeFailure, RhsError};
pub use fixed::{integrate_fixed, integrate_fixed_second_order};
pub use galpha::{integrate_generalized_alpha, GeneralizedAlphaOptions, MechanicalSystem};

/// The output callback of the integrators: called with every output time and the solution there;
/// `ControlFlow::Break(reason)` stops the integration with [`OdeError::Stopped`].
pub type Output<'a> = dyn FnMut(f64, &DVector<f64>) -> ControlFlow<String> + 'a;
pub use ndf::{integrate_ndf, integrate_ndf_second_order};
pub(super) use options::check_tolerances;
pub use options::{
    ErrorNorm, FixedStepOptions, MassRenewal, NdfOptions, OdeStats, MAX_RTOL, MIN_RTOL,
};
pub use sdirk::{integrate_sdirk, SdirkOptions};

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
