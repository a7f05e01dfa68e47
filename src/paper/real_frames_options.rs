//! The settings of Fig. 16b (`real-frames`) beyond the run's scale and seed, apart from the
//! experiment so that the run's context can carry them without importing the experiment.

use serde::Serialize;

use super::sim_to_real::{BlurError, GaussianBlur};
use crate::valid::Check;

/// "performances were averaged over 7 trials of this full division, training, and testing
/// process" (Sec. V-E).
pub const PAPER_TRIALS: usize = 7;
/// The default contact threshold, as a fraction of the sensing range: a frame whose largest taxel
/// stays below a tenth of the range is taken as the letter not touching the sensor. The paper
/// prunes non-contacts without giving its criterion.
pub const DEFAULT_CONTACT_THRESHOLD: f64 = 0.1;

/// The experiment's settings beyond the context's scale and seed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RealFramesOptions {
    /// Frames whose peak is below this fraction of the sensing range are dropped.
    pub contact_threshold: f64,
    /// Replace every taxel by its square root before describing (Sec. V-F).
    pub square_root: bool,
    /// Gaussian blur width in taxels before describing (Sec. V-F); 0 is no blur.
    pub blur_sigma_taxels: f64,
    /// Trials of the whole split-train-test process.
    pub trials: usize,
}

impl Default for RealFramesOptions {
    fn default() -> Self {
        Self {
            contact_threshold: DEFAULT_CONTACT_THRESHOLD,
            square_root: false,
            blur_sigma_taxels: 0.0,
            trials: PAPER_TRIALS,
        }
    }
}

/// A [`RealFramesOptions`] field out of range, named by its flag.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RealFramesOptionsError {
    #[error("--contact-threshold {0}: must be in [0, 1] of the sensing range")]
    ContactThreshold(f64),
    #[error("--blur-sigma: {0}")]
    BlurSigma(#[from] BlurError),
    #[error("--trials: must be at least 1")]
    Trials,
}

impl Check for RealFramesOptions {
    type Error = RealFramesOptionsError;

    /// Every setting against its range, naming the flag at fault.
    fn check(&self) -> Result<(), RealFramesOptionsError> {
        let Self {
            contact_threshold,
            square_root: _,
            blur_sigma_taxels,
            trials,
        } = *self;
        if !(contact_threshold.is_finite() && (0.0..=1.0).contains(&contact_threshold)) {
            return Err(RealFramesOptionsError::ContactThreshold(contact_threshold));
        }
        GaussianBlur::new(blur_sigma_taxels)?;
        if trials == 0 {
            return Err(RealFramesOptionsError::Trials);
        }
        Ok(())
    }
}
