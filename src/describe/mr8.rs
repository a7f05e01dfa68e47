//! MR-8 (Sec. IV-B3): the Varma-Zisserman maximal-response filter bank [48], built as the Oxford VGG
//! RFS bank [49], scaled down to tactile images.
//!
//! The bank, on a square support of half-width `h` (centred coordinates, y up), with the 1-D
//! Gaussian `g_s(t) = exp(-t^2 / 2 s^2) / sqrt(2 pi s^2)` and its derivatives
//! `g'_s(t) = -t g_s(t) / s^2`, `g''_s(t) = g_s(t) (t^2 - s^2) / s^4`:
//!
//! ```text
//! u = cos(a) x - sin(a) y,  v = sin(a) x + cos(a) y,      a = pi k / 6, k = 0..5
//! edge(s, a) = g_{3s}(u) g'_s(v)     bar(s, a) = g_{3s}(u) g''_s(v)     s in {1, 2, 4} * scale
//! Gaussian   = exp(-(x^2 + y^2) / 2 s_G^2)
//! LoG        = (x^2 + y^2 - 2 s_G^2) / s_G^4 exp(-(x^2 + y^2) / 2 s_G^2)    s_G = 10 * scale
//! every filter f:  f <- (f - mean f) / sum |f - mean f|
//! ```
//!
//! The RFS bank is 49x49 (`h = 24`, `scale = 1`). Scaling to tactile images (our choice, as the paper
//! leaves it open): the bank keeps its shape relative to its support, `scale = h / 24` (so
//! `h / s_u,max = 2` and `h / s_G = 2.4` as in RFS), and every sigma is floored at
//! [`Mr8Params::sigma_floor_px`] (0.5 px) so no filter is narrower than a taxel can resolve. The
//! support is `S = 2h + 1` with `h = floor(5 n / 12)`, `n = min(rows, cols)`: 5x5 at 6x6, 11x11 at
//! 14x14, 21x21 at 26x26, about 5/6 of the pad in every case. At 6x6 the floor makes the two
//! smaller oriented scales identical (both 0.5 px across, 0.5 px along): a 5x5 support cannot tell
//! them apart.
//!
//! Subsections: every `S x S` window of the image at a stride of [`Mr8Params::stride_px`] (1), so
//! the 6x6 case has the paper's 4 overlapping sections (16 at 14x14, 36 at 26x26). Each section's
//! feature is the responses (correlation of the filter with the section) of the 8 maximal
//! responses, in the order
//!
//! ```text
//! [Gaussian, LoG, edge s1, edge s2, edge s3, bar s1, bar s2, bar s3]
//! ```
//!
//! where edge = max over the 6 angles of `|response|` (an edge filter changes sign under a half
//! turn, which the 6 angles over [0, pi) do not cover), and bar = the response of largest magnitude
//! with its sign (bars are symmetric under a half turn, and the sign tells a ridge from a valley).
//! The image is first made zero-mean with unit RMS, as Varma and Zisserman do, so MR-8 ignores
//! intensity scale and offset; an image with no contrast (all zero, saturated, any constant) gives
//! all-zero features. Sections are listed row by row of their top-left corner.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, PoisonError, RwLock};

use serde::{Deserialize, Serialize};

use super::{Descriptor, DescriptorKind, DescriptorParams, Feature, ParamsError};
use crate::simd::dot;
use crate::tactile::TactileImage;
use crate::valid::{Check, Valid};

const ORIENTATIONS: usize = 6;
/// Across-sigmas of the RFS oriented filters, before scaling; along is 3 times as wide.
const RFS_SCALES: [f64; 3] = [1.0, 2.0, 4.0];
/// Sigma of the RFS Gaussian and LoG, before scaling.
const RFS_ISOTROPIC_SIGMA: f64 = 10.0;
/// Half-width of the RFS support (49x49).
const RFS_HALF_SUPPORT: f64 = 24.0;
/// Below this RMS an image counts as having no contrast.
const NO_CONTRAST: f64 = 1e-12;

