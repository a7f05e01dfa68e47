//! `taction collect`: readings of a set of objects by the training sampler or the planner, written as
//! a dataset (format: `taction::dataset`), with a PNG contact sheet per object of its first converged
//! readings beside it (`<out stem>.<object>.png`, like the strips of the paper's Fig. 1 and Fig. 5).

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use taction::dataset::{Dataset, describe_shortfalls};
use taction::experiment::Progress;
use taction::explore::{CollectModeName, CollectRequest, ExplorationReport, ModeChoices};
use taction::mesh::ObjectSet;
use taction::sim::{FreeBody, MotionSummary, PerturbationAct, PerturbationBounds, StartPose};
use taction::tactile::write_contact_sheet;
use taction::valid::RangeError;

use crate::cli::common::{
    ControlArg, FreeObjectArgs, ObjectSizeArg, SeedArg, ThreadsArg, UsageError, check_output_file, flag_error,
};
use crate::cli::plausible::{Carrier, build_objects};
use crate::cli::sensor_args::SensorArgs;

/// Most converged readings per object one run collects: a thousand times the paper's training
/// sets (Sec. V-B); a larger count is a typo, not a plan.
pub const MAX_READINGS: usize = 1_000_000;

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum Mode {
    /// Training sampler: area-weighted surface points, free-floating pad (Sec. V-A3).
    Sampler,
    /// Blind exploration with the arm (Sec. III-A).
    Planner,
}

#[derive(Debug, Args)]
pub struct CollectArgs {
    /// The objects: a built-in set name, a folder of OBJ/OFF/STL files, a manifest, or mesh files.
    #[arg(long, num_args = 1.., required = true, value_name = "DIR|FILES|SET")]
    pub objects: Vec<PathBuf>,
    #[command(flatten)]
    pub object_size: ObjectSizeArg,
    #[arg(long, value_enum, default_value_t = Mode::Sampler)]
    pub mode: Mode,
    /// Converged readings per object (at most 1000000; the paper trains on 1000).
    #[arg(long, default_value_t = 100, allow_hyphen_values = true)]
    pub readings: usize,
    /// Planner: probability L of the local strategy [default: 0.5].
    #[arg(long, allow_hyphen_values = true)]
    pub local_prob: Option<f64>,
    /// Planner: iterations allowed per object before it gives up short of `--readings`
    /// [default: 200 per reading asked for, at least 20000]
    #[arg(long, allow_hyphen_values = true)]
    pub max_iterations: Option<usize>,
    /// Sampler: approach only from above (raised letters, Sec. V-D).
    #[arg(long)]
    pub from_above: bool,
    /// Sampler: only starts the exploring arm can reach (no underside on the table, no patch facing
    /// away from the arm), with the arm's roll: training data that matches what the arm feels
    #[arg(long)]
    pub reachable: bool,
    /// Planner: the object on a free joint (`--free-object`, with `--object-density` and
    /// `--object-friction`); how far each touch moved it is printed per object.
    #[command(flatten)]
    pub free: FreeObjectArgs,
    /// Perturb the object after every reading: largest rotation, degrees, in [0, 180].
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub perturb_deg: f64,
    /// Perturb the object after every reading: largest translation, fraction of its width, in [0, 1].
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub perturb_frac: f64,
    /// How a perturbation moves the object: teleport (the paper's: put at the drawn pose) or push
    /// (beyond the paper, with --free-object: pushed toward it, friction stopping it)
    #[arg(long, value_name = "ACT", default_value = "teleport")]
    pub perturb_by: String,
    /// Where each object starts: canonical (as it was built) or random (a pose drawn per object
    /// from the seed, not told to the explorer: any heading about the vertical, within 10 degrees
    /// for the raised letters, whose heading is part of their identity, then a tilt of up to 10
    /// degrees and a shift of up to 10% of the width; the dataset's header records it), or
    /// turned:DEG (as random, but every object at heading DEG about the vertical; at most 10 for
    /// the letters).
    #[arg(long, value_name = "START", default_value = "canonical")]
    pub start_pose: String,
    #[command(flatten)]
    pub seed: SeedArg,
    #[command(flatten)]
    pub threads: ThreadsArg,
    #[command(flatten)]
    pub sensor: SensorArgs,
    #[command(flatten)]
    pub control: ControlArg,
    /// Dataset file to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Exit 0 even when some object got fewer converged readings than `--readings` (the shortfall
    /// is still reported on stderr). Without it such a run writes its dataset and exits 1.
    #[arg(long)]
    pub allow_short: bool,
    /// Converged readings per object drawn on its contact sheet, `<out stem>.<object>.png` beside the
    /// dataset (0: no contact sheets).
    #[arg(long, default_value_t = 24, value_name = "N")]
    pub contact_sheet: usize,
}

