//! `taction demo`: the product in one run. Trains a recogniser on the 3D object set (or reuses the
//! model it cached) the way that matches what the arm feels: readings of the training sampler
//! restricted to the starts the arm can take from any heading of the object, pressed by the same
//! controllers as the arm's pad, MNTI and SIFT fused over the neighbour codebook (the README's
//! "Training that matches the arm"). Then the arm explores one object whose identity it does not
//! know, standing on the table at a heading, tilt and place it is not told, printing after every
//! converged touch the best guess, its probability and
//! the entropy of the posterior (Sec. IV-A, Appendix Eq. 16), and writes the per-touch CSV, a plot of
//! the posterior over touches, a contact sheet of the tactile images and the paper's Fig. 1: the object
//! with a patch at every converged touch, the images beside it. The model weighs where each touch
//! landed as well as what it felt (`recognize::geometric`), so it is sure after a few touches and the
//! exploration stops there: once one guess has held probability `--stop-at-confidence` (0.9) over
//! the last `--stop-held-readings` touches (two: `explore::active::ConfidenceStop`); `--no-stop`
//! spends every touch of `--touches`. Each touch is the candidate with the largest expected
//! information gain (`active_touch`), which reaches the stop sooner than the paper's blind planner
//! (`--strategy blind`).

use std::io::Write;
use std::num::NonZeroUsize;
use std::path::PathBuf;

use clap::{Args, ValueEnum};
use rand::RngExt;
use taction::active_touch::{
    ActiveRecognition, ArmData, ArmTrainingObserver, ArmTrainingRecipe, TouchPlan, TouchRun,
    explore_recognizing,
};
use taction::control::sensor_reader;
use taction::dataset::{Perturbed, Shortfall, describe_shortfalls};
use taction::experiment::Progress;
use taction::experiment::{BAND_LABEL, Figure, Panel, ReferenceLine, Series};
use taction::explore::DEFAULT_CANDIDATES;
use taction::explore::{ConfidenceStop, Probability};
use taction::explore::{Planner, PlannerConfig};
use taction::locate::GainOf;
use taction::mesh::ObjectSet;
use taction::paper::{Placement, write_exploration_png};
use taction::pose::Pose;
use taction::recognize::Belief;
use taction::recognize::{Recognizer, TrainConfig};
use taction::rng;
use taction::sim::PAD_SITE;
use taction::sim::{ObjectMotion, ObjectSpec, PerturbationBounds, Scene, SimError, StartPose};
use taction::tactile::write_contact_sheet;
use taction::tactile::{CoveringSensor, SensorConfig, arm_with_sensor};
use taction::valid::Valid;

use crate::cli::common::{
    FreeObjectArgs, ObjectSizeArg, OutputLock, PosteriorArg, SeedArg, flag_error, parse_at_least_one,
};
use crate::cli::plausible::{Carrier, build_objects};

/// The random stream that draws the unknown object and its pose, and the planner's own stream
/// (ids of [`rng::stream`], fixed so that a seed always gives the same demo).
const UNKNOWN_OBJECT_STREAM: u64 = 0xDE30;
const PLANNER_STREAM: u64 = 0xE7;

/// The seed of the training data and the model: the model is the product's, trained once and
/// cached, whatever `--seed` draws (the unknown object, its pose, the exploration).
const TRAINING_SEED: u64 = 1;

