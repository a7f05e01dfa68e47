//! `taction pool RUNS... --out DIR`: every recognition experiment of runs that differ only in their
//! seeds, its curves over every seed with an interval that resamples whole seeds.

use std::path::PathBuf;

use clap::Args;

use taction::experiment::ReferenceLevels;

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
    /// Also compare every curve with a reference curve, seed by seed: `column=level` pairs joined by
    /// commas, each column a factor or `descriptor` (e.g. `strategy=blind,local_probability=1`).
    /// Each curve is compared with the curve of its own levels with these replaced; written per
    /// experiment (`<experiment>_differences.csv`): the differences with their 90% interval over
    /// resampled seeds, and the first number of readings at which each curve reaches the
    /// reference's accuracy.
    #[arg(long, value_name = "COLUMN=LEVEL,...")]
    pub against: Option<ReferenceLevels>,
}

/// Pools every experiment the runs hold, then prints what it wrote, each curve's pooled ECE and,
/// with `--against`, each curve against its reference.
pub fn run(args: &PoolArgs) -> Result<(), Box<dyn std::error::Error>> {
    let _lock = OutputLock::acquire(&args.out, "out")?;
    let report = taction::experiment::pool(&args.runs, &args.out, args.against.as_ref())?;
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
        match &pooled.compared {
            Some(Ok(comparisons)) => {
                let reference = args.against.as_ref().map(ToString::to_string).unwrap_or_default();
                println!("  against {reference} (each curve against the curve of its other levels):");
                for c in comparisons {
                    let target = format!(
                        "{:.3} (the reference at {} readings)",
                        c.reference_accuracy, c.reference_readings
                    );
                    let reached = match c.readings_to_reach {
                        Some(m) => format!("reaches {target} after {m} readings"),
                        None => format!("does not reach {target} within its readings"),
                    };
                    println!(
                        "    {} {}: level or ahead at {} of {} reading counts; {reached}",
                        c.descriptor, c.factors, c.counts_level_or_ahead, c.counts
                    );
                }
            }
            Some(Err(why)) => eprintln!("{}: not compared: {why}", pooled.name),
            None => {}
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
