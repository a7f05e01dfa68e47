//! SIFT (Sec. IV-B2): Lowe's descriptor [46] with VLFeat's conventions [47], one keypoint at the image
//! centre whose descriptor window is the whole image.
//!
//! Gradients: central differences, one-sided at the borders, on the raw image (image axes: x right,
//! y down, as VLFeat), `m = |grad I|`, `a = atan2(g_y, g_x)` in [0, 2 pi).
//!
//! Orientation ("the standard SIFT way"): a 36-bin histogram of `a`, each pixel adding `m w` split
//! linearly between the two nearest bins, with the Gaussian window `w = exp(-|p - c|^2 / 2 sigma^2)`;
//! smoothed six times by a circular `[1 1 1] / 3`; the peak bin refined by a parabola through it and
//! its neighbours. The window is the descriptor's, `sigma = W / 2`, so the orientation looks at the
//! whole image (Lowe's `1.5 sigma_keypoint` would only see the central `W / 4` here). Only the highest
//! peak is used: one feature per image.
//!
//! Descriptor: `B x B` spatial bins of side `W / B` px (`W = min(rows, cols)`), `B = 2` (32 values)
//! below [`SiftParams::full_grid_min_px`] and `B = 4` (128) from it on (the paper's 2x2 grid "at low
//! resolutions"). Each pixel, in the keypoint frame turned by the orientation `phi`,
//!
//! ```text
//! (n_x, n_y) = R(-phi) (p - c) / (W / B),   n_t = 8 ((a - phi) mod 2 pi) / 2 pi
//! ```
//!
//! adds `m exp(-(n_x^2 + n_y^2) / (2 (B/2)^2))` trilinearly to the bins around `(n_x, n_y, n_t)`
//! (spatial bin centres at half-integers, bins from `-B/2` to `B/2`), at index `t + 8 (x + B y)`.
//! Then: L2-normalise, clamp at 0.2, L2-normalise again (robustness to large gradients). All steps
//! are invariant to an intensity scale `I -> k I`, `k > 0`. An image without gradient (all zero,
//! saturated, any constant) gives all zeros.

use std::f64::consts::TAU;

use serde::{Deserialize, Serialize};

use super::{Descriptor, DescriptorKind, DescriptorParams, Feature, ParamsError};
use crate::tactile::TactileImage;
use crate::valid::{Check, Valid};

const ORIENTATION_BINS: usize = 36;
const ANGLE_BINS: usize = 8;
const SMOOTHING_PASSES: usize = 6;

/// Parameters of [`Sift`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SiftParams {
    /// Images whose smaller side has at least this many taxels get the full 4x4 grid (128 values),
    /// smaller ones 2x2 (32 values). Default 14.
    pub full_grid_min_px: usize,
    /// The clamp applied after the first normalisation, in (0, 1]. Default 0.2 (Lowe, VLFeat).
    pub clamp: f64,
}

impl Default for SiftParams {
    fn default() -> Self {
        Self {
            full_grid_min_px: 14,
            clamp: 0.2,
        }
    }
}

impl Check for SiftParams {
    type Error = ParamsError;

    fn check(&self) -> Result<(), ParamsError> {
        // Any grid threshold is a valid choice of where the 4x4 grid starts.
        let Self {
            full_grid_min_px: _,
            clamp,
        } = *self;
        if !(clamp.is_finite() && clamp > 0.0 && clamp <= 1.0) {
            return Err(ParamsError::OutOfRange {
                field: "sift.clamp",
                value: clamp,
                expected: "in (0, 1]",
            });
        }
        Ok(())
    }
}

/// Sec. IV-B2 (module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Sift {
    params: SiftParams,
}

/// Gradient magnitude and direction of every pixel, row-major.
struct Gradients {
    magnitude: Vec<f64>,
    angle_rad: Vec<f64>,
}