#[derive(Debug, Args)]
pub struct DemoArgs {
    /// The object set to learn (a built-in set, a folder of meshes, or mesh files).
    #[arg(long, default_value = "shapes")]
    pub objects: PathBuf,
    #[command(flatten)]
    pub object_size: ObjectSizeArg,
    /// The object to explore [default: one drawn with the seed].
    #[arg(long)]
    pub object: Option<String>,
    /// Sampler readings per object for training (starts the arm can reach).
    #[arg(long, default_value_t = 3000)]
    pub training_readings: usize,
    /// Converged touches of the unknown object at most (the stop usually ends the exploration
    /// sooner).
    #[arg(long, default_value_t = 30)]
    pub touches: usize,
    #[command(flatten)]
    pub seed: SeedArg,
    /// Output folder.
    #[arg(long, default_value = "results/demo")]
    pub out: PathBuf,
    /// How the arm chooses where to touch: `active`, the candidate touch with the largest expected
    /// information gain about the object's identity (the default: on seeds 1001-1200 right as
    /// often as blind at the default stop, after a median 7 touches against 8.5; 92.0% against
    /// 86.5% after 10), or `blind`, the paper's planner (local strategy with probability 0.5,
    /// else global).
    #[arg(long, value_enum, default_value_t = DemoStrategy::Active)]
    pub strategy: DemoStrategy,
    /// What the active strategy's expected information gain weighs: `appearance` (the default),
    /// what a touch there would show; `identity`, also where it would land on each pose hypothesis,
    /// about the object's identity with its pose marginalised; `identity-and-pose`, that about
    /// identity and pose together. Measured on the demo's seeds, the contact's gain chose touches
    /// that recognised worse (docs/measurements.md, "Touches chosen for where they land").
    #[arg(long, value_enum, default_value_t = DemoGain::Appearance)]
    pub gain: DemoGain,
    /// Stop exploring once one guess has held probability P or more over the last
    /// --stop-held-readings touches, P in (0, 1]. The posterior is calibrated on fresh
    /// explorations like the demo's, so a stop at P is right at least a fraction P of the time;
    /// 0.9 stopped the demo's seeds 1001-1200 right in 96% of runs after a median 7 touches,
    /// 0.95 in 97% after 14.5 (docs/measurements.md, "The demo stops when sure").
    #[arg(long, value_name = "P", default_value = "0.9")]
    pub stop_at_confidence: Probability,
    /// Touches the guess must hold --stop-at-confidence over before the stop fires: 1 stops at the
    /// first touch that reaches it, which is right less often than P promises (the first crossing
    /// is selected for being high).
    #[arg(long, value_name = "N", default_value_t = ConfidenceStop::DEFAULT_HELD_READINGS, value_parser = parse_at_least_one)]
    pub stop_held_readings: NonZeroUsize,
    /// Spend every touch of --touches, whatever the posterior says.
    #[arg(long, conflicts_with_all = ["stop_at_confidence", "stop_held_readings"])]
    pub no_stop: bool,
    #[command(flatten)]
    pub posterior: PosteriorArg,
    /// The unknown object on a free joint (`--free-object`, `--object-density`,
    /// `--object-friction`): the arm's presses can move it; `run.json` says how far they did.
    #[command(flatten)]
    pub free: FreeObjectArgs,
}

/// What the active strategy's gain is about (`locate::GainOf`, or appearance alone).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DemoGain {
    Identity,
    IdentityAndPose,
    Appearance,
}

impl DemoGain {
    fn contact_gain(self) -> Option<GainOf> {
        match self {
            Self::Identity => Some(GainOf::Identity),
            Self::IdentityAndPose => Some(GainOf::IdentityAndPose),
            Self::Appearance => None,
        }
    }
}

/// How the demo's arm chooses its touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DemoStrategy {
    Blind,
    Active,
}

pub fn run(args: &DemoArgs) -> Result<(), Box<dyn std::error::Error>> {
    check_args(args)?;
    let _lock = OutputLock::acquire(&args.out, "out")?;
    let sensor = SensorConfig::square(6, 6, 0.012, 0.0012);
    let set = ObjectSet::resolve(std::slice::from_ref(&args.objects), None, args.object_size.m)?;
    let objects = build_objects(&set, "demo", Carrier::Arm)?;
    // 1. The model: cached per (object set, readings, training seed, descriptors), else trained now.
    let model = load_or_train(args, &set, &objects, sensor)?.with_posterior(args.posterior.rule);
    if !model.weighs_contacts() {
        eprintln!(
            "taction demo: warning: the model weighs appearance alone (its calibration explorations gave no \
             converged reading to weigh the contacts on): expect many more touches"
        );
    }
    // 2. The unknown object, at a pose the planner is not told.
    let start = StartPose::random(set.start_heading());
    let mut unknown = place_unknown(args, &objects, model.objects(), sensor, &start)?;
    // 3. The exploration, recognising after every converged touch.
    let explored = explore_unknown(args, &objects, &model, &mut unknown, sensor)?;
    if let Some(moved) = &explored.moved {
        println!(
            "the free object's centre moved {:.2} mm and it turned {:.2} deg while the arm explored it ({})",
            moved.centre_shift_m * 1e3,
            moved.turn_rad.to_degrees(),
            moved.outcome().name()
        );
    }
    // 4. Outputs.
    write_outputs(args, &model, &unknown, &explored, sensor)
}

