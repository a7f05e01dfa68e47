//! Readings per second of the two ways of collecting readings (Sec. III-A and V-A3), each against a
//! baseline measured in the same run, on the chess pawn (12 cm diagonal) with the 6x6 sensor:
//!
//! - `sensor/bare_reading`: one free-floating reading (place the pad, `mj_forward`, copy out of
//!   `sensordata`), the cost floor of any reading;
//! - `sampler/6x6`: converged readings of the training sampler (free-floating pad, Approach, Press,
//!   Orient), reported per reading and as a ratio to the bare reading rate;
//! - `planner/kinematic`: converged readings of the planner with the arm, MuJoCo-checked kinematic
//!   edges (the default); the summary also times the same planner stepping the position servos
//!   through MuJoCo's dynamics (`Execution::Servo`, the previous behaviour, too slow for criterion's
//!   ten samples) and reports the ratio kinematic / servo, the speed-up;
//! - `planner/shapes`: the planner over every object of the `shapes` set (the ten CGAL meshes, which
//!   `cargo xtask setup` fetches, and the two chess pieces), `SHAPES_READINGS` converged readings of
//!   each, one thread, the workspace fitted to the set as `taction collect` does; the summary
//!   reports converged readings per second per core and the fraction of attempts that converge,
//!   per object and over the set;
//! - `planner/shapes_screened` and `planner/shapes_unscreened`: the planner over every object of
//!   the set in scenes compiled once, kinematic motions clearing their samples with the contact
//!   screen (the default, `sim/contact_screen.rs`) and with `mj_collision` at every sample (the
//!   baseline); the summary reports the ratio, the same readings checked to be made;
//! - `active/score_12_candidates`: the active strategy's extra work per planner iteration, the
//!   expected-information-gain scores of 12 candidate targets (`active_touch`) for a model of
//!   12 objects and 50 clusters after 30 readings; the summary reports it per iteration against a
//!   plain kinematic planner iteration on the pawn (total time / iterations of `planner/kinematic`
//!   runs), the baseline;
//! - `active/contact_gain_12_candidates`: what `--gain identity` adds to it, the contact's gain of
//!   the same 12 candidates (`locate::predict`) over the shapes' 12 surfaces at 36 pose hypotheses
//!   each, after three contacts; criterion reports it beside `active/score_12_candidates`.
//!
//! Scenes are compiled once per configuration, outside the timed loops (a collection run compiles one
//! per object). After criterion's own report a summary prints readings/s and the ratios, measured
//! with plain timers on the same routines. Quick: well under two minutes in release.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group};
use glam::DVec3;
use rand::RngExt;
use taction::active_touch::InformationGain;
use taction::control::{FreePad, sensor_reader};
use taction::dataset::Perturbed;
use taction::explore::TouchScorer;
use taction::explore::{CollectMode, CollectPlan};
use taction::explore::{ExplorationReport, Planner, PlannerConfig};
use taction::locate::{Contact, GainOf, GeometryModel, GeometryPosterior, Touch};
use taction::mesh::{BuildOptions, ObjectSet, TriMesh};
use taction::pose::{MaxHeading, PadPose};
use taction::recognize::PseudoCount;
use taction::recognize::pipeline::{ClusterHistogram, ObjectModels};
use taction::sim::{Execution, PAD_SITE};
use taction::sim::{ObjectSpec, PerturbationBounds, Scene, SceneBuilder, StartPose};
use taction::tactile::SensorConfig;
use taction::tactile::{CoveringSensor, add_sensor};
use taction::valid::Valid;

/// Converged readings per timed run.
const SAMPLER_READINGS: usize = 20;
const PLANNER_READINGS: usize = 10;
const SERVO_READINGS: usize = 2;
const SHAPES_READINGS: usize = 5;

fn sensor() -> SensorConfig {
    SensorConfig::square(6, 6, 0.012, 0.0012)
}

