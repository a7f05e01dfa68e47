//! The demo's recipe for a recogniser of the arm's own touches (beyond the paper): what it
//! collects, how it trains and calibrates, and [`ArmTrainingRecipe::train`], the whole of it for
//! `taction demo`, Python's `arm_model` and the Gymnasium environments' default model alike.

use crate::dataset::{Dataset, Shortfall};
use crate::describe::DescriptorKind;
use crate::explore::collect::{CollectError, CollectMode, CollectPlan};
use crate::explore::{PlannerConfig, SamplerConfig};
use crate::locate::{GeometryError, GeometryModel};
use crate::mesh::TriMesh;
use crate::pose::MaxHeading;
use crate::recognize::{
    CodebookKind, DescriptorChoice, DescriptorChoiceError, RecognizeError, Recognizer, TrainChoices,
    TrainConfig, TrainData, train_recognizer,
};
use crate::sim::{ObjectSpec, PerturbationBounds, StartPose};
use crate::tactile::SensorConfig;
use crate::valid::{RangeError, Valid};

/// The stream of the recipe's seed its calibration explorations draw from.
const CALIBRATION_SEED_STREAM: u64 = 7;

/// Converged readings per object of each calibration exploration, and the trials the posterior is
/// calibrated in: a fresh exploration's first touches, what the demo and an environment's episode
/// recognise.
const CALIBRATION_EXPLORATION_READINGS: usize = 10;

/// How the demo trains a recogniser on what the arm's pad feels (the README's "Training that
/// matches the arm"; docs/measurements.md has the measurements behind each choice): sampler
/// readings restricted to the starts the arm can take from any heading of the object, pressed by
/// the same controllers as the arm's pad; MNTI and SIFT fused ([`Self::DESCRIPTORS`]: SIFT's
/// gradient orientations with MNTI's moments gained on the arm's own touches as on sampler data)
/// over the neighbour codebook, one restart (the neighbour codebook draws nothing at random), the
/// `k` grid sized to the converged readings left after the hold-out
/// ([`TrainConfig::with_grid_for_dataset`]); and where each touch landed, the contacts against
/// every object's surface at a pose the model is not told (`recognize::geometric`, the README's
/// "Where each touch landed"), weighed against appearance on the arm's own explorations of objects
/// standing at random poses. Library users get the model `taction demo` gets.
///
/// ```
/// use taction::active_touch::ArmTrainingRecipe;
/// use taction::pose::MaxHeading;
///
/// let recipe = ArmTrainingRecipe { readings_per_object: 3000, seed: 1, start_heading: MaxHeading::ANY };
/// assert_eq!(recipe.descriptors()?.name(), "mnti+sift");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmTrainingRecipe {
    /// Converged sampler readings per object.
    pub readings_per_object: usize,
    /// Seeds the training data and the model selection.
    pub seed: u64,
    /// How far from its canonical heading an object may stand (the set's
    /// `ObjectSet::start_heading`: any for the 3D objects, 10 degrees for the raised letters):
    /// the calibration explorations start the objects there, and the contacts' pose hypotheses
    /// span it.
    pub start_heading: MaxHeading,
}

impl ArmTrainingRecipe {
    /// The fused descriptors.
    pub const DESCRIPTORS: [DescriptorKind; 2] = [DescriptorKind::Mnti, DescriptorKind::Sift];
    /// The codebook every descriptor's model uses.
    pub const CODEBOOK: CodebookKind = CodebookKind::Knn;

    /// [`Self::DESCRIPTORS`], fused.
    pub fn descriptors(&self) -> Result<DescriptorChoice, DescriptorChoiceError> {
        DescriptorChoice::fused(Self::DESCRIPTORS.to_vec())
    }

