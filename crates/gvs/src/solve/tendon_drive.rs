//! Statics with tendons driven by their displacement: a motor that winds a tendon in by `δ` sets
//! its length, `ℓ_k(q) = ℓ_k,rest − δ_k` ([`Model::tendon_lengths`]), and the tension follows.
//!
//! **The problem.** Tendons `k ∈ D` are driven by displacement, the others by tension. Find `q` and
//! the tensions `u_D` with `R(q, u) = 0` (paper eq. 9) and, for each `k ∈ D`, the complementarity
//! of a cable that pulls or goes slack:
//!
//! `u_k ≤ 0`,  `g_k = ℓ_k(q) − ℓ*_k ≤ 0`,  `u_k g_k = 0`,  `ℓ*_k = ℓ_k,rest − δ_k`:
//!
//! taut (`u_k < 0`) at exactly its length, or slack (`u_k = 0`) with the thread's path shorter
//! than the tendon paid out (one at its length without tension is taut at zero tension, not
//! slack: [`Model::held_modes`] holds it). An elastic tendon (axial stiffness `EA_k`,
//! [`crate::actuation::Tendon::axial_stiffness`]) stretches under its tension: its length is
//! `ℓ*_k + c_k |u_k|` with the compliance `c_k = ℓ_k,rest / EA_k`
//! ([`Model::tendon_compliances`]), so `g_k = ℓ_k(q) − ℓ*_k + c_k u_k` and `∂g/∂u = S + diag(c)`
//! below; an inextensible one has `c_k = 0`.
//!
//! **The iteration** (Newton on the tensions, with the statics solver inside). At the equilibrium
//! `q(u)`, the tensions' effect on the lengths is `S = ∂ℓ_D/∂u_D = −∇ℓ_Dᵀ (∂R/∂q)⁻¹ B_D`, from
//! `dR = ∂R/∂q dq + B du = 0`. For frictionless tendons `B_D = ∇ℓ_D` and `−∂R/∂q = K_T` is positive
//! definite at a stable equilibrium, so `S = ∇ℓ_Dᵀ K_T⁻¹ ∇ℓ_D` is a (symmetric positive
//! definite) compliance; friction makes it non-symmetric but leaves it a P-matrix for the
//! attenuations met in practice. The linearized complementarity, `u' ≤ 0`, `g + S(u' − u) ≤ 0`,
//! complementary, is `LCP(S, S u − g)` in `v = −u'` ([`super::lcp`]). Its solution is the next
//! tensions; a step that does not lower the largest violation (or whose statics fails) is halved.
//! Each statics solve starts in one stage from the last equilibrium moved along its tangent,
//! `q + (dq/du) Δu` with `dq/du = −(∂R/∂q)⁻¹ B_D`, and, if that fails or diverges, solves from the
//! straight rod with the options' ramp and continuation.
//!
//! **Bounds.** [`solve_driven_within`] bounds each tension, `|u_k| ≤ limit_k` (the front-end's: where
//! the rod leaves its elastic range); an update is clipped there, and a tendon at its bound whose
//! path is still too long ends the solve at once, instead of chasing an unreachable length through
//! absurd tensions (measured: 12 halvings and 15 s of CPU before, 3 updates now).
//!
//! **Stopping rule.** Every violation — `|g_k|` of a taut tendon, `max(g_k, 0)` of a slack one —
//! at most `max(ftol, 1e-9) · L` ([`DRIVE_TOLERANCE`], `L` the rod's length), with the statics'
//! own residual test met.

use super::lcp::{self, LcpError};
use super::statics::{StaticsError, StaticsOptions, StaticsSolution, StaticsSolver};
use super::StopCheck;
use crate::error::ModelError;
use crate::loads::Loads;
use crate::model::Model;
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};

/// Smallest length tolerance of a drive, relative to the rod's length (the module documentation).
pub const DRIVE_TOLERANCE: f64 = 1e-9;
/// Most tension updates of one solve.
pub const MAX_DRIVE_ITERATIONS: usize = 50;
/// Most halvings of one tension update before the solve is given up.
pub const MAX_DRIVE_HALVINGS: usize = 12;
/// Iteration limit of a statics solve started from the last equilibrium before the solve from the
/// straight rod is tried.
const WARM_ITERATIONS: usize = 50;

/// How an actuator (a tendon) is driven.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Drive {
    /// Its tension `u` \[N\] (negative pulls).
    Tension(f64),
    /// The length `δ` \[m\] its actuator has wound in from the rest length (negative pays out):
    /// `ℓ(q) = ℓ_rest − δ` while taut (pulling), or slack with `ℓ(q) ≤ ℓ_rest − δ`.
    Displacement(f64),
}

