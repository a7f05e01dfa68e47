//! The preprocessing of real sensor images before recognition with models trained in simulation
//! (Sec. V-F): each element replaced by its square root, then a small Gaussian blur.
//!
//! The square root compensates a force response that is no longer linear at the applied
//! displacements and the real pad not lying as flush with the surface as the simulated one; the
//! blur evens out differences between individual sensor elements. The paper gives no blur width:
//! the default here, sigma = 0.5 taxel, is "small" in the sense that a taxel keeps about 62 % of its
//! own weight (the 1-D kernel at sigma 0.5 is 0.054, 0.244, 0.403, 0.244, 0.054 over +-2 taxels).

use crate::tactile::TactileImage;

/// The default blur width, in taxels.
pub const DEFAULT_BLUR_SIGMA_TAXELS: f64 = 0.5;

/// A bad preprocessing setting.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("Gaussian blur sigma must be finite and >= 0 taxels, got {sigma_taxels}")]
pub struct BlurError {
    pub sigma_taxels: f64,
}

/// A separable Gaussian blur over the taxel grid.
///
/// The 1-D kernel is the sampled Gaussian `k(a) = exp(-a^2 / (2 sigma^2))` for integer offsets
/// `|a| <= r = ceil(3 sigma)`, normalised to sum 1. At the borders the blur is a normalised
/// convolution: taps outside the image are dropped and the remaining weights rescaled to sum 1,
///
/// `out(i, j) = sum_{a,b} k(a) k(b) I(i+a, j+b) / sum_{a,b inside} k(a) k(b)`,
///
/// so a uniform image stays uniform, every output is a convex combination of inputs (values stay in
/// [0, 1]), and mass is preserved exactly for any image whose non-zero taxels lie at least `2r`
/// from every border. sigma = 0 is the identity.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussianBlur {
    sigma_taxels: f64,
    /// `kernel[r + a] = k(a)`.
    kernel: Vec<f64>,
}

impl GaussianBlur {
    pub fn new(sigma_taxels: f64) -> Result<Self, BlurError> {
        if !(sigma_taxels.is_finite() && sigma_taxels >= 0.0) {
            return Err(BlurError { sigma_taxels });
        }
        Ok(Self::with_valid_sigma(sigma_taxels))
    }

    /// `sigma_taxels` already known finite and >= 0.
    fn with_valid_sigma(sigma_taxels: f64) -> Self {
        if sigma_taxels == 0.0 {
            return Self {
                sigma_taxels,
                kernel: vec![1.0],
            };
        }
        let radius = (3.0 * sigma_taxels).ceil() as i64;
        let raw: Vec<f64> = (-radius..=radius)
            .map(|a| (-((a * a) as f64) / (2.0 * sigma_taxels * sigma_taxels)).exp())
            .collect();
        let sum: f64 = raw.iter().sum();
        Self {
            sigma_taxels,
            kernel: raw.iter().map(|k| k / sum).collect(),
        }
    }

    pub fn sigma_taxels(&self) -> f64 {
        self.sigma_taxels
    }

    /// The normalised 1-D kernel over offsets `-r..=r`.
    pub fn kernel(&self) -> &[f64] {
        &self.kernel
    }

    fn radius(&self) -> usize {
        self.kernel.len() / 2
    }

    /// The blurred image (same size, same pose): down every column (`cols` lines of `rows`
    /// values, a row apart), then along every row (`rows` lines of `cols` values, side by side).
    pub fn apply(&self, image: &TactileImage) -> TactileImage {
        let (rows, cols) = (image.rows(), image.cols());
        let down_columns = self.pass(image.values(), cols, rows, 1, cols);
        let both = self.pass(&down_columns, rows, cols, cols, 1);
        rebuild(image, both)
    }

    /// Blurs along one axis: `n` lines of `len` values, element `t` of line `l` at
    /// `l * line_stride + t * step`.
    fn pass(&self, values: &[f64], n: usize, len: usize, line_stride: usize, step: usize) -> Vec<f64> {
        let r = self.radius() as i64;
        let mut out = vec![0.0; values.len()];
        for l in 0..n {
            for t in 0..len as i64 {
                let (mut acc, mut weight) = (0.0, 0.0);
                for a in -r..=r {
                    let s = t + a;
                    if (0..len as i64).contains(&s) {
                        let k = self.kernel[(a + r) as usize];
                        acc += k * values[l * line_stride + s as usize * step];
                        weight += k;
                    }
                }
                out[l * line_stride + t as usize * step] = acc / weight;
            }
        }
        out
    }
}

/// Sec. V-F: square root of every element, then [`GaussianBlur`].
#[derive(Debug, Clone, PartialEq)]
pub struct SimToRealPreprocess {
    pub blur: GaussianBlur,
}

impl SimToRealPreprocess {
    pub fn new(blur_sigma_taxels: f64) -> Result<Self, BlurError> {
        Ok(Self {
            blur: GaussianBlur::new(blur_sigma_taxels)?,
        })
    }

    pub fn apply(&self, image: &TactileImage) -> TactileImage {
        self.blur.apply(&square_root(image))
    }
}

impl Default for SimToRealPreprocess {
    fn default() -> Self {
        Self {
            blur: GaussianBlur::with_valid_sigma(DEFAULT_BLUR_SIGMA_TAXELS),
        }
    }
}

/// Every element replaced by its square root (in [0, 1] it stays in [0, 1]).
pub fn square_root(image: &TactileImage) -> TactileImage {
    rebuild(image, image.values().iter().map(|v| v.sqrt()).collect())
}

/// `values` (computed from `image`, in [0, 1] up to rounding) as an image with `image`'s size and pose.
fn rebuild(image: &TactileImage, values: Vec<f64>) -> TactileImage {
    let values: Vec<f64> = values.into_iter().map(|v| v.clamp(0.0, 1.0)).collect();
    let out = match TactileImage::new(image.rows(), image.cols(), values) {
        Ok(out) => out,
        Err(_) => unreachable!("same size as a valid image, values clamped to [0, 1]"),
    };
    match image.pose() {
        Some(pose) => out.with_pose(*pose),
        None => out,
    }
}