    /// The training data's collection: the sampler from starts the arm can reach, the default
    /// controllers, the object unperturbed.
    pub fn collect_plan(&self, sensor: SensorConfig) -> Result<CollectPlan, RangeError> {
        Ok(CollectPlan {
            mode: CollectMode::Sampler(Valid::new(SamplerConfig {
                reachable_by_arm: true,
                ..SamplerConfig::default()
            })?),
            sensor,
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
            readings_per_object: self.readings_per_object,
            seed: self.seed,
            start_pose: StartPose::Canonical,
            free_object: None,
        })
    }

    /// The training choices: [`Self::DESCRIPTORS`] over [`Self::CODEBOOK`], one restart, the
    /// posterior calibrated on trials of 10 of the arm's touches.
    pub fn choices(&self) -> Result<Valid<TrainChoices>, RecognizeError> {
        let descriptor = self.descriptors().map_err(|e| RecognizeError::InvalidParameter {
            name: "descriptors",
            what: e.to_string(),
        })?;
        let choices = TrainChoices {
            codebook: Self::CODEBOOK,
            restarts: 1,
            seed: self.seed,
            calibration_trial_readings: Some(CALIBRATION_EXPLORATION_READINGS),
            ..TrainChoices::of(descriptor)
        };
        Valid::new(choices)
    }

    /// Model selection for `training` (validation held out of it).
    pub fn train_config(&self, training: &Dataset) -> Result<Valid<TrainConfig>, RecognizeError> {
        self.choices()?.config(training, false)
    }

    /// Converged readings per object of the arm's own explorations the posterior is calibrated
    /// on, all explorations together: a thirtieth of the training readings in whole explorations
    /// of 10, 10 to 100 (100 for the demo's 3000).
    pub fn calibration_readings(&self) -> usize {
        self.calibration_explorations() * CALIBRATION_EXPLORATION_READINGS
    }

    /// How many explorations of 10 readings per object the calibration takes: a thirtieth of
    /// the training readings per object in tens, 1 to 10.
    pub fn calibration_explorations(&self) -> usize {
        (self.readings_per_object / (30 * CALIBRATION_EXPLORATION_READINGS)).clamp(1, 10)
    }

    /// The calibration data's collections: [`calibration_explorations`](Self::calibration_explorations)
    /// fresh explorations, each the arm exploring blind (L = 0.5, the object fixed) with the
    /// default controllers for 10 converged readings per object of `objects`, each object standing
    /// at a random start within [`start_heading`](Self::start_heading), each exploration on a seed
    /// of its own. Many short fresh explorations, not one long one: a long exploration's later
    /// touches lie spread over the object by the planner's grown tree and say more than a fresh
    /// one's first touches, which lie close together, so a posterior calibrated on its windows is
    /// sure too soon of the demo's touches, and the contacts' weight fitted on one exploration
    /// swings with its seed (docs/measurements.md, "The demo stops when sure"). The start is drawn
    /// because the contacts' weight fitted at the canonical pose would trust them more than an
    /// unknown pose allows.
    pub fn calibration_plans(
        &self,
        sensor: SensorConfig,
        objects: &[ObjectSpec],
    ) -> Result<Vec<CollectPlan>, RangeError> {
        let readings = CALIBRATION_EXPLORATION_READINGS;
        let mode = CollectMode::Planner(Valid::new(PlannerConfig::for_collection(
            objects, readings, 0.5, None,
        ))?);
        let stream = crate::rng::substream(self.seed, CALIBRATION_SEED_STREAM);
        Ok((0..self.calibration_explorations() as u64)
            .map(|exploration| CollectPlan {
                mode,
                sensor,
                control: Valid::default(),
                perturbation: PerturbationBounds::NONE,
                readings_per_object: readings,
                seed: crate::rng::substream(stream, exploration),
                start_pose: StartPose::random(self.start_heading),
                free_object: None,
            })
            .collect())
    }

