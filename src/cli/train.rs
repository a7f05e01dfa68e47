//! `taction train`: fit a bag-of-features model (Sec. IV-A) on a dataset, choosing the number of
//! clusters on validation data (Sec. V-B1), and save it.

use std::path::PathBuf;

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use taction::dataset::Dataset;
use taction::describe::DescriptorKind;
use taction::locate::GeometryModel;
use taction::mesh::{ObjectSet, TriMesh};
use taction::recognize::{
    CodebookKind, DescriptorChoice, PseudoCount, RecognizeError, Recognizer, Tempering, TrainChoices,
    TrainData, TrainObserver, TrainProgress, TrainedModel, VarianceFraction, check_contacts_weighable,
    sensor_differences, train_recognizer,
};
use taction::valid::Valid;

use crate::cli::common::{ObjectSizeArg, SeedArg, UsageError, check_output_file, parse_codebook};
use crate::cli::dataset::read_dataset;
use crate::cli::plausible::{Carrier, build_objects};

#[derive(Debug, Args)]
pub struct TrainArgs {
    /// Training dataset, as `taction collect` writes it (`taction dataset show` lists what it
    /// holds); only converged readings are used.
    #[arg(long, value_name = "FILE")]
    pub dataset: PathBuf,
    /// Validation dataset for model selection; without it the last 1/11 of each object's
    /// training readings are held out.
    #[arg(long, value_name = "FILE")]
    pub validation: Option<PathBuf>,
    /// vectorize | sift | mr8 | moment-normalized (mn) | polar-fourier (pf) | mnti (default
    /// parameters), or beyond the paper shape-index (the local shapes of a large array's frame,
    /// pooled over it: the measured best on 28x50 frames, docs/measurements.md); several joined by '+' (e.g. mnti+sift) train one model per descriptor on the
    /// same data, written as one fused model whose posterior multiplies their likelihoods.
    #[arg(long, value_name = "NAME[+NAME]", value_parser = DescriptorChoice::parse)]
    pub descriptor: DescriptorChoice,
    /// knn (beyond the paper: the objects' shares of a feature's k nearest training features;
    /// the model keeps every training feature) | mlp (beyond the paper: a network's posterior
    /// over the objects, frames combined by the product rule) | gmm (the paper's, soft
    /// membership) | kmeans (hard membership). Default: mlp for `shape-index` alone (a large
    /// array's frames: 64.5% from one frame against knn's 49.3%), knn otherwise (the 52 letters
    /// at 94.2% against the GMM's 78.8% at 20 readings); docs/measurements.md.
    #[arg(long, value_name = "KIND", value_parser = parse_codebook)]
    pub codebook: Option<CodebookKind>,
    /// Cluster counts to try, comma-separated (neighbour counts with `--codebook knn`, hidden
    /// units with mlp: 128, 256 by default). Default:
    /// four steps of 10, 20, 50, 100, 200, 400, ... starting near one cluster per object ({50,
    /// 100, 200, 400} for 52 objects), without counts that leave fewer than 5 training readings per
    /// cluster; for knn 10, 20, 50, 100 neighbours, below half an object's training readings.
    #[arg(long = "k", value_name = "K,...", value_delimiter = ',')]
    pub ks: Option<Vec<usize>>,
    /// Seeded restarts per cluster count.
    #[arg(long, default_value_t = 3)]
    pub restarts: usize,
    #[command(flatten)]
    pub seed: SeedArg,
    /// Fraction of the training variance the kept principal components explain [default: 0.9,
    /// the paper's; 0.99 with `--codebook knn`, 1 (all of it) with mlp].
    #[arg(long, value_name = "FRACTION", allow_hyphen_values = true)]
    pub variance_kept: Option<f64>,
    /// Pseudo-count added to every cluster bin of every object histogram.
    #[arg(long, default_value_t = 1.0, value_name = "ALPHA", allow_hyphen_values = true)]
    pub pseudo_count: f64,
    /// Readings per validation trial.
    #[arg(long, default_value_t = 10, value_name = "N")]
    pub trial_readings: usize,
    /// Calibration dataset: the posterior's tempering is fitted on it instead of on the
    /// validation readings. Give the arm's own explorations (`collect --mode planner`) when the
    /// model will recognise them: their successive touches are correlated, which sampler
    /// validation readings cannot show. Repeat the flag to fit on several datasets together
    /// (explorations of each kind the model will see: L = 1 touches one region again and again,
    /// and a tempering fitted on L = 0.5 alone trusts them too much; docs/measurements.md).
    #[arg(long, value_name = "FILE")]
    pub calibration: Vec<PathBuf>,
    /// Readings per calibration trial: the length of the runs the model will recognise (the
    /// tempering is only fitted at the reading counts the trials reach) [default: each object's
    /// readings in the calibration dataset as one trial].
    #[arg(long, value_name = "N", requires = "calibration")]
    pub calibration_trial_readings: Option<usize>,
    /// The object set the dataset was collected on (as `collect --objects` took it): the model
    /// then also knows where each touch landed, matching the contacts of the touches so far
    /// against every object's surface at a pose it is not told (`locate`), fused with the
    /// appearance model. The fusion's weight is fitted on `--calibration` (else `--validation`),
    /// explorations the appearance model was not trained on.
    #[arg(long, value_name = "SET|DIR|FILE...", num_args = 1..)]
    pub objects: Vec<PathBuf>,
    #[command(flatten)]
    pub object_size: ObjectSizeArg,
    /// Where to write the model (JSON).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

/// A training parameter out of range, named by the flag that set it; others (the hold-out share,
/// which no flag sets) keep the library's message.
fn named_by_flag(e: RecognizeError) -> Box<dyn std::error::Error> {
    match e {
        RecognizeError::InvalidParameter { name, what } => {
            let flag = match name {
                "k" => "k",
                "restarts" => "restarts",
                "trial_readings" => "trial-readings",
                "variance_kept" => "variance-kept",
                "pseudo_count" => "pseudo-count",
                "calibration_trial_readings" => "calibration-trial-readings",
                "objects" => "objects",
                _ => return RecognizeError::InvalidParameter { name, what }.into(),
            };
            UsageError(format!("--{flag}: {what}")).into()
        }
        other => other.into(),
    }
}

/// The flags as the library's training choices, checked before any dataset is read (a bad value
/// exits 2, named by its flag).
fn choices(args: &TrainArgs) -> Result<Valid<TrainChoices>, Box<dyn std::error::Error>> {
    let variance_kept = args
        .variance_kept
        .map(VarianceFraction::new)
        .transpose()
        .map_err(named_by_flag)?;
    let choices = TrainChoices {
        descriptor: args.descriptor.clone(),
        codebook: args
            .codebook
            .unwrap_or_else(|| TrainChoices::default_codebook(&args.descriptor)),
        ks: args.ks.clone(),
        restarts: args.restarts,
        seed: args.seed.seed,
        variance_kept,
        pseudo_count: PseudoCount::new(args.pseudo_count).map_err(named_by_flag)?,
        trial_readings: args.trial_readings,
        calibration_trial_readings: args.calibration_trial_readings,
    };
    Valid::new(choices).map_err(named_by_flag)
}

pub fn run(args: &TrainArgs) -> Result<(), Box<dyn std::error::Error>> {
    let choices = choices(args)?;
    check_contacts_weighable(
        !args.objects.is_empty(),
        !args.calibration.is_empty(),
        args.validation.is_some(),
    )
    .map_err(named_by_flag)?;
    check_output_file(&args.out, "out")?;
    let training = read_dataset(&args.dataset)?;
    let validation = args.validation.as_deref().map(read_dataset).transpose()?;
    check_datasets(args, &training, validation.as_ref())?;
    let calibration = args
        .calibration
        .iter()
        .map(|path| read_dataset(path))
        .collect::<Result<Vec<_>, _>>()?;
    let contacts = geometry_of(args, &training)?;
    let data = TrainData {
        training: &training,
        validation: validation.as_ref(),
        calibration: &calibration.iter().collect::<Vec<_>>(),
        contacts: contacts.as_ref(),
    };
    let mut printer = Printer::new(args);
    let model = train_recognizer(&choices, data, &mut printer).map_err(|e| match e {
        RecognizeError::Calibration(e) => format!("--calibration {}: {e}", printer.calibration_names).into(),
        e => named_by_flag(e),
    })?;
    model.save(&args.out)?;
    let kind = match (&model, args.descriptor.is_fused()) {
        (Recognizer::Geometric(_), _) => "model of appearance and contact geometry",
        (_, true) => "fused model",
        (_, false) => "model",
    };
    println!(
        "{kind} ({}) written to {}",
        args.descriptor.name(),
        args.out.display()
    );
    Ok(())
}

/// What training tried and chose, printed as it goes, with a progress bar over each descriptor's
/// candidates.
struct Printer {
    bar: Option<ProgressBar>,
    descriptor: String,
    calibration_names: String,
    calibration_trials: String,
}

impl Printer {
    fn new(args: &TrainArgs) -> Self {
        let names: Vec<String> = args.calibration.iter().map(|p| p.display().to_string()).collect();
        Self {
            bar: None,
            descriptor: args.descriptor.name(),
            calibration_names: names.join(", "),
            calibration_trials: match args.calibration_trial_readings {
                Some(n) => format!("{} (trials of {n} readings)", names.join(" + ")),
                None => format!("{} (each object's readings one trial)", names.join(" + ")),
            },
        }
    }