/// The flags `clap` cannot check.
fn check_args(args: &DemoArgs) -> Result<(), Box<dyn std::error::Error>> {
    if args.touches == 0 {
        return Err(flag_error("touches", 0, "want 1 or more").into());
    }
    if args.training_readings < 11 {
        return Err(flag_error(
            "training-readings",
            args.training_readings,
            "want 11 or more (1 of every 11 is held out for validation)",
        )
        .into());
    }
    Ok(())
}

/// The model the demo recognises with: the one cached in `--out` by an earlier run with the same
/// objects, readings and sensor, else one trained now by the library's [`ArmTrainingRecipe`].
fn load_or_train(
    args: &DemoArgs,
    set: &ObjectSet,
    objects: &[ObjectSpec],
    sensor: SensorConfig,
) -> Result<Recognizer, Box<dyn std::error::Error>> {
    let recipe = ArmTrainingRecipe {
        readings_per_object: args.training_readings,
        seed: TRAINING_SEED,
        start_heading: set.start_heading(),
    };
    let choice = recipe.descriptors()?;
    let model_path = args.out.join(format!(
        "model-{}-{}-{}-{}-reachable-knn-contacts-calibrated.json",
        set.id(),
        args.training_readings,
        TRAINING_SEED,
        choice.name()
    ));
    if let Ok(model) = Recognizer::load(&model_path)
        && taction::recognize::check_same_sensor(model.sensor(), &sensor).is_ok()
    {
        println!("using the model trained before: {}", model_path.display());
        return Ok(model);
    }
    let model = train_model(&recipe, set, objects, sensor)?;
    model.save(&model_path)?;
    Ok(model)
}

/// Trains the library's [`ArmTrainingRecipe`], printing its steps: a progress bar per
/// collection, its shortfalls and the posterior's calibration.
fn train_model(
    recipe: &ArmTrainingRecipe,
    set: &ObjectSet,
    objects: &[ObjectSpec],
    sensor: SensorConfig,
) -> Result<Recognizer, Box<dyn std::error::Error>> {
    let mut printer = RecipePrinter {
        descriptors: recipe.descriptors()?.name(),
        progress: None,
    };
    let trained = recipe.train(&set.id(), objects, sensor, 0, &mut printer)?;
    let t = trained.model.tempering();
    if trained.calibrated_on_the_arm() {
        println!("posterior calibrated on the arm's explorations: {t}");
    } else {
        eprintln!(
            "taction demo: warning: calibration: the arm's explorations gave no converged reading, so nothing calibrated \
             the posterior ({t}): it counts the arm's correlated touches as independent evidence"
        );
    }
    Ok(trained.model)
}

/// Prints what the recipe does, as the demo always has.
struct RecipePrinter {
    /// The fused descriptors' name.
    descriptors: String,
    /// The bar of the collection under way.
    progress: Option<Progress>,
}

