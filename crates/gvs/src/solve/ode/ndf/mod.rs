//! The variable-step, variable-order NDF/BDF integrator (quasi-constant step size, backward
//! differences), after `ode15s` (Shampine & Reichelt 1997). The formulas are in the documentation
//! of the parent module.

use super::corrector::{in_first_order, in_second_order, Corrector};
use super::scaled_norm::ScaledNorm;
use super::{
    check_common, check_tolerances, deliver, invalid, ulp, Clamp, ErrorNorm, MechanicalSystem,
    NdfOptions, OdeError, OdeFailure, OdeStats, OdeSystem, Output,
};
use nalgebra::DVector;

mod formulas;
mod work;

use formulas::GAMMA;
pub(super) use formulas::{coefficients, interpolate, rescale};
use work::Work;

/// Maximum simplified Newton iterations per attempt (`ode15s`'s).
const MAX_IT: usize = 4;
/// The same with the mass-norm error test. Its steps are not limited by the coordinates that move
/// little mass, so their predictor is far from the corrector's solution, and the componentwise
/// Newton test (`Work::newton_norm`) needs more iterations to reach it. Measured on undamped rods
/// (orders ≤ 2, rtol 1e-3; with 4 → 6 → 8): the 4-element fall of 2 s, 3 270 → 1 513 → 941 failed
/// attempts, 368 → 166 → 104 Jacobians, 18 709 → 12 692 → 12 493 residuals; the six-tendon arm
/// without damping, 2 s, 2 316 → 1 709 → 1 371 failed, 101 → 54 → 32 Jacobians; the 12-element
/// fall of 4 s, 174 307 → 154 806 → 138 966 residuals, 461 → 265 → 212 Jacobians; the undamped
/// release of `examples/undamped-release.toml`, 6 s, 9 → 2 Jacobians and a max tip error of
/// 0.71 → 0.65 % L. Energy gained unchanged (within 0.05 % of the largest kinetic energy).
const MAX_IT_MASS_NORM: usize = 8;

/// Validated options.
struct Config {
    rtol: f64,
    /// The absolute tolerance (the smallest of per-component ones), for messages.
    atol: f64,
    maxk: usize,
    hmax: f64,
    h0: Option<f64>,
    max_steps: usize,
    /// `1/((1−κ_k)γ_k)`.
    inv_ga: [f64; 5],
    /// `C_k = κ_k γ_k + 1/(k+1)`.
    erconst: [f64; 5],
    /// Newton iterations per attempt at most: [`MAX_IT`], or [`MAX_IT_MASS_NORM`].
    max_it: usize,
}

fn check_options(
    o: &NdfOptions,
    n: usize,
    t0: f64,
    tf: f64,
    thresh: &mut DVector<f64>,
) -> Result<Config, OdeError> {
    let rtol = o.rtol;
    let atol = match &o.atol_components {
        Some(v) => {
            if v.len() != n {
                return Err(invalid(
                    "atol_components",
                    format!("{} entries, the system has dimension {n}", v.len()),
                ));
            }
            for (i, &a) in v.iter().enumerate() {
                check_tolerances(rtol, a, "atol_components").map_err(|e| match e {
                    OdeError::Invalid { field, message } if field == "atol_components" => {
                        invalid(field, format!("entry {i}: {message}"))
                    }
                    e => e,
                })?;
                thresh[i] = a / rtol;
            }
            v.iter().copied().fold(f64::INFINITY, f64::min)
        }
        None => {
            check_tolerances(rtol, o.atol, "atol")?;
            thresh.fill(o.atol / rtol);
            o.atol
        }
    };
    if !(1..=5).contains(&o.max_order) {
        return Err(invalid(
            "max_order",
            format!("must be in 1..=5, got {}", o.max_order),
        ));
    }
    if let Some(h) = o.initial_step {
        if !(h > 0.0 && h.is_finite()) {
            return Err(invalid(
                "initial_step",
                format!("must be positive and finite, got {h}"),
            ));
        }
    }
    if o.max_step.is_nan() || o.max_step <= 0.0 {
        return Err(invalid(
            "max_step",
            format!("must be positive (infinity: automatic), got {}", o.max_step),
        ));
    }
    if o.max_steps == 0 {
        return Err(invalid("max_steps", "must be at least 1"));
    }
    let auto = 0.1 * (tf - t0).abs();
    let hmax = if o.max_step.is_finite() {
        o.max_step
    } else {
        auto
    };
    // Never below the time resolution, so that every step advances t.
    let hmax = hmax.max(16.0 * ulp(t0.abs().max(tf.abs())));
    let (inv_ga, erconst) = coefficients(o.bdf);
    Ok(Config {
        rtol,
        atol,
        maxk: o.max_order,
        hmax,
        h0: o.initial_step,
        max_steps: o.max_steps,
        inv_ga,
        erconst,
        max_it: match o.error_norm {
            ErrorNorm::Componentwise => MAX_IT,
            ErrorNorm::Mass => MAX_IT_MASS_NORM,
        },
    })
}

