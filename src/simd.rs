//! Whether the hot loops may run four `f64` lanes wide, chosen at run time.
//!
//! The sensor's rasteriser and image formation (`tactile`) and the Gaussian mixture's E- and
//! M-step sums (`recognize`) are compiled twice: for the x86-64 baseline and, behind
//! `#[target_feature]`, four lanes wide. Each wide build does the same IEEE operations in the same
//! order on every lane as its baseline, so the two write the same bits: the wider one only does
//! more at once.

/// Whether the processor running this has AVX2 (always false off x86-64).
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether the processor running this has AVX2 and fused multiply-add (always false off x86-64):
/// the processors on which `matrixmultiply` runs its FMA kernel, whose sums the mixture's
/// triangular products repeat.
pub(crate) fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        has_avx2() && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
