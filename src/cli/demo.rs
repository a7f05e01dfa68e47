//! `taction demo`: the product in one run. Trains a recogniser on the 3D object set (or reuses the
//! model it cached) the way that matches what the arm feels: readings of the training sampler
//! restricted to the starts the arm can take from any heading of the object, pressed by the same
//! controllers as the arm's pad, MNTI and SIFT fused over the neighbour codebook (the README's
//! "Training that matches the arm"). Then the arm explores one object whose identity it does not
//! know, standing on the table at a heading, tilt and place it is not told, printing after every
//! converged touch the best guess, its probability and
//! the entropy of the posterior (Sec. IV-A, Appendix Eq. 16), and writes the per-touch CSV, a plot of
//! the posterior over touches, a contact sheet of the tactile images and the paper's Fig. 1: the object
//! with a patch at every converged touch, the images beside it. `--strategy active` chooses
//! each touch by expected information gain (`active_touch`); `--stop-at-confidence P` ends the
//! exploration once the best guess has probability P.

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use rand::RngExt;
use taction::active_touch::{ActiveRecognition, TouchPlan, explore_recognizing};
use taction::dataset::describe_shortfalls;
use taction::describe::DescriptorKind;
use taction::experiment::figure::{Figure, Panel, ReferenceLine, Series};
use taction::experiment::progress::CollectionProgress;
use taction::explore::Probability;
use taction::explore::SamplerConfig;
use taction::explore::active::DEFAULT_CANDIDATES;
use taction::explore::collect::{CollectMode, CollectPlan, sensor_reader};
use taction::explore::{Planner, PlannerConfig};
use taction::mesh::ObjectSet;
use taction::paper::figure1::{Placement, write_exploration_png};
use taction::recognize::selection::{TrainConfig, codebook_sizes};
use taction::recognize::{CodebookKind, DescriptorChoice, FusedModel, Recognizer};
use taction::rng;
use taction::sim::arm::PAD_SITE;
use taction::sim::{Perturbation, PerturbationBounds, SceneBuilder};
use taction::tactile::image::write_contact_sheet;
use taction::tactile::{CoveringSensor, SensorConfig, add_sensor};
use taction::valid::Valid;

use crate::cli::common::{ObjectSizeArg, OutputLock, SeedArg, flag_error};
use crate::cli::plausible::{Carrier, build_objects};

/// The random stream that draws the unknown object and its pose, and the planner's own stream
/// (ids of [`rng::stream`], fixed so that a seed always gives the same demo).
const UNKNOWN_OBJECT_STREAM: u64 = 0xDE30;
const PLANNER_STREAM: u64 = 0xE7;

/// The seed of the training data and the model: the model is the product's, trained once and
/// cached, whatever `--seed` draws (the unknown object, its pose, the exploration).
const TRAINING_SEED: u64 = 1;

/// The demo's descriptors, fused: fusing SIFT's gradient orientations with MNTI's moments gained
/// on the arm's own touches as on sampler data ("Training that matches the arm" in docs/measurements.md has
/// the measurements).
const DEMO_DESCRIPTORS: [DescriptorKind; 2] = [DescriptorKind::Mnti, DescriptorKind::Sift];

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
    /// Converged touches of the unknown object.
    #[arg(long, default_value_t = 30)]
    pub touches: usize,
    #[command(flatten)]
    pub seed: SeedArg,
    /// Output folder.
    #[arg(long, default_value = "results/demo")]
    pub out: PathBuf,
    /// How the arm chooses where to touch: `blind`, the paper's planner (local strategy with
    /// probability 0.5, else global: the setting the recipe was measured at), or `active`, the
    /// candidate touch with the largest expected information gain about the object's identity.
    #[arg(long, value_enum, default_value_t = DemoStrategy::Blind)]
    pub strategy: DemoStrategy,
    /// Stop exploring once the best guess's probability reaches P, a probability in (0, 1]
    /// (e.g. 0.95) [default: spend all --touches].
    #[arg(long, value_name = "P")]
    pub stop_at_confidence: Option<Probability>,
}

/// How the demo's arm chooses its touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DemoStrategy {
    Blind,
    Active,
}

