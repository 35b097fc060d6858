//! What the adaptive one-step methods in second-order form — generalized-α
//! ([`super::integrate_generalized_alpha`]) and SDIRK4 ([`super::integrate_sdirk`]) — share: the
//! checks of their step options, the pieces between breakpoints, the matrices `M, D, K` of the
//! iteration matrix `S = M + c_v D + c_q K` with its factorization and the error norm, the
//! simplified-Newton convergence test, the first step, and what a failed attempt does.

use super::galpha::MechanicalSystem;
use super::scaled_norm::{ScaledNorm, STIFFNESS_WEIGHT};
use super::{invalid, next_down, next_up, rhs_err, ErrorNorm, Lu, OdeError, OdeFailure, OdeStats};
use nalgebra::{DMatrix, DVector};

/// Checks the step options both methods take.
pub(super) fn check_step_options(
    rtol: f64,
    atol: f64,
    max_step: f64,
    initial_step: Option<f64>,
) -> Result<(), OdeError> {
    super::check_tolerances(rtol, atol, "atol")?;
    if max_step.is_nan() || max_step <= 0.0 {
        return Err(invalid("max_step", format!("{max_step} (accepted: > 0)")));
    }
    if let Some(h) = initial_step {
        if !(h > 0.0 && h.is_finite()) {
            return Err(invalid("initial_step", format!("{h} (accepted: > 0)")));
        }
    }
    Ok(())
}

/// One piece `[a, b]` of the integration between breakpoints.
pub(super) struct Piece {
    pub(super) a: f64,
    pub(super) b: f64,
    /// Evaluation times are clamped to `[lo, hi]`: strictly inside where an end is a breakpoint.
    lo: f64,
    hi: f64,
    pub(super) hmax: f64,
}

impl Piece {
    pub(super) fn clamp(&self, t: f64) -> f64 {
        t.max(self.lo).min(self.hi)
    }
}

/// The pieces between the boundaries `bounds` (from [`super::check_common`]), with the maximum
/// step `max_step` (`f64::INFINITY`: a tenth of the whole interval).
pub(super) fn pieces(bounds: &[f64], max_step: f64) -> Vec<Piece> {
    let (t0, tf) = (bounds[0], *bounds.last().unwrap_or(&bounds[0]));
    let hmax = if max_step.is_finite() {
        max_step
    } else {
        0.1 * (tf - t0).abs().max(f64::MIN_POSITIVE)
    };
    let count = bounds.len().saturating_sub(1);
    (0..count)
        .map(|p| Piece {
            a: bounds[p],
            b: bounds[p + 1],
            lo: if p > 0 {
                next_up(bounds[p])
            } else {
                f64::NEG_INFINITY
            },
            hi: if p + 1 < count {
                next_down(bounds[p + 1])
            } else {
                f64::INFINITY
            },
            hmax,
        })
        .collect()
}

/// Integrates the pieces between `bounds` in order with `piece_fn(piece, h0, stats)` (`h0` the
/// first step: `initial_step` on the first piece, automatic on the others); the outcome with the
/// work counted up to its end or its failure.
pub(super) fn over_pieces(
    bounds: &[f64],
    max_step: f64,
    initial_step: Option<f64>,
    mut piece_fn: impl FnMut(&Piece, Option<f64>, &mut OdeStats) -> Result<(), OdeError>,
) -> Result<OdeStats, OdeFailure> {
    let mut stats = OdeStats::default();
    let result = pieces(bounds, max_step)
        .iter()
        .enumerate()
        .try_for_each(|(p, piece)| {
            piece_fn(piece, if p == 0 { initial_step } else { None }, &mut stats)
        });
    OdeFailure::with(result, &stats)
}

/// `M`, `D`, `K` of the iteration matrix, its factorization, and the error norm.
pub(super) struct Parts {
    pub(super) m: DMatrix<f64>,
    pub(super) d: DMatrix<f64>,
    pub(super) k: DMatrix<f64>,
    lu: Lu,
    /// The `h` the factored `S` was built with (`None`: not factored).
    lu_h: Option<f64>,
    /// `‖·‖_M̂` of the `M` in `m` and `‖·‖_K̂` of the `K` in `k` (with [`ErrorNorm::Mass`]), and
    /// the count of `M, D, K` evaluations.
    mnorm: Option<ScaledNorm>,
    knorm: Option<ScaledNorm>,
    m_count: usize,
    /// `D, K` (and `M`, unless a stage renewed it since: [`Self::refactor_with_new_mass`]) are
    /// those of the current point: no step accepted since they were evaluated.
    pub(super) current: bool,
}