/// Parameters of [`Mr8`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Mr8Params {
    /// Half-width `h` of the filter support (sections are `2h + 1` square); `None` picks
    /// `floor(5 n / 12)` for an `n`-taxel side. Capped to what fits in the image.
    pub half_support_px: Option<usize>,
    /// Smallest sigma of any filter, pixels, in (0, 10]. Default 0.5.
    pub sigma_floor_px: f64,
    /// Step between sections, pixels, at least 1. Default 1.
    pub stride_px: usize,
}

impl Default for Mr8Params {
    fn default() -> Self {
        Self {
            half_support_px: None,
            sigma_floor_px: 0.5,
            stride_px: 1,
        }
    }
}

impl Check for Mr8Params {
    type Error = ParamsError;

    fn check(&self) -> Result<(), ParamsError> {
        // Any half-width is valid: it is capped to what fits in the image (`half_support_for`).
        let Self {
            half_support_px: _,
            sigma_floor_px: floor,
            stride_px,
        } = *self;
        if !(floor.is_finite() && floor > 0.0 && floor <= 10.0) {
            return Err(ParamsError::OutOfRange {
                field: "mr8.sigma_floor_px",
                value: floor,
                expected: "in (0, 10]",
            });
        }
        if stride_px == 0 {
            return Err(ParamsError::OutOfRange {
                field: "mr8.stride_px",
                value: 0.0,
                expected: "at least 1",
            });
        }
        Ok(())
    }
}

impl Mr8Params {
    /// `h` for an image whose smaller side is `n`.
    pub fn half_support_for(&self, n: usize) -> usize {
        let fits = n.saturating_sub(1) / 2;
        self.half_support_px.unwrap_or(5 * n / 12).min(fits)
    }
}

/// The 38 filters of one support size, each `side x side`, row-major with row 0 at `y = +h`.
#[derive(Debug)]
struct FilterBank {
    side: usize,
    /// `edge[scale][orientation]`.
    edge: Vec<Vec<Vec<f64>>>,
    bar: Vec<Vec<Vec<f64>>>,
    gaussian: Vec<f64>,
    log: Vec<f64>,
}

/// The 1-D Gaussian of `sigma` at `t`, or its first or second derivative (`order` 1, 2 and up).
pub(super) fn gauss1d(sigma: f64, t: f64, order: u8) -> f64 {
    let variance = sigma * sigma;
    let g = (-t * t / (2.0 * variance)).exp() / (2.0 * PI * variance).sqrt();
    match order {
        0 => g,
        1 => -g * t / variance,
        _ => g * (t * t - variance) / (variance * variance),
    }
}

/// `f <- (f - mean f) / sum |f - mean f|`; a filter that is constant becomes all zero.
fn normalise(mut f: Vec<f64>) -> Vec<f64> {
    let mean = f.iter().sum::<f64>() / f.len() as f64;
    f.iter_mut().for_each(|v| *v -= mean);
    let l1: f64 = f.iter().map(|v| v.abs()).sum();
    if l1 > NO_CONTRAST {
        f.iter_mut().for_each(|v| *v /= l1);
    } else {
        f.iter_mut().for_each(|v| *v = 0.0);
    }
    f
}

impl FilterBank {
    fn new(half: usize, sigma_floor: f64) -> Self {
        let side = 2 * half + 1;
        let scale = half as f64 / RFS_HALF_SUPPORT;
        let sigma = |s: f64| (s * scale).max(sigma_floor);
        let grid = |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
            let mut out = Vec::with_capacity(side * side);
            for row in 0..side {
                for col in 0..side {
                    out.push(f(col as f64 - half as f64, half as f64 - row as f64));
                }
            }
            normalise(out)
        };
        let oriented = |order: u8| -> Vec<Vec<Vec<f64>>> {
            RFS_SCALES
                .iter()
                .map(|&s| {
                    let (along, across) = (sigma(3.0 * s), sigma(s));
                    (0..ORIENTATIONS)
                        .map(|k| {
                            let (sa, ca) = (PI * k as f64 / ORIENTATIONS as f64).sin_cos();
                            grid(&|x, y| {
                                let (u, v) = (ca * x - sa * y, sa * x + ca * y);
                                gauss1d(along, u, 0) * gauss1d(across, v, order)
                            })
                        })
                        .collect()
                })
                .collect()
        };
        let s_g = sigma(RFS_ISOTROPIC_SIGMA);
        let radial = |x: f64, y: f64| (-(x * x + y * y) / (2.0 * s_g * s_g)).exp();
        Self {
            side,
            edge: oriented(1),
            bar: oriented(2),
            gaussian: grid(&radial),
            log: grid(&|x, y| (x * x + y * y - 2.0 * s_g * s_g) / s_g.powi(4) * radial(x, y)),
        }
    }
}