pub fn run(args: &DemoArgs) -> Result<(), Box<dyn std::error::Error>> {
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
    let _lock = OutputLock::acquire(&args.out, "out")?;
    let sensor = SensorConfig::square(6, 6, 0.012, 0.0012);
    let set = ObjectSet::resolve(std::slice::from_ref(&args.objects), None, args.object_size.m)?;
    let objects = build_objects(&set, "demo", Carrier::Arm)?;
    let choice = DescriptorChoice::fused(DEMO_DESCRIPTORS.to_vec())?;
    let descriptors: Vec<_> = choice.kinds().iter().map(|k| k.build()).collect();

    // 1. The model: cached per (object set, readings, training seed, descriptors), else trained now.
    let model_path = args.out.join(format!(
        "model-{}-{}-{}-{}-reachable-knn.json",
        set.id(),
        args.training_readings,
        TRAINING_SEED,
        choice.name()
    ));
    let model = match Recognizer::load(&model_path) {
        Ok(Recognizer::Fused(model)) if model.fused.iter().all(|m| m.check_sensor(&sensor).is_ok()) => {
            println!("using the model trained before: {}", model_path.display());
            model
        }
        _ => {
            println!(
                "training: {} sampler readings of each of {} objects from starts the arm can reach ({})",
                args.training_readings,
                objects.len(),
                objects
                    .iter()
                    .map(|o| o.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            let plan = CollectPlan {
                mode: CollectMode::Sampler(Valid::new(SamplerConfig {
                    reachable_by_arm: true,
                    ..SamplerConfig::default()
                })?),
                sensor,
                control: Valid::default(),
                perturbation: PerturbationBounds::NONE,
                readings_per_object: args.training_readings,
                seed: TRAINING_SEED,
            };
            let progress = CollectionProgress::new("training data", objects.len(), args.training_readings);
            let dataset = plan.collect_dataset(&set.id(), &objects, 0, &|| progress.converged())?;
            progress.finish(dataset.converged_only().len());
            let short = dataset.shortfalls(args.training_readings);
            if !short.is_empty() {
                eprintln!("warning: training: {}", describe_shortfalls(&short));
            }
            let codebook = CodebookKind::Knn;
            let mut config = TrainConfig {
                codebook,
                restarts: 1,
                seed: TRAINING_SEED,
                variance_kept: codebook.default_variance_kept(),
                ..TrainConfig::default()
            };
            // The hold-out keeps about `holdout` of each object's readings for validation; one
            // feature per converged reading under the descriptor that gives the fewest.
            let converged = dataset.converged_only().len();
            let training_features = (converged as f64 * (1.0 - config.holdout)).floor() as usize;
            config.ks = codebook_sizes(config.codebook, dataset.header().objects.len(), training_features);
            println!(
                "training {}: {training_features} training readings; trying k = {:?}",
                choice.name(),
                config.ks
            );
            let model = FusedModel::fit(&dataset, None, &choice, config, &mut |_| {})?;
            model.save(&model_path)?;
            model
        }
    };
    let names = model.objects().to_vec();

    // 2. The unknown object, at a pose the planner is not told.
    let mut r = rng::stream(args.seed.seed, UNKNOWN_OBJECT_STREAM);
    let index = match &args.object {
        Some(name) => objects
            .iter()
            .position(|o| &o.name == name)
            .ok_or_else(|| format!("--object: '{name}' is not in the set ({})", names.join(", ")))?,
        None => r.random_range(0..objects.len()),
    };
    let unknown = objects[index].clone();
    let mut scene = add_sensor(
        SceneBuilder::with_arm_and_table().object(unknown.clone()),
        &Valid::new(sensor)?,
        "covering",
        PAD_SITE,
    )
    .build()?;
    // Any heading about the vertical, then the perturbation of Sec. V-B4 (a tilt of up to 10
    // degrees about a random axis, a shift of up to 10% of the width): the object stands on the
    // table as objects do, in a pose the planner is not told.
    let width = scene.object_width_m().unwrap_or(0.1);
    let heading = Perturbation {
        axis: glam::DVec3::Z,
        angle_rad: r.random_range(0.0..std::f64::consts::TAU),
        translation_m: glam::DVec3::ZERO,
    };
    scene.perturb_object(&heading)?;
    let shuffle = PerturbationBounds::new(10.0, 0.1)?.draw(width, &mut r);
    scene.perturb_object(&shuffle)?;
    println!(
        "exploring an unknown object with the arm (it is '{}'; the planner is not told)",
        unknown.name
    );

    let reader = sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE)?);
    let planner_config = Valid::new(
        PlannerConfig {
            local_probability: match args.strategy {
                DemoStrategy::Blind => 0.5,
                // Candidates half local, half global: the scorer picks among both kinds.
                DemoStrategy::Active => 0.5,
            },
            ..PlannerConfig::default()
        }
        .fitted_to(&objects),
    )?;
    let mut planner = Planner::new(
        &scene,
        planner_config,
        taction::explore::TouchSetup {
            sensor,
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
        },
        rng::stream(args.seed.seed, PLANNER_STREAM),
        reader,
    )?;
    let mut recognition = ActiveRecognition::fused(
        &model,
        descriptors.iter().map(|d| d.as_ref()).collect(),
        planner_config.grid_cell_m,
    )?;
    let mut csv = String::from("touch,object_true,object_guess,p_guess,p_true,entropy_nats\n");
    let mut p_true_series = Vec::new();
    println!(
        "{:>5}  {:<12} {:>8} {:>8} {:>9}",
        "touch", "best guess", "p(guess)", "p(true)", "entropy"
    );
    let run = explore_recognizing(
        &mut planner,
        &mut scene,
        &unknown.name,
        &mut recognition,
        TouchPlan {
            budget: args.touches,
            active_candidates: (args.strategy == DemoStrategy::Active).then_some(DEFAULT_CANDIDATES),
            stop_at_confidence: args.stop_at_confidence,
        },
        &mut |touch| {
            let belief = &touch.belief;
            let guess = belief.guess();
            let p = belief.probabilities();
            let n = belief.readings;
            println!(
                "{n:>5}  {:<12} {:>8.3} {:>8.3} {:>9.3}",
                names[guess],
                p[guess],
                p[index],
                belief.entropy_nats()
            );
            csv.push_str(&format!(
                "{n},{},{},{},{},{}\n",
                unknown.name,
                names[guess],
                p[guess],
                p[index],
                belief.entropy_nats()
            ));
            p_true_series.push((n as f64, p[index]));
        },
    )?;
    let attempts = run.attempts;
    if run.touches.is_empty() {
        return Err(format!(
            "the planner found no converged reading of '{}' after {attempts} attempts; \
             `taction collect --objects {} --mode planner` prints why its attempts fail, per object; \
             try another --seed or --object",
            unknown.name,
            args.objects.display()
        )
        .into());
    }
    let images: Vec<_> = run.touches.iter().map(|t| t.reading.image.clone()).collect();
    std::io::stdout().flush()?;

    // 3. Outputs.
    let csv_path = args.out.join("touches.csv");
    taction::atomic::write_atomic(&csv_path, csv.as_bytes())?;
    let figure = Figure {
        title: format!("Posterior of the true object ({}) over touches", unknown.name),
        panels: vec![Panel {
            title: String::new(),
            x_label: "touches (converged readings)".into(),
            y_label: "p(true object)".into(),
            x_range: (1.0, images.len().max(2) as f64),
            y_range: (0.0, 1.0),
            series: vec![Series {
                label: unknown.name.clone(),
                points: p_true_series,
                band: Vec::new(),
            }],
            markers: true,
            legend: true,
            integer_x: true,
            reference: Some(ReferenceLine {
                y: 1.0 / names.len() as f64,
                label: format!("chance (1/{})", names.len()),
            }),
        }],
    };
    figure.write_svg(&args.out.join("posterior.svg"))?;
    figure.write_png(&args.out.join("posterior.png"))?;
    write_contact_sheet(&images, 10, 12, &args.out.join("contact_sheet.png"))?;
    let placements = Placement::from_readings(run.touches.iter().map(|t| &t.reading));
    let shown_pose = scene.object_pose().unwrap_or(unknown.pose);
    write_exploration_png(
        &args.out.join("exploration.png"),
        &unknown.mesh,
        &shown_pose,
        &placements,
        &sensor,
    )?;
    let belief = recognition.belief();
    let ending = if run.stopped_confident {
        "stopped: confident"
    } else {
        "touch budget spent or planner out of iterations"
    };
    println!(
        "after {} touches ({} attempts; {ending}): '{}' with p = {:.3} (true: '{}'); wrote {}/{{touches.csv, posterior.svg, posterior.png, contact_sheet.png, exploration.png}}",
        images.len(),
        attempts,
        names[belief.guess()],
        belief.probabilities()[belief.guess()],
        unknown.name,
        args.out.display()
    );
    Ok(())
}
