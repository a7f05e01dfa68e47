//! Collecting readings of a set of objects, in parallel and reproducibly.
//!
//! Each object is an independent run in its own MuJoCo scene, seeded from the run's seed and the
//! object's index ([`crate::rng::stream`]); the sensor's noise stream likewise. Runs go to a rayon pool
//! of the requested size and come back in object order, so the readings do not depend on the number of
//! threads or on scheduling.
//!
//! Each object starts where [`CollectPlan::start_pose`] says: where it was built, or at a pose
//! drawn from a stream of its own ([`START_POSE_STREAM`]), so that the sampler's and the planner's
//! streams, and with them every dataset of a canonical start, are what they were before start
//! poses existed.

use std::sync::{Mutex, PoisonError};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::control::{ControlConfig, ControlError, FreePad, ReadTactile};
use crate::dataset::{Dataset, DatasetError, DatasetHeader, Perturbed};
use crate::explore::planner::{Planner, PlannerConfig};
use crate::explore::report::ExplorationReport;
use crate::explore::sampler::{SamplerConfig, TrainingSampler};
use crate::explore::setup::TouchSetup;
use crate::pose::StartPose;
use crate::rng;
use crate::sim::arm::PAD_SITE;
use crate::sim::{FreeBody, ObjectSpec, PerturbationAct, PerturbationBounds, Scene, SimError};
use crate::tactile::SensorConfig;
use crate::tactile::sensor::{CoveringSensor, TactileError, arm_with_sensor};
use crate::valid::{RangeError, Valid};

/// Which procedure collects the readings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "mode")]
pub enum CollectMode {
    /// The training sampler with the free-floating pad (Sec. V-A3).
    Sampler(Valid<SamplerConfig>),
    /// The exploration planner with the arm (Sec. III-A).
    Planner(Valid<PlannerConfig>),
}

impl CollectMode {
    /// What a dataset's header says produced it: `sampler`, `sampler from above` (Sec. V-D),
    /// `sampler reachable by the arm`, `sampler from above, reachable by the arm`, `planner L=0.5`.
    /// The one definition: the CLI and the experiments both name their datasets by it.
    pub fn generator_name(&self) -> String {
        match self {
            Self::Sampler(c) => match (c.from_above_only, c.reachable_by_arm) {
                (false, false) => "sampler".to_string(),
                (true, false) => "sampler from above".to_string(),
                (false, true) => "sampler reachable by the arm".to_string(),
                (true, true) => "sampler from above, reachable by the arm".to_string(),
            },
            Self::Planner(c) => format!("planner L={}", c.local_probability),
        }
    }
}

/// Why a collection run gave no dataset.
#[derive(Debug, thiserror::Error)]
pub enum CollectError {
    #[error("collecting readings: {0}")]
    Control(#[from] ControlError),
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    /// The procedure's parameters failed their check ([`Collect::plan`]).
    #[error(transparent)]
    Config(#[from] RangeError),
}

/// The id of the random stream an object's start pose is drawn from, under the object's own
/// stream of the run's seed (`rng::stream(rng::substream(seed, index), START_POSE_STREAM)`): a
/// stream of its own, so that drawing a start takes nothing from the planner's or the sampler's.
pub const START_POSE_STREAM: u64 = 0x57A7;

/// Everything that determines a collection run (besides the objects).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CollectPlan {
    pub mode: CollectMode,
    pub sensor: SensorConfig,
    pub control: Valid<ControlConfig>,
    pub perturbation: PerturbationBounds,
    /// Converged readings wanted per object.
    pub readings_per_object: usize,
    pub seed: u64,
    /// Where each object starts (a random start is drawn per object from [`START_POSE_STREAM`]).
    /// Left out of the plan's JSON when canonical, so that every plan written before start poses
    /// existed (an experiment's `config.json`, its cache keys) is written as it was.
    #[serde(default, skip_serializing_if = "StartPose::is_canonical")]
    pub start_pose: StartPose,
    /// The object on a free joint, made of this (issue 74), or, `None`, a mocap body, the paper's
    /// (left out of the JSON, so every plan of a mocap object is written as it was). The arm's
    /// only: [`Collect::plan`] refuses it for the sampler, whose pad floats over no table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_object: Option<FreeBody>,
}

/// The reader of a scene's covering sensor (it lives in `control`, beside the carriers).
use crate::control::sensor_reader;

/// The reader [`CollectPlan::planner_for`]'s planner reads the arm's pad with: a named type, so
/// that a caller can keep the planner in a struct (`active_touch::TouchEpisode`) and send it to
/// another thread.
pub type SensorReader = Box<dyn ReadTactile + Send>;

impl CollectPlan {
    /// The sensor of object `index`: the noise stream is the object's own.
    pub fn sensor_for(&self, index: usize) -> SensorConfig {
        SensorConfig {
            noise_seed: rng::substream(self.sensor.noise_seed ^ self.seed, index as u64),
            ..self.sensor
        }
    }

