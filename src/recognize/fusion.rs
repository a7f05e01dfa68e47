//! Descriptor fusion (beyond the paper): one recogniser from several descriptors of the same
//! readings, named `a+b` wherever a descriptor name is accepted (e.g. `mnti+mn`: MNTI and
//! Moment-Normalized).
//!
//! A fused model is nothing but one [`TrainedModel`] per descriptor, each trained (Fig. 4, with its
//! own PCA, codebook and model selection) on the same training and validation datasets. Every
//! model scores a reading on its own; the fused log-likelihood of object `O_j` is the sum of the
//! models' `ln p(U | O_j)` (Eq. 15-16), i.e. the product of their likelihoods, as if the descriptors
//! were independent given the object, and the posterior is its softmax under a uniform prior. Two
//! descriptors that err on different objects then correct each other, and the more differently
//! they describe a patch the more they do: SIFT's gradient orientations (Sec. IV-B2) beside MNTI's
//! normalised moments (Sec. IV-B6) gain more than two descriptors built on the same moments. The
//! measurements are in docs/measurements.md, "What resolution and a second descriptor buy".

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::dataset::Dataset;
use crate::describe::{DescriptorKind, Feature};
use crate::recognize::RecognizeError;
use crate::recognize::calibration::{EvidencePath, PosteriorRule, Tempering};
use crate::recognize::evaluate::{Evaluation, ReadingRange, evaluate_with};
use crate::recognize::labelled::LabelledFeatures;
use crate::recognize::model::{MODEL_FORMAT_VERSION, TrainedModel, check_same_sensor, save_json};
use crate::recognize::posterior::{FusedPosterior, ModelPosterior};
use crate::recognize::selection::TrainConfig;
use crate::recognize::trial::{Trial, make_trials};

/// A descriptor name that names no descriptor, or a fusion that names one twice or none.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DescriptorChoiceError {
    #[error("no descriptor named")]
    Empty,
    #[error("'{0}' is named twice")]
    Repeated(&'static str),
    #[error(
        "unknown descriptor '{part}' in '{text}'; expected one of {} (short: mn, pf), or several \
         joined by '+' (e.g. mnti+sift)",
        DescriptorKind::ALL.map(DescriptorKind::name).join(", ")
    )]
    Unknown { part: String, text: String },
    #[error("descriptor '{text}': {error}")]
    In {
        text: String,
        error: Box<DescriptorChoiceError>,
    },
}

/// One descriptor or several fused: the parsed form of a descriptor name such as `mnti` or
/// `mnti+mn`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct DescriptorChoice {
    kinds: Vec<DescriptorKind>,
}

impl DescriptorChoice {
    /// One descriptor.
    pub fn single(kind: DescriptorKind) -> Self {
        Self { kinds: vec![kind] }
    }

    /// Several descriptors fused; at least one, no repeats.
    pub fn fused(kinds: Vec<DescriptorKind>) -> Result<Self, DescriptorChoiceError> {
        if kinds.is_empty() {
            return Err(DescriptorChoiceError::Empty);
        }
        if let Some(i) = (0..kinds.len()).find(|&i| kinds[..i].contains(&kinds[i])) {
            return Err(DescriptorChoiceError::Repeated(kinds[i].name()));
        }
        Ok(Self { kinds })
    }

