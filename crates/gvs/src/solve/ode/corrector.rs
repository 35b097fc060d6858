//! The NDF corrector's Newton iteration for the two forms of a system the integrator accepts.
//!
//! The NDF (parent module) solves, per step, `d − c f(t_{n+1}, y⁽⁰⁾ + d) + ψ = 0` with
//! `c = h/((1−κ_k)γ_k)` for the correction `d = y_{n+1} − y⁽⁰⁾`. How one Newton iteration is done
//! depends on the form of the system:
//!
//! * [`FirstOrder`], `y' = f(t, y)` ([`OdeSystem`]): the simplified Newton step
//!   `(I − c J) Δ = c f(y⁽ⁱ⁾) − ψ − d⁽ⁱ⁾` with `J ≈ ∂f/∂y` (`dim × dim`).
//! * [`SecondOrder`], `M(q) q̈ = τ(t, q, q̇)` ([`MechanicalSystem`]) with `y = [q; v]`: the rows of
//!   `q' = v` are linear, `d_q = c v_{n+1} − ψ_q`, and are satisfied exactly at every iterate; the
//!   rows of `v` are multiplied by `M(q)/c`, which turns them into the residual of the equations of
//!   motion at the acceleration the formula implies,
//!
//!   ```text
//!     ε(d_v) = M(q) a − τ(t, q, v) = 0,   a = (ψ_v + d_v)/c,   v = v⁽⁰⁾ + d_v,   q = q⁽⁰⁾ + c v − ψ_q,
//!   ```
//!
//!   so an iteration costs one evaluation of `ε` — a recursive Newton–Euler pass, no mass matrix,
//!   no factorization of it. Newton runs on the `n` unknowns `d_v` with the `n × n` iteration
//!   matrix `S = M + c D + c² K` (`c ∂ε/∂d_v` with `∂q/∂d_v = c`, `∂a/∂d_v = 1/c`):
//!   `S δ = −c ε`, then `d_v += δ`, `d_q += c δ`. `M`, `D`, `K` come from
//!   [`MechanicalSystem::iteration_parts`] and play the role of the Jacobian: `D` and `K` are
//!   evaluated at the start and when Newton fails, as the Jacobian of the first-order form. `M`
//!   goes stale faster: unlike `I − c J`, whose leading term is exact, `S`'s leading term is `M`
//!   itself, so with an `M` kept from earlier steps the iteration contracts only as fast as
//!   `M_old⁻¹ M(q)` is close to `I` (on the six-tendon arm's large rotations without gravity,
//!   `six-tendon-no-gravity`, 10 s: 9 286 failed of 14 414 steps with `M` renewed only with `D` and
//!   `K`, 79 of 2 368 with `M` renewed at every attempt). So `M` alone is renewed ([`MechanicalSystem::mass`], one forward pass with
//!   Jacobians and a blocked product: far cheaper than `K`) at the predicted configuration of the
//!   next attempt when Newton fails, before `D` and `K` are, and of the next step when the last
//!   one contracted slower than `ρ = 0.2`; `S` is refactored with it ([`MassRenewal::WhenSlow`]), or
//!   at every attempt ([`MassRenewal::EveryAttempt`]: for a decoder's reduced model, IV-C2's AE-7,
//!   10 s, 1 009 failed attempts of 3 408, 764 in Newton, against 322 and 86), then from the same
//!   forward pass as the attempt's first residual, which is evaluated at the predicted
//!   configuration ([`MechanicalSystem::residual_and_mass`]). The
//!   discrete solution is the same as with [`FirstOrder`] (the same corrector equation); only the
//!   way Newton reaches it differs.

use super::{
    mechanical_state, rhs_err, Clamp, Counted, JacWork, Lu, MassRenewal, MechanicalSystem,
    OdeError, OdeFailure, OdeStats, OdeSystem,
};
use nalgebra::{DMatrix, DVector};

