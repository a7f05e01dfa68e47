//! The covering sensor's configuration (Sec. V-A2): what the `<config>` keys of a
//! `taction.covering` plugin instance mean, their defaults, their allowed ranges, and the
//! point-spread law.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::valid::{Check, Valid};

/// Everything that determines how the covering sensor forms an image. Lengths in metres.
///
/// A value of this type says nothing about validity by itself; its [`Check`] (called by every parser
/// and by the plugin) checks each field against [`ConfigKey::allowed`].
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
    /// Rays per taxel: each taxel is supersampled by a `k x k` grid of parallel rays, `k*k` =
    /// `rays_per_taxel` (so it must be a perfect square; 1 casts one ray through the taxel centre).
    pub rays_per_taxel: usize,
    /// Width of the uniform zero-mean additive noise as a fraction of the sensing range (Sec. V-B7):
    /// a value v becomes v + U(-f/2, f/2), clamped to [0, 1] ("an input value of 0.5 may range
    /// from 0.3 to 0.7 after applying 40% additive noise").
    pub noise_fraction: f64,
    /// Seed of the noise stream.
    pub noise_seed: u64,
}

/// The PSF law: sigma = `PSF_SIGMA_PER_THICKNESS` * t.
///
/// A point load on the surface of an elastic layer reaches the sensing plane at depth t spread
/// out; for an elastic half-space (Boussinesq) the vertical stress at depth t is
/// `sigma_z(r) ∝ t^3 / (r^2 + t^2)^(5/2)`, whose full width at half maximum is
/// `2 t sqrt(2^(2/5) - 1) ≈ 1.1305 t`. The Gaussian with the same FWHM has
/// `sigma = FWHM / (2 sqrt(2 ln 2)) ≈ 0.4801 t`. The paper only says the spread grows with the
/// covering thickness (Sec. V-B5); this law makes that growth linear, with the half-space constant.
pub const PSF_SIGMA_PER_THICKNESS: f64 = 0.480_079_409_263_117_5;

/// The paper's letters sensor (Sec. V-D): 6x6 taxels of 2 mm, a 12 mm pad.
pub const DEFAULT_PAD_M: f64 = 0.012;

/// "10% covering thickness" (Figs. 7-8) read as 10% of the pad side: 1.2 mm on the 12 mm pad.
pub const DEFAULT_THICKNESS_M: f64 = DEFAULT_THICKNESS_FRACTION * DEFAULT_PAD_M;
/// The default covering thickness as a fraction of the pad side (the paper's 10%).
pub const DEFAULT_THICKNESS_FRACTION: f64 = 0.1;

/// The Gaussian point-spread sigma of a covering of thickness `thickness_m` (see
/// `PSF_SIGMA_PER_THICKNESS`).
pub fn psf_sigma_for_thickness(thickness_m: f64) -> f64 {
    PSF_SIGMA_PER_THICKNESS * thickness_m
}

impl Default for SensorConfig {
    /// [`SensorConfig::paper`].
    fn default() -> Self {
        Self::paper()
    }
}

impl SensorConfig {
    /// The paper's letters sensor (Sec. V-D; "10% covering thickness", Figs. 7-8): 6x6 taxels on
    /// a 12 mm pad, a 1.2 mm covering, the PSF law's point-spread, 4 rays per taxel, no noise.
    ///
    /// ```
    /// use taction::tactile::SensorConfig;
    /// use taction::valid::Valid;
    ///
    /// let sensor = Valid::new(SensorConfig::paper())?;
    /// assert_eq!((sensor.rows, sensor.cols, sensor.taxel_count()), (6, 6, 36));
    /// assert_eq!((sensor.pad_width_m, sensor.thickness_m), (0.012, 0.1 * 0.012));
    /// # Ok::<(), taction::tactile::ConfigError>(())
    /// ```
    pub fn paper() -> Self {
        Self {
            rows: 6,
            cols: 6,
            pad_width_m: DEFAULT_PAD_M,
            pad_height_m: DEFAULT_PAD_M,
            thickness_m: DEFAULT_THICKNESS_M,
            psf_sigma_m: psf_sigma_for_thickness(DEFAULT_THICKNESS_M),
            rays_per_taxel: 4,
            noise_fraction: 0.0,
            noise_seed: 0,
        }
    }
}

