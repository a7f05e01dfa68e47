//! Active touch (beyond the paper): the planner's hook for choosing where to touch next by what a
//! touch there is expected to teach, and the rule that ends exploration once the recogniser is sure.
//!
//! The paper closes with this as future work: "integrating our simulator into a planning system
//! which could optimize exploration [...] such as expected information gain" (Sec. VI), and chose
//! Eq. 4 because it "is more easily adaptable to integration with a guided search framework for
//! evaluating the potential information content of future measurements" (Sec. IV-A).
//!
//! Exploration knows nothing of descriptors or trained models (they come later in the data flow),
//! so the planner asks a [`TouchScorer`] to score its candidate targets; the recogniser implements
//! it (`active_touch`). With the strategy [`Strategy::Active`](crate::dataset::Strategy) the
//! planner draws [`ActiveGuidance::candidates`] targets per iteration exactly as its local/global
//! rule would (each local with probability L once a reading exists, else global), asks the scorer,
//! and expands toward the best one (the first of equal scores, so the choice is deterministic).
//! The planner is still told nothing of the object's identity, pose or shape: the scorer sees only
//! the readings it was given and their pad locations.

use glam::DVec3;

/// Scores candidate touch targets by what a touch there is expected to tell about the object's
/// identity, given the readings it has been shown so far.
pub trait TouchScorer {
    /// One score per target of `candidates_m` (world frame, metres), in order; larger is better.
    fn score(&self, candidates_m: &[DVec3]) -> Vec<f64>;
}

/// How the planner's active strategy uses a scorer.
#[derive(Clone, Copy)]
pub struct ActiveGuidance<'a> {
    pub scorer: &'a dyn TouchScorer,
    /// Candidate targets drawn and scored per iteration (at least 1; 1 is the plain planner).
    pub candidates: usize,
}

/// Candidates per iteration by default: enough for local and global proposals to both be present
/// at L = 0.5 (the chance that 12 draws are all of one kind is 2^-11), few enough that scoring
/// stays a small share of an iteration.
pub const DEFAULT_CANDIDATES: usize = 12;

/// A probability in (0, 1]: the confidence at which exploration stops.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Probability(f64);

impl Probability {
    pub fn new(p: f64) -> Result<Self, ProbabilityError> {
        if p > 0.0 && p <= 1.0 {
            Ok(Self(p))
        } else {
            Err(ProbabilityError::OutOfRange(p))
        }
    }

    pub fn get(self) -> f64 {
        self.0
    }
}

/// A value that is not a [`Probability`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProbabilityError {
    #[error("{0} is not a probability in (0, 1]")]
    OutOfRange(f64),
    #[error("'{0}' is not a number")]
    NotANumber(String),
}

impl TryFrom<f64> for Probability {
    type Error = ProbabilityError;
    fn try_from(p: f64) -> Result<Self, ProbabilityError> {
        Self::new(p)
    }
}

impl From<Probability> for f64 {
    fn from(p: Probability) -> f64 {
        p.0
    }
}

impl std::str::FromStr for Probability {
    type Err = ProbabilityError;
    fn from_str(s: &str) -> Result<Self, ProbabilityError> {
        let p: f64 = s
            .trim()
            .parse()
            .map_err(|_| ProbabilityError::NotANumber(s.to_string()))?;
        Self::new(p)
    }
}

impl std::fmt::Display for Probability {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// The confidence stop: exploration ends at the first touch after which the posterior's largest
/// probability reaches `threshold`, or when `budget` touches are spent. Returns the touches used
/// given the largest posterior probability after each touch (1-based), or `None` when `max_p`
/// never reached the threshold within the budget (the budget is then spent).
pub fn touches_to_confidence(
    max_p: impl IntoIterator<Item = f64>,
    threshold: Probability,
    budget: usize,
) -> Option<usize> {
    max_p
        .into_iter()
        .take(budget)
        .position(|p| p >= threshold.get())
        .map(|i| i + 1)
}

/// The index of the largest score, the first of equal ones; `None` for no scores. A NaN score never
/// wins.
pub fn best_candidate(scores: &[f64]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, s) in scores.iter().enumerate() {
        if s.is_nan() {
            continue;
        }
        if best.is_none_or(|b| *s > scores[b]) {
            best = Some(i);
        }
    }
    best.or((!scores.is_empty()).then_some(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stop_fires_at_the_first_touch_reaching_the_threshold() {
        let p = |x| Probability::new(x).unwrap();
        let trace = [0.3, 0.6, 0.94, 0.95, 0.99, 0.5];
        assert_eq!(touches_to_confidence(trace, p(0.95), 10), Some(4));
        assert_eq!(touches_to_confidence(trace, p(0.9400001), 10), Some(4));
        assert_eq!(touches_to_confidence(trace, p(0.94), 10), Some(3));
        // The budget is spent first.
        assert_eq!(touches_to_confidence(trace, p(0.95), 3), None);
        assert_eq!(touches_to_confidence(trace, p(1.0), 10), None);
    }

    #[test]
    fn probabilities_outside_the_unit_interval_are_rejected() {
        for bad in ["0", "-0.1", "1.5", "nan", "x"] {
            assert!(bad.parse::<Probability>().is_err(), "{bad}");
        }
        assert_eq!("0.95".parse::<Probability>().map(Probability::get), Ok(0.95));
    }

    #[test]
    fn the_best_candidate_is_the_first_of_the_largest_and_never_nan() {
        assert_eq!(best_candidate(&[0.1, 0.3, 0.3, 0.2]), Some(1));
        assert_eq!(best_candidate(&[f64::NAN, 0.0, -1.0]), Some(1));
        assert_eq!(best_candidate(&[]), None);
    }
}