impl ArmTrainingObserver for RecipePrinter {
    fn collecting(&mut self, data: ArmData, objects: &[ObjectSpec], readings: usize) {
        let names = objects
            .iter()
            .map(|o| o.name.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        let bar = match data {
            ArmData::Training => {
                println!(
                    "training: {readings} sampler readings of each of {} objects from starts the arm can reach ({names})",
                    objects.len()
                );
                "training data"
            }
            ArmData::Calibration => {
                println!(
                    "calibration: the arm exploring each object blind, {readings} readings in explorations of 10 from random starts"
                );
                "calibration data"
            }
        };
        self.progress = Some(Progress::collection(bar, objects.len(), readings));
    }

    fn converged(&self, _data: ArmData) {
        if let Some(progress) = &self.progress {
            progress.inc();
        }
    }

    fn collected(&mut self, data: ArmData, converged: usize, short: &[Shortfall]) {
        if let Some(progress) = self.progress.take() {
            progress.finish(converged);
        }
        if !short.is_empty() {
            let what = match data {
                ArmData::Training => "training",
                ArmData::Calibration => "calibration",
            };
            eprintln!("warning: {what}: {}", describe_shortfalls(short));
        }
    }

    fn fitting(&mut self, config: &TrainConfig, features: usize) {
        println!(
            "training {}: {features} training readings; trying k = {:?}",
            self.descriptors, config.ks
        );
    }
}

/// The object to explore and its scene.
struct Unknown {
    /// Its index in the object set.
    index: usize,
    spec: ObjectSpec,
    scene: Scene,
    /// Where it stood before the first touch (a free object: after it settled).
    start: Pose,
}

/// Draws the unknown object (or takes `--object`) and places it on the table at `start`, a random
/// start (`Scene::place_at_start`: a heading about the vertical, any for the 3D objects and within
/// 10 degrees for the raised letters, whose heading is part of their identity, then the
/// perturbation of Sec. V-B4, a tilt of up to 10 degrees about a random axis, a shift of up to 10%
/// of the width), so that it stands as objects do, in a pose the planner is not told. The object
/// and its start come from one stream, drawn as they always were: a seed gives the demo of the 3D
/// objects it gave before the start was the library's.
fn place_unknown(
    args: &DemoArgs,
    objects: &[ObjectSpec],
    names: &[String],
    sensor: SensorConfig,
    start: &StartPose,
) -> Result<Unknown, Box<dyn std::error::Error>> {
    let mut r = rng::stream(args.seed.seed, UNKNOWN_OBJECT_STREAM);
    let index = match &args.object {
        Some(name) => objects
            .iter()
            .position(|o| &o.name == name)
            .ok_or_else(|| format!("--object: '{name}' is not in the set ({})", names.join(", ")))?,
        None => r.random_range(0..objects.len()),
    };
    let spec = objects[index].mounted(args.free.body()?);
    let mut scene = arm_with_sensor(spec.clone(), &Valid::new(sensor)?).build()?;
    scene.place_at_start(start, &mut r)?;
    let start = scene.object_pose().ok_or(SimError::NoObject)?;
    println!(
        "exploring an unknown object with the arm (it is '{}'; the planner is not told)",
        spec.name
    );
    Ok(Unknown {
        index,
        spec,
        scene,
        start,
    })
}

/// What the exploration felt and believed.
struct Explored {
    run: TouchRun,
    /// `touches.csv`.
    csv: String,
    /// `(touch, p(true object))` after every touch.
    p_true: Vec<(f64, f64)>,
    /// The belief after the last touch.
    belief: Belief,
    /// How far the exploration moved a free object from where it settled; `None` for the
    /// paper's mocap object, which does not move.
    moved: Option<ObjectMotion>,
}

/// The arm explores `unknown` with the planner (blind or active), the posterior updated and
/// printed after every converged touch.
fn explore_unknown(
    args: &DemoArgs,
    objects: &[ObjectSpec],
    model: &Recognizer,
    unknown: &mut Unknown,
    sensor: SensorConfig,
) -> Result<Explored, Box<dyn std::error::Error>> {
    let planner_config = arm_planner_config(objects)?;
    let reader = sensor_reader(CoveringSensor::on_site(unknown.scene.model(), PAD_SITE)?);
    let mut planner = Planner::new(
        &unknown.scene,
        planner_config,
        taction::explore::TouchSetup {
            sensor,
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
        },
        rng::stream(args.seed.seed, PLANNER_STREAM),
        reader,
    )?;
    let mut recognition = ActiveRecognition::of(model, planner_config.grid_cell_m, Perturbed::FIXED)?
        .with_contact_gain(args.gain.contact_gain());
    let mut shown = TouchTable::new(model.objects(), &unknown.spec.name, unknown.index);
    let run = explore_recognizing(
        &mut planner,
        &mut unknown.scene,
        &unknown.spec.name,
        &mut recognition,
        TouchPlan {
            budget: args.touches,
            active_candidates: (args.strategy == DemoStrategy::Active).then_some(DEFAULT_CANDIDATES),
            stop_at_confidence: confidence_stop(args),
        },
        &mut |touch| shown.add(&touch.belief),
    )?;
    if run.touches.is_empty() {
        let size = args
            .object_size
            .m
            .map_or_else(String::new, |m| format!(" --object-size-m {m}"));
        return Err(format!(
            "the planner found no converged reading of '{}' after {} attempts; \
             `taction collect --objects {}{size} --mode planner` prints why its attempts fail, per object; \
             try another --seed or --object",
            unknown.spec.name,
            run.attempts,
            args.objects.display()
        )
        .into());
    }
    std::io::stdout().flush()?;
    let moved = match unknown.scene.object_is_free() {
        true => Some(unknown.scene.object_motion_from(&unknown.start)?),
        false => None,
    };
    Ok(Explored {
        run,
        csv: shown.csv,
        p_true: shown.p_true,
        belief: recognition.belief(),
        moved,
    })
}

/// The confidence stop the flags ask for: none with `--no-stop`.
fn confidence_stop(args: &DemoArgs) -> Option<ConfidenceStop> {
    (!args.no_stop).then(|| ConfidenceStop::new(args.stop_at_confidence).held_over(args.stop_held_readings))
}

/// The paper's planner settings, fitted to the objects: the local strategy with probability 0.5,
/// the setting the recipe was measured at, for either strategy (the active scorer picks among
/// candidates half local, half global).
fn arm_planner_config(objects: &[ObjectSpec]) -> Result<Valid<PlannerConfig>, Box<dyn std::error::Error>> {
    Ok(Valid::new(PlannerConfig::exploring(objects, 0.5))?)
}

/// The belief after every touch, printed as a table and kept as `touches.csv` and the series of
/// p(true object).
struct TouchTable<'a> {
    names: &'a [String],
    truth: &'a str,
    truth_index: usize,
    csv: String,
    p_true: Vec<(f64, f64)>,
}

