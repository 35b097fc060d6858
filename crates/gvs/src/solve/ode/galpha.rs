//! The generalized-α method (Chung & Hulbert 1993) for mechanical systems in second-order form
//! `M(q) q̈ = τ(t, q, q̇)`, in the form of Arnold & Brüls (2007), with adaptive steps.
//!
//! **Why.** Lightly damped rods have undamped high-frequency modes (shear, elongation). The NDFs of
//! orders 3–5 are not A-stable, so on such modes their step is limited by stability, not accuracy.
//! Generalized-α is second order, unconditionally stable for linear systems, and dissipates the
//! frequencies above the step's resolution by a chosen amount (`ρ∞`, the spectral radius at
//! `hω → ∞`) while leaving the low ones almost untouched — the standard of flexible multibody codes.
//!
//! **Formula.** With the pseudo-acceleration `a` (`a₀ = q̈₀`) and
//! `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`, `γ = ½ + α_f − α_m`, `β = ¼ (γ + ½)²`,
//! one step from `t_n` to `t_{n+1} = t_n + h` solves for `q̈_{n+1}`:
//!
//! ```text
//!   (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) q̈_{n+1} + α_f q̈_n
//!   q_{n+1} = q_n + h q̇_n + h² (½ − β) a_n + h² β a_{n+1}
//!   q̇_{n+1} = q̇_n + h (1 − γ) a_n + h γ a_{n+1}
//!   ε(t_{n+1}, q_{n+1}, q̇_{n+1}, q̈_{n+1}) = M q̈ − τ = 0.
//! ```
//!
//! **Newton** on `q̈_{n+1}` (`n` unknowns, not `2n`): `q` and `q̇` move with `q̈` at the rates
//! `c_q = h² β (1 − α_f)/(1 − α_m)` and `c_v = h γ (1 − α_f)/(1 − α_m)`, so the iteration matrix is
//! `S = M + c_v D + c_q K` ([`MechanicalSystem::iteration_parts`]). `M`, `D`, `K` are evaluated at
//! the start of each piece and again only when Newton converges slowly; `S` is refactored when `h`
//! moves more than 20 % from the `h` it was built with. Convergence in the weighted max norm of the
//! corrections of `q` and `q̇`: with the rate `ρ = ‖δ_i‖/‖δ_{i−1}‖`, accept when
//! `ρ/(1−ρ)·‖δ_i‖ ≤ κ = 0.05` (or `‖δ₀‖ ≤ κ/10` after one iteration), fail when `ρ > 0.9` or after
//! 5 iterations; a failure re-evaluates `M, D, K` if they are stale, else cuts `h` by 4.
//!
//! **Error estimate** (Zienkiewicz & Xie 1991): the local error of `q` is
//! `e = (β − 1/6) h² (q̈_{n+1} − q̈_n)`. For a mode of frequency `ω` that the step does not resolve
//! (`ωh ≫ 1`) this is `~(ωh)²` times the mode's amplitude, although the method only damps such a
//! mode; so, as Shampine filters the estimates of stiff BDF codes through `(I − hγJ)⁻¹`, the
//! estimate is filtered through `S⁻¹M` (factor `1/(1 + c_q ω²)` per mode: 1 for resolved modes, the
//! mode's own displacement for unresolved ones). It is measured as
//! `‖e_i / (rtol·max(|q_n,i|, |q_{n+1},i|) + atol)‖∞`;
//! a step is accepted when it is ≤ 1, and the next step is `h·min(2, max(0.2, 0.9 err^{−1/3}))`
//! (increases below 20 % are not taken, so `S` is kept).
//!
//! With [`ErrorNorm::Mass`] the error estimate and the Newton corrections are measured in the norm
//! of the mass matrix instead, `‖e‖_M̂ / (rtol·max(‖q_n‖_M̂, ‖q_{n+1}‖_M̂) + atol)` (`M̂ = M·m/tr M`,
//! the `M` of the iteration matrix): the componentwise test lets the unresolved shear and
//! elongation modes of a lightly damped rod, whose coordinates are atol-sized, set the step (the
//! undamped release of issue 8: 375 477 steps for 6 s componentwise, 2 376 at rtol 1e-5 in the mass
//! norm, within 0.1 % L of a tight run). The Newton predictor extrapolates `q̈` linearly from the
//! last two steps of the piece.
//!
//! **Output** between steps: cubic Hermite interpolation of `q` from `(q, q̇)` at both ends
//! (`q̇` from its derivative). **Breakpoints** as for the NDF: the piece is integrated onto its end,
//! evaluations stay strictly inside, and the next piece restarts with consistent accelerations
//! `M q̈ = τ` (the input may jump there).

