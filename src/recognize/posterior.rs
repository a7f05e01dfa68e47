//! The belief over object identity after every touch: the histogram of all features so far, and
//! the distribution of Eq. 16 it implies. [`OnlinePosterior`] takes described readings;
//! [`ModelPosterior`] takes tactile images and describes them as the model's training did.

use glam::DVec3;

use crate::describe::{Descriptor, Feature};
use crate::locate::{ContactNoise, GainOf, GeometryPosterior, Touch};
use crate::recognize::RecognizeError;
use crate::recognize::bag::BagOfFeatures;
use crate::recognize::calibration::Tempering;
use crate::recognize::decision::Decision;
use crate::recognize::object_model::ClusterHistogram;
use crate::tactile::{SensorConfig, TactileImage};

impl BagOfFeatures {
    /// A posterior over the objects that takes readings one at a time. (Defined here, beside the
    /// posterior, so that the bag's file need not know it.)
    pub fn posterior(&self) -> OnlinePosterior<'_> {
        OnlinePosterior::new(self)
    }
}

/// The state after some readings.
#[derive(Debug, Clone, PartialEq)]
pub struct Belief {
    /// Readings observed so far.
    pub readings: usize,
    pub decision: Decision,
}

impl Belief {
    /// The current best guess (object index).
    pub fn guess(&self) -> usize {
        self.decision.guess
    }

    /// `p(O_j | readings so far)` for every object; sums to 1.
    pub fn probabilities(&self) -> &[f64] {
        &self.decision.probabilities
    }

    /// Entropy of [`probabilities`](Self::probabilities), nats.
    pub fn entropy_nats(&self) -> f64 {
        self.decision.entropy_nats()
    }
}

/// Accumulates readings one at a time and answers after each. Because the histogram is a sum,
/// the belief after readings `r_1 .. r_n` is the same whatever their order and however they were
/// grouped into calls (up to floating-point summation order).
#[derive(Debug, Clone)]
pub struct OnlinePosterior<'a> {
    bag: &'a BagOfFeatures,
    histogram: ClusterHistogram,
    readings: usize,
}

impl<'a> OnlinePosterior<'a> {
    /// No readings yet: a uniform distribution.
    pub fn new(bag: &'a BagOfFeatures) -> Self {
        Self {
            bag,
            histogram: bag.models().empty_histogram(),
            readings: 0,
        }
    }

    /// Adds one reading's features and returns the updated belief. On error (a feature of the
    /// wrong length or not finite) the state is unchanged.
    pub fn observe(&mut self, features: &[Feature]) -> Result<Belief, RecognizeError> {
        let origin = format!("reading {}", self.readings + 1);
        self.bag.add_features(features, &mut self.histogram, &origin)?;
        self.readings += 1;
        Ok(self.belief())
    }

    /// The belief now: Eq. 16 tempered by the bag's `w(n)` (`recognize::calibration`).
    pub fn belief(&self) -> Belief {
        let models = self.bag.models();
        Belief {
            readings: self.readings,
            decision: Decision::calibrated(
                models.log_likelihoods(&self.histogram),
                self.histogram.features(),
                self.bag.tempering(),
                self.readings,
            ),
        }
    }

    /// The pipeline it recognises with.
    pub fn bag(&self) -> &'a BagOfFeatures {
        self.bag
    }

    /// Readings observed so far.
    pub fn readings(&self) -> usize {
        self.readings
    }

    /// The summed cluster memberships of every feature so far.
    pub fn histogram(&self) -> &ClusterHistogram {
        &self.histogram
    }
}

/// The fused belief after each reading of a fused model (`recognize::fusion`): the softmax of the
/// models' summed log-likelihoods, tempered by the fused model's own `w(n)` (each part's tempering
/// is fitted for that part alone and is not applied here).
#[derive(Debug, Clone)]
pub struct FusedPosterior<'a> {
    pub(crate) parts: Vec<OnlinePosterior<'a>>,
    pub(crate) tempering: Tempering,
}

impl FusedPosterior<'_> {
    /// Adds one reading, `features[m]` being its features under model `m`'s descriptor. On error
    /// (a count or length that does not match) the state is unchanged.
    pub fn observe(&mut self, features: &[Vec<Feature>]) -> Result<Belief, RecognizeError> {
        if features.len() != self.parts.len() {
            return Err(RecognizeError::InvalidParameter {
                name: "fused reading",
                what: format!(
                    "{} feature lists for {} fused models",
                    features.len(),
                    self.parts.len()
                ),
            });
        }
        let mut updated = self.parts.clone();
        for (part, f) in updated.iter_mut().zip(features) {
            part.observe(f)?;
        }
        self.parts = updated;
        Ok(self.belief())
    }

    /// Readings observed so far.
    pub fn readings(&self) -> usize {
        self.parts.first().map_or(0, OnlinePosterior::readings)
    }

    /// Features observed so far, over every model.
    pub fn features(&self) -> usize {
        self.parts.iter().map(|p| p.histogram().features()).sum()
    }

    /// The fused belief now: the tempered softmax of the summed log-likelihoods.
    pub fn belief(&self) -> Belief {
        let features = self.features();
        let readings = self.readings();
        Belief {
            readings,
            decision: Decision::calibrated(self.log_likelihoods(), features, self.tempering, readings),
        }
    }

    /// `ln p(U | O_j)` summed over the models (Eq. 15 for each, untempered).
    pub fn log_likelihoods(&self) -> Vec<f64> {
        let mut log_likelihood: Vec<f64> = Vec::new();
        for part in &self.parts {
            let l = part.bag().models().log_likelihoods(part.histogram());
            if log_likelihood.is_empty() {
                log_likelihood = l;
            } else {
                for (sum, x) in log_likelihood.iter_mut().zip(l) {
                    *sum += x;
                }
            }
        }
        log_likelihood
    }
}

