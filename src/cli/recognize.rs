//! `taction recognize`: run a saved model over a test dataset touch by touch and write the
//! per-touch posterior, accuracy against the number of readings (CSV and plot), the confusion
//! matrix, and calibration: the reliability table of every belief (CSV and diagram) and its ECE,
//! and where a confidence stop would have ended each trial (`stop.csv`).

use std::path::{Path, PathBuf};

use clap::Args;
use indicatif::ProgressBar;
use taction::active_touch::{StopRecord, reported_stops};
use taction::atomic::write_atomic;
use taction::dataset::Dataset;
use taction::experiment::{AccuracyCurve, AccuracyRow, Factors, PlotSpec, SafeName};
use taction::experiment::{build_figure, reliability_figure};
use taction::recognize::{AccuracyPoint, Evaluation, ReadingRange, RecognizeError, Recognizer, Tempering};

use crate::cli::common::{PosteriorArg, check_output_folder, flag_error};
use crate::cli::dataset::read_dataset;
use clap::builder::PossibleValuesParser;
use taction::locate::ContactNoise;
use taction::recognize::Evidence;
use taction::units;

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
    /// touch, one row per object), accuracy.csv, confusion.csv, reliability.csv (the beliefs of
    /// posterior.csv in 10 bins of top probability: count, mean confidence, accuracy) with its
    /// diagram reliability.svg and reliability.png, and the plot of accuracy against readings:
    /// accuracy.svg and accuracy.png, from accuracy_trials.csv (the k-th trial of every object as
    /// trial k, the band from the lowest to the highest), and stop.csv (where a stop at 0.9, 0.95
    /// and 0.99, the guess held over two touches, would have ended each trial: trials stopped,
    /// right, the share right, the mean touches; when `--readings` starts at 1).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub posterior: PosteriorArg,
    /// With a model of appearance and contact geometry (`train --objects`): the error added to
    /// every contact before it is matched, as a multiple of the documented arm's (1 mm per axis
    /// and 2 deg; 0: the simulator's exact contacts).
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "FACTOR",
        allow_hyphen_values = true
    )]
    pub contact_noise_scale: f64,
    /// With a model of appearance and contact geometry: what its posterior weighs, fused (the
    /// product: appearance plus the fitted weight of the contacts), appearance (the bag of
    /// features alone) or contacts (the contact geometry alone); each with the tempering fitted
    /// for it on the model's calibration explorations. Default: fused.
    #[arg(long, value_name = "EVIDENCE", value_parser = PossibleValuesParser::new(Evidence::NAMES))]
    pub evidence: Option<String>,
}

pub fn run(args: &RecognizeArgs) -> Result<(), Box<dyn std::error::Error>> {
    check_output_folder(&args.out, "out")?;
    if !(0.0..=10.0).contains(&args.contact_noise_scale) {
        return Err(flag_error("contact-noise-scale", args.contact_noise_scale, "want 0 to 10").into());
    }
    let model = model_for(args)?;
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
        spinner.suspend(|| warn_short_trials(args, used));
    }
    if calibrated_on_sampler_for_arm(&model, &test) {
        spinner.suspend(|| {
            eprintln!(
                "taction recognize: warning: {} is the arm's exploration, and the model's posterior carries \
                 no calibration on the arm's explorations (the confidence map `train --calibration` fits \
                 from 100 beliefs on): it was calibrated on sampler readings held out of its training data, \
                 or on too few of the arm's. Held-out readings are independent of each other and the arm's \
                 successive touches are not, so its probabilities are likely overconfident here; train with \
                 `--calibration` on an exploration of the arm's own (README, \"A typical pipeline\")",
                args.dataset.display()
            )
        });
    }
    let rows = trial_rows(&model, &test, args.readings, &evaluation);
    spinner.finish_and_clear();
    let mut paths = evaluation.write_csvs(&args.out)?;
    paths.extend(write_plot(
        &args.out,
        &rows,
        &plot_title(args),
        model.objects().len(),
    )?);
    paths.extend(write_reliability_plot(
        &args.out,
        &evaluation,
        &model.choice().name(),
        &plot_title(args),
    )?);
    print_summary(&model, &evaluation, trials, used);
    paths.extend(replay_stops(args, &evaluation, trials, used)?);
    let names: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    println!("wrote {}", names.join(", "));
    Ok(())
}

