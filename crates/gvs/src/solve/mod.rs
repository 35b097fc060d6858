//! Solvers: the Powell dogleg trust region for `F(x) = 0` ([`dogleg`]), static equilibrium
//! ([`statics`]) with pseudo-arc-length continuation through folds ([`continuation`]), stiff ODE
//! integrators ([`ode`]) and time integration of the rod ([`dynamics`]).

pub mod continuation;
pub mod dogleg;
pub mod dynamics;
pub mod ode;
pub mod statics;

#[cfg(test)]
mod tests_continuation;
