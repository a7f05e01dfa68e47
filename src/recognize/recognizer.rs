//! A model file of any kind, as `taction recognize` takes it: one descriptor's bag of features,
//! several fused (`recognize::fusion`), or either fused with contact geometry
//! (`recognize::geometric`).

use std::path::Path;

use crate::dataset::{Dataset, Perturbed};
use crate::recognize::RecognizeError;
use crate::recognize::calibration::{PosteriorRule, Tempering};
use crate::recognize::evaluate::{Evaluation, ReadingRange};
use crate::recognize::fusion::{DescriptorChoice, FusedModel};
use crate::recognize::geometric::{Appearance, GeometricFusion};
use crate::recognize::model::{TrainedModel, check_version, encode_json, read_model_file};
use crate::recognize::posterior::ModelPosterior;
use crate::tactile::SensorConfig;

/// A model file of either kind, as `taction recognize` takes it.
#[derive(Debug, Clone, PartialEq)]
pub enum Recognizer {
    Single(Box<TrainedModel>),
    Fused(Box<FusedModel>),
    /// Appearance (either of the above) fused with contact geometry (`recognize::geometric`).
    Geometric(Box<GeometricFusion>),
}

impl Recognizer {
    /// Reads a model written by `taction train`, fused (a `fused` list) or not.
    pub fn load(path: &Path) -> Result<Self, RecognizeError> {
        let (bytes, name) = read_model_file(path)?;
        Self::from_json(&bytes, &name)
    }

    /// Parses the contents of a model file ([`load`](Self::load)); `origin` names it in errors.
    pub fn from_json(bytes: &[u8], origin: &str) -> Result<Self, RecognizeError> {
        let value = serde_json::from_slice::<serde_json::Value>(bytes).ok();
        match value {
            Some(value) if value.get("geometry").is_some() => {
                check_version(&value, origin)?;
                Ok(Self::Geometric(Box::new(GeometricFusion::from_json(
                    value, origin,
                )?)))
            }
            _ => Ok(Appearance::from_json(bytes, origin)?.into()),
        }
    }

    /// The contents of its model file, what [`from_json`](Self::from_json) reads back.
    pub fn to_json(&self) -> Result<Vec<u8>, RecognizeError> {
        match self {
            Self::Single(m) => encode_json(m.as_ref(), "the model in memory"),
            Self::Fused(f) => encode_json(f, "the model in memory"),
            Self::Geometric(g) => g.to_json(),
        }
    }

    /// Writes the model file [`load`](Self::load) reads, atomically.
    pub fn save(&self, path: &Path) -> Result<(), RecognizeError> {
        match self {
            Self::Single(m) => m.save(path),
            Self::Fused(f) => f.save(path),
            Self::Geometric(g) => g.save(path),
        }
    }

    /// The descriptor name (`mnti`, `mnti+mn`).
    pub fn choice(&self) -> DescriptorChoice {
        match self {
            Self::Single(m) => DescriptorChoice::single(m.descriptor.kind()),
            Self::Fused(f) => f.choice(),
            Self::Geometric(g) => g.appearance().choice(),
        }
    }

    pub fn objects(&self) -> &[String] {
        match self {
            Self::Single(m) => m.bag.objects(),
            Self::Fused(f) => f.objects(),
            Self::Geometric(g) => g.objects(),
        }
    }

    /// The sensor the model was trained on (a fused model's parts share it, [`FusedModel::new`]):
    /// what data must be taken with to be recognised ([`check_same_sensor`](crate::recognize::check_same_sensor)).
    pub fn sensor(&self) -> &SensorConfig {
        match self {
            Self::Single(m) => &m.sensor,
            Self::Fused(f) => &f.fused[0].sensor,
            Self::Geometric(g) => g.sensor(),
        }
    }

    /// Each model's chosen codebook size, in order.
    pub fn chosen_ks(&self) -> Vec<usize> {
        match self {
            Self::Single(m) => vec![m.selection.chosen_k],
            Self::Fused(f) => f.fused.iter().map(|m| m.selection.chosen_k).collect(),
            Self::Geometric(g) => g
                .appearance()
                .parts()
                .iter()
                .map(|m| m.selection.chosen_k)
                .collect(),
        }
    }

