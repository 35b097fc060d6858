//! An L-stable, fourth-order singly diagonally implicit Runge–Kutta method (SDIRK4 of Hairer &
//! Wanner, *Solving ODEs II*, §IV.6, Table 6.5: five stages, `γ = 1/4`, stiffly accurate, with an
//! embedded third-order solution) for mechanical systems in second-order form
//! `M(q) q̈ = τ(t, q, q̇)`, with adaptive steps.
//!
//! **Why.** An undamped rod released from a bent shape swings in its first mode but also rings in
//! its second and third, with a few per cent and a few per mille of the tip amplitude. To keep the
//! tip within 0.1 % L over a few periods, a second-order method (generalized-α, the NDF of order 2)
//! must resolve the phase of those modes, `(ωh)²` per period: thousands of steps. Fourth order
//! makes the phase error `(ωh)⁴`: a step can span a tenth of the third mode's period. L-stability
//! damps the unresolved shear and elongation modes instead of letting them ring; the NDFs of order
//! 3–5, which are not A-stable, crawl on them.
//!
//! **Formula.** With the tableau `(a_ij, b_j = a_5j, c_i)` and the first-order form
//! `y = [q; q̇]`, `f = [q̇; q̈(t, q, q̇)]`, stage `i` (`t_i = t_n + c_i h`) is
//!
//! ```text
//!   V_i = zv_i + hγ A_i,        zv_i = q̇_n + h Σ_{j<i} a_ij A_j,
//!   Q_i = zq_i + hγ V_i,        zq_i = q_n + h Σ_{j<i} a_ij V_j,
//!   ε(t_i, Q_i, V_i, A_i) = M(Q_i) A_i − τ(t_i, Q_i, V_i) = 0,
//! ```
//!
//! `n` unknowns `A_i` per stage, solved by simplified Newton with the iteration matrix
//! `S = M + hγ D + (hγ)² K` of every stage ([`MechanicalSystem::iteration_parts`]; the
//! generalized-α iteration with `c_v = hγ`, `c_q = (hγ)²`). The method is stiffly accurate:
//! `q_{n+1} = Q_5`, `q̇_{n+1} = V_5`, and `A_5` is the consistent acceleration at `t_{n+1}`.
//! `M`, `D`, `K` are evaluated at the start of each piece, before a step that follows one whose
//! slowest stage needed more than 4 Newton iterations, and when Newton fails; `S` is refactored when
//! `h` moves more than 20 % from the `h` it was built with. **`M` follows the stages** where it
//! changes within a step: for [`TRACK_STEPS`] steps after a Newton failure, each stage's first
//! residual also gives `M(Q_i)` at its predicted configuration (one pass,
//! [`MechanicalSystem::residual_and_mass`]) and `S` is refactored with it. (On a whipping,
//! undamped rod, `M` moves enough within a step of a few milliseconds that `S` built with the
//! step's first `M` contracted by up to 0.54 per iteration, against at most 0.10 with `M(Q_i)`:
//! the spectral radius of `I − S⁻¹ ∂ε/∂A` at the stages of a 4-element fall, with `∂ε/∂A` by
//! finite differences; `K` at `Q_i` changed nothing. Following `M` also after a merely slow
//! contraction, `ρ > 0.2`, cost 18 % more time on the undamped release, where `M` changes
//! slowly.) The predictor of `A_i` extrapolates `q̈` (from the last step for stage 1, through
//! `q̈_n` and `A_1` for stage 2, by the quadratic through `q̈_n, A_1, A_2` for the others). A
//! correction `δA` moves `Q_i` by `(hγ)² δA` and, through `V_i`, the later stages by up to
//! `h·hγ·δA`; that displacement, in the units of the error test (with [`ErrorNorm::Mass`], also
//! in the stiffness norm: [`Parts::newton_weighted`]), must satisfy `ρ/(1−ρ)·‖δ_i‖ ≤ κ = 10⁻³`
//! (or `‖δ₀‖ ≤ κ/10` after one iteration), where `ρ` is the contraction rate; `ρ > 0.9` or 7
//! iterations fail the step. A failure while `M` does not follow
//! the stages retries the same `h` with it following; a later one re-evaluates `M, D, K` if they
//! are stale and otherwise cuts `h` by 4. (`κ` is small because the embedded estimate overstates
//! the fourth-order solution's error: with `κ = 10⁻²` the Newton residue dominated the tip error
//! of the undamped release.)
//!
//! **Error estimate.** `e = h Σ (b_j − b̂_j) [V_j; A_j]`, the difference from the embedded
//! third-order solution, filtered as in Hairer & Wanner's codes through `(I − hγ J)⁻¹`
//! (`J = ∂f/∂y`): `x_v = S⁻¹ (M e_v − hγ K e_q)`, `x_q = e_q + hγ x_v` (one solve with `S`; a mode
//! the step resolves keeps its estimate, an unresolved one is scaled by `1/(hγω)²`). The position
//! error is measured, `‖x_q‖ / (rtol·max(‖q_n‖, ‖q_{n+1}‖) + atol)`, componentwise (max norm) or,
//! with [`ErrorNorm::Mass`], in the norm of the mass matrix. (Velocities are not tested: their
//! estimate is dominated by the unresolved modes, and at a release from rest their scale is
//! `atol`; with them the undamped release took 20 times as many steps for the same tip error.) A
//! step is accepted when the error is ≤ 1, and the next step is
//! `h·min(2, max(0.2, 0.9 err^{−1/4}))` (increases below 20 % are not taken, so `S` is kept).
//!
//! **Output** between steps: quintic Hermite interpolation of `q` from `(q, q̇, q̈)` at both ends
//! (exact for quintics; `q̇` from its derivative). **Breakpoints** as for the NDF: the piece is
//! integrated onto its end, evaluations stay strictly inside, and the next piece restarts with
//! consistent accelerations `M q̈ = τ`.