pub fn run(args: &CollectArgs) -> Result<(), Box<dyn std::error::Error>> {
    check_flags(args)?;
    let request = request(args)?;
    check_output_file(&args.out, "out")?;
    let perturbation =
        PerturbationBounds::new(args.perturb_deg, args.perturb_frac)?.by(perturbation_act(args)?);
    let sensor = args.sensor.config(args.seed.seed)?.into_inner();
    let set = ObjectSet::resolve(&args.objects, None, args.object_size.m)?;
    let carrier = match args.mode {
        Mode::Sampler => Carrier::FreePad,
        Mode::Planner => Carrier::Arm,
    };
    let objects = build_objects(&set, "collect", carrier)?;
    // The set says how far a random start may turn its objects (the letters: 10 degrees).
    let start_pose = StartPose::parse(&args.start_pose, set.start_heading()).ok_or_else(|| {
        flag_error(
            "start-pose",
            &args.start_pose,
            format!(
                "want one of {} (a turn of at most {} deg for this set)",
                StartPose::NAMES.join(", "),
                taction::units::significant(set.start_heading().rad().to_degrees())
            ),
        )
    })?;
    let collect = request
        .collection(sensor, &objects, args.readings)
        .control(args.control.valid(sensor.noise_fraction)?)
        .perturbation(perturbation)
        .start_pose(start_pose)
        .free_object(free_body(args)?)
        .seed(args.seed.seed)
        .threads(args.threads.count().get());
    let plan = collect.plan().map_err(named_by_flag)?;
    eprintln!(
        "taction collect: {} objects x {} converged readings, {} threads, into {}",
        objects.len(),
        args.readings,
        args.threads.count(),
        args.out.display()
    );
    let progress = Progress::collection(&format!("collect {}", set.name), objects.len(), args.readings);
    let reports = collect.progress(&|| progress.inc()).run(&objects)?;
    progress.finish(reports.iter().map(ExplorationReport::converged).sum());
    let planner_lines: Vec<String> = objects
        .iter()
        .zip(&reports)
        .flat_map(|(object, report)| {
            let planner = matches!(args.mode, Mode::Planner).then(|| planner_line(&object.name, report));
            let moved = args
                .free
                .free_object
                .then(|| free_object_line(&object.name, report));
            let perturbed = (!perturbation.is_none())
                .then(|| perturbation_line(&object.name, perturbation.act(), report));
            planner.into_iter().chain(moved).chain(perturbed)
        })
        .collect();
    let dataset = plan.dataset_of(&set.id(), &objects, reports)?;
    dataset.write(&args.out)?;
    println!("{}: {}", args.out.display(), dataset.summary());
    for line in planner_lines {
        println!("{line}");
    }
    for path in write_contact_sheets(&dataset, &args.out, args.contact_sheet)? {
        println!("{}", path.display());
    }
    report_shortfalls(&dataset, args)
}