fn pawn() -> ObjectSpec {
    let built = ObjectSet::chess()
        .build_object("pawn", &BuildOptions::default())
        .expect("the chess pawn is generated, no download");
    ObjectSpec::new("pawn", built.mesh)
}

fn arm_scene(object: &ObjectSpec) -> Scene {
    let builder = SceneBuilder::with_arm_and_table().object(object.clone());
    add_sensor(builder, &Valid::new(sensor()).expect("a valid sensor"), PAD_SITE)
        .build()
        .expect("arm scene compiles")
}

/// A pad 0.3 t into the side of the pawn's base, level: a reading with contact.
fn touching_pose() -> PadPose {
    let pawn = pawn();
    let (lo, hi) = pawn.mesh.bounds().expect("pawn has vertices");
    let z = lo.z + 0.1 * (hi.z - lo.z);
    PadPose::new(DVec3::new(lo.x + 0.3 * 0.0012, 0.0, z), DVec3::X, DVec3::Z).expect("unit frame")
}

fn bare_reading(free: &mut FreePad, pose: &PadPose) -> f64 {
    free.read_at(pose).expect("reading").mean()
}

fn sampler_run(free: &mut FreePad, seed: u64) -> ExplorationReport {
    let rng = taction::rng::rng(seed);
    taction::explore::TrainingSampler::new(
        Valid::default(),
        taction::explore::TouchSetup {
            sensor: sensor(),
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
        },
        rng,
    )
    .sample(free, "pawn", SAMPLER_READINGS)
    .expect("sampler run")
}

fn planner_run(scene: &mut Scene, execution: Execution, readings: usize, seed: u64) -> ExplorationReport {
    let config = PlannerConfig {
        execution,
        ..PlannerConfig::default()
    };
    explore_in(scene, config, "pawn", readings, seed)
}

/// `readings` converged readings of the planner configured by `config` on the object `name` of
/// `scene`, from the arm's home configuration and back to it.
fn explore_in(
    scene: &mut Scene,
    config: PlannerConfig,
    name: &str,
    readings: usize,
    seed: u64,
) -> ExplorationReport {
    let home = scene.arm().expect("arm").q(scene.data());
    let arm = scene.arm().expect("arm").clone();
    arm.teleport(scene, &home);
    let reader = sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE).expect("sensor"));
    let mut planner = Planner::new(
        scene,
        Valid::new(config).expect("a valid planner config"),
        taction::explore::TouchSetup {
            sensor: sensor(),
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
        },
        taction::rng::rng(seed),
        reader,
    )
    .expect("planner");
    let report = planner.explore(scene, name, readings).expect("planner run");
    arm.teleport(scene, &home);
    report
}

const SCORED_OBJECTS: usize = 12;
const SCORED_CLUSTERS: usize = 50;
const SCORED_READINGS: usize = 30;
const CANDIDATES: usize = 12;

/// Object models of `SCORED_OBJECTS` objects over `SCORED_CLUSTERS` clusters (random histograms).
fn scored_models() -> ObjectModels {
    let mut rng = taction::rng::rng(5);
    let histograms: Vec<ClusterHistogram> = (0..SCORED_OBJECTS)
        .map(|_| {
            let mut h = ClusterHistogram::new(SCORED_CLUSTERS);
            for _ in 0..200 {
                let mut m = vec![0.0; SCORED_CLUSTERS];
                m[rng.random_range(0..SCORED_CLUSTERS)] = 1.0;
                h.add(&m);
            }
            h
        })
        .collect();
    let names = (0..SCORED_OBJECTS).map(|o| format!("object{o}")).collect();
    ObjectModels::fit(names, &histograms, PseudoCount::LAPLACE).expect("models")
}

