//! The sensor flags shared by every command that simulates the covering sensor.

use clap::Args;
use taction::tactile::{ConfigKey, SensorConfig, psf_sigma_for_thickness};

#[derive(Debug, Clone, Args)]
pub struct SensorArgs {
    /// Taxel rows.
    #[arg(long, default_value_t = 6)]
    pub rows: usize,
    /// Taxel columns.
    #[arg(long, default_value_t = 6)]
    pub cols: usize,
    /// Side of the square pad, metres.
    #[arg(long, default_value_t = 0.012, allow_hyphen_values = true)]
    pub pad_m: f64,
    /// Covering thickness t, metres [default: 10% of the pad side].
    #[arg(long, allow_hyphen_values = true)]
    pub thickness_m: Option<f64>,
    /// Point-spread sigma, metres; 0 disables it [default: 0.48 t, the half-space law].
    #[arg(long, allow_hyphen_values = true)]
    pub psf_sigma_m: Option<f64>,
    /// Rays per taxel, a perfect square (1 casts one ray through each taxel centre).
    #[arg(long, default_value_t = 4)]
    pub rays_per_taxel: usize,
    /// Uniform zero-mean noise width as a fraction of the range (0.4: +-0.2).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub noise: f64,
}

/// A sensor flag out of range; names the flag.
#[derive(Debug, thiserror::Error)]
#[error("--{flag}: {value} is out of range: want {allowed}")]
pub struct SensorFlagError {
    pub flag: &'static str,
    pub value: String,
    pub allowed: String,
}

/// The flag that sets a config key.
pub fn flag_of(key: ConfigKey) -> &'static str {
    match key {
        ConfigKey::Rows => "rows",
        ConfigKey::Cols => "cols",
        ConfigKey::PadWidth | ConfigKey::PadHeight => "pad-m",
        ConfigKey::Thickness => "thickness-m",
        ConfigKey::PsfSigma => "psf-sigma-m",
        ConfigKey::RaysPerTaxel => "rays-per-taxel",
        ConfigKey::NoiseFraction => "noise",
        ConfigKey::NoiseSeed => "seed",
    }
}

impl SensorArgs {
    /// The sensor configuration the flags describe, with noise seed `noise_seed`, validated.
    pub fn config(&self, noise_seed: u64) -> Result<SensorConfig, SensorFlagError> {
        let thickness_m = self.thickness_m.unwrap_or(0.1 * self.pad_m);
        let config = SensorConfig {
            rows: self.rows,
            cols: self.cols,
            pad_width_m: self.pad_m,
            pad_height_m: self.pad_m,
            thickness_m,
            psf_sigma_m: self
                .psf_sigma_m
                .unwrap_or_else(|| psf_sigma_for_thickness(thickness_m)),
            rays_per_taxel: self.rays_per_taxel,
            noise_fraction: self.noise,
            noise_seed,
        };
        config.validate().map_err(|e| SensorFlagError {
            flag: flag_of(e.key),
            value: e.value.clone(),
            allowed: e.key.allowed(),
        })?;
        Ok(config)
    }
}