use super::one_step::{
    begin_attempt, check_step_options, first_step, newton_test, next_step, over_pieces, shrink,
    Newton, Parts, Piece,
};
use super::{
    check_common, deliver, invalid, mechanical_state, rhs_err, ErrorNorm, OdeError, OdeFailure,
    OdeStats, Output, RhsError,
};
use nalgebra::{DMatrix, DVector};

/// `M(q) q̈ = τ(t, q, q̇)`, in the form the generalized-α method needs.
pub trait MechanicalSystem {
    /// Number of coordinates `n` (the state is `[q; q̇]`, `2n`).
    fn dim(&self) -> usize;
    /// The residual `ε = M(q) q̈ − τ(t, q, q̇)`.
    fn residual(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        eps: &mut DVector<f64>,
    ) -> Result<(), RhsError>;
    /// Consistent accelerations: `q̈` with `M q̈ = τ(t, q, q̇)`.
    fn accelerations(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &mut DVector<f64>,
    ) -> Result<(), RhsError>;
    /// The mass matrix `M(q)` at time `t`.
    fn mass(&mut self, t: f64, q: &DVector<f64>, m: &mut DMatrix<f64>) -> Result<(), RhsError>;
    /// [`Self::residual`] and [`Self::mass`] at the same `(t, q)`; a system that gets both from one
    /// pass over its structure overrides it.
    fn residual_and_mass(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        eps: &mut DVector<f64>,
        m: &mut DMatrix<f64>,
    ) -> Result<(), RhsError> {
        self.mass(t, q, m)?;
        self.residual(t, q, qd, qdd, eps)
    }
    /// `M`, `D ≈ −∂τ/∂q̇` and `K ≈ ∂(M q̈ − τ)/∂q` at `(t, q, q̇)` for the iteration matrix
    /// `S = M + c_v D + c_q K`.
    #[allow(clippy::too_many_arguments)]
    fn iteration_parts(
        &mut self,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        m: &mut DMatrix<f64>,
        d: &mut DMatrix<f64>,
        k: &mut DMatrix<f64>,
    ) -> Result<(), RhsError>;
    /// Polled before every step attempt, as [`super::OdeSystem::stop_requested`]: `Some(reason)`
    /// stops the integration at once with [`super::OdeError::Stopped`]. Default: never.
    fn stop_requested(&mut self) -> Option<String> {
        None
    }
}

/// Options of [`integrate_generalized_alpha`].
#[derive(Debug, Clone)]
pub struct GeneralizedAlphaOptions {
    /// Spectral radius at infinite frequency, in `[0, 1]`: 1 keeps every frequency (no numerical
    /// dissipation), 0 annihilates the unresolved ones in one step. Default 0.8.
    pub rho_inf: f64,
    /// Relative tolerance of the position error per step (default `1e-3`), in
    /// [[`super::MIN_RTOL`], [`super::MAX_RTOL`]).
    pub rtol: f64,
    /// Absolute tolerance (default `1e-6`).
    pub atol: f64,
    /// First step (default automatic).
    pub initial_step: Option<f64>,
    /// Maximum step; `f64::INFINITY` (default) means `0.1·|tf − t0|`.
    pub max_step: f64,
    /// Maximum number of successful steps (default 1 000 000).
    pub max_steps: usize,
    /// How the error estimate and the Newton corrections are measured (default componentwise; see
    /// [`ErrorNorm::Mass`]).
    pub error_norm: ErrorNorm,
}

impl Default for GeneralizedAlphaOptions {
    fn default() -> Self {
        GeneralizedAlphaOptions {
            rho_inf: 0.8,
            rtol: 1e-3,
            atol: 1e-6,
            initial_step: None,
            max_step: f64::INFINITY,
            max_steps: 1_000_000,
            error_norm: ErrorNorm::Componentwise,
        }
    }
}

/// The method's constants for one `ρ∞`.
#[derive(Debug, Clone, Copy)]
struct Coefficients {
    alpha_m: f64,
    alpha_f: f64,
    beta: f64,
    gamma: f64,
}

impl Coefficients {
    fn new(rho_inf: f64) -> Self {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        Coefficients {
            alpha_m,
            alpha_f,
            beta: 0.25 * (gamma + 0.5).powi(2),
            gamma,
        }
    }
}

const KAPPA: f64 = 0.05;
const MAX_NEWTON: usize = 5;

/// State, trial values and matrices of an integration (allocated once).
struct Work {
    q: DVector<f64>,
    qd: DVector<f64>,
    qdd: DVector<f64>,
    a: DVector<f64>,
    q1: DVector<f64>,
    qd1: DVector<f64>,
    qdd1: DVector<f64>,
    /// `q̈` of the step before the last (for the predictor).
    qdd_prev: DVector<f64>,
    a1: DVector<f64>,
    eps: DVector<f64>,
    /// Error estimate and `M e`.
    e: DVector<f64>,
    me: DVector<f64>,
    parts: Parts,
    out: DVector<f64>,
}

