//! Object models: per object, the distribution over codebook clusters of its training features,
//! `p(c_i | O_j)` (Sec. IV-A, Eq. 11).

use serde::{Deserialize, Serialize};

use crate::recognize::RecognizeError;
use crate::valid::checked_f64;

checked_f64! {
    /// The count added to every cluster bin of every object before normalising. Eq. 4 takes
    /// `log p(c_i | O_j)`, which must be finite; with `alpha = 1` (the default, Laplace's rule) the
    /// smoothed histogram is the posterior mean of the bin probabilities under a uniform Dirichlet
    /// prior, and a cluster an object never produced in training costs it `ln(1 / (n_j + k))` per
    /// feature instead of ruling it out.
    pub struct PseudoCount(alpha) where alpha > 0.0;
    refused as RecognizeError:
        |alpha| RecognizeError::InvalidParameter {
            name: "pseudo_count",
            what: format!("{alpha} is not a positive finite count"),
        },
        |text| RecognizeError::InvalidParameter {
            name: "pseudo_count",
            what: format!("'{text}' is not a number"),
        };
}

impl PseudoCount {
    pub const LAPLACE: Self = Self(1.0);
}

impl Default for PseudoCount {
    fn default() -> Self {
        Self::LAPLACE
    }
}

/// Cluster memberships summed over a set of features: `s_i = sum_f p(c_i | f)`, and the number
/// of features `n`. Its normalised form is the empirical `p(c_i | U) = s_i / n` of Sec. IV-A; with
/// a hard codebook `s_i` is the count `k_i` of the Appendix, with a soft one its expectation.
///
/// For [`EvidenceRule::PerFrame`] it also keeps `sum_f ln max(p(c_i | f), floor)`, the product
/// rule's evidence ([`ObjectModels::empty_histogram`] makes one that does).
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterHistogram {
    sums: Vec<f64>,
    features: usize,
    log_sums: Option<Vec<f64>>,
}

/// The least membership the product rule takes from one feature: one frame that a network is
/// sure of can cost an object at most `ln 1e-6 = -13.8` nats, so a later frame can still outvote
/// it (the clip scikit-learn's comparison used).
pub const MEMBERSHIP_FLOOR: f64 = 1e-6;

impl ClusterHistogram {
    /// An empty histogram over `clusters` bins.
    pub fn new(clusters: usize) -> Self {
        Self {
            sums: vec![0.0; clusters],
            features: 0,
            log_sums: None,
        }
    }

    /// An empty histogram that also sums the memberships' logarithms (the product rule's).
    pub fn with_log_sums(clusters: usize) -> Self {
        Self {
            log_sums: Some(vec![0.0; clusters]),
            ..Self::new(clusters)
        }
    }

    /// Adds one feature's membership (length = number of clusters).
    pub fn add(&mut self, membership: &[f64]) {
        debug_assert_eq!(membership.len(), self.sums.len());
        self.sums.iter_mut().zip(membership).for_each(|(s, m)| *s += m);
        if let Some(logs) = &mut self.log_sums {
            logs.iter_mut()
                .zip(membership)
                .for_each(|(l, m)| *l += m.max(MEMBERSHIP_FLOOR).ln());
        }
        self.features += 1;
    }

    /// Adds every bin of `other` (over the same clusters); the logarithms' sums are kept only
    /// when both kept them.
    pub fn merge(&mut self, other: &ClusterHistogram) {
        debug_assert_eq!(other.sums.len(), self.sums.len());
        self.sums.iter_mut().zip(&other.sums).for_each(|(s, o)| *s += o);
        self.log_sums = match (self.log_sums.take(), &other.log_sums) {
            (Some(mut mine), Some(theirs)) => {
                mine.iter_mut().zip(theirs).for_each(|(s, o)| *s += o);
                Some(mine)
            }
            _ => None,
        };
        self.features += other.features;
    }

    /// `sum_f ln max(p(c_i | f), floor)`, when this histogram keeps it.
    pub fn log_sums(&self) -> Option<&[f64]> {
        self.log_sums.as_deref()
    }

    /// `s_i`, the summed memberships.
    pub fn sums(&self) -> &[f64] {
        &self.sums
    }

    /// `n_U`, the number of features added.
    pub fn features(&self) -> usize {
        self.features
    }

    pub fn clusters(&self) -> usize {
        self.sums.len()
    }