/// The scorer after `SCORED_READINGS` readings spread over the pawn's neighbourhood, and
/// `CANDIDATES` targets around them.
fn scorer_and_candidates(models: &ObjectModels) -> (InformationGain<'_>, Vec<DVec3>) {
    let mut rng = taction::rng::rng(6);
    let mut point = || {
        DVec3::new(
            rng.random_range(-0.06..0.06),
            rng.random_range(-0.06..0.06),
            rng.random_range(0.02..0.14),
        )
    };
    let mut gain = InformationGain::new(models, 0.03);
    let objects = models.objects().len();
    let mut posterior = vec![1.0 / objects as f64; objects];
    for r in 0..SCORED_READINGS {
        let mut h = ClusterHistogram::new(models.clusters());
        let mut m = vec![0.0; models.clusters()];
        m[(r * 7) % models.clusters()] = 1.0;
        h.add(&m);
        posterior[r % objects] += 0.1;
        let total: f64 = posterior.iter().sum();
        let normalised: Vec<f64> = posterior.iter().map(|p| p / total).collect();
        gain.record(Some(point()), &h, &normalised);
    }
    let candidates = (0..CANDIDATES).map(|_| point()).collect();
    (gain, candidates)
}

/// The weight of a contact's log-likelihood in the demo's posterior after a few touches (its fused
/// weight 0.15 times the tempering's `w(4)`, 1.35).
const CONTACT_WEIGHT: f64 = 0.2;

/// The shapes' surfaces, every object followed at the default 36 headings.
fn shapes_geometry(objects: &[ObjectSpec]) -> GeometryModel {
    let meshes: Vec<(String, &TriMesh)> = objects.iter().map(|o| (o.name.clone(), &o.mesh)).collect();
    let names: Vec<String> = objects.iter().map(|o| o.name.clone()).collect();
    GeometryModel::of_named(&names, &meshes, MaxHeading::ANY).expect("the shapes' surfaces")
}

/// The geometric posterior after three contacts on the first object's surface, and a belief
/// leaning toward it: the contact gain's work in the middle of an exploration.
fn geometry_after_contacts(geometry: &GeometryModel) -> (GeometryPosterior<'_>, Vec<f64>) {
    let mut posterior = geometry.posterior(Perturbed::FIXED);
    let surface = &geometry.surfaces()[0];
    let step = surface.points().len() / 3;
    for attempt in 0..3 {
        let i = attempt * step;
        posterior.observe(Touch {
            contact: Some(Contact {
                point_m: surface.points()[i],
                normal: surface.normals()[i],
            }),
            attempt,
        });
    }
    let objects = geometry.objects().len();
    let mut probabilities = vec![0.5 / (objects - 1) as f64; objects];
    probabilities[0] = 0.5;
    (posterior, probabilities)
}

fn shapes() -> Vec<ObjectSpec> {
    ObjectSpec::all_of(&ObjectSet::shapes()).expect("the shapes (fetched by `cargo xtask setup`)")
}

/// `SHAPES_READINGS` converged planner readings of every object of `objects`, on one thread.
fn shapes_run(objects: &[ObjectSpec], seed: u64) -> Vec<ExplorationReport> {
    let plan = CollectPlan {
        mode: CollectMode::Planner(
            Valid::new(PlannerConfig::default().fitted_to(objects)).expect("fitted config"),
        ),
        sensor: sensor(),
        control: Valid::default(),
        perturbation: PerturbationBounds::NONE,
        readings_per_object: SHAPES_READINGS,
        seed,
        start_pose: StartPose::Canonical,
        free_object: None,
    };
    plan.collect(objects, 1).expect("planner runs")
}

/// The shapes' arm scenes, compiled once, with the contact screen or without it.
fn shapes_scenes(objects: &[ObjectSpec], screened: bool) -> Vec<Scene> {
    objects
        .iter()
        .map(|object| {
            let scene = arm_scene(object);
            if screened {
                scene
            } else {
                scene.without_contact_screen()
            }
        })
        .collect()
}

/// `SHAPES_READINGS` converged planner readings of every object in its scene of `scenes`.
fn scenes_run(objects: &[ObjectSpec], scenes: &mut [Scene], seed: u64) -> Vec<ExplorationReport> {
    let config = PlannerConfig::default().fitted_to(objects);
    objects
        .iter()
        .zip(scenes.iter_mut())
        .map(|(object, scene)| explore_in(scene, config, &object.name, SHAPES_READINGS, seed))
        .collect()
}