    /// The same model with the posterior `rule` applies: the fitted tempering (the default) or
    /// the paper's Eq. 15 (`--posterior eq15`).
    pub fn with_posterior(self, rule: PosteriorRule) -> Self {
        match self {
            Self::Single(m) => Self::Single(Box::new(m.with_posterior(rule))),
            Self::Fused(f) => Self::Fused(Box::new(f.with_posterior(rule))),
            Self::Geometric(g) => Self::Geometric(Box::new(g.with_posterior(rule))),
        }
    }

    /// The same model with its posterior calibrated on the trials of every dataset of `data`
    /// together ([`TrainedModel::calibrate_on_all`]): explorations of several kinds, such as the
    /// blind planner's at L = 0.5 and at L = 1, whose readings are correlated to different degrees.
    pub fn calibrate_on_all(self, data: &[&Dataset], trial_readings: usize) -> Result<Self, RecognizeError> {
        Ok(match self {
            Self::Single(m) => Self::Single(Box::new(m.calibrate_on_all(data, trial_readings)?)),
            Self::Fused(f) => Self::Fused(Box::new(f.calibrate_on_all(data, trial_readings)?)),
            Self::Geometric(g) => Self::Geometric(Box::new(g.calibrate_on_all(data, trial_readings)?)),
        })
    }

    /// Whether the model weighs where each touch landed as well as what it felt (a posterior's
    /// readings then need their pad pose).
    pub fn weighs_contacts(&self) -> bool {
        matches!(self, Self::Geometric(_))
    }

    /// The tempering its posterior applies.
    pub fn tempering(&self) -> Tempering {
        match self {
            Self::Single(m) => m.bag.tempering(),
            Self::Fused(f) => f.tempering,
            Self::Geometric(g) => g.tempering(),
        }
    }

    /// A posterior that takes tactile images ([`ModelPosterior`]), of any kind of model, the
    /// object fixed.
    pub fn posterior(&self) -> Result<ModelPosterior<'_>, RecognizeError> {
        self.posterior_for(Perturbed::FIXED)
    }

    /// A posterior that takes tactile images of an object that `motion` perturbs after every
    /// touch (Sec. V-B4): a model that weighs the contacts follows each pose hypothesis through
    /// the moves with the weight fitted on moving objects (`recognize::geometric`); appearance
    /// does not depend on it.
    pub fn posterior_for(&self, motion: Perturbed) -> Result<ModelPosterior<'_>, RecognizeError> {
        match self {
            Self::Single(m) => m.posterior(),
            Self::Fused(f) => f.image_posterior(),
            Self::Geometric(g) => Ok(ModelPosterior::geometric(g.posterior(motion), g.descriptors()?)),
        }
    }

    /// Recognises `dataset` in trials of `range.last()` readings per object
    /// ([`TrainedModel::evaluate`]); also returns the number of trials.
    pub fn evaluate(
        &self,
        dataset: &Dataset,
        range: ReadingRange,
    ) -> Result<(Evaluation, usize), RecognizeError> {
        match self {
            Self::Single(model) => model.evaluate_counted(dataset, range),
            Self::Fused(fused) => {
                let trials = fused.trials(dataset, range.last())?;
                Ok((fused.evaluate(&trials, range)?, trials.len()))
            }
            Self::Geometric(g) => {
                let trials = g.trials(dataset, range.last())?;
                Ok((
                    g.evaluate(&trials, range, dataset.header().perturbation)?,
                    trials.len(),
                ))
            }
        }
    }
}

impl From<Appearance> for Recognizer {
    fn from(appearance: Appearance) -> Self {
        match appearance {
            Appearance::Single(m) => Self::Single(m),
            Appearance::Fused(f) => Self::Fused(f),
        }
    }
}

impl TryFrom<Recognizer> for Appearance {
    type Error = RecognizeError;

    /// The appearance model a recogniser is, refusing one already fused with geometry.
    fn try_from(recognizer: Recognizer) -> Result<Self, RecognizeError> {
        match recognizer {
            Recognizer::Single(m) => Ok(Self::Single(m)),
            Recognizer::Fused(f) => Ok(Self::Fused(f)),
            Recognizer::Geometric(_) => Err(RecognizeError::InvalidParameter {
                name: "geometric model",
                what: "the appearance model is already fused with geometry".into(),
            }),
        }
    }
}