    /// `p(c_i | U) = s_i / n_U`; all zeros when empty.
    pub fn distribution(&self) -> Vec<f64> {
        let n = self.features.max(1) as f64;
        self.sums.iter().map(|s| s / n).collect()
    }
}

/// The models `p(c_i | O_j)` of every object, smoothed:
///
/// ```text
/// p(c_i | O_j) = (s_ij + alpha) / (n_j + k alpha)
/// ```
///
/// where `s_ij` is the summed membership of object `j`'s training features in cluster `i`, `n_j`
/// its number of features, `k` the number of clusters and `alpha` the [`PseudoCount`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ObjectModelParameters", into = "ObjectModelParameters")]
pub struct ObjectModels {
    params: ObjectModelParameters,
    /// `ln p(c_i | O_j)`, row per object.
    log_probabilities: Vec<Vec<f64>>,
}

/// What a saved model stores of the object models.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectModelParameters {
    /// Object names, in index order.
    pub objects: Vec<String>,
    /// `p(c_i | O_j)`, one row per object, each summing to 1.
    pub probabilities: Vec<Vec<f64>>,
    pub pseudo_count: PseudoCount,
    /// How features make the evidence; absent (Eq. 4) in every file of the paper's codebooks.
    #[serde(default, skip_serializing_if = "EvidenceRule::is_cross_entropy")]
    pub rule: EvidenceRule,
}

/// How the memberships of an unknown object's features make `ln p(U | O_j)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EvidenceRule {
    /// Eq. 4 and 15: `sum_i s_i ln p(c_i | O_j)`, the summed memberships against each object's
    /// histogram (the paper's, for a codebook of clusters).
    #[default]
    CrossEntropy,
    /// The product rule over features, `sum_f ln p(c_j | f)`, for a codebook whose clusters are
    /// the objects and whose membership is a posterior over them under a uniform prior (the
    /// network, `recognize::mlp`): each feature an independent draw, so its `p(f | O_j)` is
    /// proportional to `p(c_j | f)`.
    PerFrame,
}

impl EvidenceRule {
    fn is_cross_entropy(&self) -> bool {
        *self == Self::CrossEntropy
    }
}

impl From<ObjectModels> for ObjectModelParameters {
    fn from(m: ObjectModels) -> Self {
        m.params
    }
}

impl TryFrom<ObjectModelParameters> for ObjectModels {
    type Error = String;
    fn try_from(params: ObjectModelParameters) -> Result<Self, String> {
        let k = params.probabilities.first().map_or(0, Vec::len);
        if params.objects.is_empty() || k == 0 {
            return Err("object models need at least one object and one cluster".into());
        }
        if params.rule == EvidenceRule::PerFrame && k != params.objects.len() {
            return Err(format!(
                "the per-frame rule needs one cluster per object: {k} clusters, {} objects",
                params.objects.len()
            ));
        }
        if params.probabilities.len() != params.objects.len() {
            return Err(format!(
                "{} objects but {} histograms",
                params.objects.len(),
                params.probabilities.len()
            ));
        }
        for (name, row) in params.objects.iter().zip(&params.probabilities) {
            if row.len() != k || row.iter().any(|p| !(p.is_finite() && *p > 0.0)) {
                return Err(format!(
                    "the histogram of '{name}' is not {k} positive probabilities"
                ));
            }
            let sum: f64 = row.iter().sum();
            if (sum - 1.0).abs() > 1e-9 {
                return Err(format!("the histogram of '{name}' sums to {sum}, not 1"));
            }
        }
        Ok(Self::from_trusted(params))
    }
}

impl ObjectModels {
    /// Builds the smoothed models from each object's training histogram (same clusters for all).
    pub fn fit(
        objects: Vec<String>,
        histograms: &[ClusterHistogram],
        pseudo_count: PseudoCount,
    ) -> Result<Self, RecognizeError> {
        if objects.len() != histograms.len() || objects.is_empty() {
            return Err(RecognizeError::InvalidParameter {
                name: "objects",
                what: format!(
                    "{} object names for {} histograms",
                    objects.len(),
                    histograms.len()
                ),
            });
        }
        if let Some(j) = histograms.iter().position(|h| h.features() == 0) {
            return Err(RecognizeError::EmptyObject {
                object: objects[j].clone(),
            });
        }
        let alpha = pseudo_count.get();
        let probabilities = histograms
            .iter()
            .map(|h| {
                let denominator = h.features() as f64 + h.clusters() as f64 * alpha;
                h.sums().iter().map(|s| (s + alpha) / denominator).collect()
            })
            .collect();
        Ok(Self::from_trusted(ObjectModelParameters {
            objects,
            probabilities,
            pseudo_count,
            rule: EvidenceRule::CrossEntropy,
        }))
    }

