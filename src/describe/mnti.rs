//! MNTI, moment-normalized translation-invariant (Sec. IV-B6): Moment-Normalized up to its
//! vectorisation, then the magnitudes of the 2-D Fourier transform.
//!
//! A translation of the image is a phase factor on its DFT, so the magnitudes ignore it (and a
//! half turn, which conjugates the DFT of a real image: the skew test of step 3 of
//! [`MomentNormalized`] no longer matters). The DFT treats the image as periodic, so to avoid the
//! jump at the wrap-around the turned image is first padded to `ratio` (1.5, "150%") times its size
//! with ramps from each border pixel linearly down to zero (separably: rows, then columns):
//!
//! ```text
//! pad pixel k = 1..w beyond a border pixel of value b, on a side of width w:  b (1 - k / (w + 1))
//! ```
//!
//! The padding is split evenly before and after (one more after when odd). Output: `|X[k_r, k_c]|`
//! of the padded `R x C` image for `k_c = 0 ..= C/2` (the rest mirrors it, [`FftPlans::magnitudes_2d`]),
//! `R (C/2 + 1)` values: 9 x 5 = 45 for 6x6, 21 x 11 = 231 for 14x14, 39 x 20 = 780 for 26x26.
//! All-zero image: all zeros. Saturated image: the magnitudes of the padded disc.

use serde::{Deserialize, Serialize};

use super::fft::FftPlans;
use super::moment_normalized::{MomentNormalized, MomentNormalizedParams};
use super::plane::Plane;
use super::{Descriptor, DescriptorKind, DescriptorParams, Feature, ParamsError};
use crate::tactile::TactileImage;
use crate::valid::{Check, Valid};

/// Parameters of [`Mnti`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MntiParams {
    /// Divide by the mean intensity in the disc first, as Moment-Normalized does. Default true.
    pub normalize_intensity: bool,
    /// Padded size over original size, per axis, in [1, 4]. Default 1.5 (Sec. IV-B6).
    pub padded_size_ratio: f64,
}

impl Default for MntiParams {
    fn default() -> Self {
        Self {
            normalize_intensity: true,
            padded_size_ratio: 1.5,
        }
    }
}

impl Check for MntiParams {
    type Error = ParamsError;

    fn check(&self) -> Result<(), ParamsError> {
        let Self {
            normalize_intensity: _,
            padded_size_ratio: r,
        } = *self;
        if !(r.is_finite() && (1.0..=4.0).contains(&r)) {
            return Err(ParamsError::OutOfRange {
                field: "mnti.padded_size_ratio",
                value: r,
                expected: "a ratio in [1, 4]",
            });
        }
        Ok(())
    }
}

/// Sec. IV-B6 (module docs).
#[derive(Debug, Default)]
pub struct Mnti {
    params: MntiParams,
    moment_normalized: MomentNormalized,
    plans: FftPlans,
}

impl Mnti {
    /// The descriptor of checked parameters (`Valid::new(MntiParams { .. })?`).
    pub fn new(params: Valid<MntiParams>) -> Self {
        let params = params.into_inner();
        let moment = MomentNormalizedParams {
            normalize_intensity: params.normalize_intensity,
        };
        Self {
            params,
            moment_normalized: MomentNormalized::new(moment),
            plans: FftPlans::new(),
        }
    }

    /// The padded size of a side of `n` pixels: `round(ratio n)`, at least `n`.
    fn padded_len(&self, n: usize) -> usize {
        ((n as f64 * self.params.padded_size_ratio).round() as usize).max(n)
    }
}

impl Descriptor for Mnti {
    fn kind(&self) -> DescriptorKind {
        DescriptorKind::Mnti
    }

    fn params(&self) -> DescriptorParams {
        DescriptorParams::Mnti(self.params)
    }

    fn describe(&self, image: &TactileImage) -> Vec<Feature> {
        let turned = self.moment_normalized.normalized_plane(image);
        let padded = pad_with_ramps(
            &turned,
            self.padded_len(turned.rows()),
            self.padded_len(turned.cols()),
        );
        vec![self.plans.magnitudes_2d(&padded)]
    }
}

/// `plane` centred in a `rows x cols` plane (each at least as large), the border pixels ramped
/// linearly to zero across the padding; in the corners the two ramps multiply (module docs).
pub fn pad_with_ramps(plane: &Plane, rows: usize, cols: usize) -> Plane {
    let mut out = Plane::zeros(rows, cols);
    for r in 0..rows {
        let (source_row, row_factor) = ramp_source(r, plane.rows(), rows);
        for c in 0..cols {
            let (source_col, col_factor) = ramp_source(c, plane.cols(), cols);
            out.set(r, c, plane.get(source_row, source_col) * row_factor * col_factor);
        }
    }
    out
}

/// For index `i` of a line of `n >= 1` values centred in `len >= n`: the index of the value it
/// copies (the nearest border value in the padding) and the ramp factor `1 - k / (w + 1)`.
fn ramp_source(i: usize, n: usize, len: usize) -> (usize, f64) {
    let total = len.saturating_sub(n);
    let (before, after) = (total / 2, total - total / 2);
    if i < before {
        (0, 1.0 - (before - i) as f64 / (before + 1) as f64)
    } else if i < before + n {
        (i - before, 1.0)
    } else {
        (n - 1, 1.0 - (i + 1 - before - n) as f64 / (after + 1) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramps_fall_linearly_to_zero() {
        // Two before (width 2: steps of 1/3), three after (width 3: steps of 1/4).
        let line = Plane::from_values(1, 3, vec![3.0, 1.0, 6.0]).unwrap();
        let padded = pad_with_ramps(&line, 1, 8);
        let want = [1.0, 2.0, 3.0, 1.0, 6.0, 4.5, 3.0, 1.5];
        assert_eq!(padded.values().len(), 8);
        for (g, w) in padded.values().iter().zip(want) {
            assert!((g - w).abs() < 1e-12, "{:?}", padded.values());
        }
    }

    #[test]
    fn padding_is_separable_with_product_ramps_in_the_corners() {
        let plane = Plane::from_values(1, 1, vec![9.0]).unwrap();
        let padded = pad_with_ramps(&plane, 3, 3);
        // One pixel each side: b (1 - 1/2) along an axis, b / 4 in the corners.
        let want = [2.25, 4.5, 2.25, 4.5, 9.0, 4.5, 2.25, 4.5, 2.25];
        assert_eq!(padded.values(), &want);
    }

    #[test]
    fn sizes_follow_the_150_percent_rule() {
        let mnti = Mnti::default();
        for (n, len) in [(6, 45), (14, 231), (26, 780)] {
            let image = TactileImage::new(n, n, (0..n * n).map(|i| (i % 7) as f64 / 7.0).collect()).unwrap();
            assert_eq!(mnti.describe(&image)[0].len(), len, "{n}x{n}");
        }
        assert!(
            Valid::new(MntiParams {
                padded_size_ratio: 0.5,
                ..Default::default()
            })
            .is_err()
        );
    }
}