impl Parts {
    /// `newton_stiffness`: the Newton test also weighs the stiffness norm
    /// ([`Self::newton_weighted`], with the mass norm only).
    pub(super) fn new(n: usize, norm: ErrorNorm, newton_stiffness: bool) -> Self {
        let mat = || DMatrix::zeros(n, n);
        Parts {
            m: mat(),
            d: mat(),
            k: mat(),
            lu: Lu::new(n),
            lu_h: None,
            mnorm: (norm == ErrorNorm::Mass).then(|| ScaledNorm::new(n)),
            knorm: (norm == ErrorNorm::Mass && newton_stiffness).then(|| ScaledNorm::new(n)),
            m_count: 0,
            current: false,
        }
    }

    /// `M, D, K` at `(t, q, q̇)` (and the norms of the new `M` and `K`); `S` is to be refactored.
    pub(super) fn eval<S: MechanicalSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        stats: &mut OdeStats,
    ) -> Result<(), OdeError> {
        stats.jacobian_evals += 1;
        sys.iteration_parts(t, q, qd, &mut self.m, &mut self.d, &mut self.k)
            .map_err(rhs_err(t))?;
        self.m_count += 1;
        if let Some(mn) = &mut self.mnorm {
            mn.set(&self.m, self.m_count);
        }
        if let Some(kn) = &mut self.knorm {
            kn.set(&self.k, self.m_count);
        }
        self.current = true;
        self.lu_h = None;
        Ok(())
    }

    /// `‖v‖ / (rtol·max(‖x‖, ‖y‖) + atol)`: componentwise (max over `i` of the weighted entries) or
    /// in the mass norm (`‖·‖_M̂`, with `atol` the largest entry's).
    pub(super) fn weighted(
        &self,
        v: &DVector<f64>,
        x: &DVector<f64>,
        y: &DVector<f64>,
        rtol: f64,
        atol: f64,
    ) -> f64 {
        match &self.mnorm {
            None => v
                .iter()
                .zip(x.iter().zip(y.iter()))
                .map(|(v, (x, y))| v.abs() / (rtol * x.abs().max(y.abs()) + atol))
                .fold(0.0, f64::max),
            Some(mn) => mn.relative(v, [x, y], (rtol, atol)),
        }
    }

    /// The norm of a Newton correction's displacement `v` in units of the error test: with the
    /// mass norm, the larger of [`Self::weighted`] and `w_K·‖v‖_K̂ / (rtol·max(‖x‖_K̂, ‖y‖_K̂) +
    /// atol)` in the norm of the stiffness `K` (`K̂ = K·m/tr K`, [`STIFFNESS_WEIGHT`] `w_K`): a
    /// correction must be small both as a mass-weighted displacement and as a strain energy,
    /// relative to the state's. The mass norm alone hardly sees the stiff shear and elongation
    /// coordinates, which move little mass; a Newton iterate stopped with them unconverged acts
    /// as a force no physics supplies and feeds energy into an undamped rod. Componentwise, as
    /// [`Self::weighted`] (each coordinate is already held to its own size).
    pub(super) fn newton_weighted(
        &self,
        v: &DVector<f64>,
        states: [&DVector<f64>; 2],
        (rtol, atol): (f64, f64),
    ) -> f64 {
        let [x, y] = states;
        let by_mass = self.weighted(v, x, y, rtol, atol);
        match &self.knorm {
            Some(kn) if kn.is_set() => {
                let by_stiffness = STIFFNESS_WEIGHT * kn.relative(v, states, (rtol, atol));
                if by_mass.is_nan() || by_stiffness.is_nan() {
                    f64::NAN
                } else {
                    by_mass.max(by_stiffness)
                }
            }
            _ => by_mass,
        }
    }

    /// Factors `S = M + c_v D + c_q K` with `(c_v, c_q) = coefficients(h)` unless it is factored for
    /// a step within 20 % of `h`. Returns the `h` the factored `S` belongs to (`None`: `S` is
    /// singular or not finite).
    pub(super) fn factor_for(
        &mut self,
        h: f64,
        coefficients: impl Fn(f64) -> (f64, f64),
        stats: &mut OdeStats,
    ) -> Option<f64> {
        if let Some(h_lu) = self.lu_h {
            if (h / h_lu - 1.0).abs() <= 0.2 {
                return Some(h_lu);
            }
        }
        let (cv, cq) = coefficients(h);
        let (m, d, k) = (&self.m, &self.d, &self.k);
        let ok = self.lu.factor_with(stats, |s| {
            for (((s, m), d), k) in s.iter_mut().zip(m.iter()).zip(d.iter()).zip(k.iter()) {
                *s = m + cv * d + cq * k;
            }
        });
        self.lu_h = ok.then_some(h);
        self.lu_h
    }

    /// `M` has been renewed in place (at a stage's configuration, by
    /// [`MechanicalSystem::residual_and_mass`]): refactors `S = M + c_v D + c_q K` for `h` with the
    /// `D`, `K` already held. Returns the `h` of the factored `S` (`None`: singular or not finite).
    pub(super) fn refactor_with_new_mass(
        &mut self,
        h: f64,
        coefficients: impl Fn(f64) -> (f64, f64),
        stats: &mut OdeStats,
    ) -> Option<f64> {
        self.lu_h = None;
        self.factor_for(h, coefficients, stats)
    }

    /// The `h` the factored `S` belongs to (`None`: not factored).
    pub(super) fn factored_for(&self) -> Option<f64> {
        self.lu_h
    }

    /// `x ← S⁻¹ x` with the factored `S`.
    pub(super) fn solve(&mut self, x: &mut DVector<f64>) {
        self.lu.solve(x);
    }

    /// After a failed attempt (Newton diverged, or `S` singular): unless the caller has a cheaper
    /// `remedy` for the next attempt (it then retries at the same `h`), renews `M, D, K` at the
    /// current point `(t, q, q̇)` if they are stale, else cuts `h` by 4; stops after 40 failures in a
    /// row, naming the tolerances `tol = (rtol, atol)`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn after_failure<S: MechanicalSystem>(
        &mut self,
        sys: &mut S,
        tol: (f64, f64),
        t: f64,
        t_eval: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        h: &mut f64,
        fails: &mut usize,
        remedy: bool,
        stats: &mut OdeStats,
    ) -> Result<(), OdeError> {
        stats.failed_steps += 1;
        stats.newton_failures += 1;
        *fails += 1;
        if *fails > 40 {
            return Err(OdeError::NewtonFailure {
                t,
                tolerances: Some(tol),
            });
        }
        if remedy {
            // the caller's remedy first, at the same step
        } else if self.current {
            *h *= 0.25;
        } else {
            self.eval(sys, t_eval, q, qd, stats)?;
        }
        Ok(())
    }
}

