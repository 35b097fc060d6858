//! Solvers: the Powell dogleg trust region for `F(x) = 0` ([`dogleg`]) and static equilibrium
//! ([`statics`]).

pub mod dogleg;
pub mod statics;