/// The posterior of a trained model (one descriptor or several fused), fed with tactile images:
/// each image is described by the model's own descriptors, so that test images are described as
/// the training images were. What [`TrainedModel::posterior`](crate::recognize::TrainedModel::posterior)
/// and [`Recognizer::posterior`](crate::recognize::Recognizer::posterior) give.
pub struct ModelPosterior<'a> {
    descriptors: Vec<Box<dyn Descriptor>>,
    beliefs: Beliefs<'a>,
}

/// The belief of one model, or of several fused (their likelihoods multiplied).
#[derive(Clone)]
enum Beliefs<'a> {
    Single(OnlinePosterior<'a>),
    Fused(FusedPosterior<'a>),
    Geometric(Box<GeometricPosterior<'a>>),
}

impl<'a> ModelPosterior<'a> {
    /// The posterior of one model whose images `descriptor` describes.
    pub(crate) fn single(bag: &'a BagOfFeatures, descriptor: Box<dyn Descriptor>) -> Self {
        Self {
            descriptors: vec![descriptor],
            beliefs: Beliefs::Single(bag.posterior()),
        }
    }

    /// The posterior of a fused model; `descriptors[m]` describes images for its model `m`.
    pub(crate) fn fused(posterior: FusedPosterior<'a>, descriptors: Vec<Box<dyn Descriptor>>) -> Self {
        Self {
            descriptors,
            beliefs: Beliefs::Fused(posterior),
        }
    }

    /// The posterior of appearance fused with contact geometry; `descriptors[m]` describes images
    /// for its appearance model `m`.
    pub(crate) fn geometric(
        posterior: GeometricPosterior<'a>,
        descriptors: Vec<Box<dyn Descriptor>>,
    ) -> Self {
        Self {
            descriptors,
            beliefs: Beliefs::Geometric(Box::new(posterior)),
        }
    }

    /// The features of `image` under each of the model's descriptors, in the model's order.
    pub fn describe(&self, image: &TactileImage) -> Vec<Vec<Feature>> {
        self.descriptors.iter().map(|d| d.describe(image)).collect()
    }

    /// Describes one reading's image, adds it and returns the belief after it.
    pub fn observe(&mut self, image: &TactileImage) -> Result<Belief, RecognizeError> {
        let features = self.describe(image);
        self.observe_described(image, features)
    }

    /// Adds one reading already described ([`describe`](Self::describe)): a model that knows
    /// where it touched also reads the contact of `image`.
    pub fn observe_described(
        &mut self,
        image: &TactileImage,
        features: Vec<Vec<Feature>>,
    ) -> Result<Belief, RecognizeError> {
        match &mut self.beliefs {
            Beliefs::Geometric(p) => {
                let touch = p.touch_of(image);
                p.observe(&(features, touch))
            }
            _ => self.observe_features(&features),
        }
    }

    /// Adds one reading already described: `features[m]` its features under descriptor `m` (one
    /// list for a model of one descriptor). On error (a count or a length that does not match) the
    /// state is unchanged.
    pub fn observe_features(&mut self, features: &[Vec<Feature>]) -> Result<Belief, RecognizeError> {
        match &mut self.beliefs {
            Beliefs::Single(p) => match features {
                [one] => p.observe(one),
                _ => Err(RecognizeError::InvalidParameter {
                    name: "reading",
                    what: format!("{} feature lists for a model of one descriptor", features.len()),
                }),
            },
            Beliefs::Fused(p) => p.observe(features),
            // Described features carry no pad pose: a touch without a contact.
            Beliefs::Geometric(p) => {
                let touch = Touch {
                    contact: None,
                    attempt: p.attempts,
                };
                p.observe(&(features.to_vec(), touch))
            }
        }
    }

    /// The belief now.
    pub fn belief(&self) -> Belief {
        match &self.beliefs {
            Beliefs::Single(p) => p.belief(),
            Beliefs::Fused(p) => p.belief(),
            Beliefs::Geometric(p) => p.belief(),
        }
    }

    /// `p(O_j | readings so far)` for every object of the model; sums to 1 (uniform before any
    /// reading).
    pub fn probabilities(&self) -> Vec<f64> {
        self.belief().decision.probabilities
    }

    /// The posterior of appearance fused with contact geometry, when the model is one.
    pub fn as_geometric(&self) -> Option<&GeometricPosterior<'a>> {
        match &self.beliefs {
            Beliefs::Geometric(p) => Some(p),
            _ => None,
        }
    }

    /// Counts a touch attempt that gave no reading: only a model that weighs contacts keeps
    /// count, since a perturbed object moved after it ([`GeometricPosterior::missed`]).
    pub fn missed(&mut self) {
        if let Beliefs::Geometric(p) = &mut self.beliefs {
            p.missed();
        }
    }

    /// Readings observed so far.
    pub fn readings(&self) -> usize {
        match &self.beliefs {
            Beliefs::Single(p) => p.readings(),
            Beliefs::Fused(p) => p.readings(),
            Beliefs::Geometric(p) => p.readings(),
        }
    }
}

/// One reading as the fused recogniser of appearance and contact geometry takes it
/// (`recognize::geometric`): its features under every appearance model's descriptor, and its
/// touch.
pub type TouchReading = (Vec<Vec<Feature>>, Touch);

/// The belief of appearance fused with contact geometry after each reading
/// (`recognize::geometric`): the tempered softmax of `A + lambda G`.
#[derive(Debug, Clone)]
pub struct GeometricPosterior<'a> {
    pub(crate) appearance: FusedPosterior<'a>,
    pub(crate) geometry: GeometryPosterior<'a>,
    pub(crate) weights: EvidenceWeights,
    pub(crate) tempering: Tempering,
    pub(crate) contact_noise: ContactNoise,
    pub(crate) sensor: SensorConfig,
    pub(crate) readings: usize,
    /// Touch attempts so far, converged or not: an object perturbed after every attempt
    /// (Sec. V-B4) moves between two readings as often as attempts were made between them, so the
    /// pose beliefs widen by that many moves (`locate::Track`).
    pub(crate) attempts: usize,
}

