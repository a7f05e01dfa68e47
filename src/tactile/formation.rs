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
//! normalisation factor into a pass along x and a pass along y, truncated at 4 sigma:
//! `q = G_y P G_x^T` with `G_x`, `G_y` the row-normalised 1D Gaussian matrices.
//!
//! The area average is separable too (`A_x`, `A_y`: the mean of the `k` samples of each taxel
//! along an axis), and everything up to the clamp is linear, so the taxel image before the clamp is
//!
//! ```text
//! I = (1 / t) (A_y G_y) P (A_x G_x)^T = (1 / t) K_y P K_x^T,   K_x[c][j] = (1/k) sum_{j' in taxel c} G_x[j'][j],
//! ```
//!
//! one `cols x (cols k)` band matrix per axis, precomputed. A reading then costs one pass of `K_x`
//! over each sample row (`cols` outputs of `k + 8 sigma` taps each) and one of `K_y` over the
//! reduced rows, instead of blurring every sample: at 26x26 taxels with 16 rays the blur alone
//! was two passes of 41 taps over 10,816 samples.
//!
//! Noise is deterministic per (noise seed, reading index): reading `n` of a sensor draws its noise
//! from [`crate::rng::stream`]`(seed, n)`, one `U(-f/2, f/2)` per taxel in row-major order.

use rand::RngExt;

use crate::simd::{dot, has_avx2};
use crate::tactile::SensorConfig;
use crate::tactile::grid::SampleGrid;

/// Kernel support in standard deviations.
const PSF_SUPPORT_SIGMAS: f64 = 4.0;

/// The 1D border-normalised Gaussian of standard deviation `sigma_samples` (in sample spacings,
/// > 0) over `n` samples, as its output `i`'s first input index and weights.
fn gaussian_rows(n: usize, sigma_samples: f64) -> Vec<(usize, Vec<f64>)> {
    let radius = (PSF_SUPPORT_SIGMAS * sigma_samples).ceil() as usize;
    (0..n)
        .map(|i| {
            let lo = i.saturating_sub(radius);
            let hi = (i + radius).min(n - 1);
            let w: Vec<f64> = (lo..=hi)
                .map(|j| {
                    let u = (j as f64 - i as f64) / sigma_samples;
                    (-0.5 * u * u).exp()
                })
                .collect();
            let sum: f64 = w.iter().sum();
            (lo, w.iter().map(|x| x / sum).collect())
        })
        .collect()
}

/// One axis of the folded point-spread and area average: `K[c][j]` for `taxels` outputs over
/// `taxels * k` samples, a band per output.
#[derive(Debug, Clone, PartialEq)]
struct TaxelPass {
    /// For taxel `c`: first sample index of its band and the band's offset in `weights`.
    start: Vec<usize>,
    offset: Vec<usize>,
    /// Band length (the same for every taxel, bands at the border padded with zeros), so that
    /// the inner loops have one trip count.
    len: usize,
    weights: Vec<f64>,
}

impl TaxelPass {
    /// `sigma_samples` is the PSF's standard deviation in sample spacings; `None` for no PSF.
    fn new(taxels: usize, k: usize, sigma_samples: Option<f64>) -> Self {
        let n = taxels * k;
        let blur = sigma_samples.map(|s| gaussian_rows(n, s));
        // Row j' of the blur touches samples [lo, lo + len); taxel c averages rows ck..ck+k.
        let band = |c: usize| -> (usize, usize) {
            match &blur {
                Some(rows) => {
                    let lo = rows[c * k].0;
                    let (last_lo, last_w) = &rows[c * k + k - 1];
                    (lo, last_lo + last_w.len())
                }
                None => (c * k, c * k + k),
            }
        };
        let len = (0..taxels).map(|c| band(c).1 - band(c).0).max().unwrap_or(0);
        let mut pass = Self {
            start: Vec::with_capacity(taxels),
            offset: Vec::with_capacity(taxels),
            len,
            weights: Vec::with_capacity(taxels * len),
        };
        let inv_k = 1.0 / k as f64;
        for c in 0..taxels {
            // Keep the band inside the samples: shift it left when it would run past the end.
            let start = band(c).0.min(n - len);
            let mut w = vec![0.0; len];
            for j in c * k..(c + 1) * k {
                match &blur {
                    Some(rows) => {
                        let (lo, row) = &rows[j];
                        for (u, x) in row.iter().enumerate() {
                            w[lo + u - start] += inv_k * x;
                        }
                    }
                    None => w[j - start] += inv_k,
                }
            }
            pass.start.push(start);
            pass.offset.push(pass.weights.len());
            pass.weights.extend(w);
        }
        pass
    }