/// Runs `integrate(corrector, dim, y0)` with the first-order corrector of `sys` and `y0` as given:
/// the entry points of the first-order form.
pub(super) fn in_first_order<S: OdeSystem>(
    sys: &mut S,
    y0: &DVector<f64>,
    integrate: impl FnOnce(&mut FirstOrder<'_, S>, usize, &DVector<f64>) -> Result<OdeStats, OdeFailure>,
) -> Result<OdeStats, OdeFailure> {
    let n = sys.dim();
    integrate(&mut FirstOrder::new(sys), n, y0)
}

/// Runs `integrate(corrector, 2n, [q0; q̇0])` with the second-order corrector of `sys` (`M`
/// renewed as `renewal` says): the entry points of the second-order form.
pub(super) fn in_second_order<S: MechanicalSystem>(
    sys: &mut S,
    (q0, qd0): (&DVector<f64>, &DVector<f64>),
    renewal: MassRenewal,
    integrate: impl FnOnce(
        &mut SecondOrder<'_, S>,
        usize,
        &DVector<f64>,
    ) -> Result<OdeStats, OdeFailure>,
) -> Result<OdeStats, OdeFailure> {
    let n = sys.dim();
    let y0 = mechanical_state(n, q0, qd0)?;
    integrate(&mut SecondOrder::new(sys, renewal), 2 * n, &y0)
}

/// One Newton iteration of the NDF corrector and what it needs (see the module documentation).
pub(super) trait Corrector {
    /// Work counters.
    fn stats(&mut self) -> &mut OdeStats;
    /// Evaluation times of the current piece.
    fn set_clamp(&mut self, clamp: Clamp);
    /// `yp = f(t, y)`; `Ok(false)` if it is not finite. `t_acc` is the last accepted time (errors).
    fn slope(
        &mut self,
        t_acc: f64,
        t: f64,
        y: &DVector<f64>,
        yp: &mut DVector<f64>,
    ) -> Result<bool, OdeError>;
    /// Evaluates the Jacobian (or its parts) at `(t, y)`; `Ok(false)` if not finite.
    fn refresh(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        thresh: &DVector<f64>,
    ) -> Result<bool, OdeError>;
    /// `out = J x` with the last Jacobian (for the initial step size).
    fn jacobian_times(&mut self, x: &DVector<f64>, out: &mut DVector<f64>);
    /// Factors the iteration matrix for the coefficient `c`; `false` if singular or not finite.
    fn factor(&mut self, c: f64) -> bool;
    /// Called before the Newton iteration of each attempt, at the predictor `ynew = y⁽⁰⁾`
    /// (`d = 0`) with the step's `c`; returns whether the iteration matrix is usable.
    fn begin_step(
        &mut self,
        _t_acc: f64,
        _tnew: f64,
        _c: f64,
        _ynew: &DVector<f64>,
        _psi: &DVector<f64>,
    ) -> Result<bool, OdeError> {
        Ok(true)
    }
    /// After a failed Newton iteration: whether a remedy cheaper than a new Jacobian remains for
    /// the next attempt at the same step (it is then applied by [`Corrector::begin_step`]).
    fn renew_cheaply(&mut self) -> bool {
        false
    }
    /// After a converged Newton iteration, with its contraction rate estimate.
    fn converged(&mut self, _rate: f64) {}
    /// The system's [`OdeSystem::stop_requested`] (or [`MechanicalSystem::stop_requested`]),
    /// polled before every attempt.
    fn stop_requested(&mut self) -> Option<String>;
    /// Whether the system has a mass matrix ([`Corrector::mass`]).
    fn has_mass(&self) -> bool {
        false
    }
    /// The latest mass matrix of a mechanical system (after the first [`Corrector::refresh`]),
    /// with the number of times it has been evaluated (it changes exactly when `M` does).
    fn mass(&self) -> Option<(&DMatrix<f64>, usize)> {
        None
    }
    /// The Newton correction `del` of `d` at the iterate `ynew = y⁽⁰⁾ + d`; `Ok(false)` if an
    /// evaluation is not finite.
    #[allow(clippy::too_many_arguments)]
    fn correction(
        &mut self,
        t_acc: f64,
        tnew: f64,
        c: f64,
        ynew: &DVector<f64>,
        psi: &DVector<f64>,
        d: &DVector<f64>,
        del: &mut DVector<f64>,
    ) -> Result<bool, OdeError>;
}

/// `y' = f(t, y)` with the full `dim × dim` iteration matrix `I − c J`.
pub(super) struct FirstOrder<'a, S: OdeSystem> {
    cs: Counted<'a, S>,
    jac: DMatrix<f64>,
    lu: Lu,
    jw: JacWork,
    f: DVector<f64>,
}