/// Sec. IV-B3 (module docs). Filter banks are built once per support size and shared.
#[derive(Debug, Default)]
pub struct Mr8 {
    params: Mr8Params,
    banks: RwLock<HashMap<usize, Arc<FilterBank>>>,
}

impl Mr8 {
    /// The descriptor of checked parameters (`Valid::new(Mr8Params { .. })?`).
    pub fn new(params: Valid<Mr8Params>) -> Self {
        Self {
            params: params.into_inner(),
            banks: RwLock::default(),
        }
    }

    fn bank(&self, half: usize) -> Arc<FilterBank> {
        if let Some(bank) = self
            .banks
            .read()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&half)
        {
            return Arc::clone(bank);
        }
        let mut banks = self.banks.write().unwrap_or_else(PoisonError::into_inner);
        let floor = self.params.sigma_floor_px;
        Arc::clone(
            banks
                .entry(half)
                .or_insert_with(|| Arc::new(FilterBank::new(half, floor))),
        )
    }

    /// Number of sections (features) for a `rows x cols` image.
    pub fn sections(&self, rows: usize, cols: usize) -> usize {
        let side = 2 * self.params.half_support_for(rows.min(cols)) + 1;
        let along = |n: usize| (n - side) / self.params.stride_px + 1;
        along(rows) * along(cols)
    }
}

