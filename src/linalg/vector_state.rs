//! The CPU's vector state after faer's kernels.
//!
//! faer's dense products (the gemm crate's hand-written AVX-512 / AVX2 micro-kernels, which run
//! inside its sparse factorisations and triangular solves too) return without `vzeroupper`. Code
//! compiled for baseline x86-64 (legacy-encoded SSE2, as every crate here is) that runs after them
//! with the upper halves of the vector registers dirty has to merge every result into the
//! full-width register, so each instruction waits on the previous value of its destination and
//! independent chains become one long chain. Measured on the plate element (elements/src/plate.rs):
//! 9.4 instead of 3.5 us per element for the tangent without P, and a residual-only sweep after it
//! 5.0 instead of 1.8 us, since the state stays dirty until something clears it. Call
//! [`clean_upper_vector_state`] after any faer call that our own arithmetic follows.

/// Mark the upper halves of the vector registers clean (`vzeroupper`) when the CPU has AVX; a
/// no-op elsewhere.
#[inline]
pub fn clean_upper_vector_state() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX.
        unsafe { zero_upper() }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn zero_upper() {
    std::arch::x86_64::_mm256_zeroupper()
}
