//! The belief over object identity after every touch: the histogram of all features so far, and
//! the distribution of Eq. 16 it implies.

use crate::describe::Feature;
use crate::recognize::RecognizeError;
use crate::recognize::bag::BagOfFeatures;
use crate::recognize::decision::Decision;
use crate::recognize::object_model::ClusterHistogram;

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
            histogram: ClusterHistogram::new(bag.models().clusters()),
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

    /// The belief now.
    pub fn belief(&self) -> Belief {
        Belief {
            readings: self.readings,
            decision: self.bag.models().decide(&self.histogram),
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