/// What the simplified-Newton test says after iteration `it` (from 0) with the correction norm
/// `norm` (in units of the error test) and the previous one `prev`: with the rate
/// `ρ = norm/prev`, converged when `ρ/(1−ρ)·norm ≤ κ` (or `norm ≤ κ/10` after one iteration),
/// failed when `ρ > 0.9` or the norm is not finite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Newton {
    Converged,
    Continue,
    Failed,
}

pub(super) fn newton_test(it: usize, norm: f64, prev: f64, kappa: f64) -> Newton {
    if !norm.is_finite() {
        return Newton::Failed;
    }
    if it == 0 {
        return if norm <= 0.1 * kappa {
            Newton::Converged
        } else {
            Newton::Continue
        };
    }
    let rate = norm / prev;
    if rate > 0.9 {
        Newton::Failed
    } else if rate / (1.0 - rate) * norm <= kappa {
        Newton::Converged
    } else {
        Newton::Continue
    }
}

/// The first step of a piece of length `span`: half a tolerance unit of displacement by the
/// velocity, one by the acceleration (`½h²|q̈|`), at most `hmax` and `span`.
#[allow(clippy::too_many_arguments)]
pub(super) fn first_step(
    parts: &Parts,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    qdd: &DVector<f64>,
    rtol: f64,
    atol: f64,
    span: f64,
    hmax: f64,
) -> f64 {
    let zero = DVector::zeros(q.len());
    let vel = parts.weighted(qd, q, &zero, rtol, atol);
    let acc = parts.weighted(qdd, q, &zero, rtol, atol);
    let mut h = span.min(hmax);
    if vel > 0.0 {
        h = h.min(0.5 / vel);
    }
    if acc > 0.0 {
        h = h.min((1.0 / acc).sqrt());
    }
    h
}

/// Before an attempt from `t` with step `h` on `piece`: errors if `h` fell below `16 ulp(t)` (naming
/// the tolerances `tol = (rtol, atol)`), the step budget is spent or `sys` asks to stop
/// ([`MechanicalSystem::stop_requested`]); lands on the end of the piece (stretching `h` by up to
/// 10 %), and returns the end of the step.
#[allow(clippy::too_many_arguments)]
pub(super) fn begin_attempt<S: MechanicalSystem>(
    sys: &mut S,
    t: f64,
    h: &mut f64,
    piece: &Piece,
    steps: usize,
    max_steps: usize,
    tol: (f64, f64),
) -> Result<f64, OdeError> {
    if let Some(reason) = sys.stop_requested() {
        return Err(OdeError::Stopped { t, reason });
    }
    let hmin = 16.0 * super::ulp(t);
    if *h < hmin {
        return Err(OdeError::StepSizeUnderflow {
            t,
            h: *h,
            h_min: hmin,
            rtol: tol.0,
            atol: tol.1,
        });
    }
    if steps >= max_steps {
        return Err(OdeError::TooManySteps { t, max_steps });
    }
    if t + 1.1 * *h >= piece.b {
        *h = piece.b - t;
    }
    Ok(if *h == piece.b - t { piece.b } else { t + *h })
}