impl<'a, S: OdeSystem> FirstOrder<'a, S> {
    pub(super) fn new(sys: &'a mut S) -> Self {
        let n = sys.dim();
        FirstOrder {
            cs: Counted::new(sys),
            jac: DMatrix::zeros(n, n),
            lu: Lu::new(n),
            jw: JacWork::new(n),
            f: DVector::zeros(n),
        }
    }
}

impl<S: OdeSystem> Corrector for FirstOrder<'_, S> {
    fn stats(&mut self) -> &mut OdeStats {
        &mut self.cs.stats
    }

    fn stop_requested(&mut self) -> Option<String> {
        self.cs.sys.stop_requested()
    }

    fn set_clamp(&mut self, clamp: Clamp) {
        self.cs.clamp = clamp;
    }

    fn slope(
        &mut self,
        t_acc: f64,
        t: f64,
        y: &DVector<f64>,
        yp: &mut DVector<f64>,
    ) -> Result<bool, OdeError> {
        self.cs.f(t_acc, t, y, yp)
    }

    fn refresh(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        thresh: &DVector<f64>,
    ) -> Result<bool, OdeError> {
        self.cs.jacobian(t, y, thresh, &mut self.jac, &mut self.jw)
    }

    fn jacobian_times(&mut self, x: &DVector<f64>, out: &mut DVector<f64>) {
        out.gemv(1.0, &self.jac, x, 0.0);
    }

    fn factor(&mut self, c: f64) -> bool {
        self.lu.factor(c, &self.jac, &mut self.cs.stats)
    }

    fn correction(
        &mut self,
        t_acc: f64,
        tnew: f64,
        c: f64,
        ynew: &DVector<f64>,
        psi: &DVector<f64>,
        d: &DVector<f64>,
        del: &mut DVector<f64>,
    ) -> Result<bool, OdeError> {
        if !self.cs.f(t_acc, tnew, ynew, &mut self.f)? {
            return Ok(false);
        }
        for i in 0..del.len() {
            del[i] = c * self.f[i] - (psi[i] + d[i]);
        }
        self.lu.solve(del);
        Ok(true)
    }
}

/// A converged Newton iteration slower than this renews `M` for the next step ([`SecondOrder`]).
const SLOW_RATE: f64 = 0.2;

/// `M(q) q̈ = τ(t, q, q̇)`, `y = [q; q̇]`, with the `n × n` iteration matrix `M + c D + c² K`.
pub(super) struct SecondOrder<'a, S: MechanicalSystem> {
    sys: &'a mut S,
    stats: OdeStats,
    clamp: Clamp,
    n: usize,
    m: DMatrix<f64>,
    d: DMatrix<f64>,
    k: DMatrix<f64>,
    /// Factors of `S` (Newton) and of `M` (the initial step's `J x`).
    lu: Lu,
    lu_m: Lu,
    m_factored: bool,
    /// Evaluations of `M` so far.
    m_evals: usize,
    /// Renew `M` at the next attempt's predicted configuration.
    m_renew: bool,
    /// Whether `M` was renewed for the current attempt.
    m_renewed: bool,
    renewal: MassRenewal,
    /// Renew `M` with the next residual (and refactor `S`): the first of an attempt, whose
    /// configuration is the predicted one.
    m_with_residual: bool,
    q: DVector<f64>,
    v: DVector<f64>,
    a: DVector<f64>,
    eps: DVector<f64>,
}

