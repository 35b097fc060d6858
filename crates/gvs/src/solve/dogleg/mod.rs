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

mod linalg;

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
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::TAU;

    type V = DVector<f64>;
    /// A test system from plain functions; `fail` makes the residual return an error.
    struct Sys {
        n: usize,
        r: fn(&V, &mut V),
        j: fn(&V, &mut DMatrix<f64>),
        fail: bool,
        scale: f64,
    }
    impl NonlinearSystem for Sys {
        fn dim(&self) -> usize {
            self.n
        }
        fn residual(&mut self, x: &V, f: &mut V) -> Result<(), EvalError> {
            (self.r)(x, f);
            match self.fail {
                true => Err(EvalError("contact solver diverged".into())),
                false => Ok(()),
            }
        }
        fn jacobian(&mut self, x: &V, _: &V, jac: &mut DMatrix<f64>) -> Result<(), EvalError> {
            (self.j)(x, jac);
            Ok(())
        }
        fn residual_scale(&self, _: &V) -> f64 {
            self.scale
        }
    }
    fn sys(n: usize, r: fn(&V, &mut V), j: fn(&V, &mut DMatrix<f64>)) -> Sys {
        Sys {
            n,
            r,
            j,
            fail: false,
            scale: 1.0,
        }
    }
    fn run(s: &mut Sys, x0: &[f64], opts: DoglegOptions) -> Result<DoglegReport, DoglegError> {
        let x0 = V::from_column_slice(x0);
        solve(s, &x0, &opts, &mut DoglegWorkspace::new(s.n))
    }
    fn ok(s: &mut Sys, x0: &[f64]) -> DoglegReport {
        let rep = run(s, x0, DoglegOptions::default()).unwrap();
        let mut f = V::zeros(s.n);
        (s.r)(&rep.x, &mut f);
        assert!(rep.residual_norm <= 1e-10 && f.amax() == rep.residual_norm);
        rep
    }
    fn no_broyden() -> DoglegOptions {
        DoglegOptions {
            broyden: false,
            ..Default::default()
        }
    }
    fn dsquare(x: &V, j: &mut DMatrix<f64>) {
        j[(0, 0)] = 2.0 * x[0];
    }

    fn rosenbrock() -> Sys {
        let r = |x: &V, f: &mut V| f.copy_from_slice(&[10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]]);
        let j = |x: &V, j: &mut DMatrix<f64>| j.copy_from_slice(&[-20.0 * x[0], -1.0, 10.0, 0.0]);
        sys(2, r, j)
    }
    /// MGH 7: F = (10(x₃ − 10θ), 10(‖(x₁, x₂)‖ − 1), x₃), θ = atan(x₂/x₁)/2π (+ ½ if x₁ < 0).
    fn helical_valley() -> Sys {
        fn r(x: &V, f: &mut V) {
            let theta = (x[1] / x[0]).atan() / TAU + if x[0] < 0.0 { 0.5 } else { 0.0 };
            f[0] = 10.0 * (x[2] - 10.0 * theta);
            f[1] = 10.0 * (x[0].hypot(x[1]) - 1.0);
            f[2] = x[2];
        }
        sys(3, r, |x, j| {
            let (r2, c) = (x[0] * x[0] + x[1] * x[1], 100.0 / TAU);
            let rows = [x[1] / r2, -x[0] / r2, 0.1, x[0], x[1], 0.0, 0.0, 0.0, 0.1];
            j.copy_from(&DMatrix::from_row_slice(3, 3, &rows));
            j.row_mut(0).scale_mut(c);
            j.row_mut(1).scale_mut(10.0 / r2.sqrt());
            j[(2, 2)] = 1.0;
        })
    }
    /// MGH 28, discrete boundary value problem; F_i = 2x_i − x_{i−1} − x_{i+1} + h²(x_i + t_i + 1)³/2.
    fn discrete_bvp(n: usize) -> (Sys, Vec<f64>) {
        let h = 1.0 / (n as f64 + 1.0);
        let r = |x: &V, f: &mut V| {
            let (n, h) = (x.len(), 1.0 / (x.len() as f64 + 1.0));
            for i in 0..n {
                let xl = if i > 0 { x[i - 1] } else { 0.0 };
                let xr = x.get(i + 1).copied().unwrap_or(0.0);
                let t = (i + 1) as f64 * h;
                f[i] = 2.0 * x[i] - xl - xr + h * h * (x[i] + t + 1.0).powi(3) / 2.0;
            }
        };
        let s = sys(n, r, |x, j| {
            let (n, h) = (x.len(), 1.0 / (x.len() as f64 + 1.0));
            j.fill(0.0);
            for i in 0..n {
                j[(i, i)] = 2.0 + 1.5 * h * h * (x[i] + (i + 1) as f64 * h + 1.0).powi(2);
                if i > 0 {
                    (j[(i, i - 1)], j[(i - 1, i)]) = (-1.0, -1.0);
                }
            }
        });
        let x0 = (1..=n).map(|i| i as f64 * h * (i as f64 * h - 1.0));
        (s, x0.collect())
    }

    #[test]
    fn rosenbrock_system_converges_to_one_one() {
        let rep = ok(&mut rosenbrock(), &[-1.2, 1.0]);
        assert_relative_eq!(rep.x, V::from_column_slice(&[1.0, 1.0]), epsilon = 1e-10);
        assert!(rep.iterations > 0 && rep.jacobian_evaluations >= 1);
    }

    #[test]
    fn powell_badly_scaled_converges_to_known_root() {
        fn r(x: &V, f: &mut V) {
            f[0] = 1e4 * x[0] * x[1] - 1.0;
            f[1] = (-x[0]).exp() + (-x[1]).exp() - 1.0001;
        }
        let j = |x: &V, j: &mut DMatrix<f64>| {
            j.copy_from_slice(&[1e4 * x[1], -(-x[0]).exp(), 1e4 * x[0], -(-x[1]).exp()])
        };
        let mut s = sys(2, r, j);
        let rep = ok(&mut s, &[0.0, 1.0]);
        assert_relative_eq!(rep.x[0], 1.098_159_329_699_76e-5, max_relative = 1e-8);
        assert_relative_eq!(rep.x[1], 9.106_146_739_867_318, max_relative = 1e-8);
    }

    #[test]
    fn helical_valley_converges_to_one_zero_zero() {
        let rep = ok(&mut helical_valley(), &[-1.0, 0.0, 0.0]);
        let root = V::from_column_slice(&[1.0, 0.0, 0.0]);
        assert_relative_eq!(rep.x, root, epsilon = 1e-10);
    }

    #[test]
    fn powell_singular_converges_although_jacobian_is_singular_at_root() {
        fn r(x: &V, f: &mut V) {
            f[0] = x[0] + 10.0 * x[1];
            f[1] = 5f64.sqrt() * (x[2] - x[3]);
            f[2] = (x[1] - 2.0 * x[2]).powi(2);
            f[3] = 10f64.sqrt() * (x[0] - x[3]).powi(2);
        }
        let mut s = sys(4, r, |x, j| {
            let (c, d) = (5f64.sqrt(), 2.0 * 10f64.sqrt() * (x[0] - x[3]));
            let (a, a2, mc, md) = (
                2.0 * (x[1] - 2.0 * x[2]),
                -4.0 * (x[1] - 2.0 * x[2]),
                -c,
                -d,
            );
            let rows = [
                1.0, 10.0, 0.0, 0.0, 0.0, 0.0, c, mc, 0.0, a, a2, 0.0, d, 0.0, 0.0, md,
            ];
            j.copy_from(&DMatrix::from_row_slice(4, 4, &rows));
        });
        let rep = ok(&mut s, &[3.0, -1.0, 0.0, 1.0]);
        assert!(rep.x.amax() < 1e-4, "x = {}", rep.x);
    }

    #[test]
    fn broyden_updates_save_jacobian_evaluations_on_discrete_bvp_30() {
        let (mut s, x0) = discrete_bvp(30);
        let on = run(&mut s, &x0, DoglegOptions::default()).unwrap();
        let off = run(&mut s, &x0, no_broyden()).unwrap();
        assert!(on.residual_norm <= 1e-10 && off.residual_norm <= 1e-10);
        assert!((&on.x - &off.x).amax() < 1e-8);
        let (j_on, j_off) = (on.jacobian_evaluations, off.jacobian_evaluations);
        eprintln!("DBV(30) Jacobian evaluations: {j_on} with Broyden updates, {j_off} without");
        assert!(j_on < j_off);
    }

    #[test]
    fn broyden_updates_correct_a_wrong_jacobian_on_a_linear_system() {
        // F = A x − b with the supplied Jacobian 2A: without updates every step is half a
        // Newton step (error × ½ per iteration); secant updates repair J within a few steps.
        const A: [f64; 9] = [4.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 2.0];
        fn r(x: &V, f: &mut V) {
            f.gemv(1.0, &DMatrix::from_row_slice(3, 3, &A), x, 0.0);
            f.add_scalar_mut(-1.0);
        }
        let mut s = sys(3, r, |_, j| {
            j.copy_from(&(DMatrix::from_row_slice(3, 3, &A) * 2.0))
        });
        let on = ok(&mut s, &[10.0, -10.0, 10.0]);
        let off = run(&mut s, &[10.0, -10.0, 10.0], no_broyden()).unwrap();
        assert!(
            on.iterations <= 10 && off.iterations >= 20,
            "{} vs {}",
            on.iterations,
            off.iterations
        );
    }

    #[test]
    fn singular_initial_jacobian_falls_back_to_steepest_descent() {
        // J = [[1, 1], [1, 2 x₂]] is exactly singular at x₂ = ½; the roots are (1, 2) and (4, −1).
        fn r(x: &V, f: &mut V) {
            f[0] = x[0] + x[1] - 3.0;
            f[1] = x[0] + x[1] * x[1] - 5.0;
        }
        let mut s = sys(2, r, |x, j| j.copy_from_slice(&[1.0, 1.0, 1.0, 2.0 * x[1]]));
        let rep = ok(&mut s, &[1.0, 0.5]);
        let near = |a: f64, b: f64| (rep.x[0] - a).abs() < 1e-9 && (rep.x[1] - b).abs() < 1e-9;
        assert!(near(1.0, 2.0) || near(4.0, -1.0), "x = {}", rep.x);
    }

    #[test]
    fn system_without_root_reports_not_converged_with_residual_one() {
        let mut s = sys(1, |x, f| f[0] = x[0] * x[0] + 1.0, dsquare);
        let err = run(&mut s, &[2.0], DoglegOptions::default()).unwrap_err();
        let msg = err.to_string();
        let DoglegError::NotConverged {
            iterations: it,
            residual_norm: fn_,
            x,
            ..
        } = err
        else {
            panic!("expected NotConverged, got {msg}");
        };
        assert!(
            it > 0 && it < 400 && (fn_ - 1.0).abs() < 1e-6 && x[0].abs() < 1e-3,
            "{msg}"
        );
        assert!(
            msg.contains(&format!("after {it} iterations: ‖F‖∞ = 1.000e0")),
            "{msg}"
        );
        assert!(
            msg.ends_with("step size below xtol = 1.0e-12 (relative to 1 + ‖x‖∞)"),
            "{msg}"
        );
    }

    #[test]
    fn iteration_limit_is_reported_as_not_converged() {
        let opts = DoglegOptions {
            max_iterations: 1,
            ..Default::default()
        };
        let err = run(&mut rosenbrock(), &[-1.2, 1.0], opts).unwrap_err();
        assert!(matches!(err, DoglegError::NotConverged { .. }));
        let msg = err.to_string();
        assert!(msg.contains("after 1 iterations") && msg.contains("maximum number of iterations"));
    }

    #[test]
    fn residual_scale_sets_the_residual_tolerance() {
        // F = x² converges linearly (singular root), so a looser tolerance saves iterations.
        let mut s = sys(1, |x, f| f[0] = x[0] * x[0], dsquare);
        let tight = ok(&mut s, &[1.0]);
        s.scale = 1e6;
        let loose = run(&mut s, &[1.0], DoglegOptions::default()).unwrap();
        assert!(loose.residual_norm <= 1e-4 && loose.residual_norm > 1e-10);
        assert!(loose.iterations < tight.iterations);
    }

    #[test]
    fn nan_residual_is_reported_as_non_finite() {
        // NaN at x0, and NaN at a trial point (the too-small Jacobian overshoots into x < 0).
        let mut s = sys(1, |x, f| f[0] = x[0].sqrt() - 0.5, |_, j| j[(0, 0)] = 0.1);
        let msg = "non-finite value (NaN or infinity) in the residual at iteration";
        let at_x0 = run(&mut s, &[-1.0], DoglegOptions::default()).unwrap_err();
        assert!(matches!(at_x0, DoglegError::NonFinite { .. }));
        assert_eq!(at_x0.to_string(), format!("{msg} 0"));
        let at_trial = run(&mut s, &[1.0], DoglegOptions::default()).unwrap_err();
        assert_eq!(at_trial.to_string(), format!("{msg} 1"));
    }

    #[test]
    fn nan_in_initial_point_is_reported_as_non_finite() {
        let x0 = [f64::NAN, 1.0];
        let err = run(&mut rosenbrock(), &x0, DoglegOptions::default()).unwrap_err();
        assert!(matches!(err, DoglegError::NonFinite { .. }));
        assert!(
            err.to_string().contains("initial point at iteration 0"),
            "{err}"
        );
    }

    #[test]
    fn infinite_jacobian_is_reported_as_non_finite() {
        let mut s = sys(
            1,
            |x, f| f[0] = x[0] - 1.0,
            |_, j| j[(0, 0)] = f64::INFINITY,
        );
        let err = run(&mut s, &[0.0], DoglegOptions::default()).unwrap_err();
        assert!(matches!(err, DoglegError::NonFinite { .. }));
        assert!(err.to_string().contains("in the Jacobian"), "{err}");
    }

    #[test]
    fn evaluation_error_is_propagated() {
        let mut s = rosenbrock();
        s.fail = true;
        let err = run(&mut s, &[1.0, 1.0], DoglegOptions::default()).unwrap_err();
        assert!(matches!(err, DoglegError::Evaluation { .. }));
        assert!(
            err.to_string()
                .ends_with("iteration 0: contact solver diverged"),
            "{err}"
        );
    }

    #[test]
    fn dimension_mismatch_is_reported() {
        let x0 = [1.0, 2.0, 3.0];
        let err = run(&mut rosenbrock(), &x0, DoglegOptions::default()).unwrap_err();
        assert!(matches!(
            err,
            DoglegError::Dimension {
                expected: 2,
                got: 3
            }
        ));
    }

    #[test]
    fn workspace_is_reused_across_solves_of_different_sizes() {
        let (mut ws, opts) = (DoglegWorkspace::new(0), DoglegOptions::default());
        let (mut bvp, x0) = discrete_bvp(30);
        let fresh = run(&mut bvp, &x0, opts.clone()).unwrap();
        let (x0, rx0) = (V::from_vec(x0), V::from_column_slice(&[-1.2, 1.0]));
        let a = solve(&mut rosenbrock(), &rx0, &opts, &mut ws).unwrap();
        let b = solve(&mut bvp, &x0, &opts, &mut ws).unwrap();
        let hx0 = V::from_column_slice(&[-1.0, 0.0, 0.0]);
        let c = solve(&mut helical_valley(), &hx0, &opts, &mut ws).unwrap();
        let b2 = solve(&mut bvp, &x0, &opts, &mut ws).unwrap();
        assert!(a.residual_norm <= 1e-10 && c.residual_norm <= 1e-10);
        // Results do not depend on what the workspace held before.
        assert!(b.x == fresh.x && b2.x == fresh.x && b.iterations == fresh.iterations);
    }

    #[test]
    fn converged_initial_point_returns_without_iterating() {
        let rep = ok(&mut rosenbrock(), &[1.0, 1.0]);
        let counts = (
            rep.iterations,
            rep.residual_evaluations,
            rep.jacobian_evaluations,
        );
        assert_eq!(counts, (0, 1, 0));
    }
}