    /// The same models deciding by `rule`; the per-frame rule needs the clusters to be the
    /// objects.
    pub fn with_rule(mut self, rule: EvidenceRule) -> Result<Self, RecognizeError> {
        if rule == EvidenceRule::PerFrame && self.clusters() != self.objects().len() {
            return Err(RecognizeError::InvalidParameter {
                name: "evidence rule",
                what: format!(
                    "the per-frame rule needs one cluster per object: {} clusters, {} objects",
                    self.clusters(),
                    self.objects().len()
                ),
            });
        }
        self.params.rule = rule;
        Ok(self)
    }

    pub fn rule(&self) -> EvidenceRule {
        self.params.rule
    }

    /// An empty histogram of the unknown object's features, keeping what [`rule`](Self::rule)
    /// decides by.
    pub fn empty_histogram(&self) -> ClusterHistogram {
        match self.params.rule {
            EvidenceRule::CrossEntropy => ClusterHistogram::new(self.clusters()),
            EvidenceRule::PerFrame => ClusterHistogram::with_log_sums(self.clusters()),
        }
    }

    fn from_trusted(params: ObjectModelParameters) -> Self {
        let log_probabilities = params
            .probabilities
            .iter()
            .map(|row| row.iter().map(|p| p.ln()).collect())
            .collect();
        Self {
            params,
            log_probabilities,
        }
    }

    /// Object names, in index order.
    pub fn objects(&self) -> &[String] {
        &self.params.objects
    }

    /// The index of `name`.
    pub fn object_index(&self, name: &str) -> Option<usize> {
        self.params.objects.iter().position(|o| o == name)
    }

    /// Number of clusters `k`.
    pub fn clusters(&self) -> usize {
        self.params.probabilities[0].len()
    }

    /// `p(c_i | O_j)` for object `j`.
    pub fn probabilities(&self, j: usize) -> &[f64] {
        &self.params.probabilities[j]
    }

    /// `ln p(c_i | O_j)` for object `j`.
    pub fn log_probabilities(&self, j: usize) -> &[f64] {
        &self.log_probabilities[j]
    }

    pub fn pseudo_count(&self) -> PseudoCount {
        self.params.pseudo_count
    }
}

/// Eq. 4's guess from `ln p(U | O_j)` of every object: the most likely object, ties to the lower
/// index (so with no features, every log-likelihood 0, object 0).
pub(crate) fn guess_of(log_likelihood: &[f64]) -> usize {
    (0..log_likelihood.len()).fold(0, |best, j| {
        if log_likelihood[j] > log_likelihood[best] {
            j
        } else {
            best
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothing_follows_the_formula_and_no_bin_is_zero() {
        let mut a = ClusterHistogram::new(3);
        a.add(&[1.0, 0.0, 0.0]);
        a.add(&[0.5, 0.5, 0.0]);
        let mut b = ClusterHistogram::new(3);
        b.add(&[0.0, 0.0, 1.0]);
        let models = ObjectModels::fit(
            vec!["a".into(), "b".into()],
            &[a, b],
            PseudoCount::new(0.5).unwrap(),
        )
        .unwrap();
        // a: s = (1.5, 0.5, 0), n = 2, k alpha = 1.5.
        let expected = [2.0 / 3.5, 1.0 / 3.5, 0.5 / 3.5];
        for (p, e) in models.probabilities(0).iter().zip(expected) {
            assert!((p - e).abs() < 1e-15);
        }
        assert!(models.probabilities(1).iter().all(|&p| p > 0.0));
        assert!((models.probabilities(1).iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn an_object_without_features_is_an_error() {
        let e = ObjectModels::fit(
            vec!["x".into()],
            &[ClusterHistogram::new(2)],
            PseudoCount::LAPLACE,
        )
        .unwrap_err();
        assert!(e.to_string().contains("'x'"), "{e}");
        assert!(PseudoCount::new(0.0).is_err());
    }
}
