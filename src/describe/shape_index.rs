//! Shape index (beyond the paper): the local shapes a large array feels, pooled over the frame.
//!
//! The paper's descriptors describe a whole 6x6 image at once, which suits a fingertip that feels
//! one patch of surface. A large array (28x50, 44x44 taxels) presses on a whole region of the
//! object: cups, ridges, saddles and flats side by side, anywhere on the pad and at any roll. So
//! this descriptor looks at every taxel's neighbourhood, at several scales, and keeps only what
//! does not move with the contact: how much of the pressure lies on each kind of local shape.
//! Koenderink and van Doorn's shape index and curvedness (Image Vision Comput. 10(8), 1992) name
//! the local shape from the principal curvatures `k1 >= k2` of the pressure seen as a surface:
//!
//! ```text
//! S = (2 / pi) atan2(k1 + k2, k1 - k2)   in [-1, 1]: -1 a cap (a point pressing), -1/2 a ridge,
//!                                          0 a saddle, 1/2 a rut, 1 a cup
//! C = sqrt((k1^2 + k2^2) / 2) sigma^2     how strongly curved, at the scale sigma
//! ```
//!
//! The curvatures are the eigenvalues of the Hessian of the frame smoothed by a Gaussian of
//! `sigma` taxels (separable sampled Gaussian derivatives out to 4 sigma, the border taxel
//! repeated beyond the frame), at `scales` octaves from `finest_scale_taxels` (1, 2, 4 by default).
//! Both are invariant to the roll of the pad, which the controllers leave free (Sec. IV), and,
//! pooled over the frame, to where the contact lies on it (Sec. IV-B6 asks the same of MNTI). The
//! frame is first divided by its largest value, so that how hard it was pressed does not count
//! either, as for the paper's descriptors but Vectorize.
//!
//! Output, one feature per frame of `12 + 46 scales` values (150 by default), each histogram's
//! bins summing to 1 and the two single values in [0, 1], so that no block outweighs another in
//! the PCA:
//! - the frame's values, 10 bins of [0, 1], as shares of the taxels; then its mean and the share
//!   of taxels above a tenth;
//! - per scale: the 8 x 4 histogram of `S` (8 bins of [-1, 1]) and `ln(1 + 20 C)` (4 bins of
//!   [0, 3]) weighed by the smoothed pressure; the 6-bin histogram of `ln(1 + 20 sigma |grad|)`
//!   over [0, 3] and the 8-bin histogram of the smoothed values over their largest, both as
//!   shares of the taxels. Values beyond a histogram's range count in its last bin.
//!
//! The factor 20 spreads the slopes and curvatures of a frame of values in [0, 1] over the bins.
//! All-zero frame (no contact): all zeros. Any grid of at least 1x1 taxels.

use std::f64::consts::FRAC_2_PI;

use serde::{Deserialize, Serialize};

use super::mr8::gauss1d;
use super::{Descriptor, DescriptorKind, DescriptorParams, Feature, ParamsError};
use crate::tactile::TactileImage;
use crate::valid::{Check, Valid};

/// Parameters of [`ShapeIndex`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShapeIndexParams {
    /// The finest smoothing sigma, taxels, in [0.5, 8]. Default 1.
    pub finest_scale_taxels: f64,
    /// How many scales, each twice the last, in 1..=5. Default 3.
    pub scales: usize,
}

impl Default for ShapeIndexParams {
    fn default() -> Self {
        Self {
            finest_scale_taxels: 1.0,
            scales: 3,
        }
    }
}

impl Check for ShapeIndexParams {
    type Error = ParamsError;

    fn check(&self) -> Result<(), ParamsError> {
        let Self {
            finest_scale_taxels: sigma,
            scales,
        } = *self;
        if !(sigma.is_finite() && (0.5..=8.0).contains(&sigma)) {
            return Err(ParamsError::OutOfRange {
                field: "shape-index.finest_scale_taxels",
                value: sigma,
                expected: "taxels in [0.5, 8]",
            });
        }
        if !(1..=5).contains(&scales) {
            return Err(ParamsError::OutOfRange {
                field: "shape-index.scales",
                value: scales as f64,
                expected: "a count in 1..=5",
            });
        }
        Ok(())
    }
}

/// Bins of the frame's values.
const VALUE_BINS: usize = 10;
/// Bins of the shape index `S`, and of the compressed curvedness.
const SHAPE_BINS: (usize, usize) = (8, 4);
/// Bins of the compressed gradient magnitude.
const SLOPE_BINS: usize = 6;
/// Bins of the smoothed values.
const SMOOTHED_BINS: usize = 8;
/// The upper end of the compressed curvedness and slope histograms: `ln(1 + 20 x)` in [0, 3].
const COMPRESSED_MAX: f64 = 3.0;
/// The factor inside the compression `ln(1 + 20 x)`.
const COMPRESSION: f64 = 20.0;
/// Values per scale.
const PER_SCALE: usize = SHAPE_BINS.0 * SHAPE_BINS.1 + SLOPE_BINS + SMOOTHED_BINS;
/// Values before the scales: the value histogram, the mean, the share above a tenth.
const GLOBAL: usize = VALUE_BINS + 2;

