//! `taction dataset show DATASET`: what a dataset file holds (see `taction::dataset` for the format).
//! `taction dataset import FRAMES --out DATASET`: recorded sensor frames as a dataset, so that
//! `train` and `recognize` take real data.
//! `taction dataset export DATASET --format npz|parquet --out PATH`: a dataset for numpy and pandas.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use taction::dataset::{Calibration, RealImport, TaxelPitch, import_real, import_real_csv};
use taction::dataset::{Dataset, DatasetError, ExportFormat};
use taction::paper::RealFramesOptions;
use taction::paper::recorded_dataset;

use crate::cli::common::{PreprocessArgs, UsageError, check_output_file};

#[derive(Debug, Args)]
pub struct DatasetArgs {
    #[command(subcommand)]
    pub command: DatasetCommand,
}

#[derive(Debug, Subcommand)]
pub enum DatasetCommand {
    /// Objects, readings per object and status, strategies, and the sensor configuration.
    Show {
        /// The dataset file.
        dataset: PathBuf,
    },
    /// Recorded sensor frames as a dataset: each label an object, each frame a `recorded`
    /// reading, `converged` when it touched and `no_contact` when the real-frames experiment would
    /// prune it, its image as that experiment describes it.
    Import(ImportArgs),
    /// A dataset in the formats the ML toolchain reads: `npz` (numpy.load: arrays `images` [N,
    /// rows, cols] float32, `pad_pose` [N, 9], `object_pose` [N, 7], `iterations`, `contact` (-1
    /// for a reading that is a contact of its own), and `object`,
    /// `status`, `strategy`, `cause`, `touched_bodies` as strings, `header` the JSON header) or
    /// `parquet` (pandas.read_parquet: the CSV's columns, taxels `t_{row}_{col}` as float32, the
    /// JSON header as the metadata `taction_header`).
    Export(ExportArgs),
}

/// `dataset export`: which dataset, as what, where.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The dataset file.
    #[arg(value_name = "DATASET.csv")]
    pub dataset: PathBuf,
    /// The format to write: npz or parquet.
    #[arg(long, value_name = "npz|parquet")]
    pub format: ExportFormat,
    /// The file to write.
    #[arg(long, value_name = "PATH")]
    pub out: PathBuf,
}

/// `dataset import`: the recording and the settings of the real-frames experiment that shape its
/// images (the same flags as `experiment real-frames`).
#[derive(Debug, Args)]
pub struct ImportArgs {
    /// Recorded frames of a rows x cols grid (2 to 128 taxels a side), as a CSV, a folder of class
    /// folders of images or an .npz. CSV: a header `label,r0c0,r0c1,...` naming every taxel, then
    /// one frame per line: its label, then one non-negative raw value per taxel; `#` lines are
    /// comments. Folder: one folder per label, each image (PNG 8/16-bit or JPEG 8-bit grayscale)
    /// one frame. npz: arrays `frames` (N, rows, cols) and `labels` (N strings or integers).
    /// Frames of one press stay one contact: a `contact` column after `label`, a folder inside a
    /// class folder, or an npz array `contacts`. Values are divided by the largest one.
    #[arg(value_name = "FRAMES")]
    pub frames: PathBuf,
    /// The dataset to write.
    #[arg(long, value_name = "DATASET.csv")]
    pub out: PathBuf,
    /// Per-taxel calibration of the frames, applied as gain * (raw - offset), clamped at 0. CSV:
    /// a header `taxel,gain,offset`, then one line per taxel (`r0c0,1.02,13`), every taxel of the
    /// grid exactly once.
    #[arg(long, value_name = "CSV")]
    pub calibration: Option<PathBuf>,
    /// The distance between neighbouring taxel centres of the recorded array, metres (e.g. 0.002):
    /// the pad is then cols x pitch wide and rows x pitch high. Without it the dataset records the
    /// pad's size as unknown, since frames alone do not tell it.
    #[arg(long, value_name = "M")]
    pub taxel_pitch_m: Option<TaxelPitch>,
    #[command(flatten)]
    pub preprocess: PreprocessArgs,
}

pub fn run(args: &DatasetArgs) -> Result<(), Box<dyn std::error::Error>> {
    match &args.command {
        DatasetCommand::Show { dataset } => {
            let data = read_dataset(dataset)?;
            let version = Dataset::file_format_version(dataset)?;
            if version == data.header().format_version {
                println!("{}", dataset.display());
            } else {
                println!(
                    "{} (written in format version {version}; read as version {}, as every command reads it)",
                    dataset.display(),
                    data.header().format_version
                );
            }
            println!("{}", data.summary());
        }
        DatasetCommand::Import(import) => run_import(import)?,
        DatasetCommand::Export(export) => run_export(export)?,
    }
    Ok(())
}

/// Reads a dataset; a file of recorded frames is not one, and the error says how to make one of it.
pub fn read_dataset(path: &Path) -> Result<Dataset, Box<dyn std::error::Error>> {
    Dataset::read(path).map_err(|e| {
        let frames = matches!(e, DatasetError::NotADataset { .. })
            && import_real_csv(path, &RealImport::default()).is_ok();
        if frames {
            format!(
                "{e}\n  it holds recorded sensor frames: `taction dataset import {} --out DATASET.csv` \
                 makes a dataset of them",
                path.display()
            )
            .into()
        } else {
            e.into()
        }
    })
}

fn run_import(args: &ImportArgs) -> Result<(), Box<dyn std::error::Error>> {
    refuse_overwriting(&args.out, &args.frames, "frames file", "dataset")?;
    check_output_file(&args.out, "out")?;
    let options = args.preprocess.options(RealFramesOptions::default().trials)?;
    let calibration = args
        .calibration
        .as_deref()
        .map(Calibration::read)
        .transpose()
        .map_err(|e| format!("--calibration: {e}"))?;
    let real = import_real(
        &args.frames,
        &RealImport {
            calibration,
            ..RealImport::default()
        },
    )?;
    let object_set = args
        .frames
        .file_stem()
        .map_or_else(|| "recorded".to_string(), |s| s.to_string_lossy().into_owned());
    let dataset =
        recorded_dataset(&real, &options, &object_set, args.taxel_pitch_m).map_err(|e| e.to_string())?;
    dataset.write(&args.out)?;
    println!("wrote {}", args.out.display());
    println!("{}", dataset.summary());
    Ok(())
}

/// `--out` naming the `input` file itself (a `what` file) is refused before it is overwritten.
fn refuse_overwriting(out: &Path, input: &Path, what: &str, written: &str) -> Result<(), UsageError> {
    let same_file = std::fs::canonicalize(out)
        .ok()
        .is_some_and(|out| std::fs::canonicalize(input).is_ok_and(|input| input == out));
    if same_file {
        return Err(UsageError(format!(
            "--out {} is the {what} itself; write the {written} to another file",
            out.display()
        )));
    }
    Ok(())
}

fn run_export(args: &ExportArgs) -> Result<(), Box<dyn std::error::Error>> {
    refuse_overwriting(&args.out, &args.dataset, "dataset", "export")?;
    check_output_file(&args.out, "out")?;
    let data = read_dataset(&args.dataset)?;
    data.export(&args.out, args.format)?;
    let sensor = &data.header().sensor;
    println!(
        "wrote {} readings of {}x{} taxels as {} to {}",
        data.len(),
        sensor.rows,
        sensor.cols,
        args.format,
        args.out.display()
    );
    Ok(())
}