impl<'a> TouchTable<'a> {
    /// Prints the table's header.
    fn new(names: &'a [String], truth: &'a str, truth_index: usize) -> Self {
        println!(
            "{:>5}  {:<12} {:>8} {:>8} {:>9}",
            "touch", "best guess", "p(guess)", "p(true)", "entropy"
        );
        Self {
            names,
            truth,
            truth_index,
            csv: String::from("touch,object_true,object_guess,p_guess,p_true,entropy_nats\n"),
            p_true: Vec::new(),
        }
    }

    fn add(&mut self, belief: &Belief) {
        let guess = belief.guess();
        let p = belief.probabilities();
        let n = belief.readings;
        let index = self.truth_index;
        println!(
            "{n:>5}  {:<12} {:>8.3} {:>8.3} {:>9.3}",
            self.names[guess],
            p[guess],
            p[index],
            belief.entropy_nats()
        );
        self.csv.push_str(&format!(
            "{n},{},{},{},{},{}\n",
            self.truth,
            self.names[guess],
            p[guess],
            p[index],
            belief.entropy_nats()
        ));
        self.p_true.push((n as f64, p[index]));
    }
}

/// Writes `touches.csv`, the posterior plot, the contact sheet and Fig. 1, and prints the outcome.
fn write_outputs(
    args: &DemoArgs,
    model: &Recognizer,
    unknown: &Unknown,
    explored: &Explored,
    sensor: SensorConfig,
) -> Result<(), Box<dyn std::error::Error>> {
    let names = model.objects();
    let run = &explored.run;
    let images: Vec<_> = run.touches.iter().map(|t| t.reading.image.clone()).collect();
    taction::atomic::write_atomic(&args.out.join("touches.csv"), explored.csv.as_bytes())?;
    let figure = posterior_figure(
        &unknown.spec.name,
        explored.p_true.clone(),
        images.len(),
        names.len(),
    );
    figure.write_svg(&args.out.join("posterior.svg"))?;
    figure.write_png(&args.out.join("posterior.png"))?;
    write_contact_sheet(&images, 10, 12, &args.out.join("contact_sheet.png"))?;
    let placements = Placement::from_readings(run.touches.iter().map(|t| &t.reading));
    let shown_pose = unknown.scene.object_pose().unwrap_or(unknown.spec.pose);
    write_exploration_png(
        &args.out.join("exploration.png"),
        &unknown.spec.mesh,
        &shown_pose,
        &placements,
        &sensor,
    )?;
    let ending = if run.stopped_confident {
        "stopped: confident".to_string()
    } else if images.len() >= args.touches {
        "the touch budget spent".to_string()
    } else {
        format!(
            "the planner ran out of iterations, {} of {} touches made",
            images.len(),
            args.touches
        )
    };
    let guess = explored.belief.guess();
    write_run_record(
        args,
        model,
        unknown,
        &ending,
        (images.len(), run.attempts),
        explored,
    )?;
    println!(
        "after {} touches ({} attempts; {ending}): '{}' with p = {:.3} (true: '{}'); wrote {}/{{touches.csv, posterior.svg, posterior.png, contact_sheet.png, exploration.png, run.json}}",
        images.len(),
        run.attempts,
        names[guess],
        explored.belief.probabilities()[guess],
        unknown.spec.name,
        args.out.display()
    );
    Ok(())
}

