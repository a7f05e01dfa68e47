//! Appearance fused with contact geometry (beyond the paper): the recogniser that knows where it
//! touched.
//!
//! The bag of features (Sec. IV) sees each tactile image alone; the geometric model
//! (`locate::GeometryModel`) matches the contacts of the touches so far against every object's
//! known surface at a pose it is not told. The fused log-likelihood of object `O_j` after `n`
//! readings is
//!
//! ```text
//! E_j(n) = A_j(n) + lambda G_j(n)
//! ```
//!
//! `A` the appearance model's Eq. 15 log-likelihood (summed over fused descriptors), `G` the
//! geometric one, and the posterior is `E`'s tempered softmax (`recognize::calibration`). The
//! weight `lambda` is chosen on calibration explorations as Sec. V-B1 chooses a codebook: the
//! most right guesses over every prefix of every exploration, ties broken by how well the
//! tempered posterior then predicts (its log loss); the tempering is fitted at that weight. A
//! touch's appearance and its place are not independent evidence (a touch of a flat face looks
//! flat and lies on a plane), and the weight is what the data say they are worth together.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::dataset::{Dataset, Perturbed};
use crate::describe::{Descriptor, Feature};
use crate::locate::{ContactNoise, GeometryModel, Touch};
use crate::recognize::RecognizeError;
use crate::recognize::calibration::{EvidencePath, PosteriorRule, Tempering};
use crate::recognize::evaluate::{Evaluation, ReadingRange, evaluate_with};
use crate::recognize::fusion::{DescriptorChoice, FusedModel};
use crate::recognize::model::{MODEL_FORMAT_VERSION, TrainedModel, check_version, encode_json, save_json};
use crate::recognize::object_model::guess_of;
use crate::recognize::posterior::{EvidenceWeights, FusedPosterior, GeometricPosterior, TouchReading};
use crate::recognize::trial::Trial;
use crate::tactile::{SensorConfig, TactileImage};

/// The weights of the geometric evidence tried when fitting (`lambda`, the module docs); 0 is
/// appearance alone, so the fit can never do worse on its calibration data than appearance.
const GEOMETRY_WEIGHTS: [f64; 12] = [0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0];

/// The evidence a geometric model's posterior weighs: both (the product), or one of its two
/// parts alone, each with the tempering fitted for it on the same calibration explorations (what
/// an experiment comparing them, and a check that the contacts learnt no pose, need).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Evidence {
    /// `A + lambda G` (the module docs).
    #[default]
    Fused,
    /// The bag of features alone, `A`: the paper's recogniser.
    Appearance,
    /// The contacts alone, `G`.
    Contacts,
}

impl Evidence {
    /// The names [`name`](Self::name) gives and [`parse`](Self::parse) takes.
    pub const NAMES: [&'static str; 3] = ["fused", "appearance", "contacts"];

    pub fn name(&self) -> &'static str {
        match self {
            Self::Fused => Self::NAMES[0],
            Self::Appearance => Self::NAMES[1],
            Self::Contacts => Self::NAMES[2],
        }
    }

    pub fn parse(name: &str) -> Option<Self> {
        [Self::Fused, Self::Appearance, Self::Contacts]
            .into_iter()
            .find(|e| e.name() == name)
    }
}

/// An appearance model and a geometric model of the same objects, fused (the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GeometricFusion {
    appearance: Appearance,
    geometry: GeometryModel,
    /// `lambda`: the weight of the geometric log-likelihood, for an object that stays where it
    /// stands.
    geometry_weight: f64,
    tempering: Tempering,
    /// The weight and tempering for an object moved after every touch (Sec. V-B4), fitted apart
    /// on perturbed explorations: the geometric evidence of a moving object is weaker and, where
    /// the object has drifted far from where it started, misleading. `None`: no perturbed
    /// calibration was given, and a moving object is recognised by appearance alone.
    moving: Option<Weighing>,
    /// The error added to every simulated contact before it is matched (`locate::ContactNoise`):
    /// the arm's, so that the model does not lean on the simulator's exactness.
    contact_noise: ContactNoise,
    /// The temperings of appearance alone and of the contacts alone, fitted beside the fused
    /// weighing (`None` for a model calibrated before they were).
    alone: Option<AloneTemperings>,
    /// What the posterior weighs ([`Evidence::Fused`] unless [`with_evidence`](Self::with_evidence)
    /// says otherwise); a choice of use, not part of the model file.
    evidence: Evidence,
}

