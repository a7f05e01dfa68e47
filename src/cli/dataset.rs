//! `taction dataset show DATASET`: what a dataset file holds (see `taction::dataset` for the format).

use std::path::PathBuf;

use clap::{Args, Subcommand};
use taction::dataset::Dataset;

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
}

pub fn run(args: &DatasetArgs) -> Result<(), Box<dyn std::error::Error>> {
    match &args.command {
        DatasetCommand::Show { dataset } => {
            let data = Dataset::read(dataset)?;
            println!("{}", dataset.display());
            println!("{}", data.summary());
        }
    }
    Ok(())
}