    /// What every touch of object `index` shares: its sensor, the controllers, the perturbation.
    pub fn setup_for(&self, index: usize) -> TouchSetup {
        TouchSetup {
            sensor: self.sensor_for(index),
            control: self.control,
            perturbation: self.perturbation,
        }
    }

    /// Puts object `index` of this plan at its start in `scene` ([`Scene::place_at_start`]), from
    /// the object's own start-pose stream; a canonical start leaves it where it was built.
    pub fn place_at_start(&self, scene: &mut Scene, index: usize) -> Result<(), SimError> {
        let mut rng = rng::stream(rng::substream(self.seed, index as u64), START_POSE_STREAM);
        scene.place_at_start(&self.start_pose, &mut rng).map(drop)
    }

    /// Collects the readings of object `index` (its name is the object's name).
    pub fn collect_object(
        &self,
        object: &ObjectSpec,
        index: usize,
    ) -> Result<ExplorationReport, ControlError> {
        self.collect_object_reporting(object, index, &mut || {})
    }

    /// [`collect_object`](Self::collect_object), running `on_converged` after each converged
    /// reading.
    pub fn collect_object_reporting(
        &self,
        object: &ObjectSpec,
        index: usize,
        on_converged: &mut dyn FnMut(),
    ) -> Result<ExplorationReport, ControlError> {
        let rng = rng::stream(self.seed, index as u64);
        match self.mode {
            CollectMode::Sampler(config) => {
                let setup = self.setup_for(index);
                let sensor = Valid::new(setup.sensor).map_err(TactileError::from)?;
                let mut pad = FreePad::new(object.clone(), &sensor)?;
                self.place_at_start(pad.scene_mut(), index)?;
                TrainingSampler::new(config, setup, rng).sample_reporting(
                    &mut pad,
                    &object.name,
                    self.readings_per_object,
                    on_converged,
                )
            }
            CollectMode::Planner(config) => {
                let (mut scene, mut planner) = self.planner_for(object, index, config)?;
                planner.explore_reporting(&mut scene, &object.name, self.readings_per_object, on_converged)
            }
        }
    }

    /// The arm's scene with `object` at its start and the planner that explores it as object
    /// `index` of this plan (its start, sensor noise stream and random stream), for callers that
    /// drive the planner themselves (active exploration, `active_touch`).
    pub fn planner_for(
        &self,
        object: &ObjectSpec,
        index: usize,
        config: Valid<PlannerConfig>,
    ) -> Result<(Scene, Planner<SensorReader>), ControlError> {
        let setup = self.setup_for(index);
        let sensor = Valid::new(setup.sensor).map_err(TactileError::from)?;
        let mut scene = arm_with_sensor(self.mounted(object), &sensor).build()?;
        self.place_at_start(&mut scene, index)?;
        let reader: SensorReader = Box::new(sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE)?));
        let planner = Planner::new(
            &scene,
            config,
            setup,
            rng::stream(self.seed, index as u64),
            reader,
        )?;
        Ok((scene, planner))
    }

    /// `object` held as this plan holds objects: on a mocap body as given, or free, made of
    /// [`free_object`](Self::free_object).
    pub fn mounted(&self, object: &ObjectSpec) -> ObjectSpec {
        object.mounted(self.free_object)
    }

    /// Collects every object on a pool of `threads` threads (0: all cores), results in object order.
    pub fn collect(
        &self,
        objects: &[ObjectSpec],
        threads: usize,
    ) -> Result<Vec<ExplorationReport>, ControlError> {
        self.collect_reporting(objects, threads, &|| {})
    }

    /// [`collect`](Self::collect), running `on_converged` (from any worker thread) after each
    /// converged reading of any object: what progress bars count.
    pub fn collect_reporting(
        &self,
        objects: &[ObjectSpec],
        threads: usize,
        on_converged: &(dyn Fn() + Sync),
    ) -> Result<Vec<ExplorationReport>, ControlError> {
        worker_pool(threads)?.install(|| {
            objects
                .par_iter()
                .enumerate()
                .map(|(i, object)| self.collect_object_reporting(object, i, &mut || on_converged()))
                .collect()
        })
    }

    /// [`Collect::dataset`] of this plan on `threads` threads (0: all cores), running
    /// `on_converged` after each converged reading.
    pub fn collect_dataset(
        &self,
        object_set: &str,
        objects: &[ObjectSpec],
        threads: usize,
        on_converged: &(dyn Fn() + Sync),
    ) -> Result<Dataset, CollectError> {
        Collect::from_plan(*self)
            .threads(threads)
            .progress(on_converged)
            .dataset(object_set, objects)
    }

    /// The readings of `reports` (one per object of `objects`, of the set with id `object_set`),
    /// object by object, as a dataset whose header says how they were made.
    pub fn dataset_of(
        &self,
        object_set: &str,
        objects: &[ObjectSpec],
        reports: Vec<ExplorationReport>,
    ) -> Result<Dataset, DatasetError> {
        let header = DatasetHeader::new(
            self.sensor,
            object_set,
            objects.iter().map(|o| o.name.clone()).collect(),
            self.mode.generator_name(),
            self.seed,
        )
        .with_start_pose(self.start_pose)
        .with_perturbation(recorded_perturbation(&self.perturbation))
        .with_free_object(self.free_object);
        Dataset::new(header, reports.into_iter().flat_map(|r| r.readings).collect())
    }
}

