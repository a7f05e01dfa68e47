//! Whether the hot loops may run four `f64` lanes wide, chosen at run time.
//!
//! The sensor's rasteriser and image formation (`tactile`) and the Gaussian mixture's E- and
//! M-step sums (`recognize`) are compiled twice: for the x86-64 baseline and, behind
//! `#[target_feature]`, four lanes wide. Each wide build does the same IEEE operations in the same
//! order on every lane as its baseline, so the two write the same bits: the wider one only does
//! more at once. [`dot`] is the baseline's inner product that the sensor's formation and MR-8's
//! filter responses share.

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

/// `sum_i a_i b_i` in four interleaved partial sums, added in a fixed order (so the result is
/// too): the additions pipeline and the loop vectorises on the baseline. The image formation's
/// four-lane pass (`tactile::formation`) writes these bits; MR-8's filter responses are most of
/// its time.
#[inline(always)]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut lanes = [0.0; 4];
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    let rest: f64 = a4
        .remainder()
        .iter()
        .zip(b4.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in a4.zip(b4) {
        for k in 0..4 {
            lanes[k] += x[k] * y[k];
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + rest
}
