//! The demo's recipe for a recogniser of the arm's own touches (beyond the paper): what it
//! collects, how it trains and calibrates, and [`ArmTrainingRecipe::train`], the whole of it for
//! `taction demo`, Python's `arm_model` and the Gymnasium environments' default model alike.

use crate::dataset::{Dataset, Shortfall};
use crate::describe::DescriptorKind;
use crate::explore::collect::{CollectError, CollectMode, CollectPlan};
use crate::explore::{PlannerConfig, SamplerConfig};
use crate::recognize::{
    CodebookKind, DescriptorChoice, DescriptorChoiceError, FusedModel, RecognizeError, Recognizer,
    TrainChoices, TrainConfig, TrainData, train_recognizer,
};
use crate::sim::{ObjectSpec, PerturbationBounds, StartPose};
use crate::tactile::SensorConfig;
use crate::valid::{RangeError, Valid};

/// The stream of the recipe's seed its calibration explorations draw from.
const CALIBRATION_SEED_STREAM: u64 = 7;

/// How the demo trains a recogniser on what the arm's pad feels (the README's "Training that
/// matches the arm"; docs/measurements.md has the measurements behind each choice): sampler
/// readings restricted to the starts the arm can take from any heading of the object, pressed by
/// the same controllers as the arm's pad; MNTI and SIFT fused ([`Self::DESCRIPTORS`]: SIFT's
/// gradient orientations with MNTI's moments gained on the arm's own touches as on sampler data)
/// over the neighbour codebook, one restart (the neighbour codebook draws nothing at random), the
/// `k` grid sized to the converged readings left after the hold-out
/// ([`TrainConfig::with_grid_for_dataset`]). Library users get the model `taction demo` gets.
///
/// ```
/// use taction::active_touch::ArmTrainingRecipe;
///
/// let recipe = ArmTrainingRecipe { readings_per_object: 3000, seed: 1 };
/// assert_eq!(recipe.descriptors()?.name(), "mnti+sift");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArmTrainingRecipe {
    /// Converged sampler readings per object.
    pub readings_per_object: usize,
    /// Seeds the training data and the model selection.
    pub seed: u64,
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
            calibration_trial_readings: Some(10),
            ..TrainChoices::of(descriptor)
        };
        Valid::new(choices)
    }

    /// Model selection for `training` (validation held out of it).
    pub fn train_config(&self, training: &Dataset) -> Result<Valid<TrainConfig>, RecognizeError> {
        self.choices()?.config(training, false)
    }

    /// Converged readings per object of the arm's own explorations the posterior is calibrated
    /// on: a thirtieth of the training readings, 10 to 100 (100 for the demo's 3000).
    pub fn calibration_readings(&self) -> usize {
        (self.readings_per_object / 30).clamp(10, 100)
    }

    /// The calibration data's collection: the arm exploring blind (L = 0.5, the object fixed) with
    /// the default controllers, [`calibration_readings`](Self::calibration_readings) per object of
    /// `objects`, on a seed of its own.
    pub fn calibration_plan(
        &self,
        sensor: SensorConfig,
        objects: &[ObjectSpec],
    ) -> Result<CollectPlan, RangeError> {
        let readings = self.calibration_readings();
        Ok(CollectPlan {
            mode: CollectMode::Planner(Valid::new(PlannerConfig::for_collection(
                objects, readings, 0.5, None,
            ))?),
            sensor,
            control: Valid::default(),
            perturbation: PerturbationBounds::NONE,
            readings_per_object: readings,
            seed: crate::rng::substream(self.seed, CALIBRATION_SEED_STREAM),
            start_pose: StartPose::Canonical,
        })
    }

    /// Trains the fused model on `training` (collected by [`collect_plan`](Self::collect_plan))
    /// and, given the arm's explorations `calibration` ([`calibration_plan`](Self::calibration_plan)),
    /// calibrates its posterior on them (`recognize::calibration`: the arm's successive touches
    /// are correlated, which the sampler's held-out readings cannot show); without them the
    /// posterior is calibrated on the held-out readings.
    pub fn fit(
        &self,
        training: &Dataset,
        calibration: Option<&Dataset>,
    ) -> Result<FusedModel, RecognizeError> {
        let data = TrainData {
            training,
            validation: None,
            calibration: calibration.as_slice(),
            contacts: None,
        };
        match train_recognizer(&self.choices()?, data, &mut ())? {
            Recognizer::Fused(model) => Ok(*model),
            _ => Err(RecognizeError::InvalidParameter {
                name: "descriptors",
                what: "the recipe fuses two descriptors".into(),
            }),
        }
    }
}

