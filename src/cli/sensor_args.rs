//! The flags shared by every command that simulates the covering sensor: the sensor itself
//! ([`SensorArgs`]) and the mesh with the pad's pose near it ([`PadArgs`], `sense` and `touch`).

use std::path::PathBuf;

use clap::Args;
use glam::DVec3;
use taction::mesh::Object;
use taction::pose::PadPose;
use taction::sim::ObjectSpec;
use taction::tactile::{ConfigKey, SensorConfig};

use crate::cli::common::ObjectSizeArg;
use crate::cli::plausible::{Carrier, check_mesh};
use taction::valid::Valid;

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
    /// Width of a rectangular pad (along an image row, the `--cols` taxels), metres [default:
    /// --pad-m].
    #[arg(long, allow_hyphen_values = true)]
    pub pad_width_m: Option<f64>,
    /// Height of a rectangular pad (along an image column, the `--rows` taxels), metres
    /// [default: --pad-m].
    #[arg(long, allow_hyphen_values = true)]
    pub pad_height_m: Option<f64>,
    /// Covering thickness t, metres [default: 10% of the pad's (shorter) side].
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

impl SensorArgs {
    /// The flag that sets a config key: a pad side's own flag when given, else `--pad-m`.
    pub fn flag_of(&self, key: ConfigKey) -> &'static str {
        match key {
            ConfigKey::Rows => "rows",
            ConfigKey::Cols => "cols",
            ConfigKey::PadWidth if self.pad_width_m.is_some() => "pad-width-m",
            ConfigKey::PadHeight if self.pad_height_m.is_some() => "pad-height-m",
            ConfigKey::PadWidth | ConfigKey::PadHeight => "pad-m",
            ConfigKey::Thickness => "thickness-m",
            ConfigKey::PsfSigma => "psf-sigma-m",
            ConfigKey::RaysPerTaxel => "rays-per-taxel",
            ConfigKey::NoiseFraction => "noise",
            ConfigKey::NoiseSeed => "seed",
        }
    }

    /// The sensor configuration the flags describe, with noise seed `noise_seed`, validated.
    pub fn config(&self, noise_seed: u64) -> Result<Valid<SensorConfig>, SensorFlagError> {
        let config = SensorConfig {
            rays_per_taxel: self.rays_per_taxel,
            noise_fraction: self.noise,
            noise_seed,
            ..SensorConfig::of_pad(
                self.rows,
                self.cols,
                self.pad_width_m.unwrap_or(self.pad_m),
                self.pad_height_m.unwrap_or(self.pad_m),
                self.thickness_m,
                self.psf_sigma_m,
            )
        };
        Valid::new(config).map_err(|e| SensorFlagError {
            flag: self.flag_of(e.key),
            value: e.value,
            allowed: e.allowed,
        })
    }
}

/// The object and the pad pose: the mesh is placed as given (its coordinates are metres in the world
/// frame); the pad's centre is the back of the covering and `--pad-normal` points from the pad into
/// the covering, toward the object.
#[derive(Debug, Clone, Args)]
pub struct PadArgs {
    /// The object: an OBJ, OFF or STL mesh, coordinates in metres, placed as given (with
    /// `--object-size-m`: rescaled to that bounding diagonal, centred and resting on z = 0).
    #[arg(long, value_name = "FILE")]
    pub mesh: PathBuf,
    #[command(flatten)]
    pub object_size: ObjectSizeArg,
    /// Centre of the pad (the back of the covering), world metres.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub pad_center: DVec3,
    /// Pad normal: from the pad into the covering, toward the object (any length).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub pad_normal: DVec3,
    /// Direction of image row 0 (made perpendicular to the normal) [default: world +z, or +y when
    /// the normal is vertical].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub pad_up: Option<DVec3>,
}

/// The pad flags describe no frame.
#[derive(Debug, Clone, thiserror::Error)]
#[error("--pad-normal / --pad-up: the normal must be non-zero and --pad-up not parallel to it")]
pub struct PadFrameError;

/// A vector flag: three comma-separated finite numbers.
pub fn parse_vec3(text: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let bad = || format!("expected three comma-separated finite numbers like 0,0,0.1, got '{text}'");
    if parts.len() != 3 {
        return Err(bad());
    }
    let mut v = [0.0; 3];
    for (slot, part) in v.iter_mut().zip(&parts) {
        *slot = part
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(bad)?;
    }
    Ok(DVec3::from_array(v))
}

impl PadArgs {
    /// The pad pose the flags describe.
    pub fn pad_pose(&self) -> Result<PadPose, PadFrameError> {
        let up = self.pad_up.unwrap_or_else(|| {
            let n = self.pad_normal.normalize_or_zero();
            if n.z.abs() > 0.999 { DVec3::Y } else { DVec3::Z }
        });
        PadPose::new(self.pad_center, self.pad_normal, up).ok_or(PadFrameError)
    }

    /// Loads `--mesh` as the object (named after the file; [`Object::from_file`] reverses
    /// inward-wound faces, since the sensor tells inside from outside by the winding, and refuses
    /// an implausible mesh), refusing a mesh `carrier` cannot explore, and warning on stderr
    /// (prefixed with `command`) about validation problems and reversed faces.
    pub fn load_object(
        &self,
        command: &str,
        carrier: Carrier,
    ) -> Result<ObjectSpec, Box<dyn std::error::Error>> {
        let object = match self.object_size.m {
            Some(size_m) => Object::from_file_with_size(&self.mesh, size_m)?,
            None => Object::from_file(&self.mesh)?,
        };
        check_mesh(&self.mesh.display().to_string(), &object.mesh, carrier)?;
        if !object.warnings.is_clean() {
            eprintln!(
                "taction {command}: warning: {}: {}",
                self.mesh.display(),
                object.warnings
            );
        }
        if object.flipped {
            eprintln!(
                "taction {command}: note: {}: faces wound inward; reversed",
                self.mesh.display()
            );
        }
        Ok(ObjectSpec::from(object))
    }
}
