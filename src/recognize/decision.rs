//! The decision rule (Sec. IV-A, Eq. 1-4) and the distribution over objects it implies
//! (Appendix, Eq. 12-16).

use crate::recognize::calibration::Tempering;
use crate::recognize::object_model::{ClusterHistogram, EvidenceRule, ObjectModels, guess_of};

/// The cross-entropy of Eq. 4, `H(U, O_j) = -sum_i p(c_i | U) ln p(c_i | O_j)`: the KL divergence
/// of Eq. 1-2 less the entropy of `p(c_i | U)`, which does not depend on `j`.
pub fn cross_entropy(p_u: &[f64], log_p_o: &[f64]) -> f64 {
    -p_u.iter().zip(log_p_o).map(|(p, l)| p * l).sum::<f64>()
}

/// Shannon entropy `-sum p ln p` in nats (`0 ln 0 = 0`).
pub fn entropy_nats(p: &[f64]) -> f64 {
    // `0 - sum`, not `-sum`: a certain belief's entropy is 0, not the -0 a CSV would show.
    0.0 - p.iter().filter(|&&p| p > 0.0).map(|p| p * p.ln()).sum::<f64>()
}

/// What the models say about a set of features `U`.
#[derive(Debug, Clone, PartialEq)]
pub struct Decision {
    /// `D = argmin_j H(U, O_j)` (Eq. 4); ties go to the lower index, so with no features (every
    /// `H` is 0) it is object 0.
    pub guess: usize,
    /// `H(U, O_j)` for every object, nats per feature.
    pub cross_entropy: Vec<f64>,
    /// `p(O_j | U)` under a uniform prior: the softmax of `ln p(U | O_j) = -n_U H(U, O_j)`
    /// (Eq. 16); uniform when `n_U = 0`.
    pub probabilities: Vec<f64>,
    /// The tempered posterior before its confidence map, where the tempering has one
    /// (`recognize::calibration`): the belief a further reading updates by Bayes' rule.
    pub evidence_probabilities: Option<Vec<f64>>,
    /// `n_U`.
    pub features: usize,
}

impl Decision {
    /// Entropy of [`probabilities`](Self::probabilities), nats: `ln n_O` when nothing is known,
    /// 0 when one object has all the probability.
    pub fn entropy_nats(&self) -> f64 {
        entropy_nats(&self.probabilities)
    }
}

impl ObjectModels {
    /// Applies Eq. 4 and Eq. 16 to the histogram of the unknown object's features.
    ///
    /// With `s_i = n_U p(c_i | U)` the summed memberships, `ln p(U | O_j) = sum_i s_i ln p(c_i | O_j)`
    /// (Eq. 15-16), so the guess and the distribution come from the same numbers:
    /// `p(O_j | U) = exp(ln p(U | O_j) - ln sum_m p(U | O_m))`.
    pub fn decide(&self, u: &ClusterHistogram) -> Decision {
        Decision::from_log_likelihoods(self.log_likelihoods(u), u.features())
    }

    /// `ln p(U | O_j) = sum_i s_i ln p(c_i | O_j)` for every object `j` (Eq. 15-16); by the
    /// product rule `sum_f ln p(c_j | f)` when the models decide per frame
    /// ([`EvidenceRule::PerFrame`]), from the sums `u` keeps for it.
    ///
    /// # Panics
    ///
    /// When the models decide per frame and `u` did not keep those sums: a histogram made by
    /// [`ClusterHistogram::new`] rather than [`ObjectModels::empty_histogram`]. Its counts cannot
    /// give the product rule's evidence, and Eq. 4 in its place would be a wrong answer given
    /// silently; every decision path of the library makes its histograms with `empty_histogram`.
    pub fn log_likelihoods(&self, u: &ClusterHistogram) -> Vec<f64> {
        debug_assert_eq!(u.clusters(), self.clusters());
        if self.rule() == EvidenceRule::PerFrame {
            return u
                .log_sums()
                .expect("a per-frame model decides from a histogram made by ObjectModels::empty_histogram")
                .to_vec();
        }
        (0..self.objects().len())
            .map(|j| {
                u.sums()
                    .iter()
                    .zip(self.log_probabilities(j))
                    .map(|(s, l)| s * l)
                    .sum()
            })
            .collect()
    }
}