/// The model of `--model` with the posterior, contact noise and evidence the flags ask for.
fn model_for(args: &RecognizeArgs) -> Result<Recognizer, Box<dyn std::error::Error>> {
    let evidence = args.evidence.as_deref().and_then(Evidence::parse);
    let model = Recognizer::load(&args.model)?.with_posterior(args.posterior.rule);
    let Recognizer::Geometric(g) = model else {
        if evidence.is_some_and(|e| e != Evidence::Appearance) {
            return Err(flag_error(
                "evidence",
                args.evidence.as_deref().unwrap_or_default(),
                format!(
                    "{} knows appearance alone; a model of contacts too is trained with `train --objects`",
                    args.model.display()
                ),
            )
            .into());
        }
        return Ok(model);
    };
    let noise = ContactNoise::ARM.scaled(args.contact_noise_scale);
    let g = g
        .with_contact_noise(noise)
        .with_evidence(evidence.unwrap_or_default());
    Ok(Recognizer::Geometric(Box::new(g)))
}

/// Replays the confidence stops from the first reading on, within the readings the trials had
/// (`used`), into `stop.csv`; when `--readings` starts later there is no replay, and a stop.csv of
/// an earlier run into this folder would otherwise stand beside this run's files.
fn replay_stops(
    args: &RecognizeArgs,
    evaluation: &Evaluation,
    trials: usize,
    used: usize,
) -> Result<Option<PathBuf>, Box<dyn std::error::Error>> {
    let stops = args.out.join(STOP_FILE);
    if args.readings.first() == 1 {
        return Ok(Some(write_stops(
            &args.out,
            evaluation,
            trials,
            used.min(args.readings.last()),
        )?));
    }
    if stops.exists() {
        std::fs::remove_file(&stops).map_err(|e| format!("{}: {e}", stops.display()))?;
        eprintln!(
            "taction recognize: removed {} of an earlier run: the stop is replayed only when --readings starts at 1",
            stops.display()
        );
    }
    Ok(None)
}

/// The confidence stops' replay a recognition writes.
const STOP_FILE: &str = "stop.csv";

/// Whether a calibrated posterior fitted on the sampler's held-out readings is about to judge the
/// arm's explorations: `train --calibration` (the arm's explorations) fits a confidence map beside
/// the tempering, from 100 beliefs on; validation alone does not (`recognize::calibration`). Measured: such a model's
/// stop at 0.95 was right in 6 of 12 stopped trials of the README's pipeline, ECE 0.30.
fn calibrated_on_sampler_for_arm(model: &Recognizer, test: &Dataset) -> bool {
    let tempering = model.tempering();
    tempering != Tempering::EQ15
        && tempering.confidence_map().is_none()
        && test.header().generator.starts_with("planner")
}

/// The posterior a recognition used: the paper's Eq. 15 or a fitted tempering.
fn posterior_words(t: Tempering) -> String {
    if t == Tempering::EQ15 {
        "Eq. 15".to_string()
    } else {
        format!("calibrated: {t}")
    }
}

/// The run in a few lines: trials and model, accuracy at the headline reading counts, calibration.
fn print_summary(model: &Recognizer, evaluation: &Evaluation, trials: usize, used: usize) {
    let ks: Vec<String> = model.chosen_ks().iter().map(usize::to_string).collect();
    println!(
        "{trials} trials of up to {used} readings over {} objects (model k = {}, {}; posterior {})",
        model.objects().len(),
        ks.join("+"),
        model.choice().name(),
        posterior_words(model.tempering())
    );
    if let Recognizer::Geometric(g) = model {
        let weighs = match g.evidence() {
            Evidence::Fused => format!(
                "appearance + {} x contacts for an object that stays, {} for one that moves",
                g.geometry_weight(),
                g.moving().map_or("appearance alone".to_string(), |m| format!(
                    "appearance + {} x contacts",
                    m.geometry_weight
                ))
            ),
            Evidence::Appearance => "appearance alone".to_string(),
            Evidence::Contacts => "contacts alone".to_string(),
        };
        println!(
            "evidence: {weighs}; contact error {} mm, {} deg RMS",
            units::significant(g.contact_noise().position_sigma_m * 1e3),
            units::significant(g.contact_noise().angle_sigma_rad.to_degrees())
        );
    }
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
    let reliability = evaluation.reliability();
    match reliability.ece() {
        Some(ece) => println!(
            "ECE (10 bins): {ece:.3} over {} predictions",
            reliability.predictions()
        ),
        None => println!("ECE (10 bins): none, no predictions"),
    }
}

