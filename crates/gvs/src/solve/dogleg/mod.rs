//! Powell's trust-region **dogleg** method for square nonlinear systems `F(x) = 0`.
//!
//! This is the Rust counterpart of MATLAB `fsolve`'s default `'trust-region-dogleg'`
//! algorithm and of MINPACK's `hybrj`: a Gauss–Newton model `F(x + p) ≈ F + J p` is
//! minimised inside a scaled trust region `‖D p‖₂ ≤ Δ`, with the analytic Jacobian from
//! [`NonlinearSystem::jacobian`] refreshed only when needed and Broyden rank-1 updates
//! in between.
//!
//! # One iteration
//! * **Scaling.** `D = diag(d_j)`, `d_j = max(d_j, ‖J_{:,j}‖₂)` at every analytic Jacobian
//!   evaluation (initially `‖J_{:,j}‖₂`, or 1 for a zero column), as in MINPACK. The first
//!   radius is `Δ₀ = factor·‖D x₀‖₂` (or `factor` if that is 0), cut to `‖D p₀‖₂` after
//!   the first step.
//! * **Dogleg step.** Gauss–Newton step `p_GN = −J⁻¹F` by an LU factorization with partial
//!   pivoting (blocked, faer), computed once per analytic Jacobian (and again only when `J`
//!   changed). After Broyden updates `J_k = J₀ + Σ u_i v_iᵀ` the LU of `J₀` is kept and the
//!   updates are applied by Sherman–Morrison, `J_{k+1}⁻¹ = (I − w_k v_kᵀ/σ_k) J_k⁻¹` with
//!   `w_k = J_k⁻¹u_k`, `σ_k = 1 + v_kᵀw_k` (O(n²) per update instead of O(n³)); `J_k` is
//!   refactored instead after [`MAX_SM_UPDATES`] updates or when `|σ_k| < `[`SM_MIN_SIGMA`]
//!   (the update nearly singular). Scaled gradient direction `s = D⁻² JᵀF` (so `‖D s‖₂ = ‖D⁻¹JᵀF‖₂ = g`),
//!   Cauchy point `p_C = −α s` with `α = g² / ‖J s‖₂²`. Then
//!   - `p = p_GN` if `‖D p_GN‖₂ ≤ Δ`;
//!   - `p = −(Δ/g) s` if `α g ≥ Δ` (steepest descent cut at the boundary);
//!   - otherwise `p = p_C + τ (p_GN − p_C)` with `τ ∈ [0, 1]` solving `‖D p‖₂ = Δ`.
//!
//!   If the LU is singular (a pivot at most `n ε max|J|`) or `p_GN` is not finite, only
//!   the steepest-descent leg is used (`p = −min(α, Δ/g) s`) instead of failing.
//! * **Ratio.** `ρ = actred / prered` with `actred = 1 − (‖F(x+p)‖₂/‖F‖₂)²` (−1 if the
//!   residual grew) and `prered = 1 − (‖F + J p‖₂/‖F‖₂)²`. The step is accepted when
//!   `ρ ≥ 10⁻⁴`. Radius (MINPACK `hybrj`): `ρ < 0.1` → `Δ = ½Δ`; otherwise, after a
//!   good (`ρ ≥ ½`) or second consecutive successful step `Δ = max(Δ, 2‖Dp‖)`, and
//!   `Δ = 2‖Dp‖` when `|ρ − 1| ≤ 0.1`. Without Broyden updates a rejection leaves the
//!   model unchanged, so there the shrink is `Δ = ½ min(Δ, ‖Dp‖)` (no step is retried).
//! * **Broyden update** (when [`DoglegOptions::broyden`]), after every trial step,
//!   accepted or not, with `y = F(x+p) − F(x)`:
//!   `J ← J + (y − J p)(D² p)ᵀ / ‖D p‖₂²` (the scaled "good" Broyden update of MINPACK;
//!   it satisfies the secant condition `J₊ p = y`). The analytic Jacobian is evaluated at
//!   the start, after two consecutive steps with `ρ < 0.1`, after three consecutive
//!   steps with `actred < 10⁻³` (hybrj's `ncfail` / `nslow1`), when the radius collapses,
//!   and when an updated Jacobian yields a step below `xtol` (that step is then neither
//!   evaluated nor allowed to shrink `Δ`). Without Broyden, it is evaluated at every
//!   newly accepted point.
//!
//! # Stopping rule
//! * `‖F(x)‖∞ ≤ ftol · residual_scale(x)` → `Ok` (also at `x₀`, with no iteration).
//! * With an analytic (not updated) Jacobian: a trial step `‖p‖∞ ≤ xtol (1 + ‖x‖∞)` that
//!   does not meet the residual test, a radius `Δ ≤ ε‖D x‖₂`, or no usable descent
//!   direction (singular Jacobian and zero gradient of `‖F‖²`); or `max_iterations` trial
//!   steps / `max_evaluations` residual evaluations → [`DoglegError::NotConverged`] naming
//!   the reason. An iteration is one trial step (accepted or not).
//! * Any NaN or infinity in `x₀`, `F` or the analytic `J` → [`DoglegError::NonFinite`]
//!   (a Broyden update that overflows is discarded for a fresh Jacobian); evaluation
//!   failures → [`DoglegError::Evaluation`]. The solver never panics on its inputs.
//!
//! All vectors and matrices live in a [`DoglegWorkspace`]; the iteration allocates
//! nothing (only the returned `x` is cloned).
//!
//! The LU kept across Broyden updates and the overflow-safe norms are in the submodule `linalg`.

