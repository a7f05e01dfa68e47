//! Image formation (Sec. V-A2): supersampled penetration -> Gaussian point-spread ->
//! area average to taxels -> fraction of the sensing range -> saturation -> additive noise.
//!
//! With `p(x, y)` the penetration (metres, in `[0, t]`) at the samples `S` of the grid:
//!
//! ```text
//! q(s)      = sum_{s' in S} g(s - s') p(s') / sum_{s' in S} g(s - s'),   g(u, v) = exp(-(u^2 + v^2) / 2 sigma^2)
//! I(r, c)   = clamp( mean_{s in taxel (r, c)} q(s) / t , 0, 1 )
//! I'(r, c)  = clamp( I(r, c) + n(r, c), 0, 1 ),   n ~ U(-f/2, f/2) i.i.d.
//! ```
//!
//! The point-spread is normalised over the pad (the covering beyond the pad's edge is not
//! sensed), so a uniform penetration stays exactly uniform: the blur moves signal, it never
//! invents or loses any. `g` is separable and the pad rectangular, so both the kernel and its
//! normalisation factor into a row pass and a column pass, truncated at 4 sigma.
//!
//! Noise is deterministic per (noise seed, reading index): reading `n` of a sensor draws its noise
//! from [`crate::rng::stream`]`(seed, n)`, one `U(-f/2, f/2)` per taxel in row-major order.

use rand::RngExt;

use crate::tactile::SensorConfig;
use crate::tactile::grid::SampleGrid;

/// Kernel support in standard deviations.
const PSF_SUPPORT_SIGMAS: f64 = 4.0;

/// One pass of a separable, border-normalised Gaussian along an axis of `n` samples.
#[derive(Debug, Clone, PartialEq)]
struct GaussianPass {
    /// For output index `i`: first input index and the offset of its weights in `weights`.
    start: Vec<usize>,
    len: Vec<usize>,
    offset: Vec<usize>,
    weights: Vec<f64>,
}

impl GaussianPass {
    /// `sigma_samples` is the standard deviation in units of the sample spacing (> 0).
    fn new(n: usize, sigma_samples: f64) -> Self {
        let radius = (PSF_SUPPORT_SIGMAS * sigma_samples).ceil() as usize;
        let mut pass = Self {
            start: Vec::with_capacity(n),
            len: Vec::with_capacity(n),
            offset: Vec::new(),
            weights: Vec::new(),
        };
        for i in 0..n {
            let lo = i.saturating_sub(radius);
            let hi = (i + radius).min(n - 1);
            let w: Vec<f64> = (lo..=hi)
                .map(|j| {
                    let u = (j as f64 - i as f64) / sigma_samples;
                    (-0.5 * u * u).exp()
                })
                .collect();
            let sum: f64 = w.iter().sum();
            pass.start.push(lo);
            pass.len.push(w.len());
            pass.offset.push(pass.weights.len());
            pass.weights.extend(w.iter().map(|x| x / sum));
        }
        pass
    }

    /// `out[i] = sum_k w_ik input[start_i + k]` along the axis with stride `stride` in the buffers.
    #[inline]
    fn apply(&self, input: &[f64], output: &mut [f64], base: usize, stride: usize) {
        for i in 0..self.start.len() {
            let w = &self.weights[self.offset[i]..self.offset[i] + self.len[i]];
            let mut acc = 0.0;
            let mut idx = base + self.start[i] * stride;
            for &wk in w {
                acc += wk * input[idx];
                idx += stride;
            }
            output[base + i * stride] = acc;
        }
    }
}

/// The fixed part of image formation for one config, with its scratch buffers.
#[derive(Debug, Clone)]
pub struct ImageFormation {
    rows: usize,
    cols: usize,
    k: usize,
    thickness_m: f64,
    noise_fraction: f64,
    /// Row pass (along x) and column pass (along y), when the PSF is on.
    psf: Option<(GaussianPass, GaussianPass)>,
    scratch: Vec<f64>,
}

impl ImageFormation {
    /// For a valid config and its grid.
    pub fn new(config: &SensorConfig, grid: &SampleGrid) -> Self {
        let psf = (config.psf_sigma_m > 0.0).then(|| {
            (
                GaussianPass::new(grid.cols, config.psf_sigma_m / grid.dx_m()),
                GaussianPass::new(grid.rows, config.psf_sigma_m / grid.dy_m()),
            )
        });
        Self {
            rows: config.rows,
            cols: config.cols,
            k: config.rays_per_side(),
            thickness_m: config.thickness_m,
            noise_fraction: config.noise_fraction,
            psf,
            scratch: vec![0.0; grid.len()],
        }
    }