/// One configuration key: the name used in MJCF `<config key=...>` and in messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ConfigKey {
    Rows,
    Cols,
    PadWidth,
    PadHeight,
    Thickness,
    PsfSigma,
    RaysPerTaxel,
    NoiseFraction,
    NoiseSeed,
}

/// Largest number of taxel rows or columns.
pub const MAX_TAXELS_PER_SIDE: usize = 256;
/// Largest supersampling: 8 x 8 rays per taxel (so at most 2048 x 2048 rays per image).
pub const MAX_RAYS_PER_TAXEL: usize = 64;
/// Largest pad side, covering thickness and PSF sigma, metres: far beyond any fingertip sensor,
/// small enough that single-precision mesh coordinates keep sub-micrometre resolution.
pub const MAX_LENGTH_M: f64 = 1.0;
/// Largest noise width as a fraction of the range: Sec. V-C goes beyond the signal (100%).
pub const MAX_NOISE_FRACTION: f64 = 2.0;

impl ConfigKey {
    /// Every key, in the order the MJCF helpers write them.
    pub const ALL: [ConfigKey; 9] = [
        Self::Rows,
        Self::Cols,
        Self::PadWidth,
        Self::PadHeight,
        Self::Thickness,
        Self::PsfSigma,
        Self::RaysPerTaxel,
        Self::NoiseFraction,
        Self::NoiseSeed,
    ];

    /// The MJCF config key.
    pub fn name(self) -> &'static str {
        match self {
            Self::Rows => "rows",
            Self::Cols => "cols",
            Self::PadWidth => "pad_width_m",
            Self::PadHeight => "pad_height_m",
            Self::Thickness => "thickness_m",
            Self::PsfSigma => "psf_sigma_m",
            Self::RaysPerTaxel => "rays_per_taxel",
            Self::NoiseFraction => "noise_fraction",
            Self::NoiseSeed => "noise_seed",
        }
    }

    /// The allowed values, as said in error messages (short: MuJoCo keeps about 80 characters of
    /// a plugin's compile error).
    pub fn allowed(self) -> String {
        match self {
            Self::Rows | Self::Cols => format!("integer 1-{MAX_TAXELS_PER_SIDE}"),
            Self::PadWidth | Self::PadHeight | Self::Thickness => format!("metres in (0, {MAX_LENGTH_M}]"),
            Self::PsfSigma => format!("metres in [0, {MAX_LENGTH_M}]"),
            Self::RaysPerTaxel => format!("perfect square 1-{MAX_RAYS_PER_TAXEL}"),
            Self::NoiseFraction => format!("fraction in [0, {MAX_NOISE_FRACTION}]"),
            Self::NoiseSeed => "unsigned 64-bit integer".to_string(),
        }
    }
}

impl fmt::Display for ConfigKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A configuration value outside its allowed range, or not a value of the key's kind at all.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("taction.covering: {key}={}: want {allowed}", shortened(value))]
pub struct ConfigError {
    pub key: ConfigKey,
    /// The value as given (text from MJCF or a flag, or the formatted number).
    pub value: String,
    /// What the key allows: its range ([`ConfigKey::allowed`]), or for the thickness also what
    /// the pad allows.
    pub allowed: String,
}

impl ConfigError {
    /// `value` outside `key`'s own range.
    fn out_of_range(key: ConfigKey, value: String) -> Self {
        Self {
            key,
            value,
            allowed: key.allowed(),
        }
    }
}

/// At most 16 characters of `value`, so the whole message fits MuJoCo's error buffer.
fn shortened(value: &str) -> String {
    if value.chars().count() <= 16 {
        value.to_string()
    } else {
        format!("{}~", value.chars().take(15).collect::<String>())
    }
}

/// The integer side `k` of a `k x k` supersampling grid, when `rays_per_taxel` is a perfect square.
pub fn rays_per_side(rays_per_taxel: usize) -> Option<usize> {
    let k = (rays_per_taxel as f64).sqrt().round() as usize;
    (k >= 1 && k * k == rays_per_taxel).then_some(k)
}

impl Check for SensorConfig {
    type Error = ConfigError;

