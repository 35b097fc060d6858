//! Fixed-step, second-order, L-stable BDF2 (variable-coefficient form where a step is not of the
//! nominal length), started and restarted after each breakpoint by backward Euler; simplified
//! Newton with an iteration matrix kept across steps and renewed only when Newton stalls — for a
//! first-order system `y' = f(t, y)` ([`integrate_fixed`]) or, with the NDF's second-order
//! corrector, for a mechanical system `M(q) q̈ = τ` ([`integrate_fixed_second_order`]).

use super::corrector::{in_first_order, in_second_order, Corrector};
use super::galpha::MechanicalSystem;
use super::{
    check_common, deliver, invalid, ulp, Clamp, FixedStepOptions, OdeError, OdeFailure, OdeStats,
    OdeSystem, Output,
};
use nalgebra::DVector;

/// After a Jacobian kept across a breakpoint stalled Newton there, it is renewed up front at this
/// many breakpoints, then kept again (and renewed for as many again if it stalls again): a model
/// whose Jacobian every input jump spoils (a POD-4 model of the IV-A arm under a controller: 205
/// failed attempts in 100 periods of one step each, 31 with the renewal, 11 when it renewed at
/// every breakpoint) pays about one renewal per breakpoint, one whose Jacobian rarely is (the full
/// IV-A model, whose renewal costs 1.2 ms) pays a few.
pub(super) const REFRESH_AFTER_STALL: usize = 8;

/// Step halvings allowed when Newton fails with a fresh Jacobian.
const MAX_HALVINGS: u32 = 10;
/// The iteration matrix `I − βJ` is refactored when `β` changes by more than this (relative);
/// a slightly stale `β` only affects the Newton rate, not the solution.
const BETA_REUSE: f64 = 1e-6;
/// BDF2 is used when the step ratio `h_n/h_{n−1}` is at most this (zero-stable below `1 + √2`);
/// otherwise the step is a backward Euler step.
const MAX_RATIO: f64 = 2.0;

struct Work {
    n: usize,
    y: DVector<f64>,
    yprev: DVector<f64>,
    /// The predictor `z⁽⁰⁾`, the Newton iterate `z = z⁽⁰⁾ + d`, and `ψ = z⁽⁰⁾ − s`, so that
    /// `z = s + β f(z)` is the corrector equation `d − β f(z⁽⁰⁾ + d) + ψ = 0` of [`Corrector`].
    z0: DVector<f64>,
    z: DVector<f64>,
    psi: DVector<f64>,
    d: DVector<f64>,
    s: DVector<f64>,
    del: DVector<f64>,
    thresh: DVector<f64>,
    out: DVector<f64>,
}

/// State carried from step to step.
struct State {
    t: f64,
    /// `y_{n−1}` and `h_{n−1}` are valid (no restart since).
    have_prev: bool,
    hprev: f64,
    /// `β` of the current factorization (NaN: none).
    lu_beta: f64,
    lu_ok: bool,
    /// The Jacobian was evaluated at the current `(t, y)`.
    jac_fresh: bool,
    /// Newton contraction rate of the previous solve with the current factorization.
    rate: Option<f64>,
    /// No step accepted yet in the current piece, which starts at a breakpoint (not the first).
    piece_start: bool,
    /// Breakpoints at which to renew the Jacobian up front, because one kept across a breakpoint
    /// stalled Newton there ([`REFRESH_AFTER_STALL`] after each such stall).
    refresh_at_breaks: usize,
}

enum Newton {
    Converged,
    Stalled,
    NonFinite,
    /// The right-hand side refused a Newton iterate (e.g. a trial `q` whose mass matrix is not
    /// positive definite, far from the solution of a step too long): the step fails and is halved
    /// like a stalled one; the error is reported only if the halvings do not help.
    Refused(OdeError),
}