impl Gradients {
    fn of(image: &TactileImage) -> Self {
        let (rows, cols) = (image.rows(), image.cols());
        let v = image.values();
        let diff = |at: usize, n: usize, get: &dyn Fn(usize) -> f64| -> f64 {
            if n < 2 {
                0.0
            } else if at == 0 {
                get(1) - get(0)
            } else if at == n - 1 {
                get(at) - get(at - 1)
            } else {
                0.5 * (get(at + 1) - get(at - 1))
            }
        };
        let mut magnitude = Vec::with_capacity(rows * cols);
        let mut angle_rad = Vec::with_capacity(rows * cols);
        for r in 0..rows {
            for c in 0..cols {
                let gx = diff(c, cols, &|k| v[r * cols + k]);
                let gy = diff(r, rows, &|k| v[k * cols + c]);
                magnitude.push(gx.hypot(gy));
                angle_rad.push(gy.atan2(gx).rem_euclid(TAU));
            }
        }
        Self { magnitude, angle_rad }
    }
}

impl Sift {
    /// The descriptor of checked parameters (`Valid::new(SiftParams { .. })?`).
    pub fn new(params: Valid<SiftParams>) -> Self {
        Self {
            params: params.into_inner(),
        }
    }

    /// Spatial bins per side for a `rows x cols` image.
    pub fn grid(&self, rows: usize, cols: usize) -> usize {
        if rows.min(cols) >= self.params.full_grid_min_px {
            4
        } else {
            2
        }
    }

    /// The dominant gradient orientation (module docs); 0 when the image has no gradient.
    fn orientation_rad(grads: &Gradients, rows: usize, cols: usize) -> f64 {
        let (cx, cy) = ((cols as f64 - 1.0) / 2.0, (rows as f64 - 1.0) / 2.0);
        let sigma = rows.min(cols) as f64 / 2.0;
        let n = ORIENTATION_BINS as f64;
        let mut hist = [0.0; ORIENTATION_BINS];
        for r in 0..rows {
            for c in 0..cols {
                let i = r * cols + c;
                let (dx, dy) = (c as f64 - cx, r as f64 - cy);
                let weight = grads.magnitude[i] * (-(dx * dx + dy * dy) / (2.0 * sigma * sigma)).exp();
                let fbin = n * grads.angle_rad[i] / TAU - 0.5;
                let bin = fbin.floor();
                let frac = fbin - bin;
                let bin = (bin as isize).rem_euclid(ORIENTATION_BINS as isize) as usize;
                hist[bin] += (1.0 - frac) * weight;
                hist[(bin + 1) % ORIENTATION_BINS] += frac * weight;
            }
        }
        for _ in 0..SMOOTHING_PASSES {
            let prev = hist;
            for (i, h) in hist.iter_mut().enumerate() {
                let left = prev[(i + ORIENTATION_BINS - 1) % ORIENTATION_BINS];
                let right = prev[(i + 1) % ORIENTATION_BINS];
                *h = (left + prev[i] + right) / 3.0;
            }
        }
        let (peak, &top) = hist
            .iter()
            .enumerate()
            .fold((0, &hist[0]), |best, cur| if cur.1 > best.1 { cur } else { best });
        if top <= 0.0 {
            return 0.0;
        }
        let left = hist[(peak + ORIENTATION_BINS - 1) % ORIENTATION_BINS];
        let right = hist[(peak + 1) % ORIENTATION_BINS];
        let curvature = right + left - 2.0 * top;
        let offset = if curvature < 0.0 {
            -0.5 * (right - left) / curvature
        } else {
            0.0
        };
        (TAU * (peak as f64 + offset + 0.5) / n).rem_euclid(TAU)
    }
}

impl Descriptor for Sift {
    fn kind(&self) -> DescriptorKind {
        DescriptorKind::Sift
    }

    fn params(&self) -> DescriptorParams {
        DescriptorParams::Sift(self.params)
    }