/// Replays the reported confidence stops (0.9, 0.95, 0.99, the guess held over the default two
/// touches) on every trial within `budget` readings, prints each and writes them to `stop.csv`.
fn write_stops(
    dir: &Path,
    evaluation: &Evaluation,
    trials: usize,
    budget: usize,
) -> Result<PathBuf, Box<dyn std::error::Error>> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    for stop in reported_stops() {
        let threshold = stop.threshold().get();
        let record = StopRecord::of(evaluation, trials, stop, budget);
        let outcome = match (record.share_right, record.mean_touches) {
            (Some(share), Some(touches)) => format!(
                "{} right ({:.1}%), after {touches:.1} touches on average",
                record.right,
                100.0 * share
            ),
            _ => "none".to_string(),
        };
        println!(
            "stop at {threshold} (the guess held over {} touches): {} of {trials} trials stopped, {outcome}",
            record.held_readings, record.stopped
        );
        writer.serialize(&record)?;
    }
    let path = dir.join(STOP_FILE);
    write_atomic(&path, &writer.into_inner().map_err(|e| e.to_string())?)?;
    Ok(path)
}

/// Draws the reliability diagram of every belief of `evaluation` as reliability.svg and
/// reliability.png in `dir` (none without predictions); returns the paths.
fn write_reliability_plot(
    dir: &Path,
    evaluation: &Evaluation,
    descriptor: &str,
    title: &str,
) -> Result<Vec<PathBuf>, Box<dyn std::error::Error>> {
    let table = evaluation.reliability();
    if table.predictions() == 0 {
        return Ok(Vec::new());
    }
    let figure = reliability_figure(
        &format!("Calibration: {title}"),
        &[(descriptor.to_string(), &table)],
    );
    let (svg, png) = (dir.join("reliability.svg"), dir.join("reliability.png"));
    figure.write_svg(&svg)?;
    figure.write_png(&png)?;
    Ok(vec![svg, png])
}

/// Warns that `--readings` asks for more readings per trial than the test data's longest trial,
/// `used`, and what that leaves in the files.
fn warn_short_trials(args: &RecognizeArgs, used: usize) {
    let accuracy = if used < args.readings.first() {
        format!(
            "accuracy.csv is empty (no trial reaches {} readings)",
            args.readings.first()
        )
    } else {
        format!("accuracy.csv ends at {used}")
    };
    eprintln!(
        "warning: --readings {} asks for up to {} readings per trial, but no object of {} has more \
         than {used} converged readings: {accuracy}, confusion.csv decides after {used}",
        args.readings,
        args.readings.last(),
        args.dataset.display()
    );
}

/// The accuracy rows of the plot, as an experiment's: trial `k` is the `k`-th trial of every object
/// that has one (the objects' converged readings, in order, cut into trials of `range.last()`), so
/// that the band spans the lowest to the highest trial as in the paper's figures. Each point of
/// `evaluation` already holds every trial's outcome in that order (`make_trials`: object by object,
/// trial by trial), so the `k`-th outcome of an object is its `k`-th trial; trial `k`'s curve ends at
/// its longest trial.
fn trial_rows(
    model: &Recognizer,
    test: &Dataset,
    range: ReadingRange,
    evaluation: &Evaluation,
) -> Vec<AccuracyRow> {
    let curve = |trial: usize| AccuracyCurve {
        experiment: "recognize".to_string(),
        descriptor: model.choice().name(),
        factors: Factors::none(),
        trial: trial as u32,
        // The test data's seed: recognition itself draws nothing.
        seed: test.header().seed,
        stream_seed: test.header().seed,
    };
    let lengths: Vec<usize> = test.converged_only().by_object().iter().map(Vec::len).collect();
    let rounds = lengths
        .iter()
        .map(|len| len.div_ceil(range.last()))
        .max()
        .unwrap_or(0);
    if rounds <= 1 {
        return curve(0).rows(&evaluation.accuracy);
    }
    let mut rows = Vec::new();
    for k in 0..rounds {
        let longest = lengths
            .iter()
            .map(|len| len.saturating_sub(k * range.last()).min(range.last()))
            .max()
            .unwrap_or(0);
        let points: Vec<AccuracyPoint> = evaluation
            .accuracy
            .iter()
            .filter(|point| point.n_readings <= longest)
            .map(|point| {
                // Outcomes of each object seen so far in this point: the next one's trial number.
                let mut seen = vec![0usize; model.objects().len()];
                let outcomes = point
                    .outcomes
                    .iter()
                    .filter_map(|outcome| {
                        let count = seen.get_mut(outcome.object)?;
                        let trial = *count;
                        *count += 1;
                        (trial == k).then_some(*outcome)
                    })
                    .collect();
                AccuracyPoint::new(point.n_readings, outcomes)
            })
            .collect();
        rows.extend(curve(k).rows(&points));
    }
    rows
}

/// The plot's title: the model and the test data, by file name.
fn plot_title(args: &RecognizeArgs) -> String {
    let name = |path: &Path| {
        path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    };
    let title = format!("{} recognised by {}", name(&args.dataset), name(&args.model));
    match &args.evidence {
        Some(evidence) => format!("{title} ({evidence})"),
        None => title,
    }
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