    /// Parses `name` or `name+name+...` (each a [`DescriptorKind::from_name`] name).
    pub fn parse(text: &str) -> Result<Self, DescriptorChoiceError> {
        let kinds = text
            .split('+')
            .map(|part| {
                DescriptorKind::from_name(part.trim()).ok_or_else(|| DescriptorChoiceError::Unknown {
                    part: part.to_string(),
                    text: text.to_string(),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Self::fused(kinds).map_err(|e| DescriptorChoiceError::In {
            text: text.to_string(),
            error: Box::new(e),
        })
    }

    pub fn kinds(&self) -> &[DescriptorKind] {
        &self.kinds
    }

    /// Whether more than one descriptor is fused.
    pub fn is_fused(&self) -> bool {
        self.kinds.len() > 1
    }

    /// The canonical name: the short names joined by `+`.
    pub fn name(&self) -> String {
        self.kinds
            .iter()
            .map(|k| k.short_name())
            .collect::<Vec<_>>()
            .join("+")
    }
}

/// One trained model per descriptor, over the same objects in the same order and the same sensor
/// (the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FusedModel {
    pub format_version: u32,
    /// The models, in the order of the fused name.
    pub fused: Vec<TrainedModel>,
    /// The fused posterior's tempering (`recognize::calibration`), fitted on the fused
    /// validation trials: the parts' evidence overlaps (they describe the same readings), which no
    /// part's own tempering knows. A file written before calibration existed has none: Eq. 15.
    #[serde(default)]
    pub tempering: Tempering,
}

impl FusedModel {
    /// Checks that the models can be fused: at least two, distinct descriptors, the same objects in
    /// the same order, the same sensor.
    pub fn new(models: Vec<TrainedModel>) -> Result<Self, RecognizeError> {
        let invalid = |what: String| RecognizeError::InvalidParameter {
            name: "fused models",
            what,
        };
        let Some(first) = models.first() else {
            return Err(invalid("no model".into()));
        };
        if models.len() < 2 {
            return Err(invalid("fusion needs at least two models".into()));
        }
        DescriptorChoice::fused(models.iter().map(|m| m.descriptor.kind()).collect())
            .map_err(|e| invalid(e.to_string()))?;
        for m in &models[1..] {
            if m.bag.objects() != first.bag.objects() {
                return Err(invalid(format!(
                    "{} and {} models know different objects ({:?} vs {:?})",
                    first.descriptor.kind().name(),
                    m.descriptor.kind().name(),
                    first.bag.objects(),
                    m.bag.objects()
                )));
            }
            check_same_sensor(&first.sensor, &m.sensor)?;
        }
        Ok(Self {
            format_version: MODEL_FORMAT_VERSION,
            fused: models,
            tempering: Tempering::EQ15,
        })
    }

    /// The same models with the fused posterior's tempering fitted on the validation trials
    /// they were chosen on (`validation`, or the readings held out of `training` by `config`):
    /// what [`train_recognizer`](crate::recognize::train_recognizer) does after fitting the parts.
    pub fn calibrated(
        mut self,
        config: &TrainConfig,
        training: &Dataset,
        validation: Option<&Dataset>,
    ) -> Result<Self, RecognizeError> {
        let trials = self.validation_trials(config, training, validation)?;
        self.tempering = Tempering::fit(&self.evidence_paths(&trials)?);
        Ok(self)
    }

    /// The same models with the fused posterior's tempering fitted again on the converged
    /// readings of every dataset of `data` together, in trials of `trial_readings`
    /// ([`TrainedModel::calibrate_on_all`]).
    pub fn calibrate_on_all(
        mut self,
        data: &[&Dataset],
        trial_readings: usize,
    ) -> Result<Self, RecognizeError> {
        let mut trials = Vec::new();
        for dataset in data {
            trials.extend(self.trials(dataset, trial_readings)?);
        }
        self.tempering = Tempering::fit_with_confidence_map(&self.evidence_paths(&trials)?);
        Ok(self)
    }

    /// The validation trials every part was chosen on, fused: `validation` when given, else the
    /// readings each part held out of `training` ([`TrainConfig::holdout`]).
    fn validation_trials(
        &self,
        config: &TrainConfig,
        training: &Dataset,
        validation: Option<&Dataset>,
    ) -> Result<Vec<Trial<Vec<Vec<Feature>>>>, RecognizeError> {
        if let Some(v) = validation {
            return self.trials(v, config.trial_readings);
        }
        let per_model = self
            .fused
            .iter()
            .map(|model| {
                let descriptor = model.build_descriptor()?;
                let features = LabelledFeatures::from_dataset(training, descriptor.as_ref());
                let (_, held_out) = features.split_validation(config.holdout)?;
                make_trials(&held_out, self.objects(), config.trial_readings)
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(zip_trials(per_model))
    }

    /// Each fused trial's summed Eq. 15 log-likelihoods after each reading.
    fn evidence_paths(
        &self,
        trials: &[Trial<Vec<Vec<Feature>>>],
    ) -> Result<Vec<EvidencePath>, RecognizeError> {
        trials
            .iter()
            .map(|trial| {
                let mut posterior = self.posterior();
                EvidencePath::of(trial, |reading| {
                    posterior.observe(reading)?;
                    Ok(posterior.log_likelihoods())
                })
            })
            .collect()
    }

    /// The same models with the posterior `rule` applies: the fitted tempering or Eq. 15.
    pub fn with_posterior(mut self, rule: PosteriorRule) -> Self {
        self.tempering = rule.tempering(self.tempering);
        self
    }

    /// The objects, in the models' (common) order.
    pub fn objects(&self) -> &[String] {
        self.fused[0].bag.objects()
    }

    /// The fused descriptor name.
    pub fn choice(&self) -> DescriptorChoice {
        DescriptorChoice {
            kinds: self.fused.iter().map(|m| m.descriptor.kind()).collect(),
        }
    }

    /// A posterior that takes one feature list per model for every reading.
    pub fn posterior(&self) -> FusedPosterior<'_> {
        FusedPosterior {
            parts: self.fused.iter().map(|m| m.bag.posterior()).collect(),
            tempering: self.tempering,
        }
    }

    /// A posterior that takes tactile images, describing each with every model's descriptor
    /// ([`ModelPosterior`]).
    pub fn image_posterior(&self) -> Result<ModelPosterior<'_>, RecognizeError> {
        let descriptors = self
            .fused
            .iter()
            .map(TrainedModel::build_descriptor)
            .collect::<Result<Vec<_>, _>>()?;
        Ok(ModelPosterior::fused(self.posterior(), descriptors))
    }

    /// Writes the model as JSON, atomically.
    pub fn save(&self, path: &Path) -> Result<(), RecognizeError> {
        save_json(self, path)
    }

    /// Parses a fused model file: every part is checked as a model file of its own
    /// ([`TrainedModel::from_json`]), then the parts against each other ([`new`](Self::new)).
    pub fn from_json(value: &serde_json::Value, origin: &str) -> Result<Self, RecognizeError> {
        let parts = value
            .get("fused")
            .and_then(serde_json::Value::as_array)
            .ok_or_else(|| RecognizeError::NotAModel {
                path: origin.to_string(),
                what: "'fused' is not a list of models".into(),
            })?;
        let models = parts
            .iter()
            .enumerate()
            .map(|(i, part)| {
                let bytes = serde_json::to_vec(part).map_err(|e| RecognizeError::NotAModel {
                    path: origin.to_string(),
                    what: e.to_string(),
                })?;
                TrainedModel::from_json(&bytes, &format!("{origin} (fused model {})", i + 1))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let tempering = match value.get("tempering") {
            None => Tempering::EQ15,
            Some(t) => Tempering::deserialize(t).map_err(|e| RecognizeError::Inconsistent {
                path: origin.to_string(),
                what: format!("tempering: {e}"),
            })?,
        };
        let fused = Self::new(models).map_err(|e| RecognizeError::Inconsistent {
            path: origin.to_string(),
            what: e.to_string(),
        })?;
        Ok(Self { tempering, ..fused })
    }

    /// Each reading of `dataset` described by every model's descriptor, as trials of up to
    /// `readings_per_trial` readings ([`TrainedModel::trials`]).
    pub fn trials(
        &self,
        dataset: &Dataset,
        readings_per_trial: usize,
    ) -> Result<Vec<Trial<Vec<Vec<Feature>>>>, RecognizeError> {
        let per_model = self
            .fused
            .iter()
            .map(|model| model.trials(dataset, readings_per_trial))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(zip_trials(per_model))
    }

    /// Recognition touch by touch over `trials` (as [`evaluate`](crate::recognize::evaluate())).
    pub fn evaluate(
        &self,
        trials: &[Trial<Vec<Vec<Feature>>>],
        range: ReadingRange,
    ) -> Result<Evaluation, RecognizeError> {
        evaluate_with(self.objects(), trials, range, || {
            let mut posterior = self.posterior();
            move |reading: &Vec<Vec<Feature>>| posterior.observe(reading)
        })
    }
}

/// Trials of the same readings described by several descriptors, zipped reading by reading. The
/// lists come from one dataset, so they agree in objects and lengths.
fn zip_trials(per_model: Vec<Vec<Trial>>) -> Vec<Trial<Vec<Vec<Feature>>>> {
    let mut models = per_model.into_iter();
    let Some(first) = models.next() else {
        return Vec::new();
    };
    let mut zipped: Vec<Trial<Vec<Vec<Feature>>>> = first
        .into_iter()
        .map(|t| Trial {
            object: t.object,
            readings: t.readings.into_iter().map(|r| vec![r]).collect(),
        })
        .collect();
    for trials in models {
        for (z, t) in zipped.iter_mut().zip(trials) {
            for (reading, features) in z.readings.iter_mut().zip(t.readings) {
                reading.push(features);
            }
        }
    }
    zipped
}
