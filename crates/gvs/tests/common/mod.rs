//! Helpers shared by the engine's integration tests.
#![allow(dead_code)]

use nalgebra::DVector;

/// Deterministic pseudo-random vector with entries in [-a, a] (an LCG; no dependency, same on every
/// platform).
pub fn pseudo_random(n: usize, seed: u64, a: f64) -> DVector<f64> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    DVector::from_fn(n, |_, _| {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * a
    })
}