impl GeometricPosterior<'_> {
    /// Adds one described reading and its touch. On error (features that do not fit the
    /// appearance models) the state is unchanged.
    pub fn observe(&mut self, (features, touch): &TouchReading) -> Result<Belief, RecognizeError> {
        self.appearance.observe(features)?;
        self.geometry.observe(*touch);
        self.readings += 1;
        self.attempts = self.attempts.max(touch.attempt + 1);
        Ok(self.belief())
    }

    /// Counts a touch attempt that gave no reading (it met nothing, collided or did not settle):
    /// the next reading's touch is one attempt later.
    pub fn missed(&mut self) {
        self.attempts += 1;
    }

    /// The touch of `image`, the next attempt of its exploration: its contact, with the model's
    /// noise (none when the image has no pad pose).
    pub fn touch_of(&self, image: &TactileImage) -> Touch {
        Touch::of_image(image, &self.sensor, &self.contact_noise, self.attempts)
    }

    /// `A + lambda G` for every object (or one part alone, `recognize::Evidence`).
    pub fn log_likelihoods(&self) -> Vec<f64> {
        self.weights.sum(
            &self.appearance.log_likelihoods(),
            self.geometry.log_likelihoods(),
        )
    }

    pub fn readings(&self) -> usize {
        self.readings
    }

    /// The expected gain of the contact of a touch toward each of `targets_m`, nats
    /// (`locate::predict`): predicted by the pose hypotheses the contacts so far left, weighed by
    /// the belief over identity before its confidence map (the gain follows Bayes' rule, which the
    /// tempered belief does and the map does not) and by the weight the next contact will have,
    /// `lambda w(n + 1)`; a touch meets a surface its target lies less than half the pad's width
    /// outside. Zero for a posterior that does not weigh contacts.
    pub fn contact_gains_nats(&self, targets_m: &[DVec3], of: GainOf) -> Vec<f64> {
        let weight = self.weights.geometry * self.tempering.weight(self.readings + 1);
        if weight.is_nan() || weight <= 0.0 {
            return vec![0.0; targets_m.len()];
        }
        let belief = self.belief();
        let reach_m = 0.5 * self.sensor.pad_width_m.min(self.sensor.pad_height_m);
        self.geometry
            .contact_gains_nats(belief.decision.evidence(), targets_m, weight, reach_m, of)
    }

    pub fn belief(&self) -> Belief {
        Belief {
            readings: self.readings,
            decision: Decision::calibrated(
                self.log_likelihoods(),
                self.appearance.features(),
                self.tempering,
                self.readings,
            ),
        }
    }
}

/// How the parts of the evidence are summed: `appearance A + geometry G`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EvidenceWeights {
    pub(crate) appearance: f64,
    pub(crate) geometry: f64,
}

impl EvidenceWeights {
    pub(crate) fn fused(geometry_weight: f64) -> Self {
        Self {
            appearance: 1.0,
            geometry: geometry_weight,
        }
    }

    pub(crate) const CONTACTS: Self = Self {
        appearance: 0.0,
        geometry: 1.0,
    };

    /// `appearance A_j + geometry G_j` for every object `j`.
    pub(crate) fn sum(&self, a: &[f64], g: &[f64]) -> Vec<f64> {
        a.iter()
            .zip(g)
            .map(|(a, g)| self.appearance * a + self.geometry * g)
            .collect()
    }
}