/// The shape-index descriptor (module docs).
#[derive(Debug, Clone, Default)]
pub struct ShapeIndex {
    params: ShapeIndexParams,
}

impl ShapeIndex {
    pub fn new(params: Valid<ShapeIndexParams>) -> Self {
        Self {
            params: params.into_inner(),
        }
    }

    /// The feature length for these parameters: `12 + 46 scales`.
    pub fn feature_len(&self) -> usize {
        GLOBAL + PER_SCALE * self.params.scales
    }

    /// The smoothing sigmas, taxels: the finest, then each twice the last.
    fn sigmas(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.params.scales).map(|i| self.params.finest_scale_taxels * f64::from(1u32 << i))
    }
}

impl Descriptor for ShapeIndex {
    fn kind(&self) -> DescriptorKind {
        DescriptorKind::ShapeIndex
    }

    fn params(&self) -> DescriptorParams {
        DescriptorParams::ShapeIndex(self.params)
    }

    fn describe(&self, image: &TactileImage) -> Vec<Feature> {
        let Some(frame) = Frame::of(image) else {
            return vec![vec![0.0; self.feature_len()]];
        };
        let mut feature = Vec::with_capacity(self.feature_len());
        feature.extend(frame.global());
        for sigma in self.sigmas() {
            feature.extend(frame.at_scale(sigma));
        }
        vec![feature]
    }
}

/// A frame's values over its largest, row-major.
struct Frame {
    rows: usize,
    cols: usize,
    values: Vec<f64>,
}

/// The smoothed frame and its derivatives at one scale, row-major; `xx` along a row (the columns'
/// direction), `yy` down a column.
struct Derivatives {
    smooth: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    xx: Vec<f64>,
    yy: Vec<f64>,
    xy: Vec<f64>,
}

impl Frame {
    /// The frame of `image`; none when nothing pressed it.
    fn of(image: &TactileImage) -> Option<Self> {
        let largest = image.values().iter().copied().fold(0.0, f64::max);
        (largest > 0.0).then(|| Self {
            rows: image.rows(),
            cols: image.cols(),
            values: image.values().iter().map(|v| v / largest).collect(),
        })
    }

    fn taxels(&self) -> f64 {
        self.values.len() as f64
    }

    /// The value histogram, the mean, the share above a tenth.
    fn global(&self) -> Vec<f64> {
        let mut out = shares(&self.values, 1.0, VALUE_BINS);
        let mean = self.values.iter().sum::<f64>() / self.taxels();
        let above = self.values.iter().filter(|&&v| v > 0.1).count() as f64 / self.taxels();
        out.extend([mean, above]);
        out
    }

    /// The shape, slope and smoothed-value histograms at `sigma` taxels.
    fn at_scale(&self, sigma: f64) -> Vec<f64> {
        let d = self.derivatives(sigma);
        let mut shape = vec![0.0; SHAPE_BINS.0 * SHAPE_BINS.1];
        let total: f64 = d.smooth.iter().map(|v| v.max(0.0)).sum();
        for k in 0..self.values.len() {
            let (s, c) = shape_and_curvedness(d.xx[k], d.yy[k], d.xy[k], sigma);
            if total > 0.0 {
                let row = bin(s, -1.0, 1.0, SHAPE_BINS.0);
                let col = bin(compressed(c), 0.0, COMPRESSED_MAX, SHAPE_BINS.1);
                shape[row * SHAPE_BINS.1 + col] += d.smooth[k].max(0.0) / total;
            }
        }
        let slopes = (0..self.values.len()).map(|k| {
            let slope = sigma * d.x[k].hypot(d.y[k]);
            bin(compressed(slope), 0.0, COMPRESSED_MAX, SLOPE_BINS)
        });
        shape.extend(counted_shares(slopes, self.values.len(), SLOPE_BINS));
        let largest = d.smooth.iter().copied().fold(0.0, f64::max);
        shape.extend(shares(&d.smooth, largest, SMOOTHED_BINS));
        shape
    }

    /// The Gaussian derivatives at `sigma` taxels: one pass along the rows for each order, then one
    /// along the columns for each derivative.
    fn derivatives(&self, sigma: f64) -> Derivatives {
        let kernels = [0u8, 1, 2].map(|order| kernel(sigma, order));
        let along_rows = kernels
            .each_ref()
            .map(|k| self.convolve(&self.values, k, Axis::AlongRow));
        let down = |plane: &[f64], order: usize| self.convolve(plane, &kernels[order], Axis::DownColumn);
        Derivatives {
            smooth: down(&along_rows[0], 0),
            x: down(&along_rows[1], 0),
            y: down(&along_rows[0], 1),
            xx: down(&along_rows[2], 0),
            yy: down(&along_rows[0], 2),
            xy: down(&along_rows[1], 1),
        }
    }

