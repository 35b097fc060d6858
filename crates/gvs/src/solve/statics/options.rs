//! The statics solver's options (`[solver]` of a scenario) and the caps that bound one solve.

use crate::error::ModelError;
use serde::{Deserialize, Serialize};

/// Largest `solver.ramp_steps` accepted: 1e4 warm-started stages are far more than any load needs.
pub const MAX_RAMP_STEPS: usize = 10_000;
/// Largest `solver.max_iterations` (per load stage) accepted.
pub const MAX_ITERATIONS: usize = 10_000;
/// Smallest `solver.min_increment` accepted: 20 halvings of a unit increment (`2⁻²⁰ ≈ 9.5e-7`).
pub const MIN_INCREMENT_FLOOR: f64 = 1e-6;
/// Largest number of load stages (including retries after halving) of one solve:
/// `2 · MAX_RAMP_STEPS`, room for the largest ramp plus its retries.
pub const MAX_LOAD_STAGES: usize = 2 * MAX_RAMP_STEPS;
/// Largest number of dogleg iterations over all load stages of one solve.
pub const MAX_TOTAL_ITERATIONS: usize = 100_000;
/// Smallest `solver.ftol` accepted: `1e-14 ≈ 45 ε`. The residual is a sum over the points whose
/// round-off is a few `ε` of its scale (measured on the presets at their equilibria: `‖R‖∞` of
/// 2e-16 … 9e-16 for a scale ≥ 1); a tolerance below it can never be met, and the solve then
/// fails after its ramp and continuation with a misleading hint (`solver.ftol = 1e-30`: "try
/// solver.ramp_steps = 10").
pub const MIN_FTOL: f64 = 1e-14;
/// Largest `solver.ftol` accepted: a residual of 0.1 % of the forces is not an equilibrium.
pub const MAX_FTOL: f64 = 1e-3;
/// Smallest `solver.xtol` accepted: `ε`; a step below `ε (1 + ‖q‖∞)` does not change `q`.
pub const MIN_XTOL: f64 = f64::EPSILON;
/// Largest `solver.xtol` accepted: a step of 0.1 % of the state is progress, not a stall (with
/// `xtol = 1e300` every solve stalled at its first step and the error blamed the load).
pub const MAX_XTOL: f64 = 1e-3;

/// Largest number of coordinates for which [`StaticsJacobian::Auto`] takes forward differences.
///
/// The analytic Jacobian has a fixed cost of about two residuals (the `J` recursion, the tendons'
/// and the backward pass's derivative terms) and a small cost per coordinate; differences cost one
/// residual per coordinate. Measured on the single-tendon arm (102 points, one equilibrium at
/// u = −2.7 N, the same iterations either way), analytic / differences:
/// POD with 1, 2, 3, 4, 6, 8, 12 modes: 191/158, 243/210, 297/265, 355/330, 437/405, 490/488,
/// 674/756 µs; autoencoders (7 hidden layers) with r = 1, 2, 4, 7: 179/141, 364/332, 734/724,
/// 2191/2276 µs. Differences are never slower up to 4 coordinates, but gain 25 % at one coordinate
/// and ~10 % at 2–4, and they stop at the residual tolerance where an analytic Newton step on a
/// nearly linear problem lands at machine precision (the closed-form hanging rod, 2 coordinates:
/// strain within 1e-12 analytic, not with differences). Hence one coordinate only: the one-DOF
/// reduced models, whose accuracy is the reduction's, not the solver's.
pub const DIFFERENCE_MAX_DOF: usize = 1;

/// How the statics solver obtains `∂R/∂q`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StaticsJacobian {
    /// Forward differences up to [`DIFFERENCE_MAX_DOF`] coordinates, analytic above.
    #[default]
    Auto,
    /// The analytic Jacobian (spec §8.2) whatever the size.
    Analytic,
    /// Forward differences `(R(q + h_j e_j) − R(q)) / h_j`, `h_j = √ε · max(1, |q_j|)`:
    /// `n` extra residual evaluations, about `√ε` relative accuracy.
    Differences,
}

/// Options of a statics solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StaticsOptions {
    /// Number of equal load increments (1 = apply everything at once).
    pub ramp_steps: usize,
    /// Smallest load increment tried after halving on failure.
    pub min_increment: f64,
    /// Relative residual tolerance (see the module doc).
    pub ftol: f64,
    /// Step tolerance `‖Δq‖∞ ≤ xtol (1 + ‖q‖∞)` below which a stalled solve is reported.
    pub xtol: f64,
    /// Iteration limit per load stage.
    pub max_iterations: usize,
    /// How `∂R/∂q` is obtained.
    pub jacobian: StaticsJacobian,
    /// Judge every equilibrium reached from the straight rod ([`super::super::stability`]) and,
    /// if it diverges, look for a stable one. `false` skips it: for a large model under
    /// non-conservative loads (follower moments, friction), whose check is an eigenvalue problem
    /// of the model's size (about 3 s at 1806 coordinates, against 0.2 s for the solve), when the
    /// equilibrium is known to be stable. Written out only when `false`, so that a scenario's
    /// serialized form (and every hash of it) is what it was before the option existed.
    #[serde(skip_serializing_if = "is_true")]
    pub check_stability: bool,
}

fn is_true(b: &bool) -> bool {
    *b
}

impl Default for StaticsOptions {
    fn default() -> Self {
        StaticsOptions {
            ramp_steps: 1,
            min_increment: 1.0 / 64.0,
            ftol: 1e-10,
            xtol: 1e-12,
            max_iterations: 400,
            jacobian: StaticsJacobian::Auto,
            check_stability: true,
        }
    }
}

impl StaticsOptions {
    /// Checks every option against its accepted range: `ramp_steps` in [1, [`MAX_RAMP_STEPS`]],
    /// `min_increment` in [[`MIN_INCREMENT_FLOOR`], 1], `ftol` in [[`MIN_FTOL`], [`MAX_FTOL`]],
    /// `xtol` in [[`MIN_XTOL`], [`MAX_XTOL`]], `max_iterations` in [1, [`MAX_ITERATIONS`]].
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(1..=MAX_RAMP_STEPS).contains(&self.ramp_steps) {
            return Err(ModelError::value(
                "solver.ramp_steps",
                self.ramp_steps as f64,
                format!("an integer in [1, {MAX_RAMP_STEPS}]"),
            ));
        }
        crate::error::check_range(
            "solver.min_increment",
            self.min_increment,
            Some((MIN_INCREMENT_FLOOR, true)),
            Some((1.0, true)),
            &format!("a number in [{MIN_INCREMENT_FLOOR:e}, 1]"),
        )?;
        crate::error::check_range(
            "solver.ftol",
            self.ftol,
            Some((MIN_FTOL, true)),
            Some((MAX_FTOL, true)),
            &format!("a number in [{MIN_FTOL:e}, {MAX_FTOL:e}]: below it the residual test asks for less than its round-off"),
        )?;
        crate::error::check_range(
            "solver.xtol",
            self.xtol,
            Some((MIN_XTOL, true)),
            Some((MAX_XTOL, true)),
            &format!("a number in [{MIN_XTOL:e} (the machine epsilon), {MAX_XTOL:e}]: a larger one takes a step that still makes progress for a stall"),
        )?;
        if !(1..=MAX_ITERATIONS).contains(&self.max_iterations) {
            return Err(ModelError::value(
                "solver.max_iterations",
                self.max_iterations as f64,
                format!("an integer in [1, {MAX_ITERATIONS}]"),
            ));
        }
        Ok(())
    }
}
