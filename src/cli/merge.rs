//! `taction merge DIRS... --out DIR`: combines the output directories of sharded experiment runs.

use std::path::PathBuf;

use clap::Args;

use crate::cli::common::OutputLock;

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Output roots of the shard runs (their `--out`), each holding `<experiment>/` directories.
    #[arg(required = true, num_args = 1..)]
    pub dirs: Vec<PathBuf>,
    /// Where the merged experiments go: the same files one unsharded run would have written.
    #[arg(long)]
    pub out: PathBuf,
}

/// Merges, assembles and plots every experiment found, then rewrites `<out>/README.md`.
pub fn run(args: &MergeArgs) -> Result<(), Box<dyn std::error::Error>> {
    let _lock = OutputLock::acquire(&args.out, "out")?;
    let report = taction::experiment::merge(&args.dirs, &args.out)?;
    println!("copied {} unit files into {}", report.copied, args.out.display());
    for (name, finished) in &report.experiments {
        let plots: Vec<String> = finished.plots.iter().map(|p| p.display().to_string()).collect();
        println!("{name}: {} ({})", finished.csv.display(), plots.join(", "));
    }
    println!("index: {}", args.out.join("README.md").display());
    Ok(())
}