/// A converged equilibrium with the tensions the displacements need.
#[derive(Debug, Clone)]
pub struct DrivenSolution {
    /// The last statics solve (at `u`), its counts summed over every solve and the sensitivities'
    /// `∂R/∂q`.
    pub statics: StaticsSolution,
    /// Every actuator's tension \[N\]: the given ones and those found.
    pub u: Vec<f64>,
    /// Per actuator, whether it is driven by displacement and slack (`u = 0`, its path shorter
    /// than the tendon).
    pub slack: Vec<bool>,
    /// The largest violation \[m\] (the module documentation); 0 without displacement drives.
    pub length_error: f64,
    /// Tension updates (0 without displacement drives).
    pub drive_iterations: usize,
    /// Statics solves, the first one included.
    pub statics_solves: usize,
}

/// The tendons' state at one equilibrium.
struct Point {
    sol: StaticsSolution,
    u: Vec<f64>,
    /// `g_k = ℓ_k(q) − ℓ*_k` for `k ∈ D` (in the order of `D`).
    g: Vec<f64>,
    violation: f64,
}

/// Solves the statics of `model` under `loads` with each actuator driven as `drives` says (the
/// module documentation), from the straight rod.
pub fn solve_driven<P: StrainParam>(
    model: &Model<P>,
    options: &StaticsOptions,
    drives: &[Drive],
    loads: &Loads,
    stop: &StopCheck<'_>,
) -> Result<DrivenSolution, StaticsError> {
    let unbounded = vec![f64::INFINITY; drives.len()];
    solve_driven_within(model, options, drives, loads, &unbounded, stop)
}

