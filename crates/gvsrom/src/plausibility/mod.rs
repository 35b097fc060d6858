//! Plausibility of the loads: an estimate, by linear beam theory on the straight reference rod, of
//! the bending and the axial/shear strain each load implies on its own, so that loads far beyond any
//! elastic range are rejected before solving, naming the load, instead of ending in a
//! non-convergence that names nothing.
//!
//! For a load with internal bending moment `M_b(s)` and internal force `N(s)` at the section `s`
//! (magnitudes, cantilever clamped at X = 0, reference configuration):
//!
//! - implied bending angle `θ = ∫₀ᴸ M_b(s) / EI(s) ds` \[rad\] (the tip rotation of a linear beam);
//! - implied strain `ε = max_s N(s) / EA(s)` for a tendon (axial), `max_s N(s) / min(EA, GA)(s)` for
//!   a force of unknown direction (axial or shear).
//!
//! The resultants per load (all on `s ≤ X` of the load; zero beyond it):
//!
//! | load | `M_b(s)` | `N(s)` |
//! |---|---|---|
//! | tendon k, tension u, offset d(X) on `[a, b]` | `|u| |d(s)|` on `[a, b]` | `|u|` on `[a, b]` |
//! | point wrench at X: force F, moment M | `|M| + |F_b| (X − s)`, its force's `θ` capped at π if world-fixed | `|F|` |
//! | uniform density f, m on `[a, b]` | `|m| ℓ(s) + |f_b| ((b − s)² − (max(s, a) − s)²)/2`, likewise | `|f| ℓ(s)`, `ℓ(s) = b − max(s, a)` |
//! | triangular pulse, peak m̂ | `m̂ ∫ₛᴸ tri(x) dx` | 0 |
//! | gravity g, density ρ | `∫ₛᴸ ρ A(x) |g| (x − s) dx`, `θ` capped at π | `∫ₛᴸ ρ A(x) |g| dx` (on `EA`) |
//! | body of mass m at X, centre of mass c | `m |g| (|c| + X − s)`, `θ` capped at π | `m |g|` (on `EA`) |
//!
//! (`F_b` is the force that bends: a follower force's component across the section, a world-fixed
//! force whole; a world-fixed force, a dead load like gravity, turns the rod at most until it lies
//! along it. The pulse's peak is `magnitude` or `2·magnitude/width` by its convention; friction only lowers a
//! tendon's tension and is ignored. Gravity, a dead load, turns the rod at most until it hangs
//! along it, so its bending counts at most π whatever the linear beam says — a soft cantilever
//! held horizontal droops, it does not coil — and its strain is the hanging rod's stretch, `N/EA`.) The integrals are evaluated on a grid of [`GRID_POINTS`]
//! intervals per division with the sections of that division (trapezoid rule), which also uses the
//! taper: a thin tip and a thick base each count where they are.
//!
//! A load is rejected when `θ > MAX_BENDING` (200 rad, about 30 turns) or `ε > MAX_STRAIN` (1: an
//! axial strain of −1 is the elongation ν₁ = 0, a section squeezed to nothing). The paper's presets
//! stay inside: single-tendon at ±30 N implies about 24 rad and an axial strain of 0.62,
//! six-tendon's full-length tendons at ±30 N about 8.6 rad and 0.095 each, the soft beam at a total
//! moment of 5 N·m (its preset's reading; the coiled beam) at most about 96 rad, at a peak of
//! 5 N·m/m (`soft-beam-peak`) at most about 4 rad.
//!
//! Every product is formed so that an overflow gives `inf` (never `0 · inf = NaN`) and every
//! comparison rejects `inf` and NaN.
//!
//! `estimates` computes `(θ, ε)` of every load; `verdict` rejects the worst beyond the bounds
//! ([`check`]) or names the largest ([`largest_load`]); `state` refuses a computed state beyond ten
//! times the bounds ([`state_violation`]), which ends a dynamics run.

mod estimates;
mod state;
#[cfg(test)]
mod tests;
mod verdict;

pub use state::{
    coordinates_violation, model_state_violation, state_violation, STATE_MAX_BENDING,
    STATE_MAX_STRAIN,
};
pub use verdict::{check, largest_load};

/// The largest tension `|u_k|` \[N\] each tendon may carry on its own before [`check`] refuses
/// it (`∞` for a tendon whose estimate vanishes): where the rod leaves its elastic range. A
/// displacement drive stops there (`gvs::solve::tendon_drive::solve_driven_within`).
pub fn tension_limits<'a>(subject: impl Into<Subject<'a>>) -> Vec<f64> {
    let subject = subject.into();
    let n = subject.model.n_actuators();
    estimates::estimates(&subject, &vec![1.0; n], 1.0, false)
        .iter()
        .take(n)
        .map(|e| match e.severity() {
            s if s > 0.0 => 1.0 / s,
            _ => f64::INFINITY,
        })
        .collect()
}

use gvs::loads::Loads;
use gvs::model::Model;
use gvs::strain::LinearBasis;

/// Largest implied bending angle `θ` accepted \[rad\] (about 30 turns).
pub const MAX_BENDING: f64 = 200.0;
/// Largest implied axial or shear strain accepted.
pub const MAX_STRAIN: f64 = 1.0;
/// Grid intervals per division of the estimate (fewer when the rod has many divisions, at least 4).
pub const GRID_POINTS: usize = 64;

/// What the check reads of a built scenario (the build layer's `Built` converts into it): the model, the
/// scenario's own tensions and its loads. The check depends on the engine only, not on `build`.
#[derive(Clone, Copy)]
pub struct Subject<'a> {
    pub model: &'a Model<LinearBasis>,
    pub u: &'a [f64],
    pub loads: &'a Loads,
}