pub(crate) mod linalg;

use crate::model::zeros_lazy;
use linalg::{all_finite, column_norm, norm2, scaled_norm, Lu};
use nalgebra::{DMatrix, DVector};

pub use linalg::{MAX_SM_UPDATES, SM_MIN_SIGMA};

/// A square nonlinear system F(x) = 0 with an analytic Jacobian.
pub trait NonlinearSystem {
    /// Number of unknowns (= number of equations).
    fn dim(&self) -> usize;
    /// Residual F(x) written into `f` (len dim). Must return Err if the residual cannot be evaluated.
    fn residual(&mut self, x: &DVector<f64>, f: &mut DVector<f64>) -> Result<(), EvalError>;
    /// Jacobian dF/dx at x written into `jac` (dim × dim). `f` is F(x), already computed, passed for reuse.
    fn jacobian(
        &mut self,
        x: &DVector<f64>,
        f: &DVector<f64>,
        jac: &mut DMatrix<f64>,
    ) -> Result<(), EvalError>;
    /// Absolute scale for the residual test: converged when ‖F(x)‖∞ ≤ opts.ftol · residual_scale(x). Default 1.
    fn residual_scale(&self, _x: &DVector<f64>) -> f64 {
        1.0
    }
}

/// Failure reported by a residual or Jacobian evaluation.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
#[error("{0}")]
pub struct EvalError(pub String);

/// Solver settings (defaults follow `fsolve` / MINPACK).
#[derive(Debug, Clone)]
pub struct DoglegOptions {
    /// Maximum number of trial steps (default 400, fsolve `MaxIterations`).
    pub max_iterations: usize,
    /// Maximum number of residual evaluations, the one at `x₀` included (default 10 000).
    pub max_evaluations: usize,
    /// Residual tolerance, relative to [`NonlinearSystem::residual_scale`] (default 1e-10).
    pub ftol: f64,
    /// Step tolerance: give up when `‖Δx‖∞ ≤ xtol (1 + ‖x‖∞)` (default 1e-12).
    pub xtol: f64,
    /// Initial radius factor, MINPACK `factor` (default 100).
    pub initial_radius_factor: f64,
    /// Broyden rank-1 updates between Jacobian evaluations (default true).
    pub broyden: bool,
}

impl Default for DoglegOptions {
    fn default() -> Self {
        Self {
            max_iterations: 400,
            max_evaluations: 10_000,
            ftol: 1e-10,
            xtol: 1e-12,
            initial_radius_factor: 100.0,
            broyden: true,
        }
    }
}

/// Result of a converged solve.
#[derive(Debug, Clone)]
pub struct DoglegReport {
    pub x: DVector<f64>,
    pub iterations: usize,
    pub residual_evaluations: usize,
    pub jacobian_evaluations: usize,
    /// ‖F(x)‖∞ at return.
    pub residual_norm: f64,
}

/// Why a solve failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum DoglegError {
    #[error(
        "dogleg did not converge after {iterations} iterations: ‖F‖∞ = {residual_norm:.3e} (tolerance {tolerance:.3e}); {reason}"
    )]
    NotConverged {
        iterations: usize,
        residual_norm: f64,
        tolerance: f64,
        reason: String,
        x: DVector<f64>,
    },
    #[error("residual or Jacobian evaluation failed at iteration {iterations}: {source}")]
    Evaluation {
        iterations: usize,
        source: EvalError,
    },
    #[error("non-finite value (NaN or infinity) in the {what} at iteration {iterations}")]
    NonFinite {
        iterations: usize,
        what: &'static str,
    },
    #[error("dimension mismatch: x0 has {got} entries, the system has {expected}")]
    Dimension { expected: usize, got: usize },
}

