//! `taction experiment NAME|list` and `taction reproduce`: the paper's experiments (Sec. V).

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use taction::dataset::{Calibration, TaxelPitch};
use taction::experiment::RunOptions;
use taction::mesh::BUILTIN_SETS;
use taction::mesh::ObjectSet;
use taction::paper::PAPER_TRIALS;
use taction::paper::headline_table;
use taction::paper::{PaperContext, PaperExperiment, RealRecording, Scale};
use taction::paper::{REFERENCE_THREADS, RunEstimate, human_duration};
use taction::paper::{SHORTFALLS_FILE, read_shortfalls};
use taction::paper::{TIMINGS_FILE, timings_table, write_timings};

use crate::cli::common::{
    ObjectSizeArg, OutputLock, PosteriorArg, PreprocessArgs, SeedArg, ThreadsArg, UsageError, parse_codebook,
};
use crate::cli::plausible::{Carrier, build_objects};
use taction::recognize::CodebookKind;

/// What every paper experiment takes.
#[derive(Debug, Args)]
pub struct PaperArgs {
    /// Fraction of the paper's data sizes (1.0: 1000 + 100 training readings and 3 x 100 test
    /// readings per object; 0.1 for a quick look).
    #[arg(long, default_value = "1.0", allow_hyphen_values = true)]
    pub scale: Scale,
    #[command(flatten)]
    pub seed: SeedArg,
    #[command(flatten)]
    pub threads: ThreadsArg,
    #[command(flatten)]
    pub run: RunOptions,
    /// The 3D objects: a built-in set, a folder of meshes, a manifest, or mesh files.
    #[arg(long, num_args = 1.., default_value = "shapes", value_name = "SET")]
    pub objects: Vec<PathBuf>,
    #[command(flatten)]
    pub object_size: ObjectSizeArg,
    /// The raised letters (Fig. 16a): the built-in `letters` or another set.
    #[arg(long, num_args = 1.., default_value = "letters", value_name = "SET")]
    pub letters: Vec<PathBuf>,
    /// Recorded real frames for the sim-to-real and real-frames experiments [default: the shipped
    /// synthetic example], of a rows x cols grid (2x2 to 128x128). CSV: a header
    /// `label,r0c0,r0c1,...` naming every taxel, then one frame per line: its label, then one
    /// non-negative raw value per taxel; `#` lines are comments. Or a folder of class folders of
    /// grayscale PNG/JPEG images, or an .npz of `frames` and `labels` (as `dataset import` takes
    /// them). Frames of one press (a `contact` column, a folder inside a class folder, an npz
    /// array `contacts`) are split by press. Frames of the wrong size or with non-finite values are
    /// rejected with their line, frame or file. Values are divided by the largest value.
    #[arg(long, value_name = "FRAMES")]
    pub real: Option<PathBuf>,
    /// Per-taxel calibration of `--real`, applied on import as gain * (raw - offset), clamped at 0.
    /// CSV: a header `taxel,gain,offset`, then one line per taxel (`r0c0,1.02,13`), every taxel of
    /// the grid exactly once.
    #[arg(long, value_name = "CSV", requires = "real")]
    pub calibration: Option<PathBuf>,
    /// The distance between neighbouring taxel centres of `--real`'s array, metres (e.g. 0.002):
    /// sim-to-real then simulates a pad of the recording's rows x cols at this pitch (cols x pitch
    /// wide, rows x pitch high; the figure's 10% covering and 30% noise) instead of the paper's
    /// 6x6 letters sensor. Needed for a recording of another grid than 6x6.
    #[arg(long, value_name = "M", requires = "real")]
    pub taxel_pitch_m: Option<TaxelPitch>,
    #[command(flatten)]
    pub preprocess: PreprocessArgs,
    /// real-frames (Fig. 16b): trials of the whole split-train-test process.
    #[arg(long, default_value_t = PAPER_TRIALS, value_name = "N", allow_hyphen_values = true)]
    pub trials: usize,
    /// Exit 0 even when a dataset got fewer converged readings than asked (the shortfalls are
    /// still listed on stderr). Without it such a run finishes every experiment, saves it, and
    /// then exits 1.
    #[arg(long)]
    pub allow_short: bool,
    /// The codebook of every model: gmm (the paper's) | kmeans | knn (beyond the paper: the
    /// objects' shares of a feature's nearest training features, PCA keeping 99%). Without it the
    /// paper's figures and training-size use gmm, and the experiments on the arm's own touches
    /// (end-to-end, active) the product's recipe, knn. A run with another codebook needs its own
    /// `--out`.
    #[arg(long, value_name = "KIND", value_parser = parse_codebook)]
    pub codebook: Option<CodebookKind>,
    #[command(flatten)]
    pub posterior: PosteriorArg,
}

