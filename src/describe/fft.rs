//! Fourier magnitudes for Polar-Fourier (Sec. IV-B5) and MNTI (Sec. IV-B6), with FFT plans cached
//! per length so that describing many images plans each size once.
//!
//! The forward DFT (rustfft's convention, unnormalised):
//!
//! ```text
//! X[k] = sum_{n=0}^{N-1} x[n] exp(-2 pi i k n / N)
//! ```
//!
//! Only magnitudes `|X[k]|` are kept: a cyclic shift of `x` multiplies `X[k]` by a unit phase, so the
//! magnitudes are invariant to it (rotation for a polar ring, translation for an image). For a real
//! signal `|X[k]| = |X[N - k]|` (Hermitian symmetry), so the lower half `k = 0 ..= N/2` holds every
//! distinct magnitude.

use std::collections::HashMap;
use std::fmt;
use std::sync::{Arc, PoisonError, RwLock};

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

use super::plane::Plane;

/// Forward FFT plans by length, shared by every thread describing images (read-mostly).
#[derive(Default)]
pub struct FftPlans {
    plans: RwLock<HashMap<usize, Arc<dyn Fft<f64>>>>,
}

impl fmt::Debug for FftPlans {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let plans = self.plans.read().unwrap_or_else(PoisonError::into_inner);
        let mut lengths: Vec<usize> = plans.keys().copied().collect();
        lengths.sort_unstable();
        f.debug_struct("FftPlans").field("lengths", &lengths).finish()
    }
}

impl FftPlans {
    pub fn new() -> Self {
        Self::default()
    }