/// Reusable scratch buffers so repeated solves (load ramps, dataset generation) do not allocate.
pub struct DoglegWorkspace {
    x: DVector<f64>,
    x_new: DVector<f64>,
    f: DVector<f64>,
    f_new: DVector<f64>,
    /// Current Jacobian: analytic, or Broyden-updated since the last evaluation.
    jac: DMatrix<f64>,
    /// The LU factorization of `jac` (or of the Jacobian before its last Broyden updates).
    lu: Lu,
    /// MINPACK scaling `D`.
    diag: DVector<f64>,
    p: DVector<f64>,
    p_gn: DVector<f64>,
    grad: DVector<f64>,
    tmp: DVector<f64>,
}

impl DoglegWorkspace {
    /// The Jacobian at the end of the last solve: analytic, or Broyden-updated since its last
    /// evaluation (an approximation at the solution).
    pub fn jacobian(&self) -> &DMatrix<f64> {
        &self.jac
    }

    /// Buffers for systems of `n` unknowns.
    pub fn new(n: usize) -> Self {
        let (v, m) = (|| DVector::zeros(n), || zeros_lazy(n, n));
        let (x, x_new, f, f_new, diag, p, p_gn, grad, tmp) =
            (v(), v(), v(), v(), v(), v(), v(), v(), v());
        Self {
            x,
            x_new,
            f,
            f_new,
            jac: m(),
            lu: Lu::new(n),
            diag,
            p,
            p_gn,
            grad,
            tmp,
        }
    }

    /// Whether every buffer (those handed to the system included) has size `n`.
    fn fits(&self, n: usize) -> bool {
        let vecs = [&self.x, &self.x_new, &self.f, &self.f_new, &self.p];
        vecs.iter().all(|v| v.len() == n) && self.jac.shape() == (n, n) && self.lu.perm.len() == n
    }

    /// Dogleg step for the radius `delta` into `self.p` (see the module docs); false when
    /// the Jacobian is singular and the gradient of ‖F‖² vanishes.
    fn dogleg(&mut self, delta: f64) -> bool {
        let n = self.x.len();
        let mut gn_ok = match self.lu.state {
            Some(ok) => ok,
            None => self.lu.factor(&self.jac),
        };
        let mut gn_norm = f64::INFINITY;
        if gn_ok {
            self.p_gn.copy_from(&self.f);
            self.p_gn.neg_mut();
            self.lu.solve(&mut self.p_gn);
            gn_norm = scaled_norm(&self.diag, &self.p_gn);
            gn_ok = gn_norm.is_finite();
            if gn_ok && gn_norm <= delta {
                self.p.copy_from(&self.p_gn);
                return true;
            }
        }
        // s = D⁻² JᵀF: the descent direction is −s, of scaled length g = ‖D s‖ = ‖D⁻¹JᵀF‖.
        self.grad.gemv_tr(1.0, &self.jac, &self.f, 0.0);
        self.grad.component_div_assign(&self.diag);
        self.grad.component_div_assign(&self.diag);
        let g = scaled_norm(&self.diag, &self.grad);
        if g == 0.0 || !g.is_finite() {
            if gn_ok {
                self.p.copy_from(&self.p_gn);
                self.p *= delta / gn_norm;
            }
            return gn_ok;
        }
        self.tmp.gemv(1.0, &self.jac, &self.grad, 0.0);
        let alpha = (g / norm2(self.tmp.iter().copied())).powi(2); // +∞ when J s = 0
        let to_boundary = alpha * g >= delta;
        self.p.copy_from(&self.grad);
        self.p *= if to_boundary { -delta / g } else { -alpha };
        if !gn_ok || to_boundary {
            return true;
        }
        // p = p_C + τ (p_GN − p_C) with ‖D p‖ = Δ, i.e. ‖a‖² + 2τ aᵀd + τ²‖d‖² = Δ²
        // for a = D p_C, d = D (p_GN − p_C).
        let (mut aa, mut ad, mut dd) = (0.0, 0.0, 0.0);
        for j in 0..n {
            let (a, d) = (self.p[j], self.p_gn[j] - self.p[j]);
            let (a, d) = (self.diag[j] * a, self.diag[j] * d);
            (aa, ad, dd) = (aa + a * a, ad + a * d, dd + d * d);
        }
        let rest = delta * delta - aa;
        let disc = (ad * ad + dd * rest).max(0.0).sqrt();
        // Cancellation-free root; dd > 0 here because ‖D p_GN‖ > Δ > ‖D p_C‖.
        let tau = if ad > 0.0 {
            rest / (ad + disc)
        } else {
            (disc - ad) / dd
        };
        let tau = if tau > 0.0 { tau.min(1.0) } else { 0.0 }; // NaN → 0
        for j in 0..n {
            self.p[j] += tau * (self.p_gn[j] - self.p[j]);
        }
        true
    }
}

