//! Solvers: the Powell dogleg trust region for `F(x) = 0` ([`dogleg`]), static equilibrium
//! ([`statics`]), stiff ODE integrators ([`ode`]) and time integration of the rod ([`dynamics`]).

pub mod dogleg;
pub mod dynamics;
pub mod ode;
pub mod statics;