/// What the active strategy's gain was about: the flag's choice, or `appearance` for a model that
/// does not weigh contacts.
fn gain_name(args: &DemoArgs, model: &Recognizer) -> String {
    let gain = if model.weighs_contacts() {
        args.gain
    } else {
        DemoGain::Appearance
    };
    gain.to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string())
}

/// `run.json`: what the run used and how it ended, so that the files beside it say which run made
/// them (each run into the folder overwrites the last one's).
fn write_run_record(
    args: &DemoArgs,
    model: &Recognizer,
    unknown: &Unknown,
    ending: &str,
    (touches, attempts): (usize, usize),
    explored: &Explored,
) -> Result<(), Box<dyn std::error::Error>> {
    let belief = &explored.belief;
    let names = model.objects();
    let pose = unknown.scene.object_pose().unwrap_or(unknown.spec.pose);
    let guess = belief.guess();
    let stop = confidence_stop(args);
    let record = serde_json::json!({
        "objects": args.objects.display().to_string(),
        "object_size_m": args.object_size.m,
        "seed": args.seed.seed,
        "strategy": args.strategy.to_possible_value().map(|v| v.get_name().to_string()),
        "gain": (args.strategy == DemoStrategy::Active).then(|| gain_name(args, model)),
        "stop_at_confidence": stop.map(|s| f64::from(s.threshold())),
        "stop_held_readings": stop.map(|s| s.held_readings().get()),
        "model_evidence": if model.weighs_contacts() { "appearance+contacts" } else { "appearance" },
        "posterior": args.posterior.rule.name(),
        "training_readings": args.training_readings,
        "object": unknown.spec.name,
        "object_position_m": pose.position_m.to_array(),
        "object_quaternion_wxyz": [pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z],
        "touches_asked": args.touches,
        "touches": touches,
        "attempts": attempts,
        "ending": ending,
        "guess": names[guess],
        "p_guess": belief.probabilities()[guess],
        "p_true": belief.probabilities()[unknown.index],
        "right": guess == unknown.index,
        "free_object": free_object_record(unknown, explored.moved.as_ref()),
    });
    let text = serde_json::to_string_pretty(&record)? + "\n";
    taction::atomic::write_atomic(&args.out.join("run.json"), text.as_bytes())?;
    Ok(())
}

/// What `run.json` says of a free object: its material and how far the exploration `moved` it
/// from where it settled; `null` for the paper's mocap object, which does not move.
fn free_object_record(unknown: &Unknown, moved: Option<&ObjectMotion>) -> serde_json::Value {
    let Some(moved) = moved else {
        return serde_json::Value::Null;
    };
    let body = unknown.spec.free_body;
    serde_json::json!({
        "density_kg_m3": body.density_kg_m3(),
        "friction": body.friction(),
        "centre_shift_mm": moved.centre_shift_m * 1e3,
        "turn_deg": moved.turn_rad.to_degrees(),
        "tilt_deg": moved.tilt_rad.to_degrees(),
        "outcome": moved.outcome().name(),
    })
}

/// The posterior of the true object over `touches` touches, chance at 1 / `objects`.
fn posterior_figure(truth: &str, p_true: Vec<(f64, f64)>, touches: usize, objects: usize) -> Figure {
    Figure {
        title: format!("Posterior of the true object ({truth}) over touches"),
        panels: vec![Panel {
            title: String::new(),
            x_label: "touches (converged readings)".into(),
            y_label: "p(true object)".into(),
            x_range: (1.0, touches.max(2) as f64),
            y_range: (0.0, 1.0),
            series: vec![Series {
                label: truth.to_string(),
                points: p_true,
                band: Vec::new(),
            }],
            markers: true,
            legend: true,
            integer_x: true,
            reference: Some(ReferenceLine {
                y: 1.0 / objects as f64,
                label: format!("chance (1/{objects})"),
            }),
            band_label: BAND_LABEL,
        }],
    }
}