impl PaperArgs {
    fn context(&self) -> Result<PaperContext, Box<dyn std::error::Error>> {
        let shapes = ObjectSet::resolve(&self.objects, None, self.object_size.m)
            .map_err(|e| format!("--objects: {e}"))?;
        let letters = ObjectSet::resolve(&self.letters, None, self.object_size.m)
            .map_err(|e| format!("--letters: {e}"))?;
        check_user_set("objects", &self.objects, &shapes)?;
        check_user_set("letters", &self.letters, &letters)?;
        let mut real = match &self.real {
            Some(path) => RealRecording::read(path).map_err(|e| format!("--real: {e}"))?,
            None => RealRecording::example(),
        };
        if let Some(path) = &self.calibration {
            real.calibration = Some(Calibration::read(path).map_err(|e| format!("--calibration: {e}"))?);
        }
        real.taxel_pitch = self.taxel_pitch_m;
        let real_frames = self.preprocess.options(self.trials)?;
        let run = RunOptions {
            threads: Some(self.threads.count()),
            ..self.run.clone()
        };
        Ok(
            PaperContext::new(self.scale, self.seed.seed, run, shapes, letters, real)
                .with_real_frames(real_frames)
                .with_codebook(self.codebook)
                .with_posterior(self.posterior.rule),
        )
    }
}

/// Builds a set of the user's meshes once before anything runs, so that a mesh the arm cannot
/// explore (millimetres read as metres, a flat or tiny mesh) stops the run with its name here rather
/// than as failed readings an hour later. The built-in sets are known to pass.
fn check_user_set(flag: &str, spec: &[PathBuf], set: &ObjectSet) -> Result<(), Box<dyn std::error::Error>> {
    if let [one] = spec
        && BUILTIN_SETS.contains(&one.to_string_lossy().as_ref())
    {
        return Ok(());
    }
    build_objects(set, "experiment", Carrier::Arm).map_err(|e| format!("--{flag}: {e}"))?;
    Ok(())
}

#[derive(Debug, Args)]
pub struct ExperimentArgs {
    /// The experiment (`list` shows them).
    pub name: String,
    #[command(flatten)]
    pub paper: PaperArgs,
}

#[derive(Debug, Args)]
pub struct ReproduceArgs {
    #[command(flatten)]
    pub paper: PaperArgs,
    /// Only these experiments, comma-separated [default: all].
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub only: Vec<String>,
}

fn parse_experiment(name: &str) -> Result<PaperExperiment, String> {
    PaperExperiment::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = PaperExperiment::ALL.iter().map(|e| e.name()).collect();
        format!(
            "no experiment '{name}' (the experiments are {})",
            names.join(", ")
        )
    })
}

pub fn run_experiment(args: &ExperimentArgs) -> Result<(), Box<dyn std::error::Error>> {
    if args.name == "list" {
        for experiment in PaperExperiment::ALL {
            println!("{:<14} {}", experiment.name(), experiment.description());
        }
        return Ok(());
    }
    let experiment = parse_experiment(&args.name).map_err(UsageError)?;
    let context = args.paper.context()?;
    let _lock = OutputLock::acquire(&context.options.out, "out")?;
    check_earlier_runs(&[experiment], &context)?;
    announce_estimate(&[experiment.name()], &context);
    let (report, times) = experiment.run_timed(&context).map_err(|e| e.to_string())?;
    println!("{report}");
    eprintln!(
        "{experiment} took {:.1} s: datasets {:.1} s, units {:.1} s ({:.1} thread-s, of which training {:.1}), \
         rest {:.1} s",
        times.wall_s,
        times.datasets_s,
        times.units_s,
        times.unit_thread_s,
        times.training_thread_s,
        times.rest_s
    );
    check_shortfalls(&context, &[experiment.name()], args.paper.allow_short)
}

/// Lists the short datasets the experiments `names` used (their `shortfalls.csv`, this run's and
/// earlier runs' into the same folder) on stderr; without `--allow-short` they fail the run (exit
/// 1), after every experiment finished and was saved.
fn check_shortfalls(
    context: &PaperContext,
    names: &[&str],
    allow_short: bool,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut short = Vec::new();
    for name in names {
        for object in read_shortfalls(&context.options.out.join(name)).map_err(|e| e.to_string())? {
            eprintln!("short dataset of {name}: {object}");
            short.push(object);
        }
    }
    if short.is_empty() {
        return Ok(());
    }
    let message = format!(
        "{} object{} of the run's datasets got fewer converged readings than asked (listed above, and \
         in each experiment's {SHORTFALLS_FILE}); the results are written and count such an object \
         with the readings it has",
        short.len(),
        if short.len() == 1 { "" } else { "s" }
    );
    if allow_short {
        eprintln!("warning: {message}");
        Ok(())
    } else {
        Err(format!("{message}; pass --allow-short to accept them").into())
    }
}

