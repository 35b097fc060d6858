//! Solvers: the Powell dogleg trust region for `F(x) = 0` ([`dogleg`]), static equilibrium
//! ([`statics`]) with pseudo-arc-length continuation through folds ([`continuation`]), stiff ODE
//! integrators ([`ode`]) and time integration of the rod ([`dynamics`]).

pub mod continuation;
pub mod dogleg;
pub mod dynamics;
pub mod lcp;
pub mod ode;
pub mod stability;
pub mod statics;
pub mod tendon_drive;

/// A check polled by long solver loops (before every step attempt of a simulation, every load stage
/// of a statics ramp and every continuation step): `Some(reason)` stops the solver with that reason
/// (e.g. an interrupt flag set by SIGINT/SIGTERM; keep it as cheap as an atomic load).
pub type StopCheck<'a> = dyn Fn() -> Option<String> + 'a;

/// The check that never stops.
pub fn never_stop() -> Option<String> {
    None
}

#[cfg(test)]
mod tests_continuation;