    fn describe(&self, image: &TactileImage) -> Vec<Feature> {
        let (rows, cols) = (image.rows(), image.cols());
        let grads = Gradients::of(image);
        let phi = Self::orientation_rad(&grads, rows, cols);
        let b = self.grid(rows, cols);
        let half = (b / 2) as isize;
        let bin_px = rows.min(cols) as f64 / b as f64;
        let window_sigma = b as f64 / 2.0;
        let (st, ct) = phi.sin_cos();
        let (cx, cy) = ((cols as f64 - 1.0) / 2.0, (rows as f64 - 1.0) / 2.0);
        let mut hist = vec![0.0; ANGLE_BINS * b * b];
        for r in 0..rows {
            for c in 0..cols {
                let i = r * cols + c;
                let mag = grads.magnitude[i];
                if mag == 0.0 {
                    continue;
                }
                let (dx, dy) = (c as f64 - cx, r as f64 - cy);
                let nx = (ct * dx + st * dy) / bin_px;
                let ny = (-st * dx + ct * dy) / bin_px;
                let nt = ANGLE_BINS as f64 * (grads.angle_rad[i] - phi).rem_euclid(TAU) / TAU;
                let weight = mag * (-(nx * nx + ny * ny) / (2.0 * window_sigma * window_sigma)).exp();
                let (bx, by, bt) = ((nx - 0.5).floor(), (ny - 0.5).floor(), nt.floor());
                let (fx, fy, ft) = (nx - (bx + 0.5), ny - (by + 0.5), nt - bt);
                let (bx, by, bt) = (bx as isize, by as isize, bt as isize);
                for (dbx, wx) in [(0, 1.0 - fx), (1, fx)] {
                    let x = bx + dbx;
                    if x < -half || x >= half {
                        continue;
                    }
                    for (dby, wy) in [(0, 1.0 - fy), (1, fy)] {
                        let y = by + dby;
                        if y < -half || y >= half {
                            continue;
                        }
                        for (dbt, wt) in [(0, 1.0 - ft), (1, ft)] {
                            let t = (bt + dbt).rem_euclid(ANGLE_BINS as isize) as usize;
                            let cell = (x + half) as usize + b * (y + half) as usize;
                            hist[t + ANGLE_BINS * cell] += weight * wx * wy * wt;
                        }
                    }
                }
            }
        }
        normalize_l2(&mut hist);
        hist.iter_mut().for_each(|v| *v = v.min(self.params.clamp));
        normalize_l2(&mut hist);
        vec![hist]
    }
}

/// Divides by the Euclidean norm; a zero vector stays zero.
fn normalize_l2(v: &mut [f64]) {
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if norm > 0.0 {
        v.iter_mut().for_each(|x| *x /= norm);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertical step: left half 0, right half `level`.
    fn step(n: usize, level: f64) -> TactileImage {
        TactileImage::new(
            n,
            n,
            (0..n * n)
                .map(|i| if i % n >= n / 2 { level } else { 0.0 })
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn a_step_points_the_orientation_across_it_and_fills_one_angle_bin() {
        let image = step(8, 0.8);
        let grads = Gradients::of(&image);
        // The gradient points along +x everywhere it is non-zero: orientation 0 (bin centres are at
        // half-bins, and the symmetric histogram peaks between bins 35 and 0, which the parabola finds).
        let phi = Sift::orientation_rad(&grads, 8, 8);
        assert!(phi.min(TAU - phi) < 1e-9, "phi = {phi}");
        let d = &Sift::default().describe(&image)[0];
        assert_eq!(d.len(), 32);
        // Every gradient has angle exactly phi: all mass in angle bin t = 0.
        for (i, v) in d.iter().enumerate() {
            if i % ANGLE_BINS != 0 {
                assert!(v.abs() < 1e-9, "bin {i} = {v}");
            }
        }
        // The step is symmetric about the centre, so the four cells get equal mass: after the
        // normalisation, clamp and renormalisation each holds 1/2.
        for cell in 0..4 {
            assert!((d[ANGLE_BINS * cell] - 0.5).abs() < 1e-9, "cell {cell}: {d:?}");
        }
    }

    #[test]
    fn grid_and_length_switch_at_fourteen() {
        let sift = Sift::default();
        assert_eq!(sift.grid(6, 6), 2);
        assert_eq!(sift.grid(13, 20), 2);
        assert_eq!(sift.grid(14, 14), 4);
        assert_eq!(sift.describe(&step(14, 1.0))[0].len(), 128);
    }

    #[test]
    fn constant_images_give_zeros_and_intensity_scale_changes_nothing() {
        let sift = Sift::default();
        for v in [0.0, 1.0, 0.4] {
            let d = sift.describe(&TactileImage::new(6, 6, vec![v; 36]).unwrap());
            assert_eq!(d, vec![vec![0.0; 32]]);
        }
        let (a, b) = (sift.describe(&step(14, 1.0)), sift.describe(&step(14, 0.3)));
        for (x, y) in a[0].iter().zip(&b[0]) {
            assert!((x - y).abs() < 1e-12);
        }
        assert!(
            Valid::new(SiftParams {
                clamp: 0.0,
                ..Default::default()
            })
            .is_err()
        );
    }
}