    /// The weights of taxel `c` and the first sample they apply to.
    #[inline]
    fn band(&self, c: usize) -> (usize, &[f64]) {
        let o = self.offset[c];
        (self.start[c], &self.weights[o..o + self.len])
    }
}

/// The fixed part of image formation for one config, with its scratch buffer.
#[derive(Debug, Clone)]
pub struct ImageFormation {
    rows: usize,
    cols: usize,
    sample_cols: usize,
    thickness_m: f64,
    noise_fraction: f64,
    /// Sample columns -> taxel columns (along x) and sample rows -> taxel rows (along y).
    along_x: TaxelPass,
    along_y: TaxelPass,
    /// `along_x` applied to every sample row: `(rows k) x cols`.
    reduced: Vec<f64>,
    /// Whether the processor has AVX2 (the passes then run four lanes wide).
    avx2: bool,
}

impl ImageFormation {
    /// For a valid config and its grid.
    pub fn new(config: &SensorConfig, grid: &SampleGrid) -> Self {
        let k = config.rays_per_side();
        let psf = config.psf_sigma_m > 0.0;
        Self {
            rows: config.rows,
            cols: config.cols,
            sample_cols: grid.cols,
            thickness_m: config.thickness_m,
            noise_fraction: config.noise_fraction,
            along_x: TaxelPass::new(config.cols, k, psf.then(|| config.psf_sigma_m / grid.dx_m())),
            along_y: TaxelPass::new(config.rows, k, psf.then(|| config.psf_sigma_m / grid.dy_m())),
            reduced: vec![0.0; grid.rows * config.cols],
            avx2: has_avx2(),
        }
    }

    /// Forms the taxel image `out` (`rows * cols`, row-major) from the per-sample penetration
    /// (metres, row-major over the grid); the noise of reading number `reading` comes from
    /// `rng::stream(noise_seed, reading)`.
    pub fn form(&mut self, penetration_m: &[f64], noise_seed: u64, reading: u64, out: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where the processor has AVX2 (checked at construction).
            unsafe { self.fold_avx2(penetration_m, out) };
        } else {
            self.fold(penetration_m, out);
        }
        #[cfg(not(target_arch = "x86_64"))]
        self.fold(penetration_m, out);
        if self.noise_fraction > 0.0 {
            let half = 0.5 * self.noise_fraction;
            let mut rng = crate::rng::stream(noise_seed, reading);
            for v in out.iter_mut() {
                let n: f64 = rng.random_range(-half..half);
                *v = (*v + n).clamp(0.0, 1.0);
            }
        }
    }

    /// [`Self::fold_body`] compiled for the processor's baseline.
    fn fold(&mut self, penetration_m: &[f64], out: &mut [f64]) {
        self.fold_body(penetration_m, out, |along_x, row, reduced| {
            for (c, r) in reduced.iter_mut().enumerate() {
                let (start, w) = along_x.band(c);
                *r = dot(w, &row[start..start + w.len()]);
            }
        });
    }

    /// [`Self::fold_body`] compiled with AVX2: four lanes per instruction where the baseline has
    /// two. Each lane runs the same additions and multiplications in the same order (Rust never
    /// fuses them), so the image is the same bit for bit.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn fold_avx2(&mut self, penetration_m: &[f64], out: &mut [f64]) {
        self.fold_body(penetration_m, out, |along_x, row, reduced| {
            // SAFETY: this function runs only where the processor has AVX2.
            unsafe { four_lanes::row_pass(along_x, row, reduced) }
        });
    }

    /// The folded point-spread and area average, `(1 / t) K_y P K_x^T`, then the clamp;
    /// `row_pass` applies `K_x` to one sample row, as [`dot`] does for each taxel column.
    #[inline(always)]
    fn fold_body(
        &mut self,
        penetration_m: &[f64],
        out: &mut [f64],
        row_pass: impl Fn(&TaxelPass, &[f64], &mut [f64]),
    ) {
        let (sc, cols) = (self.sample_cols, self.cols);
        for (row, reduced) in penetration_m
            .chunks_exact(sc)
            .zip(self.reduced.chunks_exact_mut(cols))
        {
            row_pass(&self.along_x, row, reduced);
        }
        let norm = 1.0 / self.thickness_m;
        for (r, out_row) in out.chunks_exact_mut(cols).enumerate().take(self.rows) {
            let (start, w) = self.along_y.band(r);
            out_row.fill(0.0);
            for (wi, reduced) in w.iter().zip(self.reduced[start * cols..].chunks_exact(cols)) {
                for (o, x) in out_row.iter_mut().zip(reduced) {
                    *o += wi * x;
                }
            }
            for o in out_row.iter_mut() {
                *o = (*o * norm).clamp(0.0, 1.0);
            }
        }
    }
}