    /// The contacts' model of `training`'s objects (in its order), their surfaces picked by name
    /// from `meshes`, their poses unknown within [`start_heading`](Self::start_heading).
    pub fn geometry(
        &self,
        training: &Dataset,
        meshes: &[(String, &TriMesh)],
    ) -> Result<GeometryModel, GeometryError> {
        GeometryModel::of_named(&training.header().objects, meshes, self.start_heading)
    }

    /// Trains the fused model on `training` (collected by [`collect_plan`](Self::collect_plan))
    /// and, given the arm's explorations `calibration` ([`calibration_plans`](Self::calibration_plans)),
    /// calibrates its posterior on them (`recognize::calibration`: the arm's successive touches
    /// are correlated, which the sampler's held-out readings cannot show); without them the
    /// posterior is calibrated on the held-out readings. With `contacts`
    /// ([`geometry`](Self::geometry)) the model also weighs where each touch landed, the weight
    /// fitted on `calibration`, which it then needs.
    pub fn fit(
        &self,
        training: &Dataset,
        calibration: &[&Dataset],
        contacts: Option<&GeometryModel>,
    ) -> Result<Recognizer, RecognizeError> {
        let data = TrainData {
            training,
            validation: None,
            calibration,
            contacts,
        };
        train_recognizer(&self.choices()?, data, &mut ())
    }
}

/// The two collections of [`ArmTrainingRecipe::train`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArmData {
    /// The sampler's readings the model is fitted on ([`ArmTrainingRecipe::collect_plan`]).
    Training,
    /// The arm's explorations its posterior is calibrated on
    /// ([`ArmTrainingRecipe::calibration_plans`]).
    Calibration,
}

/// What [`ArmTrainingRecipe::train`] tells whoever runs it (the demo prints progress bars and
/// warnings, Python turns shortfalls into warnings). Every method does nothing by default.
pub trait ArmTrainingObserver: Sync {
    /// `data`'s collection starts: `readings` converged readings of each of `objects`.
    fn collecting(&mut self, _data: ArmData, _objects: &[ObjectSpec], _readings: usize) {}
    /// One converged reading of `data` was gathered, on whichever worker thread gathered it.
    fn converged(&self, _data: ArmData) {}
    /// `data` is collected, `converged` readings in all; `short` lists the objects it gathered
    /// fewer readings of than asked, once per exploration that fell short (the planner may run
    /// out of iterations on an object the arm reaches badly).
    fn collected(&mut self, _data: ArmData, _converged: usize, _short: &[Shortfall]) {}
    /// The fit starts: model selection `config` over `features` training features.
    fn fitting(&mut self, _config: &TrainConfig, _features: usize) {}
}

impl ArmTrainingObserver for () {}

/// What [`ArmTrainingRecipe::train`] made: the model and the two datasets behind it.
#[derive(Debug, Clone)]
pub struct ArmTraining {
    /// The model: appearance fused with the contacts, its posterior and the contacts' weight
    /// fitted on `calibration`; when `calibration` has no converged reading, appearance alone,
    /// calibrated on the readings held out of `training` (check
    /// [`calibrated_on_the_arm`](Self::calibrated_on_the_arm)).
    pub model: Recognizer,
    pub training: Dataset,
    /// One dataset per calibration exploration.
    pub calibration: Vec<Dataset>,
}

impl ArmTraining {
    /// Whether the arm's explorations calibrated the posterior. When they gave no converged
    /// reading the held-out sampler readings did, and the posterior counts the arm's correlated
    /// touches as independent evidence: overconfident.
    pub fn calibrated_on_the_arm(&self) -> bool {
        self.calibration.iter().any(|d| d.converged().next().is_some())
    }
}