    /// Every field against its allowed range ([`ConfigKey::allowed`]); the error names the first
    /// offending key.
    fn check(&self) -> Result<(), ConfigError> {
        let Self {
            rows,
            cols,
            pad_width_m,
            pad_height_m,
            thickness_m,
            psf_sigma_m,
            rays_per_taxel,
            noise_fraction,
            noise_seed: _,
        } = *self;
        let bad = |key: ConfigKey, value: String| Err(ConfigError::out_of_range(key, value));
        for (key, n) in [(ConfigKey::Rows, rows), (ConfigKey::Cols, cols)] {
            if !(1..=MAX_TAXELS_PER_SIDE).contains(&n) {
                return bad(key, n.to_string());
            }
        }
        for (key, v) in [
            (ConfigKey::PadWidth, pad_width_m),
            (ConfigKey::PadHeight, pad_height_m),
            (ConfigKey::Thickness, thickness_m),
        ] {
            if !(v.is_finite() && v > 0.0 && v <= MAX_LENGTH_M) {
                return bad(key, v.to_string());
            }
        }
        // A covering thicker than half the pad is no thin skin on a fingertip: its point spread
        // (sigma 0.48 t, Sec. V-B5) would blur the whole pad into one value.
        let half_pad_m = 0.5 * pad_width_m.min(pad_height_m);
        if thickness_m > half_pad_m {
            return Err(ConfigError {
                key: ConfigKey::Thickness,
                value: thickness_m.to_string(),
                allowed: format!("<= half the pad side, {}", crate::units::length(half_pad_m)),
            });
        }
        if !(psf_sigma_m.is_finite() && (0.0..=MAX_LENGTH_M).contains(&psf_sigma_m)) {
            return bad(ConfigKey::PsfSigma, psf_sigma_m.to_string());
        }
        if rays_per_taxel > MAX_RAYS_PER_TAXEL || rays_per_side(rays_per_taxel).is_none() {
            return bad(ConfigKey::RaysPerTaxel, rays_per_taxel.to_string());
        }
        if !(noise_fraction.is_finite() && (0.0..=MAX_NOISE_FRACTION).contains(&noise_fraction)) {
            return bad(ConfigKey::NoiseFraction, noise_fraction.to_string());
        }
        Ok(())
    }
}

impl SensorConfig {
    /// A config with `rows x cols` taxels on a square pad of side `pad_m`, covering `thickness_m`,
    /// the PSF law, 4 rays per taxel and no noise.
    pub fn square(rows: usize, cols: usize, pad_m: f64, thickness_m: f64) -> Self {
        Self::of_pad(rows, cols, pad_m, pad_m, Some(thickness_m), None)
    }

    /// The sensor as a user describes it (the CLI's sensor flags, Python's `Sensor`): `rows x
    /// cols` taxels on a pad `pad_width_m` wide (along a row) and `pad_height_m` high (along a
    /// column), as real arrays are often not square (a 28x50 array on a gripper's finger), a
    /// covering `thickness_m` thick (default 10% of the pad's shorter side, the paper's 10% of
    /// its square pad), its point spread `psf_sigma_m` (default the half-space law for that
    /// thickness, [`psf_sigma_for_thickness`]), 4 rays per taxel and no noise. Unchecked, as
    /// every config is until [`Valid::new`].
    pub fn of_pad(
        rows: usize,
        cols: usize,
        pad_width_m: f64,
        pad_height_m: f64,
        thickness_m: Option<f64>,
        psf_sigma_m: Option<f64>,
    ) -> Self {
        let thickness_m = thickness_m.unwrap_or(DEFAULT_THICKNESS_FRACTION * pad_width_m.min(pad_height_m));
        Self {
            rows,
            cols,
            pad_width_m,
            pad_height_m,
            thickness_m,
            psf_sigma_m: psf_sigma_m.unwrap_or_else(|| psf_sigma_for_thickness(thickness_m)),
            ..Self::default()
        }
    }

    /// Whether the pad is square, as the paper's is: a user's description of it needs one side.
    pub fn is_square_pad(&self) -> bool {
        self.pad_width_m == self.pad_height_m
    }