/// The image made zero-mean with unit RMS; all zero when it has no contrast.
fn standardised(image: &TactileImage) -> Vec<f64> {
    let values = image.values();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let mut out: Vec<f64> = values.iter().map(|v| v - mean).collect();
    let rms = (out.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
    if rms > NO_CONTRAST {
        out.iter_mut().for_each(|v| *v /= rms);
    } else {
        out.iter_mut().for_each(|v| *v = 0.0);
    }
    out
}

impl Descriptor for Mr8 {
    fn kind(&self) -> DescriptorKind {
        DescriptorKind::Mr8
    }

    fn params(&self) -> DescriptorParams {
        DescriptorParams::Mr8(self.params)
    }

    fn describe(&self, image: &TactileImage) -> Vec<Feature> {
        let (rows, cols) = (image.rows(), image.cols());
        let bank = self.bank(self.params.half_support_for(rows.min(cols)));
        let side = bank.side;
        let pixels = standardised(image);
        let stride = self.params.stride_px;
        let mut window = vec![0.0; side * side];
        let mut features = Vec::with_capacity(self.sections(rows, cols));
        for top in (0..=rows - side).step_by(stride) {
            for left in (0..=cols - side).step_by(stride) {
                for r in 0..side {
                    let start = (top + r) * cols + left;
                    window[r * side..(r + 1) * side].copy_from_slice(&pixels[start..start + side]);
                }
                let respond = |f: &[f64]| dot(f, &window);
                let mut feature = Vec::with_capacity(8);
                feature.push(respond(&bank.gaussian));
                feature.push(respond(&bank.log));
                for filters in &bank.edge {
                    feature.push(filters.iter().map(|f| respond(f).abs()).fold(0.0, f64::max));
                }
                for filters in &bank.bar {
                    let strongest = filters
                        .iter()
                        .map(|f| respond(f))
                        .fold(0.0, |best: f64, r| if r.abs() > best.abs() { r } else { best });
                    feature.push(strongest);
                }
                features.push(feature);
            }
        }
        features
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filters_are_zero_mean_and_unit_l1() {
        for half in [2, 5, 10] {
            let bank = FilterBank::new(half, 0.5);
            let all = bank
                .edge
                .iter()
                .chain(&bank.bar)
                .flatten()
                .chain([&bank.gaussian, &bank.log]);
            let mut count = 0;
            for f in all {
                assert_eq!(f.len(), bank.side * bank.side);
                assert!(f.iter().sum::<f64>().abs() < 1e-12);
                assert!((f.iter().map(|v| v.abs()).sum::<f64>() - 1.0).abs() < 1e-12);
                count += 1;
            }
            assert_eq!(count, 38);
        }
    }

    #[test]
    fn section_counts_follow_the_support() {
        let mr8 = Mr8::default();
        assert_eq!(Mr8Params::default().half_support_for(6), 2);
        assert_eq!(mr8.sections(6, 6), 4);
        assert_eq!(mr8.sections(14, 14), 16);
        assert_eq!(mr8.sections(26, 26), 36);
        assert_eq!(mr8.sections(1, 1), 1);
        let image = TactileImage::new(6, 6, (0..36).map(|i| (i % 4) as f64 / 3.0).collect()).unwrap();
        let features = mr8.describe(&image);
        assert_eq!(features.len(), 4);
        assert!(features.iter().all(|f| f.len() == 8));
    }

    #[test]
    fn a_centred_vertical_step_answers_only_the_odd_filters() {
        // 11x11, one section: 0 left of the centre column, 1/2 on it, 1 right of it. The section is
        // odd about its centre, so every even filter (Gaussian, LoG, bars) gives exactly 0 by
        // symmetry, and the edge filters respond at every scale.
        let image = TactileImage::new(
            11,
            11,
            (0..121)
                .map(|i| match (i % 11).cmp(&5) {
                    std::cmp::Ordering::Less => 0.0,
                    std::cmp::Ordering::Equal => 0.5,
                    std::cmp::Ordering::Greater => 1.0,
                })
                .collect(),
        )
        .unwrap();
        let one_section = Mr8::new(
            Valid::new(Mr8Params {
                half_support_px: Some(5),
                ..Default::default()
            })
            .unwrap(),
        );
        let features = one_section.describe(&image);
        assert_eq!(features.len(), 1);
        let f = &features[0];
        for even in [0, 1, 5, 6, 7] {
            assert!(f[even].abs() < 1e-12, "{f:?}");
        }
        for edge in [2, 3, 4] {
            assert!(f[edge] > 0.5, "{f:?}");
        }
    }

    #[test]
    fn quarter_turns_permute_sections_only() {
        let n = 8;
        let values: Vec<f64> = (0..n * n).map(|i| ((i * 29 % 13) as f64) / 12.0).collect();
        let turned: Vec<f64> = (0..n * n)
            .map(|i| values[(i % n) * n + (n - 1 - i / n)])
            .collect();
        let mr8 = Mr8::default();
        let sorted = |v: Vec<f64>| -> Vec<Vec<f64>> {
            let mut fs = mr8.describe(&TactileImage::new(n, n, v).unwrap());
            fs.sort_by(|a, b| a.partial_cmp(b).unwrap());
            fs
        };
        let (a, b) = (sorted(values), sorted(turned));
        assert_eq!(a.len(), 4);
        for (fa, fb) in a.iter().zip(&b) {
            for (x, y) in fa.iter().zip(fb) {
                assert!((x - y).abs() < 1e-9, "{fa:?} vs {fb:?}");
            }
        }
    }

    #[test]
    fn no_contrast_gives_zeros_and_bad_params_are_named() {
        let mr8 = Mr8::default();
        for v in [0.0, 1.0, 0.4] {
            for f in mr8.describe(&TactileImage::new(6, 6, vec![v; 36]).unwrap()) {
                assert_eq!(f, vec![0.0; 8]);
            }
        }
        let e = Valid::new(Mr8Params {
            stride_px: 0,
            ..Default::default()
        })
        .unwrap_err();
        assert!(e.to_string().contains("mr8.stride_px"), "{e}");
    }
}