/// What can stop [`ArmTrainingRecipe::train`].
#[derive(Debug, thiserror::Error)]
pub enum ArmTrainingError {
    #[error(transparent)]
    Config(#[from] RangeError),
    #[error(transparent)]
    Collect(#[from] CollectError),
    #[error(transparent)]
    Recognize(#[from] RecognizeError),
    #[error(transparent)]
    Geometry(#[from] GeometryError),
}

impl ArmTrainingRecipe {
    /// The whole recipe on `objects` (of the set with id `object_set`, which the datasets'
    /// headers record) touched by `sensor`: collects the training data and the arm's calibration
    /// explorations on `threads` threads (0: all cores), then fits the model with the objects'
    /// surfaces and calibrates it.
    /// The demo, Python's `arm_model` and the Gymnasium environments' default model all come from
    /// here, so they are the same model for the same objects, sensor and recipe.
    pub fn train(
        &self,
        object_set: &str,
        objects: &[ObjectSpec],
        sensor: SensorConfig,
        threads: usize,
        observer: &mut dyn ArmTrainingObserver,
    ) -> Result<ArmTraining, ArmTrainingError> {
        let training = self
            .collect(ArmData::Training, object_set, objects, sensor, threads, observer)?
            .into_iter()
            .next()
            .ok_or(RecognizeError::InvalidParameter {
                name: "training",
                what: "no training data was collected".into(),
            })?;
        let calibration = self.collect_calibration(object_set, objects, sensor, threads, observer)?;
        let config = self.train_config(&training)?;
        let converged = training.converged().count();
        observer.fitting(&config, config.grid_training_features(converged, false));
        let explored: Vec<&Dataset> = calibration
            .iter()
            .filter(|d| d.converged().next().is_some())
            .collect();
        let model = if explored.is_empty() {
            // Nothing to weigh the contacts on, nor to calibrate on: appearance alone, calibrated
            // on the readings held out of the training data.
            self.fit(&training, &[], None)?
        } else {
            let meshes: Vec<(String, &TriMesh)> = objects.iter().map(|o| (o.name.clone(), &o.mesh)).collect();
            let contacts = self.geometry(&training, &meshes)?;
            self.fit(&training, &explored, Some(&contacts))?
        };
        Ok(ArmTraining {
            model,
            training,
            calibration,
        })
    }

    /// The calibration explorations of [`train`](Self::train) alone
    /// ([`calibration_plans`](Self::calibration_plans), collected), telling `observer`: for a
    /// caller that fits the model itself (Python's `collect_arm_calibration`).
    pub fn collect_calibration(
        &self,
        object_set: &str,
        objects: &[ObjectSpec],
        sensor: SensorConfig,
        threads: usize,
        observer: &mut dyn ArmTrainingObserver,
    ) -> Result<Vec<Dataset>, ArmTrainingError> {
        self.collect(
            ArmData::Calibration,
            object_set,
            objects,
            sensor,
            threads,
            observer,
        )
    }

    /// Collects `data` by its plans (one for the training data, one per calibration
    /// exploration), telling `observer`.
    fn collect(
        &self,
        data: ArmData,
        object_set: &str,
        objects: &[ObjectSpec],
        sensor: SensorConfig,
        threads: usize,
        observer: &mut dyn ArmTrainingObserver,
    ) -> Result<Vec<Dataset>, ArmTrainingError> {
        let (plans, readings) = match data {
            ArmData::Training => (vec![self.collect_plan(sensor)?], self.readings_per_object),
            ArmData::Calibration => (
                self.calibration_plans(sensor, objects)?,
                self.calibration_readings(),
            ),
        };
        observer.collecting(data, objects, readings);
        let watcher: &dyn ArmTrainingObserver = observer;
        let datasets = plans
            .iter()
            .map(|plan| plan.collect_dataset(object_set, objects, threads, &|| watcher.converged(data)))
            .collect::<Result<Vec<_>, _>>()?;
        let converged = datasets.iter().map(|d| d.converged().count()).sum();
        let short: Vec<Shortfall> = datasets
            .iter()
            .zip(&plans)
            .flat_map(|(d, plan)| d.shortfalls(plan.readings_per_object))
            .collect();
        observer.collected(data, converged, &short);
        Ok(datasets)
    }
}
