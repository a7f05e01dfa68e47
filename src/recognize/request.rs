//! The one way a user's choices become a recogniser: what `taction train` and Python's
//! `taction.train` both hand over ([`TrainChoices`], [`TrainData`]) and [`train_recognizer`], which
//! fits one model per descriptor (Sec. IV-A, choosing each codebook on validation data as Sec.
//! V-B1 does), fuses several (their likelihoods multiplied), adds the contacts' geometry when asked,
//! and calibrates the posterior on the arm's explorations. The edges parse arguments and print; the
//! choice between a single and a fused model, and the order of the steps, live here only.

use crate::dataset::Dataset;
use crate::describe::DescriptorKind;
use crate::locate::GeometryModel;
use crate::recognize::RecognizeError;
use crate::recognize::calibration::Tempering;
use crate::recognize::codebook::CodebookKind;
use crate::recognize::fusion::{DescriptorChoice, FusedModel};
use crate::recognize::geometric::{Appearance, GeometricFusion};
use crate::recognize::model::TrainedModel;
use crate::recognize::object_model::PseudoCount;
use crate::recognize::pca::VarianceFraction;
use crate::recognize::recognizer::Recognizer;
use crate::recognize::selection::{TrainConfig, TrainProgress};
use crate::valid::{Check, Valid};

/// What a user chooses when training: the descriptors, the codebook and its grid, the seed, and
/// the length of the trials the posterior is calibrated on. Plain data, checked once
/// ([`Valid<TrainChoices>`]) before any dataset is read.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainChoices {
    /// One descriptor, or several whose models are fused.
    pub descriptor: DescriptorChoice,
    pub codebook: CodebookKind,
    /// The cluster (or neighbour) counts to try; `None`: a grid sized to the training data
    /// ([`TrainConfig::with_grid_for_dataset`]).
    pub ks: Option<Vec<usize>>,
    pub restarts: usize,
    pub seed: u64,
    /// `None`: the codebook's own default ([`CodebookKind::default_variance_kept`]).
    pub variance_kept: Option<VarianceFraction>,
    pub pseudo_count: PseudoCount,
    /// Readings per validation trial.
    pub trial_readings: usize,
    /// Readings per calibration trial; `None`: each object's readings of a calibration
    /// exploration as one trial.
    pub calibration_trial_readings: Option<usize>,
}

impl TrainChoices {
    /// The choices of `descriptor` with every other field at the product's default: the
    /// codebook of [`default_codebook`](Self::default_codebook), three restarts, seed 1, trials
    /// of 10.
    pub fn of(descriptor: DescriptorChoice) -> Self {
        Self {
            codebook: Self::default_codebook(&descriptor),
            descriptor,
            ks: None,
            restarts: 3,
            seed: 1,
            variance_kept: None,
            pseudo_count: PseudoCount::LAPLACE,
            trial_readings: 10,
            calibration_trial_readings: None,
        }
    }

    /// The product's codebook for `descriptor`: the network ([`CodebookKind::Mlp`]) for the shape
    /// index alone, whose one feature holds a large array's whole contact (on the large-array
    /// benchmark 64.5% from one frame and 95.4% from five, against the neighbour codebook's 49.3%
    /// and 86.5%; docs/measurements.md, "A large array"); the neighbour codebook for every other
    /// choice (the 52 letters at 94.2% against the GMM's 78.8%, "A neighbour codebook").
    pub fn default_codebook(descriptor: &DescriptorChoice) -> CodebookKind {
        if descriptor.kinds() == [DescriptorKind::ShapeIndex] {
            CodebookKind::Mlp
        } else {
            CodebookKind::Knn
        }
    }

    /// The training configuration these choices give on `training` (a grid sized to it unless
    /// `ks` names one; `validated`: a separate validation dataset takes no readings from it).
    pub fn config(&self, training: &Dataset, validated: bool) -> Result<Valid<TrainConfig>, RecognizeError> {
        let config = self.config_without_grid();
        let config = match &self.ks {
            Some(ks) => TrainConfig {
                ks: ks.clone(),
                ..config
            },
            None => config.with_grid_for_dataset(training, validated),
        };
        Valid::new(config)
    }

    fn config_without_grid(&self) -> TrainConfig {
        TrainConfig {
            codebook: self.codebook,
            restarts: self.restarts,
            seed: self.seed,
            variance_kept: self
                .variance_kept
                .unwrap_or(self.codebook.default_variance_kept()),
            pseudo_count: self.pseudo_count,
            trial_readings: self.trial_readings,
            ks: self.ks.clone().unwrap_or_else(|| TrainConfig::default().ks),
            ..TrainConfig::default()
        }
    }
}

impl Check for TrainChoices {
    type Error = RecognizeError;

    /// The training configuration's own check (named as its fields are), and calibration trials
    /// of one reading or more.
    fn check(&self) -> Result<(), RecognizeError> {
        let Self {
            descriptor: _,
            codebook: _,
            ks: _,
            restarts: _,
            seed: _,
            variance_kept: _,
            pseudo_count: _,
            trial_readings: _,
            calibration_trial_readings,
        } = self;
        self.config_without_grid().check()?;
        if *calibration_trial_readings == Some(0) {
            return Err(RecognizeError::InvalidParameter {
                name: "calibration_trial_readings",
                what: "want 1 or more".into(),
            });
        }
        Ok(())
    }
}