use super::galpha::MechanicalSystem;
use super::one_step::{
    begin_attempt, check_step_options, first_step, newton_test, next_step, over_pieces, shrink,
    Newton, Parts, Piece,
};
use super::{
    check_common, deliver, mechanical_state, rhs_err, ErrorNorm, OdeError, OdeFailure, OdeStats,
    Output,
};
use nalgebra::DVector;

/// The diagonal `γ` of the tableau.
pub(super) const GAMMA: f64 = 0.25;
/// Number of stages.
pub(super) const STAGES: usize = 5;
/// The nodes `c_i`.
pub(super) const C: [f64; STAGES] = [0.25, 0.75, 11.0 / 20.0, 0.5, 1.0];
/// The strictly lower part of `a_ij` (`a_ii = γ`); the last row is `b`.
pub(super) const A: [[f64; STAGES]; STAGES] = [
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [0.5, 0.0, 0.0, 0.0, 0.0],
    [17.0 / 50.0, -1.0 / 25.0, 0.0, 0.0, 0.0],
    [371.0 / 1360.0, -137.0 / 2720.0, 15.0 / 544.0, 0.0, 0.0],
    [25.0 / 24.0, -49.0 / 48.0, 125.0 / 16.0, -85.0 / 12.0, 0.0],
];
/// The weights of the embedded third-order solution.
pub(super) const B_HAT: [f64; STAGES] =
    [59.0 / 48.0, -17.0 / 96.0, 225.0 / 32.0, -85.0 / 12.0, 0.0];

/// `b_j − b̂_j` (`b_5 = γ`).
fn error_weight(j: usize) -> f64 {
    let b = if j + 1 == STAGES {
        GAMMA
    } else {
        A[STAGES - 1][j]
    };
    b - B_HAT[j]
}