impl<'a, S: MechanicalSystem> SecondOrder<'a, S> {
    pub(super) fn new(sys: &'a mut S, renewal: MassRenewal) -> Self {
        let n = sys.dim();
        let v = || DVector::zeros(n);
        let mat = || DMatrix::zeros(n, n);
        SecondOrder {
            sys,
            stats: OdeStats::default(),
            clamp: Clamp::default(),
            n,
            m: mat(),
            d: mat(),
            k: mat(),
            lu: Lu::new(n),
            lu_m: Lu::new(n),
            m_factored: false,
            m_evals: 0,
            m_renew: false,
            m_renewed: false,
            renewal,
            m_with_residual: false,
            q: v(),
            v: v(),
            a: v(),
            eps: v(),
        }
    }
}

impl<S: MechanicalSystem> Corrector for SecondOrder<'_, S> {
    fn stats(&mut self) -> &mut OdeStats {
        &mut self.stats
    }

    fn stop_requested(&mut self) -> Option<String> {
        self.sys.stop_requested()
    }

    fn set_clamp(&mut self, clamp: Clamp) {
        self.clamp = clamp;
    }

    fn slope(
        &mut self,
        t_acc: f64,
        t: f64,
        y: &DVector<f64>,
        yp: &mut DVector<f64>,
    ) -> Result<bool, OdeError> {
        let n = self.n;
        self.stats.rhs_evals += 1;
        self.q.copy_from(&y.rows(0, n));
        self.v.copy_from(&y.rows(n, n));
        self.sys
            .accelerations(self.clamp.apply(t), &self.q, &self.v, &mut self.a)
            .map_err(rhs_err(t_acc))?;
        yp.rows_mut(0, n).copy_from(&self.v);
        yp.rows_mut(n, n).copy_from(&self.a);
        Ok(yp.iter().all(|x| x.is_finite()))
    }

    fn refresh(
        &mut self,
        t: f64,
        y: &DVector<f64>,
        _thresh: &DVector<f64>,
    ) -> Result<bool, OdeError> {
        let n = self.n;
        self.stats.jacobian_evals += 1;
        self.q.copy_from(&y.rows(0, n));
        self.v.copy_from(&y.rows(n, n));
        self.sys
            .iteration_parts(
                self.clamp.apply(t),
                &self.q,
                &self.v,
                &mut self.m,
                &mut self.d,
                &mut self.k,
            )
            .map_err(rhs_err(t))?;
        self.m_factored = false;
        self.m_evals += 1;
        let finite = |a: &DMatrix<f64>| a.iter().all(|x| x.is_finite());
        Ok(finite(&self.m) && finite(&self.d) && finite(&self.k))
    }

    /// `J x = [x_v; −M⁻¹ (K x_q + D x_v)]`.
    fn jacobian_times(&mut self, x: &DVector<f64>, out: &mut DVector<f64>) {
        let n = self.n;
        if !self.m_factored {
            let m = &self.m;
            self.m_factored = self.lu_m.factor_with(&mut self.stats, |a| a.copy_from(m));
        }
        if !self.m_factored {
            out.fill(0.0);
            return;
        }
        self.eps.gemv(1.0, &self.k, &x.rows(0, n), 0.0);
        self.eps.gemv(1.0, &self.d, &x.rows(n, n), 1.0);
        self.lu_m.solve(&mut self.eps);
        out.rows_mut(0, n).copy_from(&x.rows(n, n));
        out.rows_mut(n, n).copy_from(&self.eps);
        out.rows_mut(n, n).neg_mut();
    }

    fn factor(&mut self, c: f64) -> bool {
        let (m, d, k) = (&self.m, &self.d, &self.k);
        let c2 = c * c;
        self.lu.factor_with(&mut self.stats, |s| {
            for (((s, m), d), k) in s.iter_mut().zip(m.iter()).zip(d.iter()).zip(k.iter()) {
                *s = m + c * d + c2 * k;
            }
        })
    }

    /// When asked ([`Corrector::renew_cheaply`], or a slow contraction in the last step): `M` at
    /// the predicted configuration `q = q⁽⁰⁾ + c v⁽⁰⁾ − ψ_q`, and `S` refactored with it.
    fn begin_step(
        &mut self,
        t_acc: f64,
        tnew: f64,
        c: f64,
        ynew: &DVector<f64>,
        psi: &DVector<f64>,
    ) -> Result<bool, OdeError> {
        if self.renewal == MassRenewal::EveryAttempt {
            // at the first residual's configuration, from the same forward pass (`correction`)
            self.m_with_residual = true;
            self.m_renewed = true;
            return Ok(true);
        }
        self.m_renewed = self.m_renew;
        if !self.m_renew {
            return Ok(true);
        }
        self.m_renew = false;
        let n = self.n;
        for i in 0..n {
            self.q[i] = ynew[i] + c * ynew[n + i] - psi[i];
        }
        self.sys
            .mass(self.clamp.apply(tnew), &self.q, &mut self.m)
            .map_err(rhs_err(t_acc))?;
        self.m_factored = false;
        self.m_evals += 1;
        if !self.m.iter().all(|x| x.is_finite()) {
            return Ok(false);
        }
        Ok(self.factor(c))
    }

    /// Renewing `M` (if not done for this attempt already).
    fn renew_cheaply(&mut self) -> bool {
        self.m_renew = !self.m_renewed;
        self.m_renew
    }

    fn has_mass(&self) -> bool {
        true
    }

    fn mass(&self) -> Option<(&DMatrix<f64>, usize)> {
        Some((&self.m, self.m_evals))
    }

    /// A slow contraction (`ρ > 0.2`) renews `M` for the next step.
    fn converged(&mut self, rate: f64) {
        if rate > SLOW_RATE {
            self.m_renew = true;
        }
    }

    fn correction(
        &mut self,
        t_acc: f64,
        tnew: f64,
        c: f64,
        ynew: &DVector<f64>,
        psi: &DVector<f64>,
        d: &DVector<f64>,
        del: &mut DVector<f64>,
    ) -> Result<bool, OdeError> {
        let n = self.n;
        // q-rows made exact: q = q⁽⁰⁾ + c v − ψ_q, i.e. d_q += r_q
        for i in 0..n {
            let r_q = c * ynew[n + i] - (psi[i] + d[i]);
            del[i] = r_q;
            self.q[i] = ynew[i] + r_q;
            self.v[i] = ynew[n + i];
            self.a[i] = (psi[n + i] + d[n + i]) / c;
        }
        self.stats.rhs_evals += 1;
        if self.m_with_residual {
            self.m_with_residual = false;
            self.sys
                .residual_and_mass(
                    self.clamp.apply(tnew),
                    &self.q,
                    &self.v,
                    &self.a,
                    &mut self.eps,
                    &mut self.m,
                )
                .map_err(rhs_err(t_acc))?;
            self.m_factored = false;
            self.m_evals += 1;
            if !self.m.iter().all(|x| x.is_finite()) || !self.factor(c) {
                return Ok(false);
            }
        } else {
            self.sys
                .residual(
                    self.clamp.apply(tnew),
                    &self.q,
                    &self.v,
                    &self.a,
                    &mut self.eps,
                )
                .map_err(rhs_err(t_acc))?;
        }
        if !self.eps.iter().all(|x| x.is_finite()) {
            return Ok(false);
        }
        self.eps *= -c;
        self.lu.solve(&mut self.eps);
        for i in 0..n {
            let delta = self.eps[i];
            del[i] += c * delta;
            del[n + i] = delta;
        }
        Ok(true)
    }
}