/// The perturbation `bounds` as a dataset records them, and a recogniser is told them.
pub fn recorded_perturbation(bounds: &PerturbationBounds) -> Perturbed {
    Perturbed {
        // Degrees as given: the bound was made from degrees, and the file should say 10, not 10.000000000000002.
        max_rotation_deg: (bounds.max_rotation_rad().to_degrees() * 1e9).round() / 1e9,
        max_translation_fraction: bounds.max_translation_fraction(),
        pushed: bounds.act() == PerturbationAct::Push,
    }
}

/// A pool of `threads` worker threads (0: one per core) for collection runs.
fn worker_pool(threads: usize) -> Result<rayon::ThreadPool, ControlError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| ControlError::ThreadPool(format!("{threads} threads: {e}")))
}

/// One dataset of a [`collect_datasets`] batch: a checked plan and the objects it reads.
#[derive(Clone, Copy)]
pub struct BatchDataset<'a> {
    pub plan: CollectPlan,
    /// The id of the object set, as the dataset's header records it.
    pub object_set: &'a str,
    pub objects: &'a [ObjectSpec],
}

/// Collects several datasets on one pool of `threads` threads (0: one per core), every object of
/// every dataset one task of the pool, the longest first.
///
/// Collected one after another, each dataset on its own pass over the pool, a core idled at the
/// end of every dataset while its slowest object finished: a tenth of the collection time of the
/// paper's experiments, which each need two to twelve datasets. In one batch whose longest tasks go
/// first, the batch ends on its shortest ones.
///
/// Each dataset goes to `on_dataset`, with its index in `batch`, as soon as its last object is
/// done (from the worker that finished it), so that a batch stopped by an error keeps the datasets
/// it finished; `on_converged` runs after each converged reading of any of them. The readings are
/// those [`CollectPlan::collect_dataset`] gives, whatever the threads and the order the objects
/// run in: each object's random streams are its own.
pub fn collect_datasets<E>(
    batch: &[BatchDataset<'_>],
    threads: usize,
    on_converged: &(dyn Fn() + Sync),
    on_dataset: &(dyn Fn(usize, Dataset) -> Result<(), E> + Sync),
) -> Result<(), E>
where
    E: From<CollectError> + Send,
{
    let finished = |index: usize, reports: Vec<ExplorationReport>| -> Result<(), E> {
        let BatchDataset {
            plan,
            object_set,
            objects,
        } = batch[index];
        let dataset = plan
            .dataset_of(object_set, objects, reports)
            .map_err(CollectError::from)?;
        on_dataset(index, dataset)
    };
    // A dataset of no objects has no task to finish it.
    for (index, _) in batch.iter().enumerate().filter(|(_, b)| b.objects.is_empty()) {
        finished(index, Vec::new())?;
    }
    let reports: Vec<Mutex<Vec<Option<ExplorationReport>>>> = batch
        .iter()
        .map(|b| Mutex::new(b.objects.iter().map(|_| None).collect()))
        .collect();
    let run = |d: usize, o: usize| -> Result<(), E> {
        let BatchDataset { plan, objects, .. } = batch[d];
        let report = plan
            .collect_object_reporting(&objects[o], o, &mut || on_converged())
            .map_err(CollectError::from)?;
        let whole = {
            let mut slots = reports[d].lock().unwrap_or_else(PoisonError::into_inner);
            slots[o] = Some(report);
            if slots.iter().all(Option::is_some) {
                Some(slots.drain(..).flatten().collect::<Vec<_>>())
            } else {
                None
            }
        };
        whole.map_or(Ok(()), |reports| finished(d, reports))
    };
    let mut tasks: Vec<(usize, usize)> = batch
        .iter()
        .enumerate()
        .flat_map(|(d, b)| (0..b.objects.len()).map(move |o| (d, o)))
        .collect();
    tasks.sort_by_key(|&(d, _)| std::cmp::Reverse(relative_cost(&batch[d].plan)));
    let pool = worker_pool(threads).map_err(CollectError::from)?;
    pool.install(|| crate::queue::run_in_order(tasks.len(), |i| run(tasks[i].0, tasks[i].1)))?;
    Ok(())
}

/// What one object of `plan` costs against the others of a batch, roughly: a planner reading (a
/// tree search and the arm's guarded motions) took some thirty times a sampler reading (the free
/// pad placed and settled) at scale 1.0 of `reproduce`.
fn relative_cost(plan: &CollectPlan) -> usize {
    let per_reading = match plan.mode {
        CollectMode::Sampler(_) => 1,
        CollectMode::Planner(_) => 30,
    };
    plan.readings_per_object.saturating_mul(per_reading)
}

/// The procedure of a [`Collect`] before its check.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Procedure {
    Sampler(SamplerConfig),
    Planner(PlannerConfig),
}

