//! Reduced-order models for the GVS engine: POD modes and autoencoder decoders learned from strain
//! snapshots, used as the strain parameterization of the same Lagrangian model.
//!
//! - [`map`]: the [`map::CoefficientMap`] interface of a smooth reduced map and its derivatives.
//! - [`reduced`]: reduced strain on the HOM's own basis, `Ψ_s(q_r) = Φ_s P D(q_r)`.
//! - [`metrics`]: strain error (MAE %), RMSE, tip error (% of length).
//! - [`pod`]: POD modes of strain snapshots (thin SVD, faer).
//! - [`nn`]: the autoencoder (tanh MLP, training on eq. 15) and its decoder as a [`map::CoefficientMap`].

mod gemm;
pub mod map;
pub mod metrics;
pub mod nn;
pub mod pod;
pub mod reduced;