const KAPPA: f64 = 1e-3;
/// A step whose slowest stage needed more Newton iterations renews `M, D, K` for the next.
const SLOW_NEWTON: usize = 4;
const MAX_NEWTON: usize = 7;
/// `M` follows the stages for this many steps after a Newton failure.
const TRACK_STEPS: usize = 20;

/// Options of [`integrate_sdirk`].
#[derive(Debug, Clone)]
pub struct SdirkOptions {
    /// Relative tolerance of the local error per step (default `1e-3`), in
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

impl Default for SdirkOptions {
    fn default() -> Self {
        SdirkOptions {
            rtol: 1e-3,
            atol: 1e-6,
            initial_step: None,
            max_step: f64::INFINITY,
            max_steps: 1_000_000,
            error_norm: ErrorNorm::Componentwise,
        }
    }
}

/// State, stages and matrices of an integration (allocated once).
struct Work {
    q: DVector<f64>,
    qd: DVector<f64>,
    qdd: DVector<f64>,
    /// `q̈` one step back, and that step (for the first predictor), within the piece.
    qdd_prev: DVector<f64>,
    h_prev: Option<f64>,
    /// Stage velocities `V_i` and accelerations `A_i`.
    vs: Vec<DVector<f64>>,
    acc: Vec<DVector<f64>>,
    /// Stage bases `zq_i`, `zv_i` and the stage configuration `Q_i`.
    zq: DVector<f64>,
    zv: DVector<f64>,
    qs: DVector<f64>,
    eps: DVector<f64>,
    /// Error estimate (`e_q`, filtered in place; `e_v`) and the filtered `x_v`.
    eq: DVector<f64>,
    ev: DVector<f64>,
    tmp: DVector<f64>,
    parts: Parts,
    out: DVector<f64>,
    /// Steps left during which every stage renews `M` at its configuration (0: `M` is kept).
    mass_steps: usize,
}

impl Work {
    fn new(n: usize, norm: ErrorNorm) -> Self {
        let v = || DVector::zeros(n);
        Work {
            q: v(),
            qd: v(),
            qdd: v(),
            qdd_prev: v(),
            h_prev: None,
            vs: (0..STAGES).map(|_| v()).collect(),
            acc: (0..STAGES).map(|_| v()).collect(),
            zq: v(),
            zv: v(),
            qs: v(),
            eps: v(),
            eq: v(),
            ev: v(),
            tmp: v(),
            parts: Parts::new(n, norm, true),
            out: DVector::zeros(2 * n),
            mass_steps: 0,
        }
    }

    /// `zq_i`, `zv_i` of stage `i` from the stages before it.
    fn stage_base(&mut self, i: usize, h: f64) {
        self.zq.copy_from(&self.q);
        self.zv.copy_from(&self.qd);
        for j in 0..i {
            let a = h * A[i][j];
            if a != 0.0 {
                self.zq.axpy(a, &self.vs[j], 1.0);
                self.zv.axpy(a, &self.acc[j], 1.0);
            }
        }
    }

    /// The Newton predictor of `A_i`: `q̈` extrapolated from the previous step for the first stage,
    /// linearly through `(t_n, q̈_n)` and `A_1` for the second, and by the quadratic through
    /// `q̈_n`, `A_1`, `A_2` for the others.
    fn predict(&mut self, i: usize, h: f64) {
        let (done, rest) = self.acc.split_at_mut(i);
        let p = &mut rest[0];
        match i {
            0 => {
                p.copy_from(&self.qdd);
                if let Some(hp) = self.h_prev {
                    let r = C[0] * h / hp;
                    p.axpy(r, &self.qdd, 1.0);
                    p.axpy(-r, &self.qdd_prev, 1.0);
                }
            }
            1 => {
                let r = C[1] / C[0];
                p.copy_from(&self.qdd);
                p.axpy(r, &done[0], 1.0);
                p.axpy(-r, &self.qdd, 1.0);
            }
            _ => {
                // Lagrange weights at c_i of the nodes 0, c_1, c_2
                let (x, x0, x1, x2) = (C[i], 0.0, C[0], C[1]);
                let l0 = (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2));
                let l1 = (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2));
                let l2 = (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1));
                p.copy_from(&self.qdd);
                *p *= l0;
                p.axpy(l1, &done[0], 1.0);
                p.axpy(l2, &done[1], 1.0);
            }
        }
    }

    /// `V_i = zv_i + hγ A_i`, `Q_i = zq_i + hγ V_i`.
    fn stage_state(&mut self, i: usize, hg: f64) {
        let (v, a) = (&mut self.vs[i], &self.acc[i]);
        for r in 0..v.len() {
            v[r] = self.zv[r] + hg * a[r];
            self.qs[r] = self.zq[r] + hg * v[r];
        }
    }
}

