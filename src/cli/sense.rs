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
use taction::control::{ControlError, FreePad};
use taction::pose::PadPose;
use taction::tactile::SensorConfig;
use taction::valid::Valid;

use crate::cli::common::{SeedArg, check_output_file};
use crate::cli::plausible::Carrier;
use crate::cli::sensor_args::{PadArgs, PadFrameError, SensorArgs, SensorFlagError};

#[derive(Debug, Args)]
pub struct SenseArgs {
    #[command(flatten)]
    pub pad: PadArgs,
    #[command(flatten)]
    pub sensor: SensorArgs,
    #[command(flatten)]
    pub seed: SeedArg,
    /// Output image: FILE.csv (values) or FILE.png (grey levels, upscaled).
    #[arg(long, value_name = "FILE.csv|FILE.png")]
    pub out: PathBuf,
}

/// What can go wrong; each names the flag or file at fault.
#[derive(Debug, thiserror::Error)]
pub enum SenseError {
    #[error(transparent)]
    Flag(#[from] SensorFlagError),
    #[error(transparent)]
    PadFrame(#[from] PadFrameError),
    #[error("--out: {0}: the file name must end in .csv or .png")]
    OutFormat(String),
    #[error(transparent)]
    Mesh(#[from] taction::mesh::MeshError),
    #[error(transparent)]
    Pad(#[from] ControlError),
    #[error(transparent)]
    Image(#[from] taction::tactile::ImageError),
}

impl SenseArgs {
    /// The sensor configuration the flags describe, validated.
    pub fn config(&self) -> Result<Valid<SensorConfig>, SenseError> {
        Ok(self.sensor.config(self.seed.seed)?)
    }

    /// The pad pose the flags describe.
    pub fn pad_pose(&self) -> Result<PadPose, SenseError> {
        Ok(self.pad.pad_pose()?)
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
    check_output_file(&args.out, "out")?;
    let object = args.pad.load_object("sense", Carrier::FreePad)?;
    let mut pad = FreePad::new(object, &config).map_err(SenseError::from)?;
    let image = pad.read_at(&pose).map_err(SenseError::from)?;
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