/// A weight of the geometric evidence and the tempering fitted at it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Weighing {
    pub geometry_weight: f64,
    pub tempering: Tempering,
}

/// The tempering of each part of the evidence alone ([`Evidence`]), for an object that stays
/// where it stands and, when perturbed explorations calibrated the model, for a moving one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AloneTemperings {
    pub appearance: Tempering,
    pub contacts: Tempering,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moving_appearance: Option<Tempering>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moving_contacts: Option<Tempering>,
}

impl AloneTemperings {
    /// The tempering fitted for `part` alone (appearance unless [`Evidence::Contacts`]) of an
    /// object that stays (`fixed`) or moves; `None` where no perturbed exploration fitted one.
    fn of(&self, part: Evidence, fixed: bool) -> Option<Tempering> {
        match (part, fixed) {
            (Evidence::Contacts, true) => Some(self.contacts),
            (Evidence::Contacts, false) => self.moving_contacts,
            (_, true) => Some(self.appearance),
            (_, false) => self.moving_appearance,
        }
    }
}

/// The model file: the appearance model's own file as a field.
#[derive(Serialize, Deserialize)]
struct GeometricFile {
    format_version: u32,
    appearance: serde_json::Value,
    geometry: GeometryModel,
    geometry_weight: f64,
    tempering: Tempering,
    #[serde(default)]
    moving: Option<Weighing>,
    contact_noise: ContactNoise,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    alone: Option<AloneTemperings>,
}

impl GeometricFusion {
    /// Fuses `appearance` (not itself geometric) with `geometry`, which must know the same objects
    /// in the same order; appearance alone until [`calibrate_on_all`](Self::calibrate_on_all).
    pub fn new(appearance: Appearance, geometry: GeometryModel) -> Result<Self, RecognizeError> {
        if geometry.objects() != appearance.objects() {
            return Err(RecognizeError::InvalidParameter {
                name: "geometric model",
                what: format!(
                    "the geometric model knows {:?}, the appearance model {:?}",
                    geometry.objects(),
                    appearance.objects()
                ),
            });
        }
        let tempering = appearance.tempering();
        Ok(Self {
            appearance,
            geometry,
            geometry_weight: 0.0,
            tempering,
            moving: None,
            contact_noise: ContactNoise::ARM,
            alone: None,
            evidence: Evidence::Fused,
        })
    }

    pub fn appearance(&self) -> &Appearance {
        &self.appearance
    }

    pub fn geometry(&self) -> &GeometryModel {
        &self.geometry
    }

    /// `lambda`, the fitted weight of the geometric evidence.
    pub fn geometry_weight(&self) -> f64 {
        self.geometry_weight
    }

    /// The tempering of the evidence weighed ([`evidence`](Self::evidence)) for an object that
    /// stays where it stands: the fused one unless one part alone was asked for.
    pub fn tempering(&self) -> Tempering {
        self.weighing_for(Perturbed::FIXED).1
    }

    /// The weighing of a moving object's evidence, when perturbed explorations calibrated it.
    pub fn moving(&self) -> Option<Weighing> {
        self.moving
    }

    /// The temperings of each part of the evidence alone, when calibrated.
    pub fn alone(&self) -> Option<AloneTemperings> {
        self.alone
    }

    pub fn evidence(&self) -> Evidence {
        self.evidence
    }

    /// The same model weighing `evidence` ([`Evidence`]).
    pub fn with_evidence(self, evidence: Evidence) -> Self {
        Self { evidence, ..self }
    }

