//! The settings of Fig. 16b (`real-frames`) beyond the run's scale and seed, apart from the
//! experiment so that the run's context can carry them without importing the experiment.

use serde::Serialize;

use super::sim_to_real::GaussianBlur;

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

impl RealFramesOptions {
    /// Checks the settings, naming the flag at fault.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.contact_threshold.is_finite() && (0.0..=1.0).contains(&self.contact_threshold)) {
            return Err(format!(
                "--contact-threshold {}: must be in [0, 1] of the sensing range",
                self.contact_threshold
            ));
        }
        GaussianBlur::new(self.blur_sigma_taxels).map_err(|e| format!("--blur-sigma: {e}"))?;
        if self.trials == 0 {
            return Err("--trials: must be at least 1".into());
        }
        Ok(())
    }
}