impl Decision {
    /// The decision given `ln p(U | O_j)` for every object and the number of features `n_U` behind
    /// them: the most likely object and the softmax of the log-likelihoods (Eq. 16).
    pub fn from_log_likelihoods(log_likelihood: Vec<f64>, n: usize) -> Decision {
        Self::calibrated(log_likelihood, n, Tempering::EQ15, 1)
    }

    /// [`from_log_likelihoods`](Self::from_log_likelihoods) with the probabilities of a calibrated
    /// posterior after `readings` readings (`recognize::calibration`). The guess and the
    /// cross-entropies are Eq. 4's whatever the tempering.
    pub fn calibrated(log_likelihood: Vec<f64>, n: usize, tempering: Tempering, readings: usize) -> Decision {
        let cross_entropy: Vec<f64> = log_likelihood
            .iter()
            .map(|l| if n == 0 { 0.0 } else { -l / n as f64 })
            .collect();
        let guess = guess_of(&log_likelihood);
        let evidence = tempering.evidence_probabilities(&log_likelihood, readings);
        // Every belief of every evaluation comes through here: the evidence is copied only when a
        // map moves it.
        let (probabilities, evidence_probabilities) = match tempering.confidence_map() {
            Some(_) => (tempering.mapped(evidence.clone()), Some(evidence)),
            None => (evidence, None),
        };
        Decision {
            guess,
            cross_entropy,
            probabilities,
            evidence_probabilities,
            features: n,
        }
    }