impl Work {
    fn new(n: usize, norm: ErrorNorm) -> Self {
        let v = || DVector::zeros(n);
        Work {
            q: v(),
            qd: v(),
            qdd: v(),
            a: v(),
            q1: v(),
            qd1: v(),
            qdd1: v(),
            qdd_prev: v(),
            a1: v(),
            eps: v(),
            e: v(),
            me: v(),
            parts: Parts::new(n, norm, false),
            out: DVector::zeros(2 * n),
        }
    }

    /// `a_{n+1}`, `q_{n+1}`, `q̇_{n+1}` from `q̈_{n+1}` (the module doc's update).
    fn update(&mut self, c: &Coefficients, h: f64) {
        let (am, af, b, g) = (c.alpha_m, c.alpha_f, c.beta, c.gamma);
        for i in 0..self.q.len() {
            let a1 = ((1.0 - af) * self.qdd1[i] + af * self.qdd[i] - am * self.a[i]) / (1.0 - am);
            self.a1[i] = a1;
            self.q1[i] = self.q[i] + h * self.qd[i] + h * h * ((0.5 - b) * self.a[i] + b * a1);
            self.qd1[i] = self.qd[i] + h * ((1.0 - g) * self.a[i] + g * a1);
        }
    }
}

/// Integrates `M(q) q̈ = τ(t, q, q̇)` from `(q0, q̇0)` at `t0`, calling `output` with `[q; q̇]` at every
/// time of `t_out` (ascending; the first may equal `t0`). See the module doc.
#[allow(clippy::too_many_arguments)]
pub fn integrate_generalized_alpha<S: MechanicalSystem>(
    sys: &mut S,
    t0: f64,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
    t_out: &[f64],
    breakpoints: &[f64],
    opts: &GeneralizedAlphaOptions,
    output: &mut Output<'_>,
) -> Result<OdeStats, OdeFailure> {
    let n = sys.dim();
    let y0 = mechanical_state(n, q0, qd0)?;
    let bounds = check_common(2 * n, t0, &y0, t_out, breakpoints)?;
    if !(0.0..=1.0).contains(&opts.rho_inf) {
        return Err(invalid(
            "rho_inf",
            format!("{} (accepted: a number in [0, 1])", opts.rho_inf),
        )
        .into());
    }
    check_step_options(opts.rtol, opts.atol, opts.max_step, opts.initial_step)?;
    let mut w = Work::new(n, opts.error_norm);
    w.q.copy_from(q0);
    w.qd.copy_from(qd0);
    let mut next = 0;
    deliver(t_out, &mut next, t0, &mut w.out, output, |_, b| {
        b.copy_from(&y0)
    })?;
    let c = Coefficients::new(opts.rho_inf);
    over_pieces(
        &bounds,
        opts.max_step,
        opts.initial_step,
        |piece, h0, stats| {
            integrate_piece(
                sys, &mut w, &c, opts, piece, h0, t_out, &mut next, output, stats,
            )
        },
    )
}