/// Wraps an evaluation failure at iteration `iterations`.
fn eval_err(iterations: usize) -> impl Fn(EvalError) -> DoglegError {
    move |source| DoglegError::Evaluation { iterations, source }
}

/// Error unless `size_ok` and every entry of `v` is finite.
fn check(size_ok: bool, v: &[f64], it: usize, what: &'static str) -> Result<(), DoglegError> {
    if !size_ok {
        let msg = format!("the {what} has the wrong size");
        return Err(eval_err(it)(EvalError(msg)));
    }
    let iterations = it;
    match all_finite(v) {
        true => Ok(()),
        false => Err(DoglegError::NonFinite { iterations, what }),
    }
}

/// `f = F(x)`, checked; returns `‖f‖₂`.
fn eval_residual<S: NonlinearSystem>(
    sys: &mut S,
    x: &DVector<f64>,
    f: &mut DVector<f64>,
    iterations: usize,
) -> Result<f64, DoglegError> {
    sys.residual(x, f).map_err(eval_err(iterations))?;
    check(f.len() == x.len(), f.as_slice(), iterations, "residual")?;
    Ok(norm2(f.iter().copied()))
}

/// Solves `F(x) = 0` from `x0` by the trust-region dogleg method (see the module docs).
/// `ws` is resized when its size does not match `sys.dim()`.
pub fn solve<S: NonlinearSystem>(
    sys: &mut S,
    x0: &DVector<f64>,
    opts: &DoglegOptions,
    ws: &mut DoglegWorkspace,
) -> Result<DoglegReport, DoglegError> {
    let n = sys.dim();
    if x0.len() != n {
        let (expected, got) = (n, x0.len());
        return Err(DoglegError::Dimension { expected, got });
    }
    check(true, x0.as_slice(), 0, "initial point")?;
    if !ws.fits(n) {
        *ws = DoglegWorkspace::new(n);
    }
    ws.x.copy_from(x0);
    let mut fnorm = eval_residual(sys, &ws.x, &mut ws.f, 0)?;
    let (mut iter, mut nfev, mut njev) = (0, 1, 0);
    let mut finf = ws.f.amax();
    let mut tolerance = opts.ftol * sys.residual_scale(&ws.x);
    let (mut delta, mut xnorm) = (0.0, 0.0);
    let (mut need_jac, mut jac_fresh, mut first) = (true, false, true);
    let (mut ncfail, mut ncsuc, mut nslow) = (0, 0, 0);
    let (max_it, max_ev, xtol) = (opts.max_iterations, opts.max_evaluations, opts.xtol);
    ws.diag.fill(0.0);

    macro_rules! not_converged {
        ($($reason:tt)*) => {{
            let (reason, x) = (format!($($reason)*), ws.x.clone());
            let (iterations, residual_norm) = (iter, finf);
            return Err(DoglegError::NotConverged { iterations, residual_norm, tolerance, reason, x });
        }};
    }

    loop {
        if finf <= tolerance {
            let (x, iterations, residual_norm) = (ws.x.clone(), iter, finf);
            let (residual_evaluations, jacobian_evaluations) = (nfev, njev);
            return Ok(DoglegReport {
                x,
                iterations,
                residual_evaluations,
                jacobian_evaluations,
                residual_norm,
            });
        }
        if iter >= max_it {
            not_converged!("maximum number of iterations ({max_it}) reached");
        }
        if nfev >= max_ev {
            not_converged!("maximum number of residual evaluations ({max_ev}) reached");
        }
        if need_jac {
            sys.jacobian(&ws.x, &ws.f, &mut ws.jac)
                .map_err(eval_err(iter))?;
            ws.lu.state = None;
            njev += 1;
            let shape_ok = ws.jac.shape() == (n, n);
            check(shape_ok, ws.jac.as_slice(), iter, "Jacobian")?;
            // D ← max(D, column norms); zero columns of the first Jacobian get 1.
            for j in 0..n {
                let c = column_norm(ws.jac.column(j).as_slice()).min(f64::MAX);
                ws.diag[j] = ws.diag[j].max(c);
                if ws.diag[j] == 0.0 {
                    ws.diag[j] = 1.0;
                }
            }
            if first {
                xnorm = scaled_norm(&ws.diag, &ws.x);
                delta = opts.initial_radius_factor * xnorm;
                if !(delta.is_finite() && delta > 0.0) {
                    delta = opts.initial_radius_factor;
                }
            }
            (need_jac, jac_fresh, ncfail, nslow) = (false, true, 0, 0);
        }

        if !ws.dogleg(delta) {
            if jac_fresh {
                not_converged!("no descent direction: singular Jacobian and zero gradient of ‖F‖²");
            }
            need_jac = true;
            continue;
        }
        check(true, ws.p.as_slice(), iter, "step")?;
        let step_small = ws.p.amax() <= xtol * (1.0 + ws.x.amax());
        if step_small && !jac_fresh {
            // A negligible step from an updated model says nothing about the trust region.
            need_jac = true;
            continue;
        }
        iter += 1;
        let pnorm = scaled_norm(&ws.diag, &ws.p);
        if first {
            (delta, first) = (delta.min(pnorm), false);
        }
        let used_fresh = jac_fresh;

        // Trial point x + p.
        ws.x_new.copy_from(&ws.x);
        ws.x_new += &ws.p;
        let fnorm1 = eval_residual(sys, &ws.x_new, &mut ws.f_new, iter)?;
        nfev += 1;

        // Actual and predicted relative reductions of ‖F‖₂², using tmp = F + J p.
        ws.tmp.copy_from(&ws.f);
        ws.tmp.gemv(1.0, &ws.jac, &ws.p, 1.0);
        let fpred = norm2(ws.tmp.iter().copied());
        let rel = |a: f64| 1.0 - (a / fnorm).powi(2);
        let actred = if fnorm1 < fnorm { rel(fnorm1) } else { -1.0 };
        let prered = if fpred < fnorm { rel(fpred) } else { 0.0 };
        let ratio = if prered > 0.0 { actred / prered } else { 0.0 };

        if ratio < 0.1 {
            (ncsuc, ncfail) = (0, ncfail + 1);
            // Without Broyden the model is unchanged, so shrink below the rejected step.
            let cap = if opts.broyden { delta } else { pnorm };
            delta = 0.5 * delta.min(cap);
        } else {
            (ncsuc, ncfail) = (ncsuc + 1, 0);
            if ratio >= 0.5 || ncsuc > 1 {
                delta = delta.max(2.0 * pnorm);
            }
            if (ratio - 1.0).abs() <= 0.1 {
                delta = 2.0 * pnorm;
            }
        }
        nslow = if actred >= 1e-3 { 0 } else { nslow + 1 };

        // Broyden: J ← J + (y − J p)(D²p)ᵀ / ‖Dp‖² with y = F(x + p) − F(x), so that
        // y − J p = F(x + p) − tmp; each factor is divided by ‖Dp‖ (as in hybrj).
        if opts.broyden && pnorm > 0.0 {
            for j in 0..n {
                ws.tmp[j] = (ws.f_new[j] - ws.tmp[j]) / pnorm;
                ws.grad[j] = ws.diag[j] * (ws.diag[j] * ws.p[j] / pnorm);
            }
            ws.jac.ger(1.0, &ws.tmp, &ws.grad, 1.0);
            ws.lu.update(&ws.tmp, &ws.grad, &mut ws.p_gn);
            jac_fresh = false;
            // An update that overflowed is discarded: the analytic Jacobian replaces it.
            need_jac = !all_finite(ws.jac.as_slice());
        }

        if ratio >= 1e-4 {
            std::mem::swap(&mut ws.x, &mut ws.x_new);
            std::mem::swap(&mut ws.f, &mut ws.f_new);
            (fnorm, finf) = (fnorm1, ws.f.amax());
            xnorm = scaled_norm(&ws.diag, &ws.x);
            tolerance = opts.ftol * sys.residual_scale(&ws.x);
            if finf <= tolerance {
                continue;
            }
            need_jac |= !opts.broyden;
        }

        // (step_small implies that the step came from an analytic Jacobian.)
        if step_small {
            not_converged!("step size below xtol = {xtol:.1e} (relative to 1 + ‖x‖∞)");
        }
        let collapsed = delta <= f64::EPSILON * xnorm || delta <= f64::MIN_POSITIVE;
        if collapsed && used_fresh {
            not_converged!("trust-region radius collapsed (Δ = {delta:.3e})");
        }
        if opts.broyden && !jac_fresh && (collapsed || ncfail >= 2 || nslow >= 3) {
            need_jac = true;
        }
    }
}

#[cfg(test)]
mod tests;