    /// Forms the taxel image `out` (`rows * cols`, row-major) from the per-sample penetration
    /// (metres; blurred in place); the noise of reading number `reading` comes from
    /// `rng::stream(noise_seed, reading)`.
    pub fn form(&mut self, penetration_m: &mut [f64], noise_seed: u64, reading: u64, out: &mut [f64]) {
        let (sc, sr) = (self.cols * self.k, self.rows * self.k);
        if let Some((along_x, along_y)) = &self.psf {
            for i in 0..sr {
                along_x.apply(penetration_m, &mut self.scratch, i * sc, 1);
            }
            for j in 0..sc {
                along_y.apply(&self.scratch, penetration_m, j, sc);
            }
        }
        let norm = 1.0 / ((self.k * self.k) as f64 * self.thickness_m);
        for r in 0..self.rows {
            for c in 0..self.cols {
                let mut sum = 0.0;
                for i in r * self.k..(r + 1) * self.k {
                    let row = &penetration_m[i * sc + c * self.k..i * sc + (c + 1) * self.k];
                    sum += row.iter().sum::<f64>();
                }
                out[r * self.cols + c] = (sum * norm).clamp(0.0, 1.0);
            }
        }
        if self.noise_fraction > 0.0 {
            let half = 0.5 * self.noise_fraction;
            let mut rng = crate::rng::stream(noise_seed, reading);
            for v in out.iter_mut() {
                let n: f64 = rng.random_range(-half..half);
                *v = (*v + n).clamp(0.0, 1.0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup(config: &SensorConfig) -> (SampleGrid, ImageFormation) {
        let grid = SampleGrid::new(config);
        let formation = ImageFormation::new(config, &grid);
        (grid, formation)
    }

    #[test]
    fn uniform_penetration_stays_uniform_under_any_psf() {
        for sigma in [0.0, 0.0002, 0.003, 0.05] {
            let config = SensorConfig {
                psf_sigma_m: sigma,
                rays_per_taxel: 9,
                ..SensorConfig::default()
            };
            let (grid, mut f) = setup(&config);
            let mut p = vec![0.3 * config.thickness_m; grid.len()];
            let mut out = vec![0.0; 36];
            f.form(&mut p, 0, 0, &mut out);
            assert!(out.iter().all(|v| (v - 0.3).abs() < 1e-12), "{sigma}: {out:?}");
        }
    }

    #[test]
    fn area_average_then_saturation() {
        let config = SensorConfig {
            rows: 1,
            cols: 2,
            psf_sigma_m: 0.0,
            rays_per_taxel: 4,
            ..SensorConfig::default()
        };
        let (grid, mut f) = setup(&config);
        assert_eq!((grid.rows, grid.cols), (2, 4));
        let t = config.thickness_m;
        // Left taxel: samples 0,1 of both rows; right taxel: samples 2,3.
        let mut p = vec![0.0, t, t, t, 0.0, 0.0, t, 2.0 * t];
        let mut out = vec![0.0; 2];
        f.form(&mut p, 0, 0, &mut out);
        assert!((out[0] - 0.25).abs() < 1e-15 && out[1] == 1.0, "{out:?}");
    }

    #[test]
    fn psf_blurs_a_point_into_a_normalised_gaussian() {
        // 25 x 25 taxels of 0.48 mm, sigma 0.72 mm = 1.5 samples: support +-6 samples.
        let config = SensorConfig {
            rows: 25,
            cols: 25,
            psf_sigma_m: 0.00072,
            rays_per_taxel: 1,
            ..SensorConfig::default()
        };
        let (grid, mut f) = setup(&config);
        let t = config.thickness_m;
        let mut p = vec![0.0; grid.len()];
        let centre = 12 * 25 + 12;
        p[centre] = t;
        let mut out = vec![0.0; 625];
        f.form(&mut p, 0, 0, &mut out);
        // Far from the border the blur keeps the total; the peak drops to the Gaussian's centre weight.
        let sum: f64 = out.iter().sum();
        assert!((sum - 1.0).abs() < 1e-12, "{sum}");
        let s = 0.00072 / grid.dx_m();
        let w0 = 1.0
            / (-6..=6)
                .map(|j| (-0.5 * (j as f64 / s).powi(2)).exp())
                .sum::<f64>();
        assert!((out[centre] - w0 * w0).abs() < 1e-12);
        assert_eq!(out[centre - 1], out[centre + 1]);
        assert_eq!(out[centre - 25], out[centre + 25]);
    }

    #[test]
    fn noise_is_zero_mean_bounded_and_seeded() {
        let config = SensorConfig {
            rows: 32,
            cols: 32,
            noise_fraction: 0.4,
            psf_sigma_m: 0.0,
            rays_per_taxel: 1,
            ..SensorConfig::default()
        };
        let (grid, mut f) = setup(&config);
        let t = config.thickness_m;
        let form = |f: &mut ImageFormation, reading| {
            let mut p = vec![0.5 * t; grid.len()];
            let mut out = vec![0.0; 1024];
            f.form(&mut p, 9, reading, &mut out);
            out
        };
        let a = form(&mut f, 0);
        assert_eq!(a, form(&mut f, 0));
        assert_ne!(a, form(&mut f, 1));
        assert!(a.iter().all(|v| (0.3..=0.7).contains(v)));
        let mean = a.iter().sum::<f64>() / a.len() as f64;
        // U(-0.2, 0.2) has sd 0.115; the mean of 1024 has sd 0.0036.
        assert!((mean - 0.5).abs() < 0.015, "{mean}");
    }
}