    /// Where taxel (`row`, `col`)'s centre is on the pad: (right, up) in metres from the pad's
    /// centre, row 0 at the top (the image's layout, Sec. V-A2). Orient's plane fit and the
    /// contact a reading felt both place taxels by it.
    pub fn taxel_centre_m(&self, row: usize, col: usize) -> (f64, f64) {
        let x = ((col as f64 + 0.5) / self.cols as f64 - 0.5) * self.pad_width_m;
        let y = (0.5 - (row as f64 + 0.5) / self.rows as f64) * self.pad_height_m;
        (x, y)
    }

    /// The `k` of the `k x k` rays per taxel (valid configs only; 1 otherwise).
    pub fn rays_per_side(&self) -> usize {
        rays_per_side(self.rays_per_taxel).unwrap_or(1)
    }

    /// Parses `key -> text` pairs as MJCF `<config>` gives them. A key that is absent or empty
    /// keeps its default; `psf_sigma_m` absent or empty follows the thickness by the PSF law. The
    /// result is validated.
    pub fn from_key_values<'a>(
        lookup: impl Fn(ConfigKey) -> Option<&'a str>,
    ) -> Result<Valid<Self>, ConfigError> {
        let mut config = Self::default();
        let text = |key| lookup(key).map(str::trim).filter(|s| !s.is_empty());
        let bad = |key: ConfigKey, value: &str| ConfigError::out_of_range(key, value.to_string());
        let integer = |key: ConfigKey, default: usize| -> Result<usize, ConfigError> {
            match text(key) {
                None => Ok(default),
                Some(s) => s.parse().map_err(|_| bad(key, s)),
            }
        };
        let real = |key: ConfigKey, default: f64| -> Result<f64, ConfigError> {
            match text(key) {
                None => Ok(default),
                Some(s) => s
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad(key, s)),
            }
        };
        config.rows = integer(ConfigKey::Rows, config.rows)?;
        config.cols = integer(ConfigKey::Cols, config.cols)?;
        config.pad_width_m = real(ConfigKey::PadWidth, config.pad_width_m)?;
        config.pad_height_m = real(ConfigKey::PadHeight, config.pad_height_m)?;
        config.thickness_m = real(ConfigKey::Thickness, config.thickness_m)?;
        config.psf_sigma_m = real(ConfigKey::PsfSigma, psf_sigma_for_thickness(config.thickness_m))?;
        config.rays_per_taxel = integer(ConfigKey::RaysPerTaxel, config.rays_per_taxel)?;
        config.noise_fraction = real(ConfigKey::NoiseFraction, config.noise_fraction)?;
        config.noise_seed = match text(ConfigKey::NoiseSeed) {
            None => config.noise_seed,
            Some(s) => s.parse().map_err(|_| bad(ConfigKey::NoiseSeed, s))?,
        };
        Valid::new(config)
    }

    /// The value of `key` as MJCF config text, in shortest round-trip form (so that parsing it back
    /// gives this exact config).
    pub fn value_text(&self, key: ConfigKey) -> String {
        match key {
            ConfigKey::Rows => self.rows.to_string(),
            ConfigKey::Cols => self.cols.to_string(),
            ConfigKey::PadWidth => self.pad_width_m.to_string(),
            ConfigKey::PadHeight => self.pad_height_m.to_string(),
            ConfigKey::Thickness => self.thickness_m.to_string(),
            ConfigKey::PsfSigma => self.psf_sigma_m.to_string(),
            ConfigKey::RaysPerTaxel => self.rays_per_taxel.to_string(),
            ConfigKey::NoiseFraction => self.noise_fraction.to_string(),
            ConfigKey::NoiseSeed => self.noise_seed.to_string(),
        }
    }

    /// Number of taxels, the sensor's `sensordata` dimension.
    pub fn taxel_count(&self) -> usize {
        self.rows * self.cols
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(pairs: &[(&str, &str)]) -> Result<SensorConfig, ConfigError> {
        SensorConfig::from_key_values(|key| pairs.iter().find(|(k, _)| *k == key.name()).map(|(_, v)| *v))
            .map(Valid::into_inner)
    }

    #[test]
    fn psf_law_matches_the_half_space_fwhm() {
        let fwhm_per_t = 2.0 * (2f64.powf(0.4) - 1.0).sqrt();
        let sigma_per_t = fwhm_per_t / (2.0 * (2.0 * 2f64.ln()).sqrt());
        assert!(
            (sigma_per_t - PSF_SIGMA_PER_THICKNESS).abs() < 1e-15,
            "{sigma_per_t}"
        );
        assert_eq!(psf_sigma_for_thickness(0.002), PSF_SIGMA_PER_THICKNESS * 0.002);
    }

    #[test]
    fn defaults_are_valid_and_empty_config_gives_them() {
        SensorConfig::default().check().unwrap();
        assert_eq!(parse(&[]).unwrap(), SensorConfig::default());
        assert_eq!(
            parse(&[("rows", " "), ("noise_seed", "")]).unwrap(),
            SensorConfig::default()
        );
    }

    #[test]
    fn text_round_trip_is_exact() {
        let config = SensorConfig {
            rows: 14,
            cols: 26,
            pad_width_m: 0.0123,
            pad_height_m: 0.0101,
            thickness_m: 0.0017,
            psf_sigma_m: 0.0,
            rays_per_taxel: 9,
            noise_fraction: 0.3,
            noise_seed: u64::MAX,
        };
        let back = SensorConfig::from_key_values(|key| {
            let text: &'static str = Box::leak(config.value_text(key).into_boxed_str());
            Some(text)
        })
        .unwrap();
        assert_eq!(*back, config);
    }

    #[test]
    fn sigma_follows_thickness_unless_given() {
        let c = parse(&[("thickness_m", "0.002")]).unwrap();
        assert_eq!(c.psf_sigma_m, psf_sigma_for_thickness(0.002));
        let c = parse(&[("thickness_m", "0.002"), ("psf_sigma_m", "0")]).unwrap();
        assert_eq!(c.psf_sigma_m, 0.0);
    }

    #[test]
    fn each_bad_value_names_its_key_and_range() {
        let cases = [
            ("rows", "0"),
            ("rows", "-3"),
            ("cols", "257"),
            ("cols", "six"),
            ("pad_width_m", "0"),
            ("pad_height_m", "-0.01"),
            ("thickness_m", "nan"),
            ("thickness_m", "2"),
            ("psf_sigma_m", "-1e-3"),
            ("rays_per_taxel", "0"),
            ("rays_per_taxel", "5"),
            ("rays_per_taxel", "81"),
            ("noise_fraction", "2.5"),
            ("noise_fraction", "inf"),
            ("noise_seed", "-1"),
            ("noise_seed", "123456789012345678901234567890"),
        ];
        for (key, value) in cases {
            let e = parse(&[(key, value)]).unwrap_err();
            assert_eq!(e.key.name(), key, "{key}={value}");
            let message = e.to_string();
            assert!(
                message.contains(&format!(" {key}=")) && message.contains("want"),
                "{message}"
            );
            assert!(message.contains(&e.key.allowed()), "{message}");
            assert!(
                message.len() <= 76,
                "too long for MuJoCo's error buffer: {message}"
            );
        }
    }

    #[test]
    fn a_covering_thicker_than_half_the_shorter_pad_side_is_refused_in_mujocos_buffer() {
        // Half of the 12 mm pad is allowed; a hair more is not, from MJCF as from a flag.
        assert!(parse(&[("thickness_m", "0.006")]).is_ok());
        let e = parse(&[("thickness_m", "0.0061")]).unwrap_err();
        assert_eq!(e.key, ConfigKey::Thickness);
        let message = e.to_string();
        assert_eq!(
            message,
            "taction.covering: thickness_m=0.0061: want <= half the pad side, 6 mm"
        );
        assert!(message.len() <= 76, "{message}");
        // The shorter side rules: a 12 x 4 mm pad takes at most 2 mm.
        let e = parse(&[("pad_height_m", "0.004"), ("thickness_m", "0.003")]).unwrap_err();
        assert!(e.to_string().ends_with("want <= half the pad side, 2 mm"), "{e}");
    }

    #[test]
    fn rays_per_side_is_the_integer_square_root() {
        assert_eq!(rays_per_side(1), Some(1));
        assert_eq!(rays_per_side(4), Some(2));
        assert_eq!(rays_per_side(64), Some(8));
        assert_eq!(rays_per_side(0), None);
        assert_eq!(rays_per_side(8), None);
    }
}