/// The two collections of [`ArmTrainingRecipe::train`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArmData {
    /// The sampler's readings the model is fitted on ([`ArmTrainingRecipe::collect_plan`]).
    Training,
    /// The arm's explorations its posterior is calibrated on
    /// ([`ArmTrainingRecipe::calibration_plan`]).
    Calibration,
}

/// What [`ArmTrainingRecipe::train`] tells whoever runs it (the demo prints progress bars and
/// warnings, Python turns shortfalls into warnings). Every method does nothing by default.
pub trait ArmTrainingObserver: Sync {
    /// `data`'s collection starts: `readings` converged readings of each of `objects`.
    fn collecting(&mut self, _data: ArmData, _objects: &[ObjectSpec], _readings: usize) {}
    /// One converged reading of `data` was gathered, on whichever worker thread gathered it.
    fn converged(&self, _data: ArmData) {}
    /// `data` is collected; `short` lists the objects it gathered fewer readings of than asked
    /// (the planner may run out of iterations on an object the arm reaches badly).
    fn collected(&mut self, _data: ArmData, _dataset: &Dataset, _short: &[Shortfall]) {}
    /// The fit starts: model selection `config` over `features` training features.
    fn fitting(&mut self, _config: &TrainConfig, _features: usize) {}
}

impl ArmTrainingObserver for () {}

/// What [`ArmTrainingRecipe::train`] made: the model and the two datasets behind it.
#[derive(Debug, Clone)]
pub struct ArmTraining {
    /// The fused model, its posterior calibrated on `calibration` (on the readings held out of
    /// `training` when `calibration` has no converged reading: check
    /// [`calibrated_on_the_arm`](Self::calibrated_on_the_arm)).
    pub model: FusedModel,
    pub training: Dataset,
    pub calibration: Dataset,
}

impl ArmTraining {
    /// Whether the arm's explorations calibrated the posterior. When they gave no converged
    /// reading the held-out sampler readings did, and the posterior counts the arm's correlated
    /// touches as independent evidence: overconfident.
    pub fn calibrated_on_the_arm(&self) -> bool {
        self.calibration.converged().next().is_some()
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
}

impl ArmTrainingRecipe {
    /// The whole recipe on `objects` (of the set with id `object_set`, which the datasets'
    /// headers record) touched by `sensor`: collects the training data and the arm's calibration
    /// explorations on `threads` threads (0: all cores), then fits and calibrates the model.
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
        let training = self.collect(ArmData::Training, object_set, objects, sensor, threads, observer)?;
        let calibration = self.collect(
            ArmData::Calibration,
            object_set,
            objects,
            sensor,
            threads,
            observer,
        )?;
        let config = self.train_config(&training)?;
        let converged = training.converged().count();
        observer.fitting(&config, config.grid_training_features(converged, false));
        let model = self.fit(&training, Some(&calibration))?;
        Ok(ArmTraining {
            model,
            training,
            calibration,
        })
    }

    /// Collects `data` by its plan, telling `observer`.
    fn collect(
        &self,
        data: ArmData,
        object_set: &str,
        objects: &[ObjectSpec],
        sensor: SensorConfig,
        threads: usize,
        observer: &mut dyn ArmTrainingObserver,
    ) -> Result<Dataset, ArmTrainingError> {
        let (plan, readings) = match data {
            ArmData::Training => (self.collect_plan(sensor)?, self.readings_per_object),
            ArmData::Calibration => (
                self.calibration_plan(sensor, objects)?,
                self.calibration_readings(),
            ),
        };
        observer.collecting(data, objects, readings);
        let watcher: &dyn ArmTrainingObserver = observer;
        let dataset = plan.collect_dataset(object_set, objects, threads, &|| watcher.converged(data))?;
        observer.collected(data, &dataset, &dataset.shortfalls(readings));
        Ok(dataset)
    }
}
