//! Reduced-order models for the GVS engine: POD modes and autoencoder decoders learned from strain
//! snapshots, used as the strain parameterization of the same Lagrangian model.
//!
//! - [`map`]: the [`map::CoefficientMap`] interface of a smooth reduced map and its derivatives.
//! - [`nn`]: the autoencoder (tanh MLP, training on eq. 15) and its decoder as a [`map::CoefficientMap`].

pub mod map;
pub mod nn;