/// Refuses, before any estimate or data collection, to resume an experiment whose folder holds a
/// run of another scale, seed or codebook (its `config.json`): the runner would refuse it only
/// after collecting this run's data, and the shipped `results/` (scale 1.0, seed 1, each
/// experiment's own codebook) is the default output folder.
fn check_earlier_runs(
    experiments: &[PaperExperiment],
    context: &PaperContext,
) -> Result<(), Box<dyn std::error::Error>> {
    for &experiment in experiments {
        let ours = RunSettings {
            scale: context.scale.fraction(),
            seed: context.seed,
            codebook: serde_json::to_value(context.codebook_for(experiment))?
                .as_str()
                .map(str::to_owned),
        };
        let path = context.options.out.join(experiment.name()).join("config.json");
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let config: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        let theirs = RunSettings {
            scale: config["scale"].as_f64().unwrap_or(ours.scale),
            seed: config["seed"].as_u64().unwrap_or(ours.seed),
            codebook: match config["training"]["codebook"].as_str() {
                Some(kind) => Some(kind.to_owned()),
                None => ours.codebook.clone(),
            },
        };
        if theirs != ours {
            return Err(format!(
                "{} holds a run at {theirs} ({}); this run is at {ours}, and resuming would mix the two: \
                 give this run its own --out, or delete {}",
                path.parent().unwrap_or(&path).display(),
                path.display(),
                path.parent().unwrap_or(&path).display()
            )
            .into());
        }
    }
    Ok(())
}

/// What an experiment's folder must share with a run that resumes it, as `check_earlier_runs`
/// reads it from `config.json`.
#[derive(Debug, PartialEq)]
struct RunSettings {
    scale: f64,
    seed: u64,
    codebook: Option<String>,
}

impl std::fmt::Display for RunSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "scale {}, seed {}", self.scale, self.seed)?;
        match &self.codebook {
            Some(kind) => write!(f, ", codebook {kind}"),
            None => Ok(()),
        }
    }
}

/// Prints the estimated duration of running `names` (those not finished in the output folder) and
/// returns the estimate to update as they finish.
fn announce_estimate(names: &[&str], context: &PaperContext) -> RunEstimate {
    let threads = context
        .options
        .threads
        .map_or(REFERENCE_THREADS, std::num::NonZeroUsize::get);
    let estimate = RunEstimate::new(names, context.scale, threads, &context.options.out);
    eprintln!(
        "estimated duration: about {} at scale {} with {threads} threads (from timings on a 2-core machine, \
         corrected as experiments finish)",
        human_duration(estimate.total_s()),
        context.scale
    );
    estimate
}

pub fn run_reproduce(args: &ReproduceArgs) -> Result<(), Box<dyn std::error::Error>> {
    let experiments: Vec<PaperExperiment> = if args.only.is_empty() {
        PaperExperiment::ALL.to_vec()
    } else {
        args.only
            .iter()
            .map(|n| parse_experiment(n.trim()).map_err(|e| UsageError(format!("--only: {e}"))))
            .collect::<Result<_, _>>()?
    };
    let context = args.paper.context()?;
    let _lock = OutputLock::acquire(&context.options.out, "out")?;
    let names: Vec<&str> = experiments.iter().map(|e| e.name()).collect();
    check_earlier_runs(&experiments, &context)?;
    let started = Instant::now();
    let mut estimate = announce_estimate(&names, &context);
    let mut timings = Vec::new();
    for experiment in &experiments {
        eprintln!("== {experiment}: {}", experiment.description());
        let (report, times) = experiment.run_timed(&context).map_err(|e| e.to_string())?;
        println!("{report}");
        let seconds = times.wall_s;
        estimate.finished(experiment.name(), seconds);
        timings.push(times);
        // Written after every experiment, so a run stopped later keeps the phases it measured.
        write_timings(&context.options.out, &timings).map_err(|e| e.to_string())?;
        eprintln!(
            "== {experiment} done in {seconds:.1} s; about {} to go",
            human_duration(estimate.remaining_s())
        );
    }
    let names: Vec<&str> = experiments
        .iter()
        .filter(|e| e.is_recognition())
        .map(|e| e.name())
        .collect();
    let table = headline_table(&context.options.out, &names)?;
    println!(
        "\naccuracy (%) after n readings, mean over trials, scale {}:\n{table}\nwhere the time went \
         (seconds, also in {}; datasets: collected or read, units: the experiments' work on the \
         worker pool, rest: assembling and plotting; thread-s summed over the workers):\n{}\nreproduce took {:.1} s",
        context.scale,
        context.options.out.join(TIMINGS_FILE).display(),
        timings_table(&timings),
        started.elapsed().as_secs_f64()
    );
    let all: Vec<&str> = experiments.iter().map(|e| e.name()).collect();
    check_shortfalls(&context, &all, args.paper.allow_short)
}