fn benches(c: &mut Criterion) {
    let object = pawn();
    let pose = touching_pose();
    let mut free = FreePad::new(object.clone(), &Valid::new(sensor()).expect("a valid sensor"))
        .expect("free-floating scene");
    let mut group = c.benchmark_group("explore");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    group.throughput(Throughput::Elements(1));
    group.bench_function("sensor/bare_reading", |b| {
        b.iter(|| bare_reading(&mut free, black_box(&pose)))
    });
    group.throughput(Throughput::Elements(SAMPLER_READINGS as u64));
    let mut seed = 0;
    group.bench_function("sampler/6x6", |b| {
        b.iter(|| {
            seed += 1;
            sampler_run(&mut free, seed)
        })
    });
    let mut scene = arm_scene(&object);
    group.throughput(Throughput::Elements(PLANNER_READINGS as u64));
    group.bench_function("planner/kinematic", |b| {
        b.iter(|| {
            seed += 1;
            planner_run(&mut scene, Execution::Kinematic, PLANNER_READINGS, seed)
        })
    });
    let models = scored_models();
    let (gain, candidates) = scorer_and_candidates(&models);
    group.throughput(Throughput::Elements(1));
    group.bench_function("active/score_12_candidates", |b| {
        b.iter(|| black_box(gain.score(black_box(&candidates))))
    });
    let objects = shapes();
    let geometry = shapes_geometry(&objects);
    let (posterior, probabilities) = geometry_after_contacts(&geometry);
    group.bench_function("active/contact_gain_12_candidates", |b| {
        b.iter(|| {
            black_box(posterior.contact_gains_nats(
                &probabilities,
                black_box(&candidates),
                CONTACT_WEIGHT,
                0.006,
                GainOf::Identity,
            ))
        })
    });
    group.throughput(Throughput::Elements((SHAPES_READINGS * objects.len()) as u64));
    group.bench_function("planner/shapes", |b| {
        b.iter(|| {
            seed += 1;
            shapes_run(&objects, seed)
        })
    });
    for (name, screened) in [
        ("planner/shapes_screened", true),
        ("planner/shapes_unscreened", false),
    ] {
        let mut scenes = shapes_scenes(&objects, screened);
        let mut seed = 500;
        group.bench_function(name, |b| {
            b.iter(|| {
                seed += 1;
                scenes_run(&objects, &mut scenes, seed)
            })
        });
    }
    group.finish();
}

/// Converged readings and attempts per second over `runs` timed runs.
fn rate(runs: u64, mut run: impl FnMut(u64) -> ExplorationReport) -> (f64, f64, usize, usize) {
    let (mut converged, mut attempts) = (0, 0);
    let start = Instant::now();
    for seed in 0..runs {
        let report = run(1000 + seed);
        converged += report.converged();
        attempts += report.readings.len();
    }
    let s = start.elapsed().as_secs_f64();
    (converged as f64 / s, attempts as f64 / s, converged, attempts)
}