/// A collection run, set up step by step: the procedure (the training sampler of Sec. V-A3 or the
/// exploration planner of Sec. III-A) and the sensor, then how many converged readings per
/// object, the seed, the controllers, the perturbation, the objects' start, the threads and a
/// progress callback.
/// [`run`](Self::run) checks the procedure's parameters once and collects every object; the
/// readings depend on the seed only, not on the threads.
///
/// ```
/// use glam::DVec3;
/// use taction::explore::Collect;
/// use taction::mesh::TriMesh;
/// use taction::sim::ObjectSpec;
/// use taction::tactile::SensorConfig;
///
/// let objects = [ObjectSpec::new("box", TriMesh::cuboid(DVec3::new(0.03, 0.03, 0.02)))];
/// let dataset = Collect::sampler(SensorConfig::default())
///     .from_above()
///     .per_object(2)
///     .seed(1)
///     .threads(1)
///     .dataset("boxes", &objects)?;
/// assert_eq!(dataset.header().generator, "sampler from above");
/// assert_eq!(dataset.converged().count(), 2);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy)]
pub struct Collect<'p> {
    procedure: Procedure,
    sensor: SensorConfig,
    control: Valid<ControlConfig>,
    perturbation: PerturbationBounds,
    start_pose: StartPose,
    free_object: Option<FreeBody>,
    per_object: usize,
    seed: u64,
    threads: usize,
    progress: Option<&'p (dyn Fn() + Sync)>,
}

impl Collect<'static> {
    /// The training sampler with the paper's parameters ([`SamplerConfig::default`]), 100
    /// readings per object, seed 0, the default controllers, no perturbation, the objects where
    /// they were built, all cores.
    pub fn sampler(sensor: SensorConfig) -> Self {
        Self::with(Procedure::Sampler(SamplerConfig::default()), sensor)
    }

    /// The exploration planner with `config` (checked by [`run`](Collect::run)), with the
    /// defaults of [`sampler`](Self::sampler) otherwise.
    pub fn planner(sensor: SensorConfig, config: PlannerConfig) -> Self {
        Self::with(Procedure::Planner(config), sensor)
    }

    /// The run `plan` describes, on all cores.
    pub fn from_plan(plan: CollectPlan) -> Self {
        let procedure = match plan.mode {
            CollectMode::Sampler(c) => Procedure::Sampler(c.into_inner()),
            CollectMode::Planner(c) => Procedure::Planner(c.into_inner()),
        };
        Self {
            control: plan.control,
            perturbation: plan.perturbation,
            start_pose: plan.start_pose,
            free_object: plan.free_object,
            per_object: plan.readings_per_object,
            seed: plan.seed,
            ..Self::with(procedure, plan.sensor)
        }
    }

    fn with(procedure: Procedure, sensor: SensorConfig) -> Self {
        Self {
            procedure,
            sensor,
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
            start_pose: StartPose::Canonical,
            free_object: None,
            per_object: 100,
            seed: 0,
            threads: 0,
            progress: None,
        }
    }
}