/// Integrates `M(q) q̈ = τ(t, q, q̇)` from `(q0, q̇0)` at `t0`, calling `output` with `[q; q̇]` at every
/// time of `t_out` (ascending; the first may equal `t0`). See the module doc.
#[allow(clippy::too_many_arguments)]
pub fn integrate_sdirk<S: MechanicalSystem>(
    sys: &mut S,
    t0: f64,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
    t_out: &[f64],
    breakpoints: &[f64],
    opts: &SdirkOptions,
    output: &mut Output<'_>,
) -> Result<OdeStats, OdeFailure> {
    let n = sys.dim();
    let y0 = mechanical_state(n, q0, qd0)?;
    let bounds = check_common(2 * n, t0, &y0, t_out, breakpoints)?;
    check_step_options(opts.rtol, opts.atol, opts.max_step, opts.initial_step)?;
    let mut w = Work::new(n, opts.error_norm);
    w.q.copy_from(q0);
    w.qd.copy_from(qd0);
    let mut next = 0;
    deliver(t_out, &mut next, t0, &mut w.out, output, |_, b| {
        b.copy_from(&y0)
    })?;
    over_pieces(
        &bounds,
        opts.max_step,
        opts.initial_step,
        |piece, h0, stats| {
            integrate_piece(
                sys, &mut w, opts, piece, h0, t_out, &mut next, output, stats,
            )
        },
    )
}

/// The outcome of the stages of a step attempt.
enum Attempt {
    /// Newton did not converge (or produced a non-finite value).
    Diverged,
    /// The stages converged, the slowest in this many iterations.
    Converged(usize),
}

/// The five stages of one step of length `h` from `(t, q_n, q̇_n, q̈_n)`.
fn stages<S: MechanicalSystem>(
    sys: &mut S,
    w: &mut Work,
    t: f64,
    h: f64,
    tol: (f64, f64),
    piece: &Piece,
    stats: &mut OdeStats,
) -> Result<Attempt, OdeError> {
    let hg = h * GAMMA;
    // a correction δA moves V_i by hγ δA, hence Q_i by (hγ)² δA and the later stages' Q by up to
    // h·hγ·δA: measured as that displacement
    let cq = h * hg;
    let mut most = 0;
    for i in 0..STAGES {
        w.stage_base(i, h);
        w.predict(i, h);
        let ti = piece.clamp(t + C[i] * h);
        let mut converged = false;
        let mut prev = f64::NAN;
        for it in 0..MAX_NEWTON {
            w.stage_state(i, hg);
            stats.rhs_evals += 1;
            stats.newton_iterations += 1;
            if it == 0 && w.mass_steps > 0 {
                // M(Q_i) from the same pass as the predictor's residual, and S with it
                sys.residual_and_mass(ti, &w.qs, &w.vs[i], &w.acc[i], &mut w.eps, &mut w.parts.m)
                    .map_err(rhs_err(t))?;
                if w.parts.refactor_with_new_mass(h, rates, stats).is_none() {
                    return Ok(Attempt::Diverged);
                }
            } else {
                sys.residual(ti, &w.qs, &w.vs[i], &w.acc[i], &mut w.eps)
                    .map_err(rhs_err(t))?;
            }
            if w.eps.iter().any(|v| !v.is_finite()) {
                return Ok(Attempt::Diverged);
            }
            w.eps.neg_mut();
            w.parts.solve(&mut w.eps);
            w.acc[i] += &w.eps;
            let norm = w.parts.newton_weighted(&w.eps, [&w.q, &w.qs], tol) * cq;
            most = most.max(it + 1);
            match newton_test(it, norm, prev, KAPPA) {
                Newton::Converged => {
                    converged = true;
                    break;
                }
                Newton::Failed => break,
                Newton::Continue => prev = norm,
            }
        }
        if !converged {
            return Ok(Attempt::Diverged);
        }
        w.stage_state(i, hg);
    }
    Ok(Attempt::Converged(most))
}