/// Integrates `y' = f(t, y)` from `(t0, y0)` to the last of `t_out` with the variable-step,
/// variable-order NDF method of `ode15s` (see the module documentation for the formulas).
///
/// * `t_out`: output times, strictly ascending, `≥ t0`, at least one; `output(t, y)` is called at
///   each, in order, from the interpolating polynomial of the step covering it (the integrator does
///   not step onto them). An output time equal to `t0` receives `y0`.
/// * `breakpoints`: ascending times where `f` is discontinuous (input switches). Those in `(t0, tf)`
///   are stepped onto exactly, and the integration restarts after each (order 1, new initial step,
///   new Jacobian); `f` is only called strictly inside each piece (see the module documentation).
///   Breakpoints outside `(t0, tf)` are ignored, duplicates merged.
/// * On error, every output time before the time reached has been delivered.
///
/// Errors: [`OdeError::Invalid`] for bad options, dimensions, non-finite `y0` or badly ordered
/// times (nothing is integrated); [`OdeError::NonFinite`] when `f` returns NaN/∞ and no smaller
/// step avoids it; [`OdeError::StepSizeUnderflow`] when the error test fails at the minimum step
/// `16 ulp(t)`; [`OdeError::NewtonFailure`] when Newton fails at the minimum step;
/// [`OdeError::Rhs`] as soon as `f` or its Jacobian returns an error; [`OdeError::TooManySteps`].
pub fn integrate_ndf<S: OdeSystem>(
    sys: &mut S,
    t0: f64,
    y0: &DVector<f64>,
    t_out: &[f64],
    breakpoints: &[f64],
    opts: &NdfOptions,
    output: &mut Output<'_>,
) -> Result<OdeStats, OdeFailure> {
    in_first_order(sys, y0, |cs, n, y0| {
        integrate(cs, n, t0, y0, t_out, breakpoints, opts, output)
    })
}

/// [`integrate_ndf`] for a mechanical system `M(q) q̈ = τ(t, q, q̇)` in second-order form, with the
/// state `y = [q; q̇]` (of dimension `2n`) for the differences, the error test and the output: the
/// same method and the same discrete solution, but each Newton iteration evaluates the residual
/// `ε = M q̈ − τ` instead of `M⁻¹ τ` and solves with the `n × n` matrix `M + c D + c² K` (see
/// `corrector`). `output` receives `[q; q̇]`.
#[allow(clippy::too_many_arguments)]
pub fn integrate_ndf_second_order<S: MechanicalSystem>(
    sys: &mut S,
    t0: f64,
    q0: &DVector<f64>,
    qd0: &DVector<f64>,
    t_out: &[f64],
    breakpoints: &[f64],
    opts: &NdfOptions,
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
    opts: &NdfOptions,
    output: &mut Output<'_>,
) -> Result<OdeStats, OdeFailure> {
    let bounds = check_common(n, t0, y0, t_out, breakpoints)?;
    let tf = *bounds.last().unwrap_or(&t0);
    let mut w = Work::new(n);
    let cfg = check_options(opts, n, t0, tf, &mut w.thresh)?;
    if opts.error_norm == ErrorNorm::Mass {
        if !cs.has_mass() {
            return Err(invalid(
                "error_norm",
                "the mass norm needs a mechanical system (integrate_ndf_second_order)",
            )
            .into());
        }
        w.mass_norm = true;
        w.mnorm = ScaledNorm::new(n / 2);
    }
    w.y.copy_from(y0);
    let mut next = 0;
    deliver(t_out, &mut next, t0, &mut w.out, output, |_, b| {
        b.copy_from(y0)
    })?;
    let pieces = bounds.len().saturating_sub(1);
    let result = (0..pieces).try_for_each(|p| {
        let (a, b) = (bounds[p], bounds[p + 1]);
        cs.set_clamp(Clamp::piece(a, p > 0, b, p + 1 < pieces));
        let h0 = if p == 0 { cfg.h0 } else { None };
        integrate_piece(cs, &mut w, &cfg, a, b, h0, t_out, &mut next, output)
    });
    OdeFailure::with(result, cs.stats())
}