    /// `plane` convolved with the odd-length `kernel` along one axis, the border taxel repeated.
    fn convolve(&self, plane: &[f64], kernel: &[f64], axis: Axis) -> Vec<f64> {
        let half = (kernel.len() / 2) as isize;
        let (rows, cols) = (self.rows, self.cols);
        let mut out = vec![0.0; plane.len()];
        for r in 0..rows {
            for c in 0..cols {
                let mut sum = 0.0;
                for (j, w) in kernel.iter().enumerate() {
                    let offset = j as isize - half;
                    let at = match axis {
                        Axis::AlongRow => r * cols + clamp(c as isize - offset, cols),
                        Axis::DownColumn => clamp(r as isize - offset, rows) * cols + c,
                    };
                    sum += w * plane[at];
                }
                out[r * cols + c] = sum;
            }
        }
        out
    }
}

/// Which way a pass of [`Frame::convolve`] runs.
#[derive(Clone, Copy)]
enum Axis {
    AlongRow,
    DownColumn,
}

/// `index` within `0..len`, the nearest end beyond it.
fn clamp(index: isize, len: usize) -> usize {
    index.clamp(0, len as isize - 1) as usize
}

/// The sampled Gaussian derivative of `order` at `sigma` taxels, out to 4 sigma; the smoothing
/// kernel sums to 1, so a constant frame stays itself and has no slope or curvature.
fn kernel(sigma: f64, order: u8) -> Vec<f64> {
    let half = (4.0 * sigma).ceil() as i64;
    let taps: Vec<f64> = (-half..=half).map(|t| gauss1d(sigma, t as f64, order)).collect();
    if order == 0 {
        let sum: f64 = taps.iter().sum();
        return taps.into_iter().map(|w| w / sum).collect();
    }
    // The sampled derivative's moments as the continuous one's: zero sum, and the first (or
    // second) moment that makes a ramp (or parabola) answer its true slope (or curvature).
    let mean = taps.iter().sum::<f64>() / taps.len() as f64;
    let centred: Vec<f64> = taps.iter().map(|w| w - mean).collect();
    let moment: f64 = centred
        .iter()
        .enumerate()
        .map(|(j, w)| w * ((j as i64 - half) as f64).powi(i32::from(order)))
        .sum();
    let target = if order == 1 { -1.0 } else { 2.0 };
    centred.into_iter().map(|w| w * target / moment).collect()
}

/// Below this scale-normalised curvedness the surface is flat: the shape index of a flat is
/// undefined, and the curvatures of a constant frame are rounding errors whose signs would scatter
/// it, so a flat is named as the saddle's `S = 0` with curvedness 0.
const FLAT: f64 = 1e-9;

/// The shape index and the scale-normalised curvedness of the Hessian `[[xx, xy], [xy, yy]]`.
fn shape_and_curvedness(xx: f64, yy: f64, xy: f64, sigma: f64) -> (f64, f64) {
    let half_trace = 0.5 * (xx + yy);
    let radius = (0.5 * (xx - yy)).hypot(xy);
    let (k1, k2) = (half_trace + radius, half_trace - radius);
    let c = ((k1 * k1 + k2 * k2) / 2.0).sqrt() * sigma * sigma;
    if c < FLAT {
        return (0.0, 0.0);
    }
    // k1 + k2 = 2 half_trace and k1 - k2 = 2 radius >= +0, so S stays in [-1, 1].
    (FRAC_2_PI * half_trace.atan2(radius), c)
}

/// `ln(1 + 20 x)`.
fn compressed(x: f64) -> f64 {
    (COMPRESSION * x).ln_1p()
}

/// The bin of `v` among `bins` equal bins of `[lo, hi]`; beyond either end, the end's bin.
fn bin(v: f64, lo: f64, hi: f64, bins: usize) -> usize {
    let at = ((v - lo) / (hi - lo) * bins as f64).floor();
    if at.is_nan() {
        0
    } else {
        (at.max(0.0) as usize).min(bins - 1)
    }
}

/// The shares of `values` in `bins` equal bins of `[0, largest]` (all in the first when `largest`
/// is not above 0).
fn shares(values: &[f64], largest: f64, bins: usize) -> Vec<f64> {
    counted_shares(
        values.iter().map(|&v| {
            if largest > 0.0 {
                bin(v / largest, 0.0, 1.0, bins)
            } else {
                0
            }
        }),
        values.len(),
        bins,
    )
}