/// `(c_v, c_q) = (hγ, (hγ)²)` of the iteration matrix `S = M + c_v D + c_q K` for a step `h`.
fn rates(h: f64) -> (f64, f64) {
    (h * GAMMA, (h * GAMMA).powi(2))
}

#[allow(clippy::too_many_arguments)]
fn integrate_piece<S: MechanicalSystem>(
    sys: &mut S,
    w: &mut Work,
    opts: &SdirkOptions,
    piece: &Piece,
    h0: Option<f64>,
    t_out: &[f64],
    next: &mut usize,
    output: &mut Output<'_>,
    stats: &mut OdeStats,
) -> Result<(), OdeError> {
    let n = w.q.len();
    let tol = (opts.rtol, opts.atol);
    let mut t = piece.a;
    // consistent accelerations at the start of the piece
    stats.rhs_evals += 1;
    sys.accelerations(piece.clamp(t), &w.q, &w.qd, &mut w.qdd)
        .map_err(rhs_err(t))?;
    if w.qdd.iter().any(|v| !v.is_finite()) {
        return Err(OdeError::NonFinite { t });
    }
    w.h_prev = None;
    w.parts.eval(sys, piece.clamp(t), &w.q, &w.qd, stats)?;
    // renew M, D, K before the next step (its Newton was slow)
    let mut refresh = false;
    let span = piece.b - piece.a;
    let mut h = h0
        .unwrap_or_else(|| {
            first_step(
                &w.parts, &w.q, &w.qd, &w.qdd, tol.0, tol.1, span, piece.hmax,
            )
        })
        .min(piece.hmax)
        .min(span);
    let mut fails_here = 0usize;
    while t < piece.b {
        let t1 = begin_attempt(sys, t, &mut h, piece, stats.steps, opts.max_steps, tol)?;
        if refresh && !w.parts.current {
            // the last step's Newton was slow: M, D, K at the current point
            w.parts.eval(sys, piece.clamp(t), &w.q, &w.qd, stats)?;
        }
        refresh = false;
        // a singular (or non-finite) S fails the attempt as a diverged Newton iteration would;
        // where M follows the stages, the first one factors S
        let ready = w.mass_steps > 0 || w.parts.factor_for(h, rates, stats).is_some();
        let attempt = if ready {
            stages(sys, w, t, h, tol, piece, stats)?
        } else {
            Attempt::Diverged
        };
        // the h of S as the stages left it
        let h_lu = w.parts.factored_for();
        let (Attempt::Converged(iterations), Some(h_lu)) = (attempt, h_lu) else {
            // first remedy: M follows the stages
            let remedy = w.mass_steps == 0;
            w.mass_steps = TRACK_STEPS;
            let (q, qd) = (&w.q, &w.qd);
            w.parts.after_failure(
                sys,
                tol,
                t,
                piece.clamp(t),
                q,
                qd,
                &mut h,
                &mut fails_here,
                remedy,
                stats,
            )?;
            continue;
        };
        let last = STAGES - 1;
        if w.qs.iter().chain(w.vs[last].iter()).any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite { t });
        }
        // embedded error, filtered through (I − hγJ)⁻¹
        w.eq.fill(0.0);
        w.ev.fill(0.0);
        for j in 0..STAGES {
            let c = h * error_weight(j);
            w.eq.axpy(c, &w.vs[j], 1.0);
            w.ev.axpy(c, &w.acc[j], 1.0);
        }
        let hg = h_lu * GAMMA;
        w.tmp.gemv(1.0, &w.parts.m, &w.ev, 0.0);
        w.tmp.gemv(-hg, &w.parts.k, &w.eq, 1.0);
        w.parts.solve(&mut w.tmp);
        w.eq.axpy(hg, &w.tmp, 1.0);
        let err = w.parts.weighted(&w.eq, &w.q, &w.qs, tol.0, tol.1);
        if err.is_nan() || err > 1.0 {
            stats.failed_steps += 1;
            fails_here += 1;
            h *= shrink(err, 0.25);
            continue;
        }
        // accepted: outputs in (t, t1] by quintic Hermite interpolation
        stats.steps += 1;
        fails_here = 0;
        {
            let (q0, v0, a0) = (&w.q, &w.qd, &w.qdd);
            let (q1, v1, a1) = (&w.qs, &w.vs[last], &w.acc[last]);
            deliver(t_out, next, t1, &mut w.out, output, |tau, y| {
                let s = ((tau - t) / h).clamp(0.0, 1.0);
                let (b, db) = quintic_hermite(s);
                let hh = h * h;
                for i in 0..n {
                    let nodes = [q0[i], h * v0[i], hh * a0[i], q1[i], h * v1[i], hh * a1[i]];
                    let (mut x, mut dx) = (0.0, 0.0);
                    for k in 0..6 {
                        x += b[k] * nodes[k];
                        dx += db[k] * nodes[k];
                    }
                    y[i] = x;
                    y[n + i] = dx / h;
                }
            })?;
        }
        t = t1;
        w.q.copy_from(&w.qs);
        w.qd.copy_from(&w.vs[last]);
        std::mem::swap(&mut w.qdd_prev, &mut w.qdd);
        w.qdd.copy_from(&w.acc[last]);
        w.h_prev = Some(h);
        w.parts.current = false;
        refresh = iterations > SLOW_NEWTON;
        w.mass_steps = w.mass_steps.saturating_sub(1);
        h = next_step(h, err, 0.25, piece.hmax);
    }
    Ok(())
}

/// The quintic Hermite basis on `s ∈ [0, 1]` for the nodes `(x₀, h x₀', h² x₀'', x₁, h x₁', h² x₁'')`
/// and its derivative in `s`.
fn quintic_hermite(s: f64) -> ([f64; 6], [f64; 6]) {
    let (s2, s3) = (s * s, s * s * s);
    let (s4, s5) = (s3 * s, s3 * s2);
    let b = [
        1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5,
        s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5,
        0.5 * (s2 - 3.0 * s3 + 3.0 * s4 - s5),
        10.0 * s3 - 15.0 * s4 + 6.0 * s5,
        -4.0 * s3 + 7.0 * s4 - 3.0 * s5,
        0.5 * (s3 - 2.0 * s4 + s5),
    ];
    let db = [
        -30.0 * s2 + 60.0 * s3 - 30.0 * s4,
        1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4,
        0.5 * (2.0 * s - 9.0 * s2 + 12.0 * s3 - 5.0 * s4),
        30.0 * s2 - 60.0 * s3 + 30.0 * s4,
        -12.0 * s2 + 28.0 * s3 - 15.0 * s4,
        0.5 * (3.0 * s2 - 8.0 * s3 + 5.0 * s4),
    ];
    (b, db)
}