    /// [`evidence_probabilities`](Self::evidence_probabilities), or the probabilities themselves
    /// where no map moved them.
    pub fn evidence(&self) -> &[f64] {
        self.evidence_probabilities
            .as_deref()
            .unwrap_or(&self.probabilities)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recognize::object_model::PseudoCount;

    fn models() -> ObjectModels {
        let mut hist = Vec::new();
        for counts in [[8.0, 1.0, 1.0], [1.0, 8.0, 1.0], [3.0, 3.0, 4.0]] {
            let mut h = ClusterHistogram::new(3);
            for (i, c) in counts.iter().enumerate() {
                for _ in 0..*c as usize {
                    let mut m = [0.0; 3];
                    m[i] = 1.0;
                    h.add(&m);
                }
            }
            hist.push(h);
        }
        ObjectModels::fit(
            vec!["a".into(), "b".into(), "c".into()],
            &hist,
            PseudoCount::LAPLACE,
        )
        .unwrap()
    }

    /// A tempering with a confidence map: the guess and the order of the objects are the
    /// evidence's, the top probability the map's, and the belief before the map is kept for
    /// what predicts by Bayes' rule (active touch).
    #[test]
    fn a_mapped_decision_keeps_the_guess_and_the_evidence() {
        use crate::recognize::calibration::ConfidenceMap;
        let log_likelihood = vec![-3.0, -1.0, -2.5];
        let plain = Tempering::new(1.0, 1.0).unwrap();
        let map = ConfidenceMap::new(&[[0.4, 0.35], [0.7, 0.45]]).unwrap();
        let mapped = Decision::calibrated(log_likelihood.clone(), 4, plain.with_confidence_map(map), 4);
        let before = Decision::calibrated(log_likelihood, 4, plain, 4);
        assert_eq!(before.evidence_probabilities, None);
        assert_eq!(mapped.guess, 1);
        assert_eq!(mapped.guess, before.guess);
        assert_eq!(mapped.evidence(), before.probabilities.as_slice());
        let top = before.probabilities[1];
        assert!(top > 0.7, "{before:?}");
        assert!((mapped.probabilities[1] - 0.45).abs() < 1e-9, "{mapped:?}");
        assert!(mapped.probabilities[2] > mapped.probabilities[0]);
    }

    #[test]
    fn entropy_of_known_distributions() {
        assert!((entropy_nats(&[0.5, 0.5]) - 2f64.ln()).abs() < 1e-15);
        assert_eq!(entropy_nats(&[1.0, 0.0]), 0.0);
    }

    #[test]
    fn no_features_gives_a_uniform_distribution() {
        let d = models().decide(&ClusterHistogram::new(3));
        assert!(d.probabilities.iter().all(|p| (p - 1.0 / 3.0).abs() < 1e-15));
        assert!((d.entropy_nats() - 3f64.ln()).abs() < 1e-12);
        assert_eq!(d.guess, 0);
    }

    #[test]
    fn soft_memberships_weigh_in_proportionally() {
        let m = models();
        let mut u = ClusterHistogram::new(3);
        u.add(&[0.1, 0.9, 0.0]);
        let d = m.decide(&u);
        assert_eq!(d.guess, 1);
        let expected: f64 = -(0.1 * m.log_probabilities(1)[0] + 0.9 * m.log_probabilities(1)[1]);
        assert!((d.cross_entropy[1] - expected).abs() < 1e-15);
    }

    /// The per-frame rule (a classifier's memberships): `ln p(U | O_j)` is the sum of each
    /// feature's `ln p(c_j | f)`, a zero floored, whatever the object histograms say; a merged
    /// histogram decides as the features added one by one; clusters that are not the objects
    /// cannot decide so.
    #[test]
    fn the_per_frame_rule_multiplies_the_memberships() {
        use crate::recognize::object_model::MEMBERSHIP_FLOOR;
        let per_frame = models().with_rule(EvidenceRule::PerFrame).unwrap();
        let features = [[0.7, 0.2, 0.1], [0.1, 0.9, 0.0]];
        let mut u = per_frame.empty_histogram();
        let mut halves = (per_frame.empty_histogram(), per_frame.empty_histogram());
        for f in &features {
            u.add(f);
        }
        halves.0.add(&features[0]);
        halves.1.add(&features[1]);
        halves.0.merge(&halves.1);
        let expected = [
            0.7f64.ln() + 0.1f64.ln(),
            0.2f64.ln() + 0.9f64.ln(),
            0.1f64.ln() + MEMBERSHIP_FLOOR.ln(),
        ];
        for (got, want) in per_frame.log_likelihoods(&u).iter().zip(expected) {
            assert!((got - want).abs() < 1e-12, "{got} {want}");
        }
        assert_eq!(
            per_frame.log_likelihoods(&halves.0),
            per_frame.log_likelihoods(&u)
        );
        assert_eq!(per_frame.decide(&u).guess, 1);
        // Eq. 4 on the same features weighs them against the histograms instead.
        assert_ne!(models().log_likelihoods(&u), per_frame.log_likelihoods(&u));
        let mut four = ClusterHistogram::new(4);
        four.add(&[1.0, 0.0, 0.0, 0.0]);
        let wide = ObjectModels::fit(vec!["a".into()], &[four], PseudoCount::LAPLACE).unwrap();
        let e = wide.with_rule(EvidenceRule::PerFrame).unwrap_err();
        assert!(e.to_string().contains("one cluster per object"), "{e}");
    }

    /// A histogram of counts alone cannot give the product rule's evidence: a per-frame model
    /// refuses it loudly rather than deciding by Eq. 4 in its place.
    #[test]
    #[should_panic(expected = "ObjectModels::empty_histogram")]
    fn a_per_frame_model_refuses_a_histogram_without_its_sums() {
        let per_frame = models().with_rule(EvidenceRule::PerFrame).unwrap();
        let mut counts = ClusterHistogram::new(3);
        counts.add(&[0.7, 0.2, 0.1]);
        per_frame.decide(&counts);
    }
}
