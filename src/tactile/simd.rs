//! Whether the reading's hot loops may run four `f64` lanes wide.
//!
//! The rasteriser's sample loops and image formation's passes are compiled twice: for the
//! x86-64 baseline (SSE2, two lanes) and, behind `#[target_feature(enable = "avx2")]`, four lanes
//! wide; a reading takes the second where the processor has AVX2. Both run the same IEEE
//! additions, multiplications and comparisons in the same order on every lane (Rust never fuses a
//! multiply and an add), so they write the same bits: the wider one only does more at once.

/// Whether the processor running this has AVX2 (always false off x86-64).
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