/// The pass along x four lanes wide, each taxel's sum [`dot`]'s bit for bit.
#[cfg(target_arch = "x86_64")]
mod four_lanes {
    use std::arch::x86_64::{
        __m256d, _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };

    use super::TaxelPass;

    /// `K_x` applied to one sample row: the taxel columns four at a time ([`sums`] of four bands),
    /// so that four independent chains of additions are in flight where one taxel's sum waits on
    /// its last addition; the columns left over one at a time.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn row_pass(along_x: &TaxelPass, row: &[f64], reduced: &mut [f64]) {
        let bands = |c: usize| {
            let (start, w) = along_x.band(c);
            (w, &row[start..start + w.len()])
        };
        let done = reduced.len() - reduced.len() % 4;
        for (q, out) in reduced.chunks_exact_mut(4).enumerate() {
            // SAFETY: the processor has AVX2 (this function's contract), and every band of
            // `along_x` and its slice of `row` have the pass's length.
            out.copy_from_slice(&unsafe { sums([0, 1, 2, 3].map(|i| bands(4 * q + i))) });
        }
        for (c, o) in reduced.iter_mut().enumerate().skip(done) {
            // SAFETY: as above.
            [*o] = unsafe { sums([bands(c)]) };
        }
    }

    /// [`dot`](crate::simd::dot) of `N` pairs of bands of one length at once, each pair's four partial
    /// sums in a register of its own (lane `l` is `dot`'s `lanes[l]`).
    ///
    /// # Safety
    /// The processor must have AVX2, and every slice of `pairs` must be as long as the first
    /// (the bands of one [`TaxelPass`] all have its length): the loads read that many values of
    /// each.
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn sums<const N: usize>(pairs: [(&[f64], &[f64]); N]) -> [f64; N] {
        let len = pairs.first().map_or(0, |(w, _)| w.len());
        debug_assert!(pairs.iter().all(|(w, p)| w.len() == len && p.len() == len));
        let whole = len - len % 4;
        let mut acc = [_mm256_setzero_pd(); N];
        for m in (0..whole).step_by(4) {
            for (acc, (w, p)) in acc.iter_mut().zip(&pairs) {
                // SAFETY: `m + 4 <= whole <= len`, the length of both slices of every pair.
                *acc = unsafe { add_product(*acc, w.as_ptr().add(m), p.as_ptr().add(m)) };
            }
        }
        let mut out = [0.0; N];
        for ((o, acc), (w, p)) in out.iter_mut().zip(acc).zip(&pairs) {
            *o = finish(acc, &w[whole..], &p[whole..]);
        }
        out
    }

    /// `acc + a[0..4] * b[0..4]`, lane by lane (never fused).
    ///
    /// # Safety
    /// Four `f64` must be readable at `a` and at `b`.
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn add_product(acc: __m256d, a: *const f64, b: *const f64) -> __m256d {
        // SAFETY: the caller's promise; unaligned loads.
        unsafe { _mm256_add_pd(acc, _mm256_mul_pd(_mm256_loadu_pd(a), _mm256_loadu_pd(b))) }
    }

    /// [`dot`](crate::simd::dot)'s last step: its four partial sums, then the terms after the last whole
    /// chunk of four.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn finish(acc: __m256d, a_tail: &[f64], b_tail: &[f64]) -> f64 {
        let mut lanes = [0.0; 4];
        // SAFETY: `lanes` holds four `f64`.
        unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), acc) };
        let tail: f64 = a_tail.iter().zip(b_tail).map(|(x, y)| x * y).sum();
        (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
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
            let p = vec![0.3 * config.thickness_m; grid.len()];
            let mut out = vec![0.0; 36];
            f.form(&p, 0, 0, &mut out);
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
        let p = vec![0.0, t, t, t, 0.0, 0.0, t, 2.0 * t];
        let mut out = vec![0.0; 2];
        f.form(&p, 0, 0, &mut out);
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
        f.form(&p, 0, 0, &mut out);
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
    fn folded_kernel_equals_blur_then_average() {
        use rand::RngExt;
        // The definition, step by step: the 2D border-normalised Gaussian over all samples, then
        // the mean over each taxel's samples, then the clamp.
        let config = SensorConfig {
            rows: 5,
            cols: 7,
            psf_sigma_m: 0.0009,
            rays_per_taxel: 9,
            ..SensorConfig::default()
        };
        let (grid, mut f) = setup(&config);
        let t = config.thickness_m;
        let mut rng = crate::rng::rng(3);
        let p: Vec<f64> = (0..grid.len()).map(|_| rng.random_range(0.0..t)).collect();
        let (sr, sc, k) = (grid.rows as i64, grid.cols as i64, 3);
        let (sx, sy) = (config.psf_sigma_m / grid.dx_m(), config.psf_sigma_m / grid.dy_m());
        let (rx, ry) = ((4.0 * sx).ceil() as i64, (4.0 * sy).ceil() as i64);
        let mut q = vec![0.0; grid.len()];
        for i in 0..sr {
            for j in 0..sc {
                let (mut num, mut den) = (0.0, 0.0);
                for u in (i - ry).max(0)..=(i + ry).min(sr - 1) {
                    for v in (j - rx).max(0)..=(j + rx).min(sc - 1) {
                        let g =
                            (-0.5 * (((u - i) as f64 / sy).powi(2) + ((v - j) as f64 / sx).powi(2))).exp();
                        num += g * p[(u * sc + v) as usize];
                        den += g;
                    }
                }
                q[(i * sc + j) as usize] = num / den;
            }
        }
        let mut out = vec![0.0; config.taxel_count()];
        f.form(&p, 0, 0, &mut out);
        for r in 0..config.rows as i64 {
            for c in 0..config.cols as i64 {
                let mean = (0..k)
                    .flat_map(|a| (0..k).map(move |b| ((r * k + a) * sc + c * k + b) as usize))
                    .map(|s| q[s])
                    .sum::<f64>()
                    / (k * k) as f64;
                let got = out[(r * config.cols as i64 + c) as usize];
                assert!(
                    (got - (mean / t).clamp(0.0, 1.0)).abs() < 1e-12,
                    "({r}, {c}): {got} vs {mean}"
                );
            }
        }
    }

    #[test]
    fn the_four_lane_passes_form_the_same_image_as_the_baseline() {
        use rand::RngExt;
        // The AVX2 build of the folded passes against the baseline build, bit for bit, on
        // penetrations with no contact, full contact, and patches of both with random depths,
        // at the bench's sizes, with and without the point-spread; taxel columns in fours with
        // three or none left over, and fewer than four.
        if !has_avx2() {
            return;
        }
        let mut rng = crate::rng::rng(31);
        for (n, rays, sigma) in [
            (2, 4, None),
            (6, 4, None),
            (6, 16, None),
            (14, 4, None),
            (26, 16, None),
            (7, 9, Some(0.0)),
        ] {
            let base = SensorConfig::default();
            let config = SensorConfig {
                rows: n,
                cols: n + 1,
                rays_per_taxel: rays,
                psf_sigma_m: sigma.unwrap_or(base.psf_sigma_m),
                ..base
            };
            let (grid, mut wide) = setup(&config);
            let mut baseline = wide.clone();
            assert!(wide.avx2);
            baseline.avx2 = false;
            let t = config.thickness_m;
            for case in 0..12 {
                let p: Vec<f64> = (0..grid.len())
                    .map(|_| match case {
                        0 => 0.0,
                        1 => t,
                        _ if rng.random_bool(0.4) => 0.0,
                        _ => rng.random_range(0.0..=t),
                    })
                    .collect();
                let (mut a, mut b) = (vec![0.0; config.taxel_count()], vec![0.0; config.taxel_count()]);
                wide.form(&p, 0, 0, &mut a);
                baseline.form(&p, 0, 0, &mut b);
                assert_eq!(
                    a.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    b.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    "{n}x{n}x{rays}, case {case}"
                );
            }
        }
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
            let p = vec![0.5 * t; grid.len()];
            let mut out = vec![0.0; 1024];
            f.form(&p, 9, reading, &mut out);
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