impl<'p> Collect<'p> {
    /// Converged readings wanted per object.
    pub fn per_object(self, readings: usize) -> Self {
        Self {
            per_object: readings,
            ..self
        }
    }

    /// The run's seed: each object's random stream and sensor noise stream derive from it.
    pub fn seed(self, seed: u64) -> Self {
        Self { seed, ..self }
    }

    /// Worker threads (0: one per core); the readings do not depend on it.
    pub fn threads(self, threads: usize) -> Self {
        Self { threads, ..self }
    }

    /// The surface contact controllers that settle every touch (Sec. III-B).
    pub fn control(self, control: Valid<ControlConfig>) -> Self {
        Self { control, ..self }
    }

    /// How far the object is moved after every reading.
    pub fn perturbation(self, perturbation: PerturbationBounds) -> Self {
        Self { perturbation, ..self }
    }

    /// Where each object starts: where it was built, or at a pose drawn per object that the
    /// explorer is not told ([`StartPose`]).
    pub fn start_pose(self, start_pose: StartPose) -> Self {
        Self { start_pose, ..self }
    }

    /// Planner: every object on a free joint, made of `body` (`None`: a mocap body, the paper's
    /// and the default): the covering pushes it, gravity and the table hold it, and every touch
    /// runs through MuJoCo's dynamics (`sim::free_object`).
    pub fn free_object(self, body: Option<FreeBody>) -> Self {
        Self {
            free_object: body,
            ..self
        }
    }

    /// Sampler: approach only from above (the raised letters, Sec. V-D).
    pub fn from_above(self) -> Self {
        self.map_sampler(|c| SamplerConfig {
            from_above_only: true,
            ..c
        })
    }

    /// Sampler: only starts the exploring arm can reach ([`SamplerConfig::reachable_by_arm`]).
    pub fn reachable_by_arm(self) -> Self {
        self.map_sampler(|c| SamplerConfig {
            reachable_by_arm: true,
            ..c
        })
    }

    fn map_sampler(self, change: impl FnOnce(SamplerConfig) -> SamplerConfig) -> Self {
        match self.procedure {
            Procedure::Sampler(c) => Self {
                procedure: Procedure::Sampler(change(c)),
                ..self
            },
            Procedure::Planner(_) => self,
        }
    }