    fn bar(&mut self, kind: DescriptorKind) -> &ProgressBar {
        self.bar.get_or_insert_with(|| {
            let bar = ProgressBar::new(0);
            bar.set_style(
                ProgressStyle::with_template("{bar:30} {pos}/{len} candidates  {msg}  [{elapsed}]")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar.set_message(format!("describing readings ({})", kind.name()));
            bar
        })
    }
}

impl TrainObserver for Printer {
    fn progress(&mut self, kind: DescriptorKind, event: TrainProgress) {
        let bar = self.bar(kind);
        match event {
            TrainProgress::PcaFitted { total, .. } => bar.set_length(total as u64),
            TrainProgress::Fitting { k, restart, .. } => {
                bar.set_message(format!("fitting k={k} restart={restart}"))
            }
            TrainProgress::Scored(_) => bar.inc(1),
        }
    }

    fn fitted(&mut self, model: &TrainedModel) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
        print_selection(model);
    }

    fn fused(&mut self, tempering: Tempering) {
        print_tempering("fused", "validation", tempering);
    }

    fn weighed_on_validation(&mut self, model: &Recognizer) {
        print_geometry(model, "validation");
    }

    fn calibrated(&mut self, model: &Recognizer) {
        // A model of contacts too weighs them on the calibration, and says so itself.
        if !matches!(model, Recognizer::Geometric(_)) {
            print_tempering(&self.descriptor, &self.calibration_trials, model.tempering());
        }
        print_geometry(model, &self.calibration_trials);
    }
}

/// The training data has converged readings of every object, and the validation data is of the
/// same sensor and objects: said here naming the files, rather than by the fit, which knows no file.
fn check_datasets(
    args: &TrainArgs,
    training: &Dataset,
    validation: Option<&Dataset>,
) -> Result<(), Box<dyn std::error::Error>> {
    let train = args.dataset.display();
    if let Some(empty) = training.shortfalls(1).first() {
        return Err(format!(
            "--dataset {train}: object '{}' has no converged reading to train on",
            empty.object
        )
        .into());
    }
    let (Some(validation), Some(path)) = (validation, &args.validation) else {
        return Ok(());
    };
    let path = path.display();
    let sensors = (
        (&training.header().sensor, "training"),
        (&validation.header().sensor, "validation"),
    );
    if let Some(differences) = sensor_differences(sensors.0, sensors.1) {
        return Err(
            format!("--validation {path}: another sensor than --dataset {train}'s: {differences}").into(),
        );
    }
    let known = &training.header().objects;
    if let Some(stranger) = validation.header().objects.iter().find(|o| !known.contains(o)) {
        return Err(format!(
            "--validation {path}: object '{stranger}' is not one of --dataset {train}'s objects ({})",
            known.join(", ")
        )
        .into());
    }
    Ok(())
}

/// What model selection tried and chose.
fn print_selection(model: &TrainedModel) {
    let s = &model.selection;
    println!(
        "{}: trained on {} readings ({} features) of {} objects; validation: {}",
        model.descriptor.kind().name(),
        s.training_readings,
        s.training_features,
        model.bag.objects().len(),
        s.validation
    );
    println!(
        "PCA: {} components explain {:.1}% of the variance",
        s.pca_components,
        s.pca_variance_ratio * 100.0
    );
    for c in &s.candidates {
        match &c.failure {
            Some(why) => println!("  k={:<4} restart={}  failed: {why}", c.k, c.restart),
            None => println!(
                "  k={:<4} restart={}  validation accuracy {:.3} ({}/{})  reliability {:.3}",
                c.k,
                c.restart,
                c.accuracy(),
                c.correct,
                c.trials,
                c.reliability
            ),
        }
    }
    let chosen = s.chosen().map_or(String::new(), |c| {
        format!(
            " (validation accuracy {:.3}, reliability {:.3})",
            c.accuracy(),
            c.reliability
        )
    });
    println!("chosen k = {}, restart {}{chosen}", s.chosen_k, s.chosen_restart);
    print_tempering(
        model.descriptor.kind().short_name(),
        "validation",
        model.bag.tempering(),
    );
}

/// The posterior's tempering and what it was fitted `on` (`--posterior eq15` at recognition turns
/// it off).
fn print_tempering(name: &str, on: &str, t: Tempering) {
    println!(
        "{name} posterior calibrated on {on}: {t} (10 readings count as {:.1} independent ones, 30 as {:.1})",
        t.effective_readings(10),
        t.effective_readings(30)
    );
}

/// The geometric model of `--objects`, when given: the set the training data was collected on
/// (its id is the dataset header's), the surface of each of the dataset's objects, in its order,
/// in its canonical frame.
fn geometry_of(
    args: &TrainArgs,
    training: &Dataset,
) -> Result<Option<GeometryModel>, Box<dyn std::error::Error>> {
    if args.objects.is_empty() {
        return Ok(None);
    }
    let set = ObjectSet::resolve(&args.objects, None, args.object_size.m)?;
    let recorded = &training.header().object_set;
    if &set.id() != recorded {
        return Err(format!(
            "--objects: set '{}' (id {}) is not the set --dataset {} was collected on (id {recorded}); \
             give the --objects and --object-size-m that collect was given",
            set.name,
            set.id(),
            args.dataset.display()
        )
        .into());
    }
    let objects = build_objects(&set, "train", Carrier::FreePad)?;
    let meshes: Vec<(String, &TriMesh)> = objects.iter().map(|o| (o.name.clone(), &o.mesh)).collect();
    let geometry = GeometryModel::of_named(&training.header().objects, &meshes, set.start_heading())?;
    Ok(Some(geometry))
}

/// The fitted weight of the geometric evidence, and what it was fitted on.
fn print_geometry(model: &Recognizer, on: &str) {
    if let Recognizer::Geometric(g) = model {
        let moving = g.moving().map_or(
            "appearance alone (no perturbed exploration given)".to_string(),
            |m| format!("lambda = {}, posterior {}", m.geometry_weight, m.tempering),
        );
        println!(
            "appearance + lambda x contacts weighed on {on}: for an object that stays lambda = {} (0: appearance \
             alone), posterior {}; for one that moves {moving}",
            g.geometry_weight(),
            g.tempering()
        );
    }
}