/// The share of `taxels` in each of `bins` bins, counted first so that a full bin is exactly 1.
fn counted_shares(bin_of_each: impl Iterator<Item = usize>, taxels: usize, bins: usize) -> Vec<f64> {
    let mut counts = vec![0usize; bins];
    for b in bin_of_each {
        counts[b] += 1;
    }
    counts.into_iter().map(|n| n as f64 / taxels as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(rows: usize, cols: usize, f: impl Fn(f64, f64) -> f64) -> TactileImage {
        let values = (0..rows * cols)
            .map(|k| f((k / cols) as f64, (k % cols) as f64))
            .collect();
        TactileImage::new(rows, cols, values).expect("a valid image")
    }

    #[test]
    fn derivative_kernels_answer_a_ramp_and_a_parabola_exactly() {
        for sigma in [1.0, 2.5] {
            let slope = kernel(sigma, 1);
            let curvature = kernel(sigma, 2);
            let half = (slope.len() / 2) as f64;
            let at = |k: &[f64], f: &dyn Fn(f64) -> f64| -> f64 {
                k.iter().enumerate().map(|(j, w)| w * f(half - j as f64)).sum()
            };
            assert!((at(&slope, &|x| 3.0 * x + 1.0) - 3.0).abs() < 1e-12);
            assert!((at(&curvature, &|x| 0.5 * x * x + x) - 1.0).abs() < 1e-12);
            assert!((kernel(sigma, 0).iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn the_shape_index_names_caps_ridges_saddles_and_cups() {
        let cases = [
            ((-1.0, -1.0, 0.0), -1.0),
            ((-1.0, 0.0, 0.0), -0.5),
            ((1.0, -1.0, 0.0), 0.0),
            ((0.0, 1.0, 0.0), 0.5),
            ((2.0, 2.0, 0.0), 1.0),
        ];
        for ((xx, yy, xy), want) in cases {
            let (s, _) = shape_and_curvedness(xx, yy, xy, 1.0);
            assert!((s - want).abs() < 1e-12, "{xx} {yy} {xy}: {s}");
        }
    }

    #[test]
    fn a_pressed_cap_weighs_on_the_cap_bins_and_every_block_sums_to_one() {
        let cap = image(28, 50, |r, c| {
            (1.0 - ((r - 14.0).powi(2) + (c - 25.0).powi(2)) / 60.0).max(0.0)
        });
        let f = &ShapeIndex::default().describe(&cap)[0];
        assert_eq!(f.len(), 150);
        assert!((f[..VALUE_BINS].iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let scale = &f[GLOBAL..GLOBAL + PER_SCALE];
        let shape = &scale[..32];
        assert!((shape.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        // The cap's pressure lies on S in [-1, -0.75): the first row of the 8 x 4 histogram.
        assert!(shape[..4].iter().sum::<f64>() > 0.5, "{shape:?}");
        assert!((scale[32..38].iter().sum::<f64>() - 1.0).abs() < 1e-9);
        assert!((scale[38..].iter().sum::<f64>() - 1.0).abs() < 1e-9);
    }

    fn distance(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
    }

    /// A large pad feels the same contact wherever it lies on the pad (so long as the smoothing
    /// of the coarsest scale, out to 16 taxels, stays on the pad), and a cap apart from a ridge.
    #[test]
    fn where_the_contact_lies_on_a_large_pad_does_not_count_but_its_shape_does() {
        let describe =
            |f: &dyn Fn(f64, f64) -> f64| ShapeIndex::default().describe(&image(44, 60, f)).remove(0);
        let cap =
            |c0: f64| move |r: f64, c: f64| (1.0 - ((r - 22.0).powi(2) + (c - c0).powi(2)) / 10.0).max(0.0);
        let ridge = |r: f64, _c: f64| (1.0 - (r - 22.0).powi(2) / 10.0).max(0.0);
        let (here, there) = (describe(&cap(20.0)), describe(&cap(40.0)));
        let moved = distance(&here, &there);
        let other = distance(&here, &describe(&ridge));
        assert!(moved < 1e-9 && other > 0.3, "moved {moved}, other shape {other}");
    }

    #[test]
    fn a_blank_frame_says_nothing_and_bad_parameters_are_named() {
        let f = &ShapeIndex::default().describe(&image(6, 6, |_, _| 0.0))[0];
        assert_eq!(f.len(), 150);
        assert!(f.iter().all(|&v| v == 0.0));
        for bad in [
            ShapeIndexParams {
                finest_scale_taxels: 0.1,
                ..Default::default()
            },
            ShapeIndexParams {
                scales: 0,
                ..Default::default()
            },
        ] {
            let e = bad.check().unwrap_err().to_string();
            assert!(e.contains("shape-index."), "{e}");
        }
    }
}