/// [`solve_driven`] with the tensions of displacement-driven tendons bounded, `|u_k| ≤
/// limits[k]` (e.g. where the rod leaves its elastic range): an update is clipped to the bound,
/// and a tendon that still falls short of its length there ends the solve at once
/// ([`StaticsError::DriveNotReached`]) instead of chasing it through absurd tensions.
pub fn solve_driven_within<P: StrainParam>(
    model: &Model<P>,
    options: &StaticsOptions,
    drives: &[Drive],
    loads: &Loads,
    limits: &[f64],
    stop: &StopCheck<'_>,
) -> Result<DrivenSolution, StaticsError> {
    let na = model.n_actuators();
    if limits.len() != drives.len() {
        return Err(ModelError::invalid(
            "limits",
            format!(
                "{} tension limits for {} drives",
                limits.len(),
                drives.len()
            ),
        )
        .into());
    }
    if drives.len() != na {
        return Err(StaticsError::ActuatorCount {
            expected: na,
            got: drives.len(),
        });
    }
    let rest = model.tendon_rest_lengths();
    let compliance = model.tendon_compliances();
    let mut d = vec![]; // the displacement-driven actuators
    let mut target = vec![];
    let mut stretch = vec![];
    let mut asked = vec![];
    let mut u = vec![0.0; na];
    for (k, drive) in drives.iter().enumerate() {
        match *drive {
            Drive::Tension(v) => u[k] = v,
            Drive::Displacement(delta) => {
                let field = format!("drives[{k}]");
                crate::error::check_finite(&field, delta)?;
                if delta.abs() >= rest[k] {
                    return Err(ModelError::invalid(
                        field,
                        format!(
                            "a displacement of {delta} m: accepted of magnitude below {:.6} m, the tendon's rest length (a tendon cannot be wound in by its whole length)",
                            rest[k]
                        ),
                    )
                    .into());
                }
                d.push(k);
                target.push(rest[k] - delta);
                stretch.push(compliance[k]);
                asked.push(delta);
            }
        }
    }
    let tol = options.ftol.max(DRIVE_TOLERANCE) * model.disc.length();
    let mut solver = StaticsSolver::new(model, options.clone());
    let mut counts = Counts::default();
    let first = solver.solve_interruptible(&u, loads, None, stop)?;
    counts.add(&first);
    let tendons = Driven {
        d: &d,
        target: &target,
        compliance: &stretch,
    };
    let mut at = point(model, &mut solver, first, u, &tendons);
    let mut iterations = 0;
    while at.violation > tol {
        if iterations == MAX_DRIVE_ITERATIONS {
            return Err(not_reached(
                iterations,
                &at,
                tol,
                "the tension updates did not converge".into(),
                (&d, &asked),
            ));
        }
        // a tendon at its tension limit whose path is still too long: the displacement lies
        // beyond the limit
        if let Some(i) = (0..d.len()).find(|&i| at.u[d[i]] <= -limits[d[i]] && at.g[i] > tol) {
            return Err(not_reached(
                iterations,
                &at,
                tol,
                format!(
                    "tendon {} needs more than its tension limit |u| = {:.4} N (beyond the rod's elastic range)",
                    d[i],
                    limits[d[i]]
                ),
                (&d, &asked),
            ));
        }
        iterations += 1;
        let (mut s, dq_du) = sensitivity(model, &mut solver, &at, loads, &d)?;
        // an elastic tendon stretches by c_k |u_k|: `∂g/∂u = S + diag(c)`
        for (i, c) in stretch.iter().enumerate() {
            s[(i, i)] += c;
        }
        // a relative 1e-10 on the diagonal: a compliance only semi-definite (a reduced model with
        // fewer coordinates than pulling tendons, two tendons along one path) still has a solution
        // the pivoting finds, the tension shared by the regularization
        let scale = (0..d.len()).map(|i| s[(i, i)].abs()).fold(0.0, f64::max);
        for i in 0..d.len() {
            s[(i, i)] += 1e-10 * scale;
        }
        counts.jacobians += 1;
        let u_d = DVector::from_fn(d.len(), |i, _| at.u[d[i]]);
        let c = &s * &u_d - DVector::from_column_slice(&at.g);
        let guess: Vec<bool> = u_d.iter().map(|&v| v < 0.0).collect();
        let (v, _) = lcp::solve_lcp(&s, &c, &guess, 1e-12).map_err(|e| {
            let why = match e {
                LcpError::Singular | LcpError::Cycled => "the tendons' compliance S = ∂ℓ/∂u is not a P-matrix (an unstable equilibrium, or a reduced model with fewer coordinates than the tendons that pull)",
            };
            not_reached(iterations, &at, tol, why.into(), (&d, &asked))
        })?;
        let mut alpha = 1.0;
        let mut halvings = 0;
        at = loop {
            let mut u_try = at.u.clone();
            // the tangent predictor q + (dq/du) Δu starts the statics solve
            let mut q_try = at.sol.q.clone();
            for (i, &k) in d.iter().enumerate() {
                let u_next = (-v[i]).max(-limits[k]);
                u_try[k] = at.u[k] + alpha * (u_next - at.u[k]);
                q_try.axpy(u_try[k] - at.u[k], &dq_du.column(i), 1.0);
            }
            let tried = solve_from(
                &mut solver,
                options,
                &u_try,
                loads,
                &q_try,
                stop,
                &mut counts,
            )?;
            if let Some(sol) = tried {
                let next = point(model, &mut solver, sol, u_try, &tendons);
                if next.violation < at.violation {
                    break next;
                }
            }
            halvings += 1;
            if halvings > MAX_DRIVE_HALVINGS {
                return Err(not_reached(
                    iterations,
                    &at,
                    tol,
                    format!(
                        "no tension update lowered the length error, down to a step of {alpha:.1e} of the Newton step ({})",
                        match d.len() > model.n_dof() {
                            true => format!("the model has {} coordinates for {} tendons held at their lengths: a reduced model holds at most as many tendons taut as it has coordinates", model.n_dof(), d.len()),
                            false => "a displacement beyond what the rod can take, or an equilibrium the statics cannot reach".into(),
                        }
                    ),
                    (&d, &asked),
                ));
            }
            alpha *= 0.5;
        };
    }
    // slack: no tension and a path shorter than the tendon (one at its length without tension
    // is taut at zero tension: held, not slack)
    let slack = (0..na)
        .map(|k| match d.iter().position(|&j| j == k) {
            Some(i) => at.u[k] == 0.0 && at.g[i] < -tol,
            None => false,
        })
        .collect();
    let statics_solves = counts.solves;
    let mut statics = at.sol;
    counts.write_into(&mut statics);
    Ok(DrivenSolution {
        statics,
        u: at.u,
        slack,
        length_error: at.violation,
        drive_iterations: iterations,
        statics_solves,
    })
}

/// The displacement-driven tendons: their actuators, unstretched lengths `ℓ*_k` and compliances.
struct Driven<'a> {
    d: &'a [usize],
    target: &'a [f64],
    compliance: &'a [f64],
}

/// The tendons' lengths, their errors `g_k = ℓ_k(q) − ℓ*_k + c_k u_k` (the path against the
/// tendon stretched by its tension) and the largest violation at the equilibrium `sol` under `u`.
fn point<P: StrainParam>(
    model: &Model<P>,
    solver: &mut StaticsSolver<'_, P>,
    sol: StaticsSolution,
    u: Vec<f64>,
    tendons: &Driven<'_>,
) -> Point {
    let lengths = model.tendon_lengths(&sol.q, solver.workspace());
    let d = tendons.d;
    let g: Vec<f64> = (d.iter().zip(tendons.target).zip(tendons.compliance))
        .map(|((&k, t), c)| lengths[k] - t + c * u[k])
        .collect();
    let violation = d
        .iter()
        .zip(&g)
        .map(|(&k, &g)| if u[k] < 0.0 { g.abs() } else { g.max(0.0) })
        .fold(0.0, f64::max);
    Point {
        sol,
        u,
        g,
        violation,
    }
}

