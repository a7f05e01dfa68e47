//! Collecting readings of a set of objects, in parallel and reproducibly.
//!
//! Each object is an independent run in its own MuJoCo scene, seeded from the run's seed and the
//! object's index ([`crate::rng::stream`]); the sensor's noise stream likewise. Runs go to a rayon pool
//! of the requested size and come back in object order, so the readings do not depend on the number of
//! threads or on scheduling.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::control::{ControlConfig, ControlError, FreePad, ReadTactile};
use crate::dataset::{Dataset, DatasetError, DatasetHeader};
use crate::explore::planner::{Planner, PlannerConfig};
use crate::explore::report::ExplorationReport;
use crate::explore::sampler::{SamplerConfig, sample_readings};
use crate::rng;
use crate::sim::arm::PAD_SITE;
use crate::sim::{ObjectSpec, PerturbationBounds, Scene, SceneBuilder};
use crate::tactile::SensorConfig;
use crate::tactile::sensor::{CoveringSensor, TactileError, add_sensor};
use crate::valid::Valid;

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
    /// What a dataset's header says produced it: `sampler` (or `sampler from above`), `planner L=0.5`.
    pub fn generator_name(&self) -> String {
        match self {
            Self::Sampler(c) if c.from_above_only => "sampler from above".to_string(),
            Self::Sampler(_) => "sampler".to_string(),
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
}

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
}

/// The reader of a scene's covering sensor (it lives in `control`, beside the carriers).
pub use crate::control::sensor_reader;

impl CollectPlan {
    /// The sensor of object `index`: the noise stream is the object's own.
    pub fn sensor_for(&self, index: usize) -> SensorConfig {
        SensorConfig {
            noise_seed: rng::substream(self.sensor.noise_seed ^ self.seed, index as u64),
            ..self.sensor
        }
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
        let sensor = self.sensor_for(index);
        let mut rng = rng::stream(self.seed, index as u64);
        match self.mode {
            CollectMode::Sampler(config) => {
                let valid = Valid::new(sensor).map_err(TactileError::from)?;
                let mut pad = FreePad::new(object.clone(), &valid)?;
                sample_readings(
                    &mut pad,
                    &object.name,
                    sensor,
                    &self.control,
                    &config,
                    self.perturbation,
                    self.readings_per_object,
                    &mut rng,
                    on_converged,
                )
            }
            CollectMode::Planner(config) => {
                let (mut scene, mut planner) = self.planner_for(object, index, config)?;
                planner.explore_reporting(&mut scene, &object.name, self.readings_per_object, on_converged)
            }
        }
    }

    /// The arm's scene with `object` and the planner that explores it as object `index` of this
    /// plan (its sensor noise stream and random stream), for callers that drive the planner
    /// themselves (active exploration, `active_touch`).
    #[allow(clippy::type_complexity)]
    pub fn planner_for(
        &self,
        object: &ObjectSpec,
        index: usize,
        config: Valid<PlannerConfig>,
    ) -> Result<(Scene, Planner<impl ReadTactile + use<>>), ControlError> {
        let sensor = self.sensor_for(index);
        let builder = SceneBuilder::with_arm_and_table().object(object.clone());
        let valid = Valid::new(sensor).map_err(TactileError::from)?;
        let scene = add_sensor(builder, &valid, "covering", PAD_SITE).build()?;
        let reader = sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE)?);
        let planner = Planner::new(
            &scene,
            config,
            self.control,
            sensor,
            self.perturbation,
            rng::stream(self.seed, index as u64),
            reader,
        )?;
        Ok((scene, planner))
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
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| ControlError::ThreadPool(format!("{threads} threads: {e}")))?;
        pool.install(|| {
            objects
                .par_iter()
                .enumerate()
                .map(|(i, object)| self.collect_object_reporting(object, i, &mut || on_converged()))
                .collect()
        })
    }

    /// Collects `objects` (of the set with id `object_set`) as [`collect_reporting`](Self::collect_reporting)
    /// does and gathers the readings, object by object, into a dataset whose header says how they
    /// were made.
    pub fn collect_dataset(
        &self,
        object_set: &str,
        objects: &[ObjectSpec],
        threads: usize,
        on_converged: &(dyn Fn() + Sync),
    ) -> Result<Dataset, CollectError> {
        let reports = self.collect_reporting(objects, threads, on_converged)?;
        let header = DatasetHeader::new(
            self.sensor,
            object_set,
            objects.iter().map(|o| o.name.clone()).collect(),
            self.mode.generator_name(),
            self.seed,
        );
        Ok(Dataset::new(
            header,
            reports.into_iter().flat_map(|r| r.readings).collect(),
        )?)
    }
}