    /// The weights and tempering used for an object that moves as `motion` says, for the
    /// evidence asked for. A moving object without a weighing of its own is recognised by
    /// appearance alone; a part alone without a fitted tempering takes Eq. 15's (the guesses are
    /// the same, the beliefs untempered).
    fn weighing_for(&self, motion: Perturbed) -> (EvidenceWeights, Tempering) {
        let fixed = motion.is_fixed();
        match self.evidence {
            Evidence::Fused if fixed => (EvidenceWeights::fused(self.geometry_weight), self.tempering),
            Evidence::Fused => match self.moving {
                Some(m) => (EvidenceWeights::fused(m.geometry_weight), m.tempering),
                None => (EvidenceWeights::fused(0.0), self.appearance_tempering(motion)),
            },
            Evidence::Appearance => (EvidenceWeights::fused(0.0), self.appearance_tempering(motion)),
            Evidence::Contacts => {
                let fitted = self.alone.and_then(|a| a.of(Evidence::Contacts, fixed));
                (EvidenceWeights::CONTACTS, fitted.unwrap_or(Tempering::EQ15))
            }
        }
    }

    /// Appearance alone's tempering for an object that moves as `motion` says: fitted on the
    /// calibration explorations of its kind, else the appearance model's own.
    fn appearance_tempering(&self, motion: Perturbed) -> Tempering {
        self.alone
            .and_then(|a| a.of(Evidence::Appearance, motion.is_fixed()))
            .unwrap_or(self.appearance.tempering())
    }

    pub fn contact_noise(&self) -> ContactNoise {
        self.contact_noise
    }

    /// The same model matching contacts with `noise` added (the recogniser's test of doubled
    /// noise, or none for data of a real arm, whose contacts carry their own error).
    pub fn with_contact_noise(self, noise: ContactNoise) -> Self {
        Self {
            contact_noise: noise,
            ..self
        }
    }

    /// The same model with the posterior `rule` applies.
    pub fn with_posterior(self, rule: PosteriorRule) -> Self {
        let t = |t: Tempering| rule.tempering(t);
        Self {
            tempering: t(self.tempering),
            moving: self.moving.map(|m| Weighing {
                tempering: t(m.tempering),
                ..m
            }),
            alone: self.alone.map(|a| AloneTemperings {
                appearance: t(a.appearance),
                contacts: t(a.contacts),
                moving_appearance: a.moving_appearance.map(t),
                moving_contacts: a.moving_contacts.map(t),
            }),
            appearance: self.appearance.with_posterior(rule),
            ..self
        }
    }

    /// The same model with `lambda` and the tempering fitted on the explorations of every dataset
    /// of `data`, each object's converged readings cut into trials of `trial_readings` (the
    /// module docs); a perturbed dataset's contacts are discounted as its header's perturbation
    /// says, and its explorations weigh a moving object's evidence apart.
    pub fn calibrate_on_all(
        mut self,
        data: &[&Dataset],
        trial_readings: usize,
    ) -> Result<Self, RecognizeError> {
        let (fixed, moving): (Vec<&Dataset>, Vec<&Dataset>) = data
            .iter()
            .copied()
            .partition(|d| d.header().perturbation.is_fixed());
        if let Some((w, [appearance, contacts])) = self.weighing_on(&fixed, trial_readings)? {
            self.geometry_weight = w.geometry_weight;
            self.tempering = w.tempering;
            self.alone = Some(AloneTemperings {
                appearance,
                contacts,
                moving_appearance: None,
                moving_contacts: None,
            });
        }
        if let Some((w, [appearance, contacts])) = self.weighing_on(&moving, trial_readings)? {
            self.moving = Some(w);
            self.alone = self.alone.map(|a| AloneTemperings {
                moving_appearance: Some(appearance),
                moving_contacts: Some(contacts),
                ..a
            });
        }
        Ok(self)
    }

