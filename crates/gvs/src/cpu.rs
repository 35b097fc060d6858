//! The vector unit's state after a wide-SIMD kernel.
//!
//! faer's kernels (through `gemm` and `pulp`) choose AVX2 or AVX-512 at run time and may return with
//! the upper halves of the vector registers in use (no `vzeroupper`). This crate is compiled for the
//! baseline x86-64 target, whose scalar and 2-wide float code is legacy-SSE encoded; in that state
//! every such instruction pays a transition penalty. Measured on the engine's forward kinematics
//! (single-tendon arm, 102 points, this project's 2-core AMD EPYC host): 14.5 µs, 34.6 µs after one
//! faer product, 14.5 µs again after [`clear_upper_state`]. A reduced model calls faer in every
//! strain evaluation (the decoder, the stacked basis), so its whole residual ran in that state.
//!
//! Call [`clear_upper_state`] after a faer call on a hot path. Elsewhere it is a no-op.

/// Ends a dirty upper vector-register state (`vzeroupper`) where the CPU has AVX; no-op otherwise.
///
/// Cheap (a cached feature test and one instruction); safe to call anywhere, since no Rust value
/// lives in the upper register halves across a call.
#[inline]
pub fn clear_upper_state() {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU supports AVX (checked just above), the only requirement of `vzeroupper`.
            unsafe { zeroupper() }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn zeroupper() {
    std::arch::x86_64::_mm256_zeroupper();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clearing_the_upper_state_keeps_every_value() {
        // vzeroupper touches only the registers' upper halves, never a live f64 value
        let x: Vec<f64> = (0..64).map(|i| (i as f64).sin()).collect();
        let before: f64 = x.iter().sum();
        clear_upper_state();
        let after: f64 = x.iter().sum();
        assert_eq!(before.to_bits(), after.to_bits());
    }
}