#[allow(clippy::too_many_arguments)]
fn integrate_piece<S: MechanicalSystem>(
    sys: &mut S,
    w: &mut Work,
    c: &Coefficients,
    opts: &GeneralizedAlphaOptions,
    piece: &Piece,
    h0: Option<f64>,
    t_out: &[f64],
    next: &mut usize,
    output: &mut Output<'_>,
    stats: &mut OdeStats,
) -> Result<(), OdeError> {
    let n = w.q.len();
    let (rtol, atol) = (opts.rtol, opts.atol);
    let mut t = piece.a;
    // consistent accelerations at the start of the piece
    stats.rhs_evals += 1;
    sys.accelerations(piece.clamp(t), &w.q, &w.qd, &mut w.qdd)
        .map_err(rhs_err(t))?;
    if w.qdd.iter().any(|v| !v.is_finite()) {
        return Err(OdeError::NonFinite { t });
    }
    w.a.copy_from(&w.qdd);
    w.parts.eval(sys, piece.clamp(t), &w.q, &w.qd, stats)?;
    let span = piece.b - piece.a;
    let mut h = h0
        .unwrap_or_else(|| first_step(&w.parts, &w.q, &w.qd, &w.qdd, rtol, atol, span, piece.hmax))
        .min(piece.hmax)
        .min(span);
    let mut fails_here = 0usize;
    let mut h_prev: Option<f64> = None;
    // `q` and `q̇` move with `q̈_{n+1}` at the rates `c_q`, `c_v` (module doc)
    let scale = (1.0 - c.alpha_f) / (1.0 - c.alpha_m);
    let rates = |h: f64| (h * c.gamma * scale, h * h * c.beta * scale);
    while t < piece.b {
        let t1 = begin_attempt(
            sys,
            t,
            &mut h,
            piece,
            stats.steps,
            opts.max_steps,
            (rtol, atol),
        )?;
        let (cv, cq) = rates(h);
        let factored = w.parts.factor_for(h, rates, stats).is_some();

        // simplified Newton on q̈_{n+1}, predictor: q̈ extrapolated linearly from the last two
        // steps of this piece (q̈_n on its first step)
        w.qdd1.copy_from(&w.qdd);
        if let Some(hp) = h_prev {
            let r = h / hp;
            w.qdd1.axpy(r, &w.qdd, 1.0);
            w.qdd1.axpy(-r, &w.qdd_prev, 1.0);
        }
        // a singular (or non-finite) S fails the attempt as a diverged Newton iteration would
        let mut converged = false;
        if factored {
            let mut prev = f64::NAN;
            for it in 0..MAX_NEWTON {
                w.update(c, h);
                stats.rhs_evals += 1;
                stats.newton_iterations += 1;
                sys.residual(piece.clamp(t1), &w.q1, &w.qd1, &w.qdd1, &mut w.eps)
                    .map_err(rhs_err(t))?;
                if w.eps.iter().any(|v| !v.is_finite()) {
                    break;
                }
                w.eps.neg_mut();
                w.parts.solve(&mut w.eps);
                w.qdd1 += &w.eps;
                let dq = w.parts.weighted(&w.eps, &w.q, &w.q1, rtol, atol) * cq;
                let dv = w.parts.weighted(&w.eps, &w.qd, &w.qd1, rtol, atol) * cv;
                match newton_test(it, dq.max(dv), prev, KAPPA) {
                    Newton::Converged => {
                        converged = true;
                        break;
                    }
                    Newton::Failed => break,
                    Newton::Continue => prev = dq.max(dv),
                }
            }
        }
        if !converged {
            let (q, qd) = (&w.q, &w.qd);
            w.parts.after_failure(
                sys,
                (rtol, atol),
                t,
                piece.clamp(t),
                q,
                qd,
                &mut h,
                &mut fails_here,
                false,
                stats,
            )?;
            continue;
        }
        w.update(c, h);
        if w.q1.iter().chain(w.qd1.iter()).any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite { t });
        }
        // local error of q (Zienkiewicz–Xie), filtered through S⁻¹M
        let ce = (c.beta - 1.0 / 6.0) * h * h;
        w.e.copy_from(&w.qdd1);
        w.e -= &w.qdd;
        w.me.gemv(ce, &w.parts.m, &w.e, 0.0);
        w.parts.solve(&mut w.me);
        let err = w.parts.weighted(&w.me, &w.q, &w.q1, rtol, atol);
        if err.is_nan() || err > 1.0 {
            stats.failed_steps += 1;
            fails_here += 1;
            h *= shrink(err, 1.0 / 3.0);
            continue;
        }
        // accepted: outputs in (t, t1] by cubic Hermite interpolation
        stats.steps += 1;
        fails_here = 0;
        {
            let (q0, v0, q1, v1) = (&w.q, &w.qd, &w.q1, &w.qd1);
            deliver(t_out, next, t1, &mut w.out, output, |tau, y| {
                let s = ((tau - t) / h).clamp(0.0, 1.0);
                let (s2, s3) = (s * s, s * s * s);
                let (h00, h10, h01, h11) = (
                    2.0 * s3 - 3.0 * s2 + 1.0,
                    s3 - 2.0 * s2 + s,
                    3.0 * s2 - 2.0 * s3,
                    s3 - s2,
                );
                let (d00, d10, d01, d11) = (
                    6.0 * s2 - 6.0 * s,
                    3.0 * s2 - 4.0 * s + 1.0,
                    6.0 * s - 6.0 * s2,
                    3.0 * s2 - 2.0 * s,
                );
                for i in 0..n {
                    y[i] = h00 * q0[i] + h10 * h * v0[i] + h01 * q1[i] + h11 * h * v1[i];
                    y[n + i] = (d00 * q0[i] + d01 * q1[i]) / h + d10 * v0[i] + d11 * v1[i];
                }
            })?;
        }
        t = t1;
        std::mem::swap(&mut w.q, &mut w.q1);
        std::mem::swap(&mut w.qd, &mut w.qd1);
        w.qdd_prev.copy_from(&w.qdd);
        h_prev = Some(h);
        std::mem::swap(&mut w.qdd, &mut w.qdd1);
        std::mem::swap(&mut w.a, &mut w.a1);
        w.parts.current = false;
        h = next_step(h, err, 1.0 / 3.0, piece.hmax);
    }
    Ok(())
}
