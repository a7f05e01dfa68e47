//! `taction recognize`: run a saved model over a test dataset touch by touch and write the
//! per-touch posterior, accuracy against the number of readings (CSV and plot), and the confusion
//! matrix.

use std::path::{Path, PathBuf};

use clap::Args;
use indicatif::ProgressBar;
use taction::atomic::write_atomic;
use taction::dataset::{Dataset, DatasetHeader};
use taction::experiment::plot::build_figure;
use taction::experiment::{AccuracyCurve, AccuracyRow, Factors, PlotSpec, SafeName};
use taction::recognize::{Evaluation, ReadingRange, RecognizeError, Recognizer};

use crate::cli::dataset::read_dataset;

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
    /// Directory for posterior.csv (p(true) per touch), posterior_long.csv (the whole posterior per
    /// touch, one row per object), accuracy.csv, confusion.csv, and the plot of accuracy against
    /// readings: accuracy.svg and accuracy.png, from accuracy_trials.csv (the k-th trial of every
    /// object as trial k, the band from the lowest to the highest).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

pub fn run(args: &RecognizeArgs) -> Result<(), Box<dyn std::error::Error>> {
    let model = Recognizer::load(&args.model)?;
    let test = read_dataset(&args.dataset)?;
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
    let used = evaluation.confusion.n_readings();
    if used < args.readings.last() {
        let accuracy = if used < args.readings.first() {
            format!(
                "accuracy.csv is empty (no trial reaches {} readings)",
                args.readings.first()
            )
        } else {
            format!("accuracy.csv ends at {used}")
        };
        spinner.suspend(|| {
            eprintln!(
                "warning: --readings {} asks for up to {} readings per trial, but no object of {} has more \
                 than {used} converged readings: {accuracy}, confusion.csv decides after {used}",
                args.readings,
                args.readings.last(),
                args.dataset.display()
            )
        });
    }
    let rows = trial_rows(&model, &test, args.readings, &evaluation)?;
    spinner.finish_and_clear();
    let mut paths = evaluation.write_csvs(&args.out)?;
    paths.extend(write_plot(
        &args.out,
        &rows,
        &plot_title(args),
        model.objects().len(),
    )?);
    let ks: Vec<String> = model.chosen_ks().iter().map(usize::to_string).collect();
    println!(
        "{trials} trials of up to {used} readings over {} objects (model k = {}, {})",
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

/// The accuracy rows of the plot, as an experiment's: trial `k` is the `k`-th trial of every object
/// that has one (the objects' converged readings, in order, cut into trials of `range.last()`), so
/// that the band spans the lowest to the highest trial as in the paper's figures. With one trial
/// per object that is `evaluation` itself; otherwise each is recognised on its own, by the same
/// definition of accuracy.
fn trial_rows(
    model: &Recognizer,
    test: &Dataset,
    range: ReadingRange,
    evaluation: &Evaluation,
) -> Result<Vec<AccuracyRow>, Box<dyn std::error::Error>> {
    let curve = |trial: usize| AccuracyCurve {
        experiment: "recognize".to_string(),
        descriptor: model.choice().name(),
        factors: Factors::none(),
        trial: trial as u32,
        seed: 0,
        stream_seed: 0,
    };
    let converged = test.converged_only();
    let by_object = converged.by_object();
    let rounds = by_object
        .iter()
        .map(|readings| readings.len().div_ceil(range.last()))
        .max()
        .unwrap_or(0);
    if rounds <= 1 {
        return Ok(curve(0).rows(&evaluation.accuracy));
    }
    let mut rows = Vec::new();
    for k in 0..rounds {
        let (mut objects, mut readings) = (Vec::new(), Vec::new());
        for (object, of_object) in test.header().objects.iter().zip(&by_object) {
            let chunk = of_object.iter().skip(k * range.last()).take(range.last());
            // An object never read is the first trial's miss, as in `evaluation`.
            if k * range.last() < of_object.len() || k == 0 {
                objects.push(object.clone());
                readings.extend(chunk.map(|&reading| reading.clone()));
            }
        }
        let header = DatasetHeader {
            objects,
            ..test.header().clone()
        };
        let (part, _) = model.evaluate(&Dataset::new(header, readings)?, range)?;
        rows.extend(curve(k).rows(&part.accuracy));
    }
    Ok(rows)
}

/// The plot's title: the model and the test data, by file name.
fn plot_title(args: &RecognizeArgs) -> String {
    let name = |path: &Path| {
        path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    };
    format!("{} recognised by {}", name(&args.dataset), name(&args.model))
}

/// Writes `rows` as accuracy_trials.csv and plots them as accuracy.svg and accuracy.png in `dir`
/// (the plot code of the experiments: mean over trials, lowest-to-highest band, chance at
/// 1/objects); returns the paths.
fn write_plot(
    dir: &Path,
    rows: &[AccuracyRow],
    title: &str,
    objects: usize,
) -> Result<Vec<PathBuf>, Box<dyn std::error::Error>> {
    let csv = dir.join("accuracy_trials.csv");
    let mut writer = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    for row in rows {
        writer.serialize(row)?;
    }
    write_atomic(&csv, &writer.into_inner().map_err(|e| e.to_string())?)?;
    if rows.is_empty() {
        return Ok(vec![csv]);
    }
    let spec = PlotSpec::accuracy(SafeName::new("accuracy")?, title).with_chance(objects);
    let figure = build_figure(&spec, &csv)?;
    let (svg, png) = (dir.join("accuracy.svg"), dir.join("accuracy.png"));
    figure.write_svg(&svg)?;
    figure.write_png(&png)?;
    Ok(vec![csv, svg, png])
}