/// Integrates `y' = f(t, y)` from `(t0, y0)` to the last of `t_out` with fixed steps `opts.h` of
/// BDF2 (second order, A- and L-stable), each solved by simplified Newton.
///
/// * Steps: `t_k = a + k·h` from the start `a` of each piece (`t0` or a breakpoint); the last step
///   of a piece is shortened (or stretched by up to 10 %) to land exactly on its end, so every
///   breakpoint is hit by a step. Steps of other than nominal length use the variable-coefficient
///   BDF2; the first step of every piece (and any step more than twice as long as the previous
///   one) is a backward Euler step.
/// * Newton: at most `max_newton` iterations with the iteration matrix `I − βJ` (`β = 2h/3` at the
///   nominal step; in second-order form `M + βD + β²K`, [`integrate_fixed_second_order`]), factored
///   only when `β` changes; converged when `ρ/(1−ρ)‖Δ‖ ≤ newton_tol`
///   (`‖Δ‖ ≤ newton_tol` before a rate `ρ` is known) in the norm `max_i |Δ_i|/max(1, |y_i|)`. The
///   rate measured in one step is carried to the next, so a step can end after one iteration; it is
///   inflated (`ρ ← ρ^0.8`) at every step, which forces a re-measuring second iteration every few
///   steps. The
///   Jacobian (analytic, or forward differences with increment `√eps·max(|y_j|, 1)`) is evaluated
///   at the start and re-evaluated, at most once per step, only when Newton stalls (`ρ > 0.9` or no
///   convergence within `max_newton`) — and up front at the next 8 (`REFRESH_AFTER_STALL`)
///   breakpoints once one kept across a breakpoint stalled there (the input's jump changes it: a
///   tendon's load stiffness scales with its tension; a sampled-data controller's breakpoints come
///   every period); if it still fails, or the right-hand side refuses a Newton
///   iterate (a trial state far from the step's solution), the step is split in halves (up to 10
///   times) before giving up with [`OdeError::NewtonFailure`] (or [`OdeError::NonFinite`] when the
///   failure is a NaN/∞ right-hand side, or the right-hand side's own error).
/// * Output: same contract as [`super::integrate_ndf`]; values between steps come from the
///   quadratic through `y_{n−1}, y_n, y_{n+1}` (the linear interpolant on backward Euler steps):
///   second-order accurate, and built from values only (no derivatives), so a stiff transient
///   cannot make it overshoot by more than a fraction of the step's values.
pub fn integrate_fixed<S: OdeSystem>(
    sys: &mut S,
    t0: f64,
    y0: &DVector<f64>,
    t_out: &[f64],
    breakpoints: &[f64],
    opts: &FixedStepOptions,
    output: &mut Output<'_>,
) -> Result<OdeStats, OdeFailure> {
    in_first_order(sys, y0, |cs, n, y0| {
        integrate(cs, n, t0, y0, t_out, breakpoints, opts, output)
    })
}

/// [`integrate_fixed`] for a mechanical system `M(q) q̈ = τ(t, q, q̇)` in second-order form, with the
/// state `y = [q; q̇]` for the steps and the output: the same BDF2 and the same discrete solution,
/// but Newton runs as the NDF's second-order corrector — each iteration one residual `ε = M q̈ − τ`
/// and a solve with the `n × n` matrix `S = M + βD + β²K` ([`MechanicalSystem::iteration_parts`]),
/// `M` renewed at the predicted configuration after a slow contraction (`ρ > 0.2`) or a failed
/// iteration, before `D` and `K` are (or at every attempt: `opts.mass_renewal`). The first-order
/// form's Jacobian `[0 I; −M⁻¹K −M⁻¹D]` keeps `M` of the configuration where it was evaluated; on
/// the six-tendon arm released under gravity (1 s, h = 0.01 / 0.002 s) its Newton failed 465 /
/// 298 times. `output` receives `[q; q̇]`.
#[allow(clippy::too_many_arguments)]
pub fn integrate_fixed_second_order<S: MechanicalSystem>(
    sys: &mut S,
    t0: f64,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
    t_out: &[f64],
    breakpoints: &[f64],
    opts: &FixedStepOptions,
    output: &mut Output<'_>,
) -> Result<OdeStats, OdeFailure> {
    in_second_order(sys, (q0, qd0), opts.mass_renewal, |cs, n, y0| {
        integrate(cs, n, t0, y0, t_out, breakpoints, opts, output)
    })
}

