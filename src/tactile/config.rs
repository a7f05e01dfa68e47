//! The covering sensor's configuration (Sec. V-A2, DESIGN.md §4).

use serde::{Deserialize, Serialize};

/// Everything that determines how the covering sensor forms an image. Lengths in metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SensorConfig {
    /// Taxel rows (image height).
    pub rows: usize,
    /// Taxel columns (image width).
    pub cols: usize,
    /// Pad extent along the image columns (the pad's right axis), metres.
    pub pad_width_m: f64,
    /// Pad extent along the image rows (the pad's up axis), metres.
    pub pad_height_m: f64,
    /// Covering thickness t: the depth of the viewing volume, metres.
    pub thickness_m: f64,
    /// Standard deviation of the Gaussian point-spread, metres (0 disables it).
    pub psf_sigma_m: f64,
    /// Rays per taxel side: each taxel is supersampled by a `k x k` grid of rays.
    pub rays_per_taxel: usize,
    /// Amplitude of uniform zero-mean additive noise as a fraction of the sensing range (Sec. V-B7).
    pub noise_fraction: f64,
    /// Seed of the noise stream.
    pub noise_seed: u64,
}
