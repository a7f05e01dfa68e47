//! `taction recognize`: run a saved model over a test dataset touch by touch and write the
//! per-touch posterior, accuracy against the number of readings, and the confusion matrix.

use std::path::PathBuf;

use clap::Args;
use indicatif::ProgressBar;
use taction::dataset::Dataset;
use taction::recognize::{ReadingRange, RecognizeError, Recognizer};

#[derive(Debug, Args)]
pub struct RecognizeArgs {
    /// A model written by `taction train` (one descriptor, or several fused).
    #[arg(long, value_name = "FILE")]
    pub model: PathBuf,
    /// Test dataset; each object's converged readings, in order, are split into trials of as many
    /// readings as the end of `--readings`.
    #[arg(long, value_name = "FILE")]
    pub dataset: PathBuf,
    /// Reading counts to report, `A..B` (both included) or `N` (= `1..N`).
    #[arg(long, default_value = "1..100", value_name = "A..B")]
    pub readings: ReadingRange,
    /// Directory for posterior.csv (p(true) per touch), posterior_long.csv (the whole posterior per touch, one row per object), accuracy.csv and confusion.csv.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

pub fn run(args: &RecognizeArgs) -> Result<(), Box<dyn std::error::Error>> {
    let model = Recognizer::load(&args.model)?;
    let test = Dataset::read(&args.dataset)?;
    let spinner = ProgressBar::new_spinner().with_message("describing and recognising");
    spinner.enable_steady_tick(std::time::Duration::from_millis(120));
    let (evaluation, trials) = model.evaluate(&test, args.readings).map_err(|e| match e {
        RecognizeError::UnknownObject { object, known } => format!(
            "{}: object '{object}' is not one of the objects of the model {} ({}); recognise a dataset of the \
             object set the model was trained on",
            args.dataset.display(),
            args.model.display(),
            known.join(", ")
        ),
        other => format!("{}: {other}", args.dataset.display()),
    })?;
    spinner.finish_and_clear();
    let paths = evaluation.write_csvs(&args.out)?;
    let ks: Vec<String> = model.chosen_ks().iter().map(usize::to_string).collect();
    println!(
        "{trials} trials of up to {} readings over {} objects (model k = {}, {})",
        args.readings.last(),
        model.objects().len(),
        ks.join("+"),
        model.choice().name()
    );
    for n in [1, 10, 30, 100] {
        if let Some(row) = evaluation.accuracy.iter().find(|r| r.n_readings == n) {
            println!(
                "accuracy at {n:>3} readings: {:.3} ({}/{} trials, reliability {:.3})",
                row.accuracy(),
                row.correct,
                row.trials,
                row.reliability
            );
        }
    }
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    println!("wrote {}", names.join(", "));
    Ok(())
}