#[allow(clippy::too_many_arguments)]
fn integrate<C: Corrector>(
    cs: &mut C,
    n: usize,
    t0: f64,
    y0: &DVector<f64>,
    t_out: &[f64],
    breakpoints: &[f64],
    opts: &FixedStepOptions,
    output: &mut Output<'_>,
) -> Result<OdeStats, OdeFailure> {
    let bounds = check_common(n, t0, y0, t_out, breakpoints)?;
    let tf = *bounds.last().unwrap_or(&t0);
    let h = opts.h;
    if !(h > 0.0 && h.is_finite()) {
        return Err(invalid("h", format!("must be positive and finite, got {h}")).into());
    }
    if h < 4.0 * ulp(t0.abs().max(tf.abs())) {
        return Err(invalid(
            "h",
            format!("{h:e} is below the time resolution at t = {tf}"),
        )
        .into());
    }
    if !(opts.newton_tol > 0.0 && opts.newton_tol.is_finite()) {
        return Err(invalid(
            "newton_tol",
            format!("must be positive and finite, got {}", opts.newton_tol),
        )
        .into());
    }
    if opts.max_newton == 0 {
        return Err(invalid("max_newton", "must be at least 1").into());
    }
    let v = || DVector::zeros(n);
    let mut w = Work {
        n,
        y: y0.clone(),
        yprev: v(),
        z0: v(),
        z: v(),
        psi: v(),
        d: v(),
        s: v(),
        del: v(),
        thresh: DVector::from_element(n, 1.0),
        out: v(),
    };
    let mut next = 0;
    deliver(t_out, &mut next, t0, &mut w.out, output, |_, b| {
        b.copy_from(y0)
    })?;
    let mut st = State {
        t: t0,
        have_prev: false,
        hprev: h,
        lu_beta: f64::NAN,
        lu_ok: false,
        jac_fresh: false,
        rate: None,
        piece_start: false,
        refresh_at_breaks: 0,
    };
    let pieces = bounds.len().saturating_sub(1);
    let mut run = || -> Result<(), OdeError> {
        if pieces > 0 {
            cs.set_clamp(Clamp::piece(bounds[0], false, bounds[1], pieces > 1));
            if !cs.refresh(t0, &w.y, &w.thresh)? {
                return Err(OdeError::NonFinite { t: t0 });
            }
            st.jac_fresh = true;
        }
        for p in 0..pieces {
            let (a, b) = (bounds[p], bounds[p + 1]);
            cs.set_clamp(Clamp::piece(a, p > 0, b, p + 1 < pieces));
            st.have_prev = false;
            st.piece_start = p > 0;
            // the input jumped: Newton's rate measured before says nothing of the new piece (a
            // tiny one carried over accepted a first correction far from the root)
            st.rate = None;
            // the input's jump changes the Jacobian (a tendon's load stiffness scales with its
            // tension): once a kept one failed at a breakpoint, it is renewed at each up front
            if p > 0 && st.refresh_at_breaks > 0 && !st.jac_fresh {
                st.refresh_at_breaks -= 1;
                if !cs.refresh(a, &w.y, &w.thresh)? {
                    return Err(OdeError::NonFinite { t: a });
                }
                st.jac_fresh = true;
                st.lu_beta = f64::NAN;
            }
            // Number of steps: the last one is in [0.1h, 1.1h].
            let nsteps = ((b - a) / h - 0.1).ceil().max(1.0) as usize;
            for i in 1..=nsteps {
                let target = if i == nsteps { b } else { a + i as f64 * h };
                advance(cs, &mut w, &mut st, opts, target, t_out, &mut next, output)?;
            }
        }
        Ok(())
    };
    let result = run();
    OdeFailure::with(result, cs.stats())
}