/// The factor of `h` after the error test rejected a step with the error `err` (> 1, or NaN):
/// `0.9 err^{−e}` within `[0.2, 0.9]` (`e = 1/(p + 1)` for an estimate of order `p`), or `0.25`
/// for a non-finite error.
pub(super) fn shrink(err: f64, e: f64) -> f64 {
    if err.is_finite() {
        (0.9 * err.powf(-e)).clamp(0.2, 0.9)
    } else {
        0.25
    }
}

/// The step after an accepted one of length `h` with the error `err`:
/// `h·min(2, max(0.2, 0.9 err^{−e}))`, unchanged for an increase below 20 % (so `S` is kept), at
/// most `hmax`.
pub(super) fn next_step(h: f64, err: f64, e: f64, hmax: f64) -> f64 {
    let ratio = (0.9 * err.max(1e-12).powf(-e)).clamp(0.2, 2.0);
    let h = if (1.0..=1.2).contains(&ratio) {
        h
    } else {
        h * ratio
    };
    h.min(hmax)
}

#[cfg(test)]
mod tests {
    use super::super::tests_galpha::Oscillators;
    use super::*;

    /// Two unit masses, one soft (`k = 1`) and one stiff (`k = 10⁶`, like a shear or elongation
    /// coordinate): a correction along the stiff one that the mass norm passes is held to its
    /// strain energy; one along the soft one is measured as before.
    #[test]
    fn the_newton_norm_weighs_a_stiff_correction_by_its_strain_energy() {
        let mut sys = Oscillators {
            m: 1.0,
            c: 0.0,
            k: vec![1.0, 1e6],
            f_after: 0.0,
            t_step: f64::INFINITY,
        };
        let (rtol, atol) = (1e-3, 1e-9);
        let x = DVector::from_column_slice(&[1.0, 1e-3]);
        let zero = DVector::zeros(2);
        let mut stats = OdeStats::default();
        let mut parts = Parts::new(2, ErrorNorm::Mass, true);
        parts.eval(&mut sys, 0.0, &x, &zero, &mut stats).unwrap();
        // M̂ = I; K̂ = K·2/tr K = diag(2/(1+10⁶), 2·10⁶/(1+10⁶))
        let kh = [2.0 / (1.0 + 1e6), 2e6 / (1.0 + 1e6)];
        let k_norm = |v: &[f64]| (kh[0] * v[0] * v[0] + kh[1] * v[1] * v[1]).sqrt();
        let sx = k_norm(&[1.0, 1e-3]);
        let mass_test =
            |v: &[f64]| (v[0] * v[0] + v[1] * v[1]).sqrt() / (rtol * (1.0f64 + 1e-6).sqrt() + atol);
        for (v, stiff_decides) in [([0.0, 1e-6], true), ([1e-4, 0.0], false)] {
            let by_mass = mass_test(&v);
            let by_stiffness = 0.1 * k_norm(&v) / (rtol * sx + atol);
            let dv = DVector::from_column_slice(&v);
            let weighted = parts.weighted(&dv, &x, &x, rtol, atol);
            let newton = parts.newton_weighted(&dv, [&x, &x], (rtol, atol));
            assert!(
                (weighted - by_mass).abs() <= 1e-12 * by_mass,
                "{weighted} {by_mass}"
            );
            let want = by_mass.max(by_stiffness);
            assert!(
                (newton - want).abs() <= 1e-12 * want,
                "{v:?}: {newton} vs {want}"
            );
            assert_eq!(by_stiffness > by_mass, stiff_decides, "{v:?}");
        }
        // the stiff correction: 70 times what the mass norm alone reads
        let dv = DVector::from_column_slice(&[0.0, 1e-6]);
        let ratio = parts.newton_weighted(&dv, [&x, &x], (rtol, atol))
            / parts.weighted(&dv, &x, &x, rtol, atol);
        assert!(ratio > 50.0, "{ratio}");
        // componentwise: each coordinate is already held to its own size, nothing is added
        let mut parts = Parts::new(2, ErrorNorm::Componentwise, true);
        parts.eval(&mut sys, 0.0, &x, &zero, &mut stats).unwrap();
        let (w, n) = (
            parts.weighted(&dv, &x, &x, rtol, atol),
            parts.newton_weighted(&dv, [&x, &x], (rtol, atol)),
        );
        assert_eq!(w, n);
    }
}
