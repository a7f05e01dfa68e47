//! `taction pool RUNS... --out DIR`: every recognition experiment of runs that differ only in their
//! seeds, its curves over every seed with an interval that resamples whole seeds.

use std::path::PathBuf;

use clap::Args;

use crate::cli::common::OutputLock;

#[derive(Debug, Args)]
pub struct PoolArgs {
    /// Finished runs that differ only in `--seed`, at least two: each the output root of a run (its
    /// `--out`, the same `<experiment>/` folders in each) or one experiment's folder in it
    /// (`results/active`).
    #[arg(required = true, num_args = 1..)]
    pub runs: Vec<PathBuf>,
    /// Where the pooled experiments go: per experiment every seed's rows, the pooled curves with
    /// their 90% interval over resampled seeds, the curves per seed, the summed reliability
    /// tables, the plots and `pool.json`.
    #[arg(long)]
    pub out: PathBuf,
}

/// Pools every experiment the runs hold, then prints what it wrote and each curve's pooled ECE.
pub fn run(args: &PoolArgs) -> Result<(), Box<dyn std::error::Error>> {
    let _lock = OutputLock::acquire(&args.out, "out")?;
    let report = taction::experiment::pool(&args.runs, &args.out)?;
    for pooled in &report.pooled {
        let seeds: Vec<String> = pooled.seeds.iter().map(u64::to_string).collect();
        println!(
            "{}: {} seeds pooled ({})",
            pooled.name,
            seeds.len(),
            seeds.join(", ")
        );
        for file in &pooled.files {
            println!("  {}", file.display());
        }
        for curve in &pooled.calibration {
            println!("  calibration: {curve}");
        }
    }
    for (name, why) in &report.skipped {
        eprintln!("{name}: not pooled: {why}");
    }
    if report.pooled.is_empty() {
        return Err("no experiment with recognition curves to pool".into());
    }
    Ok(())
}