/// Steps from `st.t` to `target` (one step, or halves of it if Newton fails).
#[allow(clippy::too_many_arguments)]
fn advance<C: Corrector>(
    cs: &mut C,
    w: &mut Work,
    st: &mut State,
    opts: &FixedStepOptions,
    target: f64,
    t_out: &[f64],
    next: &mut usize,
    output: &mut Output<'_>,
) -> Result<(), OdeError> {
    let n = w.n;
    let mut halvings = 0u32;
    let mut hs_max = f64::INFINITY;
    while st.t < target {
        let t = st.t;
        if let Some(reason) = cs.stop_requested() {
            return Err(OdeError::Stopped { t, reason });
        }
        let tn = if target - t <= hs_max {
            target
        } else {
            t + hs_max
        };
        let hs = tn - t;
        let omega = hs / st.hprev;
        let bdf2 = st.have_prev && omega <= MAX_RATIO;
        let beta = if bdf2 {
            let c0 = (1.0 + omega) * (1.0 + omega) / (1.0 + 2.0 * omega);
            let c1 = omega * omega / (1.0 + 2.0 * omega);
            for i in 0..n {
                w.s[i] = c0 * w.y[i] - c1 * w.yprev[i];
                w.z0[i] = w.y[i] + omega * (w.y[i] - w.yprev[i]);
            }
            hs * (1.0 + omega) / (1.0 + 2.0 * omega)
        } else {
            w.s.copy_from(&w.y);
            w.z0.copy_from(&w.y);
            hs
        };
        w.psi.copy_from(&w.z0);
        w.psi -= &w.s;
        let reusable = (beta - st.lu_beta).abs() <= BETA_REUSE * beta; // false for NaN (no factorization)
        if !reusable {
            st.lu_ok = cs.factor(beta);
            st.lu_beta = if st.lu_ok { beta } else { f64::NAN };
            st.rate = None;
        }
        let result = if st.lu_ok {
            newton(cs, w, st, opts, t, tn, beta)?
        } else {
            Newton::Stalled
        };
        match result {
            Newton::Converged => {
                cs.stats().steps += 1;
                let (y, yprev, z, hprev) = (&w.y, &w.yprev, &w.z, st.hprev);
                deliver(t_out, next, tn, &mut w.out, output, |tq, buf| {
                    let sg = tq - t;
                    if tq == tn {
                        buf.copy_from(z);
                    } else if bdf2 {
                        let l0 = sg * (sg - hs) / (hprev * (hprev + hs));
                        let l1 = -(sg + hprev) * (sg - hs) / (hprev * hs);
                        let l2 = (sg + hprev) * sg / ((hprev + hs) * hs);
                        for i in 0..buf.len() {
                            buf[i] = l0 * yprev[i] + l1 * y[i] + l2 * z[i];
                        }
                    } else {
                        let l2 = sg / hs;
                        for i in 0..buf.len() {
                            buf[i] = (1.0 - l2) * y[i] + l2 * z[i];
                        }
                    }
                })?;
                std::mem::swap(&mut w.yprev, &mut w.y);
                w.y.copy_from(&w.z);
                st.hprev = hs;
                st.have_prev = true;
                st.t = tn;
                st.jac_fresh = false;
                st.piece_start = false;
            }
            // a cheaper remedy first (the second-order form: `M` at the predicted configuration)
            // (only after an iteration ran: a singular matrix the remedy never reached would be
            // refactored unchanged, for ever)
            Newton::Stalled if st.lu_ok && cs.renew_cheaply() => {
                cs.stats().failed_steps += 1;
                cs.stats().newton_failures += 1;
            }
            Newton::Stalled if !st.jac_fresh => {
                cs.stats().failed_steps += 1;
                cs.stats().newton_failures += 1;
                if st.piece_start {
                    st.refresh_at_breaks = REFRESH_AFTER_STALL;
                }
                if !cs.refresh(t, &w.y, &w.thresh)? {
                    return Err(OdeError::NonFinite { t });
                }
                st.jac_fresh = true;
                st.lu_beta = f64::NAN;
            }
            failure => {
                cs.stats().failed_steps += 1;
                cs.stats().newton_failures += 1;
                if halvings >= MAX_HALVINGS {
                    return Err(match failure {
                        Newton::Refused(e) => e,
                        Newton::NonFinite => OdeError::NonFinite { t },
                        _ => OdeError::NewtonFailure {
                            t,
                            tolerances: None,
                        },
                    });
                }
                halvings += 1;
                hs_max = 0.5 * hs;
            }
        }
    }
    Ok(())
}