    /// Runs `on_converged` (from any worker thread) after each converged reading of any object:
    /// what progress bars count.
    pub fn progress<'q>(self, on_converged: &'q (dyn Fn() + Sync)) -> Collect<'q> {
        Collect {
            progress: Some(on_converged),
            procedure: self.procedure,
            sensor: self.sensor,
            control: self.control,
            perturbation: self.perturbation,
            start_pose: self.start_pose,
            free_object: self.free_object,
            per_object: self.per_object,
            seed: self.seed,
            threads: self.threads,
        }
    }

    /// The checked plan: everything the readings depend on (what an experiment's cache key hashes).
    pub fn plan(&self) -> Result<CollectPlan, RangeError> {
        let mode = match self.procedure {
            Procedure::Sampler(_) if self.free_object.is_some() => {
                return Err(RangeError {
                    config: "collection",
                    field: "free_object",
                    value: "a free object".into(),
                    allowed: "the planner's only (the sampler's pad floats over no table)",
                });
            }
            Procedure::Sampler(c) => CollectMode::Sampler(Valid::new(c)?),
            Procedure::Planner(c) => CollectMode::Planner(Valid::new(c)?),
        };
        self.perturbation.check_act_on(self.free_object, "collection")?;
        Ok(CollectPlan {
            mode,
            sensor: self.sensor,
            control: self.control,
            perturbation: self.perturbation,
            readings_per_object: self.per_object,
            seed: self.seed,
            start_pose: self.start_pose,
            free_object: self.free_object,
        })
    }

    /// Collects every object, one report per object in object order.
    pub fn run(&self, objects: &[ObjectSpec]) -> Result<Vec<ExplorationReport>, CollectError> {
        let plan = self.plan()?;
        let on_converged = self.progress.unwrap_or(&|| {});
        Ok(plan.collect_reporting(objects, self.threads, on_converged)?)
    }

    /// Collects every object (of the set with id `object_set`) into a dataset whose header says
    /// how the readings were made.
    pub fn dataset(&self, object_set: &str, objects: &[ObjectSpec]) -> Result<Dataset, CollectError> {
        let reports = self.run(objects)?;
        Ok(self.plan()?.dataset_of(object_set, objects, reports)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_generator_name_says_how_the_sampler_was_restricted() {
        let name = |collect: Collect| collect.plan().unwrap().mode.generator_name();
        let sampler = || Collect::sampler(SensorConfig::default());
        assert_eq!(name(sampler()), "sampler");
        assert_eq!(name(sampler().from_above()), "sampler from above");
        assert_eq!(name(sampler().reachable_by_arm()), "sampler reachable by the arm");
        assert_eq!(
            name(sampler().from_above().reachable_by_arm()),
            "sampler from above, reachable by the arm"
        );
        let planner = PlannerConfig {
            local_probability: 0.8,
            ..PlannerConfig::default()
        };
        assert_eq!(
            name(Collect::planner(SensorConfig::default(), planner).from_above()),
            "planner L=0.8"
        );
    }

    #[test]
    fn a_plan_comes_back_from_its_builder_unchanged() {
        let plan = CollectPlan {
            mode: CollectMode::Sampler(Valid::default()),
            sensor: SensorConfig::default(),
            control: Valid::default(),
            perturbation: PerturbationBounds::new(5.0, 0.05).unwrap(),
            readings_per_object: 7,
            seed: 3,
            start_pose: StartPose::random(crate::pose::MaxHeading::LETTERS),
            free_object: None,
        };
        assert_eq!(Collect::from_plan(plan).plan().unwrap(), plan);
        // A random start is in the plan's JSON; a canonical one is not, so that a plan written
        // before start poses existed (an experiment's cache key) is written as it was.
        let json = serde_json::to_string(&plan).unwrap();
        assert!(
            json.ends_with(r#","start_pose":{"random":{"max_heading_rad":0.17453292519943295}}}"#),
            "{json}"
        );
        assert_eq!(serde_json::from_str::<CollectPlan>(&json).unwrap(), plan);
        let canonical = CollectPlan {
            start_pose: StartPose::Canonical,
            ..plan
        };
        let json = serde_json::to_string(&canonical).unwrap();
        assert!(json.ends_with(r#""seed":3}"#), "{json}");
        assert_eq!(serde_json::from_str::<CollectPlan>(&json).unwrap(), canonical);
        let beyond = json.replace(
            r#""seed":3}"#,
            r#""seed":3,"start_pose":{"random":{"max_heading_rad":4}}}"#,
        );
        let error = serde_json::from_str::<CollectPlan>(&beyond)
            .unwrap_err()
            .to_string();
        assert!(error.contains("max_heading_rad 4 is outside [0, pi]"), "{error}");
        let bad = PlannerConfig {
            max_iterations: 0,
            ..PlannerConfig::default()
        };
        let error = Collect::planner(SensorConfig::default(), bad).plan().unwrap_err();
        assert_eq!(error.field, "max_iterations");

        // A free object is in the plan's JSON, checked on the way back in, and the arm's only.
        let free = CollectPlan {
            mode: CollectMode::Planner(Valid::default()),
            free_object: Some(FreeBody::new(600.0, 0.3).unwrap()),
            ..canonical
        };
        assert_eq!(Collect::from_plan(free).plan().unwrap(), free);
        let json = serde_json::to_string(&free).unwrap();
        assert!(
            json.ends_with(r#""free_object":{"density_kg_m3":600.0,"friction":0.3}}"#),
            "{json}"
        );
        assert_eq!(serde_json::from_str::<CollectPlan>(&json).unwrap(), free);
        let heavy = json.replace("600.0", "60000.0");
        let error = serde_json::from_str::<CollectPlan>(&heavy)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("object density 60000 kg/m3 is outside [10, 20000]"),
            "{error}"
        );
        let sampled = Collect::sampler(SensorConfig::default()).free_object(Some(FreeBody::DEFAULT));
        assert_eq!(sampled.plan().unwrap_err().field, "free_object");
    }
}