/// The flags no configuration checks: the readings per object, the perturbation's bounds (named
/// by their flags before `PerturbationBounds` would name them otherwise).
fn check_flags(args: &CollectArgs) -> Result<(), UsageError> {
    if !(1..=MAX_READINGS).contains(&args.readings) {
        return Err(flag_error(
            "readings",
            args.readings,
            format!("want 1 to {MAX_READINGS} per object"),
        ));
    }
    if !(0.0..=180.0).contains(&args.perturb_deg) {
        return Err(flag_error(
            "perturb-deg",
            args.perturb_deg,
            "is outside [0, 180] degrees",
        ));
    }
    if !(0.0..=1.0).contains(&args.perturb_frac) {
        return Err(flag_error(
            "perturb-frac",
            args.perturb_frac,
            "is outside [0, 1] of the object's width",
        ));
    }
    Ok(())
}

/// The mode the flags ask for with its own flags; a flag of the other mode is refused by its name
/// (it would be ignored without a word: the run would not be the one asked for).
fn request(args: &CollectArgs) -> Result<CollectRequest, UsageError> {
    let mode = match args.mode {
        Mode::Sampler => CollectModeName::Sampler,
        Mode::Planner => CollectModeName::Planner,
    };
    let choices = ModeChoices {
        from_above: args.from_above,
        reachable_by_arm: args.reachable,
        local_probability: args.local_prob,
        max_iterations: args.max_iterations,
    };
    CollectRequest::of_mode(mode, choices).map_err(|e| {
        let flags: Vec<String> = e
            .choices
            .iter()
            .map(|&choice| format!("--{}", flag_of(choice).unwrap_or(choice)))
            .collect();
        let what = if flags.len() == 1 { "a flag" } else { "flags" };
        UsageError(format!(
            "{}: not {what} of --mode {} (the help says which mode each flag belongs to)",
            flags.join(", "),
            e.mode.name()
        ))
    })
}

/// The free object's material ([`FreeObjectArgs::body`]); the sampler refused by name, its pad
/// floating over no table.
fn free_body(args: &CollectArgs) -> Result<Option<FreeBody>, UsageError> {
    if let (Mode::Sampler, true) = (args.mode, args.free.free_object) {
        return Err(UsageError(
            "--free-object: not a flag of --mode sampler (its pad floats over no table; the arm's planner touches a free object)".into(),
        ));
    }
    args.free.body()
}

/// The flag (without its dashes) that sets a field of [`ModeChoices`] and of the planner's
/// configuration it becomes.
fn flag_of(field: &str) -> Option<&'static str> {
    match field {
        "from_above" => Some("from-above"),
        "reachable_by_arm" => Some("reachable"),
        "local_probability" => Some("local-prob"),
        "max_iterations" => Some("max-iterations"),
        "perturbation" => Some("perturb-by"),
        _ => None,
    }
}

/// A planner parameter out of range, named by the flag that set it.
fn named_by_flag(e: RangeError) -> Box<dyn std::error::Error> {
    let Some(flag) = flag_of(e.field) else {
        return e.into();
    };
    let what = match e.allowed.starts_with(['[', '(']) {
        true => format!("is outside {}", e.allowed),
        false => format!("want {}", e.allowed),
    };
    flag_error(flag, e.value, what).into()
}

/// The objects that got fewer converged readings than `--readings`: a warning with
/// `--allow-short`, else an error (the dataset is written either way).
fn report_shortfalls(dataset: &Dataset, args: &CollectArgs) -> Result<(), Box<dyn std::error::Error>> {
    let short = dataset.shortfalls(args.readings);
    if short.is_empty() {
        return Ok(());
    }
    let message = format!(
        "{} ({} written; the causes per object are in the table above)",
        describe_shortfalls(&short),
        args.out.display()
    );
    if args.allow_short {
        eprintln!("warning: {message}");
        Ok(())
    } else {
        Err(format!("{message}; pass --allow-short to accept a short dataset").into())
    }
}