    /// The weighing fitted on the explorations of `data` (the module docs) and the temperings of
    /// appearance alone and of the contacts alone, `None` without any.
    fn weighing_on(
        &self,
        data: &[&Dataset],
        trial_readings: usize,
    ) -> Result<Option<(Weighing, [Tempering; 2])>, RecognizeError> {
        let mut paths = Vec::new();
        for dataset in data {
            let motion = dataset.header().perturbation;
            for trial in self.trials(dataset, trial_readings)? {
                paths.push(self.evidence_parts(&trial, motion)?);
            }
        }
        if paths.is_empty() {
            return Ok(None);
        }
        // Sec. V-B1's model selection: the best accuracy (over every prefix of every trial),
        // ties broken by reliability (here the fitted posterior's log loss).
        let mut best: Option<(usize, f64, f64, Tempering, Vec<EvidencePath>)> = None;
        for weight in GEOMETRY_WEIGHTS {
            let combined: Vec<EvidencePath> = paths
                .iter()
                .map(|p| p.combined(EvidenceWeights::fused(weight)))
                .collect();
            let right = combined
                .iter()
                .flat_map(|p| p.log_likelihoods.iter().map(move |l| guess_of(l) == p.object))
                .filter(|&r| r)
                .count();
            let (tempering, loss) = Tempering::fit_scored(&combined);
            if best
                .as_ref()
                .is_none_or(|(r, l, ..)| right > *r || (right == *r && loss < *l))
            {
                best = Some((right, loss, weight, tempering, combined));
            }
        }
        let alone = |weights: EvidenceWeights| {
            let combined: Vec<EvidencePath> = paths.iter().map(|p| p.combined(weights)).collect();
            Tempering::fit_scored(&combined)
                .0
                .with_confidence_map_of(&combined)
        };
        let alone = [
            alone(EvidenceWeights::fused(0.0)),
            alone(EvidenceWeights::CONTACTS),
        ];
        Ok(best.map(|(_, _, weight, tempering, combined)| {
            let weighing = Weighing {
                geometry_weight: weight,
                tempering: tempering.with_confidence_map_of(&combined),
            };
            (weighing, alone)
        }))
    }

    /// Each converged reading of `dataset` described by every appearance model, with its touch
    /// (the contact with this model's noise), as trials of up to `readings_per_trial` readings.
    pub fn trials(
        &self,
        dataset: &Dataset,
        readings_per_trial: usize,
    ) -> Result<Vec<Trial<TouchReading>>, RecognizeError> {
        let appearance = appearance_trials(&self.appearance, dataset, readings_per_trial)?;
        let touches = Touch::of_dataset(dataset, &self.contact_noise);
        let names = &dataset.header().objects;
        let mut next = vec![0usize; names.len()];
        appearance
            .into_iter()
            .map(|trial| {
                let name = &self.objects()[trial.object];
                let j = dataset
                    .header()
                    .object_index(name)
                    .ok_or_else(|| RecognizeError::UnknownObject {
                        object: name.clone(),
                        known: names.clone(),
                    })?;
                let from = next[j];
                next[j] += trial.readings.len();
                let readings = trial
                    .readings
                    .into_iter()
                    .zip(touches[j][from..].iter().copied())
                    .collect();
                Ok(Trial {
                    object: trial.object,
                    readings,
                })
            })
            .collect()
    }

    /// Recognition touch by touch over `trials` of an object that moves as `motion` says.
    pub fn evaluate(
        &self,
        trials: &[Trial<TouchReading>],
        range: ReadingRange,
        motion: Perturbed,
    ) -> Result<Evaluation, RecognizeError> {
        evaluate_with(self.objects(), trials, range, || {
            let mut posterior = self.posterior(motion);
            move |reading: &TouchReading| posterior.observe(reading)
        })
    }

    pub fn objects(&self) -> &[String] {
        self.appearance.objects()
    }

    pub fn sensor(&self) -> &SensorConfig {
        self.appearance.sensor()
    }

