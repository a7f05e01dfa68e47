//! `taction sense`: one raw reading of the free-floating covering sensor (no controllers), to look
//! at what the sensor sees.
//!
//! The mesh is placed as given (its coordinates are metres in the world frame). The pad's centre
//! is the back of the covering; `--pad-normal` points from the pad into the covering, toward the
//! object. The output image has `rows` lines of `cols` values in [0, 1]: row 0 is the pad's `+up`
//! edge, column 0 its left edge seen from behind the pad (looking along the normal), so the
//! columns run along `normal x up`.

use std::path::{Path, PathBuf};

use clap::Args;
use glam::DVec3;
use taction::sim::ObjectSpec;
use taction::tactile::{FreeFloatingSensor, PadPose, SensorConfig};

use crate::cli::sensor_args::{SensorArgs, SensorFlagError};

#[derive(Debug, Args)]
pub struct SenseArgs {
    /// The object: an OBJ, OFF or STL mesh, coordinates in metres, placed as given.
    #[arg(long, value_name = "FILE")]
    pub mesh: PathBuf,
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
    #[command(flatten)]
    pub sensor: SensorArgs,
    /// Noise seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output image: FILE.csv (values) or FILE.png (grey levels, upscaled).
    #[arg(long, value_name = "FILE.csv|FILE.png")]
    pub out: PathBuf,
}

/// What can go wrong; each names the flag or file at fault.
#[derive(Debug, thiserror::Error)]
pub enum SenseError {
    #[error(transparent)]
    Flag(#[from] SensorFlagError),
    #[error("--pad-normal / --pad-up: the normal must be non-zero and --pad-up not parallel to it")]
    PadFrame,
    #[error("--out: {0}: the file name must end in .csv or .png")]
    OutFormat(String),
    #[error(transparent)]
    Mesh(#[from] taction::mesh::MeshError),
    #[error(transparent)]
    Tactile(#[from] taction::tactile::TactileError),
    #[error(transparent)]
    Image(#[from] taction::tactile::ImageError),
}

/// A vector flag: three comma-separated finite numbers.
fn parse_vec3(text: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let bad = || format!("expected three comma-separated numbers like 0,0,0.1, got '{text}'");
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

impl SenseArgs {
    /// The sensor configuration the flags describe, validated.
    pub fn config(&self) -> Result<SensorConfig, SenseError> {
        Ok(self.sensor.config(self.seed)?)
    }

    /// The pad pose the flags describe.
    pub fn pad_pose(&self) -> Result<PadPose, SenseError> {
        let up = self.pad_up.unwrap_or_else(|| {
            let n = self.pad_normal.normalize_or_zero();
            if n.z.abs() > 0.999 { DVec3::Y } else { DVec3::Z }
        });
        PadPose::new(self.pad_center, self.pad_normal, up).ok_or(SenseError::PadFrame)
    }
}

/// Whether `path` names a PNG (else a CSV); other extensions are an error.
fn wants_png(path: &Path) -> Result<bool, SenseError> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => Ok(true),
        Some("csv") => Ok(false),
        _ => Err(SenseError::OutFormat(path.display().to_string())),
    }
}

/// Loads the mesh, places the free-floating pad, takes one reading and writes it.
pub fn run(args: &SenseArgs) -> Result<(), Box<dyn std::error::Error>> {
    let config = args.config()?;
    let pose = args.pad_pose()?;
    let png = wants_png(&args.out)?;
    let loaded = taction::mesh::load(&args.mesh).map_err(SenseError::from)?;
    if !loaded.warnings.is_clean() {
        eprintln!(
            "taction sense: warning: {}: {}",
            args.mesh.display(),
            loaded.warnings
        );
    }
    let name = args
        .mesh
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "object".into());
    // The sensor tells inside from outside by the winding (outward normals), so fix an inverted mesh.
    let (mesh, flipped) = taction::mesh::orient_outward(loaded.mesh);
    if flipped {
        eprintln!(
            "taction sense: note: {}: faces wound inward; reversed",
            args.mesh.display()
        );
    }
    let mut sensor =
        FreeFloatingSensor::new(ObjectSpec::new(name, mesh), &config).map_err(SenseError::from)?;
    let image = sensor.read_at(&pose).map_err(SenseError::from)?;
    if png {
        image.write_png(&args.out, 0).map_err(SenseError::from)?;
    } else {
        image.write_csv(&args.out).map_err(SenseError::from)?;
    }
    println!(
        "{}: {}x{} reading, max {:.3}, mean {:.3}",
        args.out.display(),
        image.rows(),
        image.cols(),
        image.max(),
        image.mean()
    );
    Ok(())
}