    /// The forward plan for length `len`, planned on first use.
    pub fn forward(&self, len: usize) -> Arc<dyn Fft<f64>> {
        if let Some(plan) = self
            .plans
            .read()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&len)
        {
            return Arc::clone(plan);
        }
        let mut plans = self.plans.write().unwrap_or_else(PoisonError::into_inner);
        Arc::clone(
            plans
                .entry(len)
                .or_insert_with(|| FftPlanner::new().plan_fft_forward(len)),
        )
    }

    /// `|X[k]|` for every `k` of each consecutive chunk of `len` values of `signal` (one DFT per
    /// chunk), written over a buffer reused by the caller.
    pub fn magnitudes_of_chunks(&self, len: usize, signal: &[f64], out: &mut Vec<f64>) {
        out.clear();
        if len == 0 || signal.is_empty() {
            return;
        }
        let fft = self.forward(len);
        let mut buffer: Vec<Complex<f64>> = signal.iter().map(|&v| Complex::new(v, 0.0)).collect();
        let mut scratch = vec![Complex::new(0.0, 0.0); fft.get_inplace_scratch_len()];
        fft.process_with_scratch(&mut buffer, &mut scratch);
        out.extend(buffer.iter().map(|z| z.norm()));
    }

    /// The 2-D DFT magnitudes of a real plane, `|X[k_r, k_c]|` for `k_r = 0 .. rows` and
    /// `k_c = 0 ..= cols / 2` (the other half mirrors it), vectorised column by column (`k_r`
    /// fastest), as Vectorize does with images.
    ///
    /// ```text
    /// X[k_r, k_c] = sum_{r, c} I[r, c] exp(-2 pi i (k_r r / rows + k_c c / cols))
    /// ```
    pub fn magnitudes_2d(&self, plane: &Plane) -> Vec<f64> {
        let (rows, cols) = (plane.rows(), plane.cols());
        if rows == 0 || cols == 0 {
            return Vec::new();
        }
        let (row_fft, col_fft) = (self.forward(cols), self.forward(rows));
        let scratch_len = row_fft
            .get_inplace_scratch_len()
            .max(col_fft.get_inplace_scratch_len());
        let mut scratch = vec![Complex::new(0.0, 0.0); scratch_len];
        // Rows first (rustfft transforms each consecutive chunk of `cols`).
        let mut by_rows: Vec<Complex<f64>> = plane.values().iter().map(|&v| Complex::new(v, 0.0)).collect();
        row_fft.process_with_scratch(&mut by_rows, &mut scratch[..row_fft.get_inplace_scratch_len()]);
        // Then the kept columns, each gathered contiguously.
        let kept = cols / 2 + 1;
        let mut by_cols = Vec::with_capacity(rows * kept);
        for k_c in 0..kept {
            by_cols.extend((0..rows).map(|r| by_rows[r * cols + k_c]));
        }
        col_fft.process_with_scratch(&mut by_cols, &mut scratch[..col_fft.get_inplace_scratch_len()]);
        by_cols.iter().map(|z| z.norm()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;
    use std::f64::consts::PI;

    fn direct_dft_2d(plane: &Plane, k_r: usize, k_c: usize) -> f64 {
        let (rows, cols) = (plane.rows(), plane.cols());
        let mut z = Complex::new(0.0, 0.0);
        for r in 0..rows {
            for c in 0..cols {
                let phase = -2.0 * PI * ((k_r * r) as f64 / rows as f64 + (k_c * c) as f64 / cols as f64);
                z += plane.get(r, c) * Complex::new(phase.cos(), phase.sin());
            }
        }
        z.norm()
    }

    #[test]
    fn one_d_magnitudes_match_a_direct_dft() {
        let mut rng = crate::rng::stream(11, 0);
        let signal: Vec<f64> = (0..14).map(|_| rng.random_range(0.0..1.0)).collect();
        let plans = FftPlans::new();
        let mut out = Vec::new();
        // Two chunks of 7: each transformed separately.
        plans.magnitudes_of_chunks(7, &signal, &mut out);
        assert_eq!(out.len(), 14);
        for (chunk, mags) in signal.chunks(7).zip(out.chunks(7)) {
            for (k, &m) in mags.iter().enumerate() {
                let z: Complex<f64> = chunk
                    .iter()
                    .enumerate()
                    .map(|(n, &x)| x * Complex::from_polar(1.0, -2.0 * PI * (k * n) as f64 / 7.0))
                    .sum();
                assert!((z.norm() - m).abs() < 1e-12, "k = {k}: {} vs {m}", z.norm());
            }
        }
    }

    #[test]
    fn two_d_magnitudes_match_a_direct_dft_and_skip_the_mirror_half() {
        let mut rng = crate::rng::stream(12, 0);
        for (rows, cols) in [(5, 6), (6, 5), (9, 9), (1, 4)] {
            let plane = Plane::from_values(
                rows,
                cols,
                (0..rows * cols).map(|_| rng.random_range(0.0..1.0)).collect(),
            )
            .unwrap();
            let mags = FftPlans::new().magnitudes_2d(&plane);
            let kept = cols / 2 + 1;
            assert_eq!(mags.len(), rows * kept);
            for k_c in 0..kept {
                for k_r in 0..rows {
                    let want = direct_dft_2d(&plane, k_r, k_c);
                    assert!(
                        (mags[k_c * rows + k_r] - want).abs() < 1e-12,
                        "{rows}x{cols} ({k_r}, {k_c})"
                    );
                }
            }
            // The dropped half mirrors the kept one.
            let k_r = 1 % rows;
            let mirrored = direct_dft_2d(&plane, (rows - k_r) % rows, cols - 1);
            assert!(
                (mags[rows + k_r] - mirrored).abs() < 1e-12,
                "{rows}x{cols} mirror"
            );
        }
    }

    #[test]
    fn plans_are_cached_per_length() {
        let plans = FftPlans::new();
        let a = plans.forward(9);
        let b = plans.forward(9);
        assert!(Arc::ptr_eq(&a, &b));
        assert_eq!(format!("{plans:?}"), "FftPlans { lengths: [9] }");
    }
}