    /// A posterior over described readings and their touches.
    pub fn posterior(&self, motion: Perturbed) -> GeometricPosterior<'_> {
        let (weights, tempering) = self.weighing_for(motion);
        GeometricPosterior {
            appearance: appearance_posterior(&self.appearance),
            geometry: self.geometry.posterior(motion),
            weights,
            tempering,
            contact_noise: self.contact_noise,
            sensor: *self.sensor(),
            readings: 0,
            attempts: 0,
        }
    }

    /// The appearance models' descriptors, in order.
    pub(crate) fn descriptors(&self) -> Result<Vec<Box<dyn Descriptor>>, RecognizeError> {
        self.appearance
            .parts()
            .iter()
            .map(|m| m.build_descriptor())
            .collect()
    }

    /// A reading of an exploration made with the model in the loop, as [`trials`](Self::trials)
    /// takes a recorded one: `image` described by every appearance model (`descriptors`, from
    /// [`descriptors`](Self::descriptors)), its touch the exploration's `attempt`-th.
    pub(crate) fn touch_reading(
        &self,
        descriptors: &[Box<dyn Descriptor>],
        image: &TactileImage,
        attempt: usize,
    ) -> TouchReading {
        let features = descriptors.iter().map(|d| d.describe(image)).collect();
        (
            features,
            Touch::of_image(image, self.sensor(), &self.contact_noise, attempt),
        )
    }

    /// The model file's contents.
    pub fn to_json(&self) -> Result<Vec<u8>, RecognizeError> {
        encode_json(&self.file()?, "the model in memory")
    }

    /// Writes the model file, atomically.
    pub fn save(&self, path: &Path) -> Result<(), RecognizeError> {
        save_json(&self.file()?, path)
    }

    fn file(&self) -> Result<GeometricFile, RecognizeError> {
        let appearance =
            serde_json::from_slice(&self.appearance.to_json()?).map_err(|e| RecognizeError::NotAModel {
                path: "the model in memory".into(),
                what: e.to_string(),
            })?;
        Ok(GeometricFile {
            format_version: MODEL_FORMAT_VERSION,
            appearance,
            geometry: self.geometry.clone(),
            geometry_weight: self.geometry_weight,
            tempering: self.tempering,
            moving: self.moving,
            contact_noise: self.contact_noise,
            alone: self.alone,
        })
    }

    /// Parses a geometric model file (a JSON object with `geometry`); `origin` names it in errors.
    pub fn from_json(value: serde_json::Value, origin: &str) -> Result<Self, RecognizeError> {
        let file = GeometricFile::deserialize(value).map_err(|e| RecognizeError::NotAModel {
            path: origin.to_string(),
            what: e.to_string(),
        })?;
        let bytes = serde_json::to_vec(&file.appearance).map_err(|e| RecognizeError::NotAModel {
            path: origin.to_string(),
            what: e.to_string(),
        })?;
        let appearance = Appearance::from_json(&bytes, &format!("{origin} (appearance model)"))?;
        let inconsistent = |what: String| RecognizeError::Inconsistent {
            path: origin.to_string(),
            what,
        };
        let weights = [Some(file.geometry_weight), file.moving.map(|m| m.geometry_weight)];
        if let Some(w) = weights
            .into_iter()
            .flatten()
            .find(|w| !(w.is_finite() && *w >= 0.0))
        {
            return Err(inconsistent(format!(
                "geometry_weight {w} is not a finite number of 0 or more"
            )));
        }
        let noise = file.contact_noise;
        if !(noise.position_sigma_m >= 0.0
            && noise.position_sigma_m <= 0.1
            && noise.angle_sigma_rad >= 0.0
            && noise.angle_sigma_rad <= 1.0)
        {
            return Err(inconsistent(format!(
                "contact_noise {noise:?} is outside [0, 0.1] m and [0, 1] rad"
            )));
        }
        let fused = Self::new(appearance, file.geometry).map_err(|e| inconsistent(e.to_string()))?;
        Ok(Self {
            geometry_weight: file.geometry_weight,
            tempering: file.tempering,
            moving: file.moving,
            contact_noise: noise,
            alone: file.alone,
            ..fused
        })
    }

    /// A trial's appearance and geometric log-likelihoods after each reading, apart.
    fn evidence_parts(
        &self,
        trial: &Trial<TouchReading>,
        motion: Perturbed,
    ) -> Result<EvidenceParts, RecognizeError> {
        let mut appearance = appearance_posterior(&self.appearance);
        let mut geometry = self.geometry.posterior(motion);
        let mut parts = EvidenceParts {
            object: trial.object,
            appearance: Vec::new(),
            geometry: Vec::new(),
        };
        for (features, touch) in &trial.readings {
            appearance.observe(features)?;
            parts.appearance.push(appearance.log_likelihoods());
            parts.geometry.push(geometry.observe(*touch).to_vec());
        }
        Ok(parts)
    }
}

/// The appearance part of a [`GeometricFusion`]: the bag of features of one descriptor or of
/// several fused, never itself fused with geometry (a type, so that no model nests).
#[derive(Debug, Clone, PartialEq)]
pub enum Appearance {
    Single(Box<TrainedModel>),
    Fused(Box<FusedModel>),
}