/// Integrates the piece `[a, b]` from `w.y` (at `a`) to `b`, leaving `y(b)` in `w.y`.
#[allow(clippy::too_many_arguments)]
fn integrate_piece<C: Corrector>(
    cs: &mut C,
    w: &mut Work,
    cfg: &Config,
    a: f64,
    b: f64,
    h0: Option<f64>,
    t_out: &[f64],
    next: &mut usize,
    output: &mut Output<'_>,
) -> Result<(), OdeError> {
    let n = w.n;
    let rtol = cfg.rtol;
    let hmax = cfg.hmax;
    let inv_ga = &cfg.inv_ga;
    let erconst = &cfg.erconst;
    let mut t = a;

    // Initial slope and Jacobian.
    if !cs.slope(t, t, &w.y, &mut w.yp)? {
        return Err(OdeError::NonFinite { t });
    }
    if !cs.refresh(t, &w.y, &w.thresh)? {
        return Err(OdeError::NonFinite { t });
    }
    let mut jcurrent = true;

    // Initial step (ode15s).
    let mut hmin = 16.0 * ulp(t);
    let span = b - a;
    let mut absh = match h0 {
        Some(h) => hmax.min(hmin.max(h)),
        None => {
            let wt = |i: usize| w.y[i].abs().max(w.thresh[i]);
            let rh =
                1.25 * (0..n).map(|i| (w.yp[i] / wt(i)).abs()).fold(0.0, f64::max) / rtol.sqrt();
            let mut absh = hmax.min(span);
            if absh * rh > 1.0 {
                absh = 1.0 / rh;
            }
            absh = absh.max(hmin);
            // Error ½h²y'' of the first (order-1) step: y'' = ∂f/∂t + J y'.
            let tdel = (t + (f64::EPSILON.sqrt() * t.abs().max((t + absh).abs())).min(absh)) - t;
            if tdel > 0.0 && cs.slope(t, t + tdel, &w.y, &mut w.f)? {
                cs.jacobian_times(&w.yp, &mut w.tmp);
                let ypp = (0..n)
                    .map(|i| (((w.f[i] - w.yp[i]) / tdel + w.tmp[i]) / wt(i)).abs())
                    .fold(0.0, f64::max);
                let rh = 1.25 * (0.5 * ypp / rtol).sqrt();
                absh = hmax.min(span);
                if absh * rh > 1.0 {
                    absh = 1.0 / rh;
                }
                absh = absh.max(hmin);
            }
            absh
        }
    };

    let mut k = 1usize;
    let mut klast = k;
    let mut abshlast = absh;
    w.dif.fill(0.0);
    w.dif.column_mut(0).axpy(absh, &w.yp, 0.0);
    let mut hinvgak = absh * inv_ga[0];
    let mut nconhk = 0usize;
    let mut lu_ok = cs.factor(hinvgak);
    let mut havrate = false;
    let mut rate = 0.0f64;
    let mut done = false;
    let mut at_hmin = false;

    while !done {
        hmin = 16.0 * ulp(t);
        absh = hmax.min(hmin.max(absh));
        if absh == hmin {
            if at_hmin {
                absh = abshlast; // required by step size recovery (ode15s)
            }
            at_hmin = true;
        } else {
            at_hmin = false;
        }
        // Stretch the step if within 10 % of the end of the piece.
        if 1.1 * absh >= b - t {
            absh = b - t;
            done = true;
        }
        if absh != abshlast || k != klast {
            rescale(&mut w.dif, k, absh / abshlast);
            hinvgak = absh * inv_ga[k - 1];
            nconhk = 0;
            lu_ok = cs.factor(hinvgak);
            havrate = false;
        }
        if cs.stats().steps >= cfg.max_steps {
            return Err(OdeError::TooManySteps {
                t,
                max_steps: cfg.max_steps,
            });
        }

        // Advance one step: retry until the error test passes.
        let mut nofailed = true;
        let (tnew, h, err) = loop {
            // Solve the corrector for ynew (retrying with a new Jacobian or a smaller step).
            let (tnew, h) = loop {
                if let Some(reason) = cs.stop_requested() {
                    return Err(OdeError::Stopped { t, reason });
                }
                let tnew = if done { b } else { t + absh };
                let h = tnew - t;
                {
                    let d = w.dif.as_slice();
                    let c = inv_ga[k - 1];
                    for i in 0..n {
                        let (mut p, mut s) = (w.y[i], 0.0);
                        for j in 0..k {
                            let v = d[i + j * n];
                            p += v;
                            s += v * GAMMA[j];
                        }
                        w.pred[i] = p;
                        w.psi[i] = s * c;
                        w.invwt[i] = 1.0 / w.y[i].abs().max(p.abs()).max(w.thresh[i]);
                    }
                }
                if w.mass_norm {
                    if let Some((m, count)) = cs.mass() {
                        w.mnorm.set(m, count);
                    }
                    w.set_mass_scales();
                }
                w.ynew.copy_from(&w.pred);
                w.difkp1.fill(0.0);
                // Newton is measured componentwise whatever the error test's norm (see
                // `Work::newton_norm`)
                let minnrm = 100.0 * f64::EPSILON * w.newton_norm(&w.ynew);

                let mut converged = false;
                let mut nonfinite = false;
                if lu_ok {
                    lu_ok = cs.begin_step(t, tnew, hinvgak, &w.ynew, &w.psi)?;
                }
                if lu_ok {
                    let mut oldnrm = 0.0;
                    for iter in 1..=cfg.max_it {
                        if !cs
                            .correction(t, tnew, hinvgak, &w.ynew, &w.psi, &w.difkp1, &mut w.del)?
                        {
                            nonfinite = true;
                            break;
                        }
                        cs.stats().newton_iterations += 1;
                        let newnrm = w.newton_norm(&w.del);
                        w.difkp1 += &w.del;
                        w.ynew.copy_from(&w.pred);
                        w.ynew += &w.difkp1;
                        if !newnrm.is_finite() {
                            nonfinite = true;
                            break;
                        }
                        if newnrm <= minnrm {
                            converged = true;
                            break;
                        } else if iter == 1 {
                            if havrate {
                                if newnrm * rate / (1.0 - rate) <= 0.05 * rtol {
                                    converged = true; // more stringent when using the old rate
                                    break;
                                }
                            } else {
                                rate = 0.0;
                            }
                        } else if newnrm > 0.9 * oldnrm {
                            break; // too slow
                        } else {
                            rate = (0.9 * rate).max(newnrm / oldnrm);
                            havrate = true;
                            let errit = newnrm * rate / (1.0 - rate);
                            if errit <= 0.5 * rtol {
                                converged = true;
                                break;
                            } else if iter == cfg.max_it
                                || 0.5 * rtol < errit * rate.powi((cfg.max_it - iter) as i32)
                            {
                                break; // too slow
                            }
                        }
                        oldnrm = newnrm;
                    }
                }
                if converged {
                    cs.converged(rate);
                    break (tnew, h);
                }
                // Too slow (or singular iteration matrix, or non-finite values): new Jacobian if
                // the current one is stale, else a smaller step.
                cs.stats().failed_steps += 1;
                cs.stats().newton_failures += 1;
                // (only after an iteration ran: a singular matrix the remedy never reached
                // would be refactored unchanged, for ever)
                if !nonfinite && lu_ok && cs.renew_cheaply() {
                    // retry the step with the cheap remedy first
                } else if !nonfinite && !jcurrent {
                    if !cs.refresh(t, &w.y, &w.thresh)? {
                        return Err(OdeError::NonFinite { t });
                    }
                    jcurrent = true;
                } else if absh <= hmin {
                    return Err(if nonfinite {
                        OdeError::NonFinite { t }
                    } else {
                        OdeError::NewtonFailure {
                            t,
                            tolerances: Some((rtol, cfg.atol)),
                        }
                    });
                } else {
                    abshlast = absh;
                    absh = (0.3 * absh).max(hmin);
                    done = false;
                    rescale(&mut w.dif, k, absh / abshlast);
                    hinvgak = absh * inv_ga[k - 1];
                    nconhk = 0;
                }
                lu_ok = cs.factor(hinvgak);
                havrate = false;
            };

            // Error test: ‖∇^{k+1} y_{n+1}‖·C_k ≤ rtol.
            let err = w.norm(&w.difkp1) * erconst[k - 1];
            if err <= rtol {
                break (tnew, h, err);
            }
            cs.stats().failed_steps += 1;
            if absh <= hmin {
                return Err(OdeError::StepSizeUnderflow {
                    t,
                    h: absh,
                    h_min: hmin,
                    rtol,
                    atol: cfg.atol,
                });
            }
            abshlast = absh;
            if nofailed {
                nofailed = false;
                let mut hopt = absh * (0.833 * (rtol / err).powf(1.0 / (k + 1) as f64)).max(0.1);
                if k > 1 {
                    let errkm1 = w.norm_col(k - 1, true) * erconst[k - 2];
                    let hkm1 = absh * (0.769 * (rtol / errkm1).powf(1.0 / k as f64)).max(0.1);
                    if hkm1 > hopt {
                        hopt = hkm1.min(absh); // no step increase after a failure
                        k -= 1;
                    }
                }
                absh = hmin.max(hopt);
            } else {
                absh = hmin.max(0.5 * absh);
            }
            if absh < abshlast {
                done = false;
            }
            rescale(&mut w.dif, k, absh / abshlast);
            hinvgak = absh * inv_ga[k - 1];
            nconhk = 0;
            lu_ok = cs.factor(hinvgak);
            havrate = false;
        };
        cs.stats().steps += 1;

        // Update the differences to those of ynew: ∇^{k+2}, ∇^{k+1} = difkp1, then ∇^j += ∇^{j+1}.
        {
            let d = w.dif.as_mut_slice();
            for i in 0..n {
                let dk1 = w.difkp1[i];
                d[i + (k + 1) * n] = dk1 - d[i + k * n];
                d[i + k * n] = dk1;
                for j in (0..k).rev() {
                    d[i + j * n] += d[i + (j + 1) * n];
                }
            }
        }

        let (ynew, dif) = (&w.ynew, &w.dif);
        deliver(t_out, next, tnew, &mut w.out, output, |tq, buf| {
            interpolate(tq, tnew, h, ynew, dif, k, buf)
        })?;
        t = tnew;
        w.y.copy_from(&w.ynew);
        w.ynorm = None;
        if done {
            break;
        }

        // Step size and order for the next step.
        klast = k;
        abshlast = absh;
        nconhk = (nconhk + 1).min(cfg.maxk + 2);
        if nconhk >= k + 2 {
            let ratio = |e: f64, safety: f64, p: usize| {
                let temp = safety * (e / rtol).powf(1.0 / p as f64);
                if temp > 0.1 {
                    1.0 / temp
                } else {
                    10.0
                }
            };
            let mut hopt = absh * ratio(err, 1.2, k + 1);
            let mut kopt = k;
            if k > 1 {
                let errkm1 = w.norm_col(k - 1, false) * erconst[k - 2];
                let hkm1 = absh * ratio(errkm1, 1.3, k);
                if hkm1 > hopt {
                    hopt = hkm1;
                    kopt = k - 1;
                }
            }
            if k < cfg.maxk {
                let errkp1 = w.norm_col(k + 1, false) * erconst[k];
                let hkp1 = absh * ratio(errkp1, 1.4, k + 2);
                if hkp1 > hopt {
                    hopt = hkp1;
                    kopt = k + 1;
                }
            }
            if hopt > absh {
                absh = hopt;
                k = kopt;
            }
        }
        jcurrent = false;
    }
    Ok(())
}