/// `S = −∇ℓ_Dᵀ (∂R/∂q)⁻¹ B_D` at the point (the module documentation), and the equilibrium's
/// tangent `dq/du_D = −(∂R/∂q)⁻¹ B_D` (n × |D|).
fn sensitivity<P: StrainParam>(
    model: &Model<P>,
    solver: &mut StaticsSolver<'_, P>,
    at: &Point,
    loads: &Loads,
    d: &[usize],
) -> Result<(DMatrix<f64>, DMatrix<f64>), StaticsError> {
    let n = model.n_dof();
    let q = &at.sol.q;
    let prepared = model.prepare_loads(loads)?;
    let ws = solver.workspace();
    let mut jac = DMatrix::zeros(n, n);
    model.statics_jacobian(q, &at.u, &prepared, ws, &mut jac);
    let b = model.actuation_matrix(q, ws);
    let grad = model.tendon_length_jacobian(q, ws);
    let b_d = DMatrix::from_fn(n, d.len(), |i, j| b[(i, d[j])]);
    let x = -jac.lu().solve(&b_d).ok_or_else(|| {
        StaticsError::Model(ModelError::invalid(
            "drives",
            "the statics Jacobian is singular at the equilibrium: the tensions' effect on the lengths is undefined",
        ))
    })?;
    let s = DMatrix::from_fn(d.len(), d.len(), |i, j| grad.column(d[i]).dot(&x.column(j)));
    Ok((s, x))
}

/// The equilibrium under `u`: from `q` (the tangent predictor) in one stage, else (a failure, or an equilibrium that
/// diverges) from the straight rod with `options`. `Ok(None)` if neither converges.
fn solve_from<P: StrainParam>(
    solver: &mut StaticsSolver<'_, P>,
    options: &StaticsOptions,
    u: &[f64],
    loads: &Loads,
    q: &DVector<f64>,
    stop: &StopCheck<'_>,
    counts: &mut Counts,
) -> Result<Option<StaticsSolution>, StaticsError> {
    solver.options = StaticsOptions {
        ramp_steps: 1,
        min_increment: 1.0,
        max_iterations: options.max_iterations.min(WARM_ITERATIONS),
        ..options.clone()
    };
    let warm = solver.solve_interruptible(u, loads, Some(q), stop);
    solver.options = options.clone();
    match warm {
        Ok(s) if s.divergence.is_none() => {
            counts.add(&s);
            return Ok(Some(s));
        }
        Err(e @ StaticsError::Stopped { .. }) => return Err(e),
        Ok(s) => counts.add(&s),
        Err(_) => counts.solves += 1,
    }
    match solver.solve_interruptible(u, loads, None, stop) {
        Ok(s) => {
            counts.add(&s);
            Ok(Some(s))
        }
        Err(e @ StaticsError::Stopped { .. }) => Err(e),
        Err(_) => {
            counts.solves += 1;
            Ok(None)
        }
    }
}

/// The error of a drive that stopped at `at`, with each displacement-driven tendon's
/// displacement there against the one asked (`drives`: the tendons and their displacements).
fn not_reached(
    iterations: usize,
    at: &Point,
    tol: f64,
    reason: String,
    (d, asked): (&[usize], &[f64]),
) -> StaticsError {
    let reached: Vec<String> = (d.iter().zip(asked).zip(&at.g))
        .map(|((&k, &delta), &g)| {
            format!(
                "tendon {k} at {:.4} mm of the {:.4} mm asked (u = {:.4} N)",
                1e3 * (delta - g),
                1e3 * delta,
                at.u[k]
            )
        })
        .collect();
    StaticsError::DriveNotReached {
        iterations,
        length_error: at.violation,
        tolerance: tol,
        reason: format!("{reason}; reached: {}", reached.join(", ")),
    }
}

/// The work of every statics solve of a driven solve.
#[derive(Default)]
struct Counts {
    solves: usize,
    iterations: usize,
    residuals: usize,
    jacobians: usize,
    stages: usize,
}

impl Counts {
    fn add(&mut self, s: &StaticsSolution) {
        self.solves += 1;
        self.iterations += s.iterations;
        self.residuals += s.residual_evaluations;
        self.jacobians += s.jacobian_evaluations;
        self.stages += s.load_stages;
    }

    /// Writes the sums into the last solve's statistics.
    fn write_into(self, s: &mut StaticsSolution) {
        s.iterations = self.iterations;
        s.residual_evaluations = self.residuals;
        s.jacobian_evaluations = self.jacobians;
        s.load_stages = self.stages;
    }
}