impl Appearance {
    /// Parses an appearance model file (fused when it has a `fused` list).
    pub fn from_json(bytes: &[u8], origin: &str) -> Result<Self, RecognizeError> {
        let value = serde_json::from_slice::<serde_json::Value>(bytes).ok();
        match value {
            Some(value) if value.get("geometry").is_some() => Err(RecognizeError::NotAModel {
                path: origin.to_string(),
                what: "an appearance model fused with geometry where an appearance model was expected".into(),
            }),
            Some(value) if value.get("fused").is_some() => {
                check_version(&value, origin)?;
                Ok(Self::Fused(Box::new(FusedModel::from_json(&value, origin)?)))
            }
            _ => Ok(Self::Single(Box::new(TrainedModel::from_json(bytes, origin)?))),
        }
    }

    /// The models, one per descriptor, in order.
    pub fn parts(&self) -> &[TrainedModel] {
        match self {
            Self::Single(m) => std::slice::from_ref(m.as_ref()),
            Self::Fused(f) => &f.fused,
        }
    }

    pub fn objects(&self) -> &[String] {
        self.parts()[0].bag.objects()
    }

    pub fn sensor(&self) -> &SensorConfig {
        &self.parts()[0].sensor
    }

    /// The descriptor name (`mnti`, `mnti+sift`).
    pub fn choice(&self) -> DescriptorChoice {
        match self {
            Self::Single(m) => DescriptorChoice::single(m.descriptor.kind()),
            Self::Fused(f) => f.choice(),
        }
    }

    /// The tempering of the appearance posterior alone.
    pub fn tempering(&self) -> Tempering {
        match self {
            Self::Single(m) => m.bag.tempering(),
            Self::Fused(f) => f.tempering,
        }
    }

    fn with_posterior(self, rule: PosteriorRule) -> Self {
        match self {
            Self::Single(m) => Self::Single(Box::new(m.with_posterior(rule))),
            Self::Fused(f) => Self::Fused(Box::new(f.with_posterior(rule))),
        }
    }

    fn to_json(&self) -> Result<Vec<u8>, RecognizeError> {
        match self {
            Self::Single(m) => encode_json(m.as_ref(), "the model in memory"),
            Self::Fused(f) => encode_json(f, "the model in memory"),
        }
    }
}

/// The appearance models' posterior, Eq. 15 untempered whatever the parts' own tempering: a
/// single model as a fusion of one.
fn appearance_posterior(appearance: &Appearance) -> FusedPosterior<'_> {
    match appearance {
        Appearance::Single(m) => FusedPosterior {
            parts: vec![m.bag.posterior()],
            tempering: Tempering::EQ15,
        },
        Appearance::Fused(f) => f.posterior(),
    }
}

/// The converged readings of `dataset` described by every appearance model, as trials.
fn appearance_trials(
    appearance: &Appearance,
    dataset: &Dataset,
    readings_per_trial: usize,
) -> Result<Vec<Trial<Vec<Vec<Feature>>>>, RecognizeError> {
    match appearance {
        Appearance::Single(m) => Ok(m
            .trials(dataset, readings_per_trial)?
            .into_iter()
            .map(|t| Trial {
                object: t.object,
                readings: t.readings.into_iter().map(|r| vec![r]).collect(),
            })
            .collect()),
        Appearance::Fused(f) => {
            f.fused[0].check_sensor(&dataset.header().sensor)?;
            f.trials(dataset, readings_per_trial)
        }
    }
}

/// One calibration trial's evidence, appearance and geometry apart, after each reading.
struct EvidenceParts {
    object: usize,
    appearance: Vec<Vec<f64>>,
    geometry: Vec<Vec<f64>>,
}

impl EvidenceParts {
    fn combined(&self, weights: EvidenceWeights) -> EvidencePath {
        EvidencePath {
            object: self.object,
            log_likelihoods: self
                .appearance
                .iter()
                .zip(&self.geometry)
                .map(|(a, g)| weights.sum(a, g))
                .collect(),
        }
    }
}