/// Writes one contact sheet per object with its first `per_object` converged readings (12 a row,
/// about 48 pixels an image) beside `out`; objects without converged readings get none. Returns the
/// files written.
pub fn write_contact_sheets(
    dataset: &Dataset,
    out: &Path,
    per_object: usize,
) -> Result<Vec<PathBuf>, Box<dyn std::error::Error>> {
    let mut written = Vec::new();
    if per_object == 0 {
        return Ok(written);
    }
    let stem = out
        .file_stem()
        .ok_or_else(|| format!("--out {}: has no file name", out.display()))?
        .to_string_lossy()
        .into_owned();
    let dir = out.parent().unwrap_or_else(|| Path::new(""));
    for (object, readings) in dataset.header().objects.iter().zip(dataset.by_object()) {
        let images: Vec<_> = readings
            .iter()
            .filter(|r| r.is_converged())
            .take(per_object)
            .map(|r| r.image.clone())
            .collect();
        let Some(first) = images.first() else {
            continue;
        };
        let scale = (48 / first.cols().max(first.rows()).max(1)).max(1);
        let safe: String = object
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let path = dir.join(format!("{stem}.{safe}.png"));
        write_contact_sheet(&images, images.len().min(12), scale, &path)
            .map_err(|e| format!("contact sheet {}: {e}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

/// How the touches moved a free object: the mean and largest shift and turn per touch, and the
/// touches that tipped it over or pushed it off the table.
fn free_object_line(object: &str, report: &ExplorationReport) -> String {
    let s = MotionSummary::of(&report.object_motions);
    // Where it stood when the first touch began: a mesh not stable as the set orients it lies
    // down while it settles, before any touch.
    let rest = report.readings.first().map_or_else(
        || "it was never touched".to_string(),
        |r| {
            format!(
                "it came to rest {:.1} deg from upright",
                r.object_pose.tilt_rad().to_degrees()
            )
        },
    );
    format!(
        "free object {object}: {} touches moved it {:.3} mm and {:.3} deg each on average (at most {:.3} mm, {:.3} deg); {} tipped it over, {} pushed it off the table; {rest}",
        s.motions,
        s.shift_m.mean * 1e3,
        s.turn_rad.mean.to_degrees(),
        s.shift_m.max * 1e3,
        s.turn_rad.max.to_degrees(),
        s.tipped,
        s.off_table,
    )
}

/// How the perturbations moved the object (`act`: teleported or pushed): the mean and 95th
/// percentile of its centre's shift along the table and of its turn, and those that tipped it or
/// left it off the table. The same numbers for either act, so a push is compared with a teleport.
fn perturbation_line(object: &str, act: PerturbationAct, report: &ExplorationReport) -> String {
    let s = MotionSummary::of(&report.perturbation_motions);
    format!(
        "perturbed {object} ({}): {} moves, centre shifted {:.3} mm on average (95th percentile {:.3} mm), turned {:.3} deg (95th percentile {:.3} deg); {} tipped it over, {} left it off the table",
        act.name(),
        s.motions,
        s.centre_shift_m.mean * 1e3,
        s.centre_shift_m.p95 * 1e3,
        s.turn_rad.mean.to_degrees(),
        s.turn_rad.p95.to_degrees(),
        s.tipped,
        s.off_table,
    )
}

/// The `--perturb-by` act, named by the flag when unknown.
fn perturbation_act(args: &CollectArgs) -> Result<PerturbationAct, UsageError> {
    PerturbationAct::from_name(&args.perturb_by).ok_or_else(|| {
        flag_error(
            "perturb-by",
            &args.perturb_by,
            format!("want one of {}", PerturbationAct::NAMES.join(", ")),
        )
    })
}

/// What the planner did on the way to `object`'s readings, beyond them: iterations, expansion steps
/// stopped short (by the causes' names: who touched whom, or a physics fault) or without an
/// inverse-kinematics solution.
fn planner_line(object: &str, report: &ExplorationReport) -> String {
    let stops: Vec<String> = report
        .expansion_stops
        .iter()
        .map(|(kind, n)| format!("{} {n}", kind.name()))
        .collect();
    format!(
        "planner {object}: {} iterations, {} expansion steps stopped ({}), {} unreachable steps",
        report.iterations,
        report.expansion_stops.values().sum::<usize>(),
        if stops.is_empty() {
            "none".to_string()
        } else {
            stops.join(", ")
        },
        report.unreachable_steps
    )
}
