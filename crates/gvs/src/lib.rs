//! # gvs — the Geometric Variable Strain engine
//!
//! A Cosserat rod whose strain field is parameterized by generalized coordinates `q` (paper eq. 2, 3):
//! `ξ(X) = Ψ(X, q) + ξ*(X)`. The pose `g(X)` follows from integrating `g' = g ξ̂` with Magnus
//! (Zanna) collocation; statics and dynamics are projected onto `q` with the geometric Jacobian.
//!
//! Layers: [`lie`] (SE(3) algebra) → [`rod`] (sections, material) → [`discretize`] (points, Magnus
//! sites) → [`strain`] (the [`strain::StrainParam`] trait and bases) → [`model`] (kinematics,
//! generalized forces) with [`actuation`], [`loads`] and [`bodies`] (rigid bodies fixed to the rod) →
//! [`solve`] (statics).
//!
//! Conventions (gvs-spec §1): 6-vectors angular first, `[torsion, bend-y, bend-z, elongation,
//! shear-y, shear-z]`; the rod runs along its local x-axis; SI units.

pub mod actuation;
pub mod bodies;
pub mod cpu;
pub mod discretize;
pub mod dynamics;
pub mod error;
pub mod feedback;
pub mod inputs;
pub mod lie;
pub mod loads;
pub mod model;
pub mod rod;
pub mod solve;
pub mod strain;

pub use error::ModelError;