/// Solves `z = s + β f(tn, z)` by simplified Newton from the predictor `w.z0`: the corrector
/// equation `d − β f(z⁽⁰⁾ + d) + ψ = 0` with `ψ = z⁽⁰⁾ − s`, one [`Corrector::correction`] per
/// iteration; the iterate is left in `w.z`.
#[allow(clippy::too_many_arguments)]
fn newton<C: Corrector>(
    cs: &mut C,
    w: &mut Work,
    st: &mut State,
    opts: &FixedStepOptions,
    t: f64,
    tn: f64,
    beta: f64,
) -> Result<Newton, OdeError> {
    let n = w.n;
    let tol = opts.newton_tol;
    let mut oldnrm = 0.0;
    w.d.fill(0.0);
    w.z.copy_from(&w.z0);
    // `M` renewed at the predicted configuration if the corrector asks (second-order form)
    if !cs.begin_step(t, tn, beta, &w.z0, &w.psi)? {
        return Ok(Newton::Stalled);
    }
    // The rate carried over from earlier steps is inflated each step (ρ ← ρ^0.8, as RADAU5 does),
    // so that a second iteration, which measures it afresh, is forced every few steps.
    let mut rate = st.rate.map(|r| r.max(f64::EPSILON).powf(0.8));
    st.rate = rate;
    for it in 1..=opts.max_newton {
        match cs.correction(t, tn, beta, &w.z, &w.psi, &w.d, &mut w.del) {
            Ok(true) => {}
            Ok(false) => return Ok(Newton::NonFinite),
            Err(e @ OdeError::Rhs { .. }) => return Ok(Newton::Refused(e)),
            Err(e) => return Err(e),
        }
        cs.stats().newton_iterations += 1;
        w.d += &w.del;
        let mut nrm = 0.0f64;
        for i in 0..n {
            w.z[i] = w.z0[i] + w.d[i];
            nrm = nrm.max(w.del[i].abs() / w.z[i].abs().max(1.0));
        }
        if !(nrm.is_finite() && w.z.iter().all(|v| v.is_finite())) {
            return Ok(Newton::NonFinite);
        }
        if nrm <= 100.0 * f64::EPSILON {
            if it > 1 {
                st.rate = Some(nrm / oldnrm); // converged to roundoff: a tiny rate
            }
            cs.converged(st.rate.unwrap_or(0.0));
            return Ok(Newton::Converged);
        }
        if it > 1 {
            if nrm > 0.9 * oldnrm {
                return Ok(Newton::Stalled);
            }
            let r = nrm / oldnrm;
            rate = Some(rate.map_or(r, |q| r.max(0.9 * q)));
        }
        // after a breakpoint with a Jacobian from before it, a second iteration measures how
        // fast it still contracts: one small correction alone says nothing of that (with ρ near
        // 1 the error is ρ/(1−ρ) times it)
        let measure = it == 1 && st.piece_start && !st.jac_fresh;
        let converged = match rate {
            Some(r) => nrm * r / (1.0 - r) <= tol,
            None => nrm <= tol && !measure,
        };
        if converged {
            st.rate = rate;
            // the rate in use, inflated where it was carried over: it renews `M` more often than
            // the rate measured in this step would (six-tendon under gravity, h = 2 ms: 89 failed
            // attempts against 463)
            cs.converged(rate.unwrap_or(0.0));
            return Ok(Newton::Converged);
        }
        oldnrm = nrm;
    }
    Ok(Newton::Stalled)
}