/// The data a recogniser is trained on.
#[derive(Debug, Clone, Copy)]
pub struct TrainData<'a> {
    /// The appearance model's training readings (converged ones are used).
    pub training: &'a Dataset,
    /// Readings the codebook is chosen on; `None`: the last 1/11 of each object's training
    /// readings are held out.
    pub validation: Option<&'a Dataset>,
    /// The arm's explorations the posterior's tempering (and the weight of the contacts) is
    /// fitted on, together; none: the validation trials fit them.
    pub calibration: &'a [&'a Dataset],
    /// The surfaces of the training dataset's objects, in its order: the model then also weighs
    /// where each touch landed (`recognize::geometric`).
    pub contacts: Option<&'a GeometryModel>,
}

impl TrainData<'_> {
    fn check(&self) -> Result<(), RecognizeError> {
        check_contacts_weighable(
            self.contacts.is_some(),
            !self.calibration.is_empty(),
            self.validation.is_some(),
        )
    }
}

/// The contacts' weight is fitted on explorations the appearance model was not trained on:
/// training with `contacts` needs `calibration` explorations or a `validation` dataset. An edge
/// asks before it reads any dataset; [`train_recognizer`] asks again of the data it is given.
pub fn check_contacts_weighable(
    contacts: bool,
    calibration: bool,
    validation: bool,
) -> Result<(), RecognizeError> {
    if contacts && !calibration && !validation {
        return Err(RecognizeError::InvalidParameter {
            name: "objects",
            what: "the fusion of appearance and contact geometry is weighed on explorations the \
                   appearance model was not trained on: give calibration (the arm's explorations) \
                   or validation"
                .into(),
        });
    }
    Ok(())
}

/// What training says as it goes, for an edge that shows it (a progress bar, a report). Every
/// method does nothing unless overridden; `()` shows nothing.
pub trait TrainObserver: Send {
    /// The fit of `kind`'s model moved on.
    fn progress(&mut self, _kind: DescriptorKind, _event: TrainProgress) {}
    /// One descriptor's model is fitted, its codebook chosen and its posterior calibrated on
    /// the validation trials.
    fn fitted(&mut self, _model: &TrainedModel) {}
    /// Several descriptors' models are fused, the fused posterior calibrated on the validation
    /// trials.
    fn fused(&mut self, _tempering: Tempering) {}
    /// The contacts' weight (and the posterior) fitted on the validation trials, there being no
    /// calibration exploration.
    fn weighed_on_validation(&mut self, _model: &Recognizer) {}
    /// The posterior (and the contacts' weight) fitted on the calibration explorations.
    fn calibrated(&mut self, _model: &Recognizer) {}
}

impl TrainObserver for () {}

/// Trains the recogniser `choices` ask for on `data`: a model per descriptor, fused when there
/// are several, fused with the contacts' geometry when `data` has it, calibrated on
/// `data.calibration` when there is any.
pub fn train_recognizer(
    choices: &Valid<TrainChoices>,
    data: TrainData<'_>,
    observer: &mut dyn TrainObserver,
) -> Result<Recognizer, RecognizeError> {
    data.check()?;
    let config = choices.config(data.training, data.validation.is_some())?;
    let appearance = appearance(choices, &config, data, observer)?;
    let model = match data.contacts {
        None => appearance,
        Some(geometry) => with_contacts(appearance, geometry, &config, data, observer)?,
    };
    if data.calibration.is_empty() {
        return Ok(model);
    }
    let trial_readings = choices.calibration_trial_readings.unwrap_or(usize::MAX);
    let model = model
        .calibrate_on_all(data.calibration, trial_readings)
        .map_err(|e| RecognizeError::Calibration(Box::new(e)))?;
    observer.calibrated(&model);
    Ok(model)
}

/// The bag-of-features model of each descriptor, fused when there are several.
fn appearance(
    choices: &TrainChoices,
    config: &Valid<TrainConfig>,
    data: TrainData<'_>,
    observer: &mut dyn TrainObserver,
) -> Result<Recognizer, RecognizeError> {
    let mut models = Vec::new();
    for &kind in choices.descriptor.kinds() {
        let descriptor = kind.build();
        let mut progress = |event| observer.progress(kind, event);
        let model = TrainedModel::fit(
            config,
            data.training,
            data.validation,
            descriptor.as_ref(),
            &mut progress,
        )?;
        observer.fitted(&model);
        models.push(model);
    }
    if !choices.descriptor.is_fused() {
        let model = models
            .into_iter()
            .next()
            .ok_or(RecognizeError::InvalidParameter {
                name: "descriptor",
                what: "no descriptor to train".into(),
            })?;
        return Ok(Recognizer::Single(Box::new(model)));
    }
    let fused = FusedModel::new(models)?.calibrated(config, data.training, data.validation)?;
    observer.fused(fused.tempering);
    Ok(Recognizer::Fused(Box::new(fused)))
}

/// `appearance` fused with the contacts' geometry, weighed on the validation trials when no
/// calibration exploration will weigh it.
fn with_contacts(
    appearance: Recognizer,
    geometry: &GeometryModel,
    config: &TrainConfig,
    data: TrainData<'_>,
    observer: &mut dyn TrainObserver,
) -> Result<Recognizer, RecognizeError> {
    let fused = GeometricFusion::new(Appearance::try_from(appearance)?, geometry.clone())?;
    let model = Recognizer::Geometric(Box::new(fused));
    match data.validation {
        Some(validation) if data.calibration.is_empty() => {
            let model = model.calibrate_on_all(&[validation], config.trial_readings)?;
            observer.weighed_on_validation(&model);
            Ok(model)
        }
        _ => Ok(model),
    }
}