fn summary() {
    let object = pawn();
    let pose = touching_pose();
    let mut free = FreePad::new(object.clone(), &Valid::new(sensor()).expect("a valid sensor"))
        .expect("free-floating scene");
    let n = 2000;
    let start = Instant::now();
    for _ in 0..n {
        black_box(bare_reading(&mut free, &pose));
    }
    let bare = n as f64 / start.elapsed().as_secs_f64();
    let (sampler, sampler_attempts, sc, sa) = rate(10, |seed| sampler_run(&mut free, seed));
    let mut scene = arm_scene(&object);
    let (kinematic, kinematic_attempts, kc, ka) = rate(5, |seed| {
        planner_run(&mut scene, Execution::Kinematic, PLANNER_READINGS, seed)
    });
    let (servo, servo_attempts, vc, va) = rate(2, |seed| {
        planner_run(&mut scene, Execution::Servo, SERVO_READINGS, seed)
    });
    println!("\nexplore summary (pawn, 6x6, one core; converged readings per second):");
    println!("  bare sensor reading       {bare:9.0} /s  (baseline of the sampler)");
    println!(
        "  sampler 6x6               {sampler:9.1} /s  = {:.4} x bare reading; {sampler_attempts:.1} attempts/s, {sc}/{sa} converged",
        sampler / bare
    );
    println!(
        "  planner, servo (previous) {servo:9.2} /s  (baseline of the planner); {servo_attempts:.2} attempts/s, {vc}/{va} converged"
    );
    println!(
        "  planner, kinematic        {kinematic:9.1} /s  = {:.1} x servo, {:.4} x bare reading; {kinematic_attempts:.1} attempts/s, {kc}/{ka} converged",
        kinematic / servo,
        kinematic / bare
    );
    // The active strategy's scoring per iteration against a plain planner iteration.
    let (mut iterations, start) = (0, Instant::now());
    for seed in 0..5 {
        iterations += planner_run(&mut scene, Execution::Kinematic, PLANNER_READINGS, 3000 + seed).iterations;
    }
    let per_iteration_s = start.elapsed().as_secs_f64() / iterations.max(1) as f64;
    let models = scored_models();
    let (gain, candidates) = scorer_and_candidates(&models);
    let scores = 20_000;
    let start = Instant::now();
    for _ in 0..scores {
        black_box(gain.score(black_box(&candidates)));
    }
    let per_score_s = start.elapsed().as_secs_f64() / scores as f64;
    println!(
        "  planner iteration (plain) {:9.1} us  (baseline; {iterations} iterations of 5 runs)",
        1e6 * per_iteration_s
    );
    println!(
        "  active scoring, {CANDIDATES} cand.  {:9.2} us  = {:.4} x a plain iteration ({SCORED_OBJECTS} objects, k = {SCORED_CLUSTERS}, {SCORED_READINGS} readings)",
        1e6 * per_score_s,
        per_score_s / per_iteration_s
    );
    // The whole `shapes` set: per object and over the set, three seeds.
    let objects = shapes();
    let mut per_object = vec![(0, 0); objects.len()];
    let start = Instant::now();
    for seed in 0..3 {
        for (counts, report) in per_object.iter_mut().zip(shapes_run(&objects, 2000 + seed)) {
            counts.0 += report.converged();
            counts.1 += report.readings.len();
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let (converged, attempts) = per_object
        .iter()
        .fold((0, 0), |(c, a), (oc, oa)| (c + oc, a + oa));
    println!(
        "  planner, shapes set       {:9.1} /s  = {:.4} x bare reading; {converged}/{attempts} attempts converged ({:.0}%), 3 x {SHAPES_READINGS} asked of each object:",
        converged as f64 / seconds,
        converged as f64 / seconds / bare,
        100.0 * converged as f64 / attempts.max(1) as f64
    );
    for (object, (c, a)) in objects.iter().zip(&per_object) {
        println!("    {:12} {c:3}/{a:3} converged", object.name);
    }
    // The contact screen against `mj_collision` at every sample, alternating, the same readings.
    let (mut screened, mut unscreened) = (shapes_scenes(&objects, true), shapes_scenes(&objects, false));
    let (mut with_s, mut without_s) = (0.0, 0.0);
    for seed in 0..3 {
        let start = Instant::now();
        let reports = scenes_run(&objects, &mut unscreened, 4000 + seed);
        without_s += start.elapsed().as_secs_f64();
        let start = Instant::now();
        let same = scenes_run(&objects, &mut screened, 4000 + seed) == reports;
        with_s += start.elapsed().as_secs_f64();
        assert!(same, "the contact screen changed a planner run");
    }
    println!(
        "  planner, shapes set, contact screen {with_s:.2} s against mj_collision at every sample {without_s:.2} s: {:.2}x faster, the same readings",
        without_s / with_s
    );
}

criterion_group!(explore, benches);

fn main() {
    explore();
    Criterion::default().configure_from_args().final_summary();
    summary();
}
