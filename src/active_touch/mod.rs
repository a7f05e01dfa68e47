//! Active touch by expected information gain, and stopping when sure (beyond the paper; its Sec. VI
//! names "expected information gain" as the planning criterion it leaves to future work).
//!
//! [`InformationGain`] implements the planner's [`TouchScorer`]. For a candidate target `x` it
//! predicts the distribution of the codebook cluster `c` a touch near `x` would show, and scores
//! `x` by the expected reduction of the entropy of the posterior over identity (Eq. 16):
//!
//! ```text
//! EIG(x) = H(pi) - sum_c q_x(c) H(pi | c),   (pi | c)_j  ∝  pi_j p(c | O_j)^w
//! ```
//!
//! with `pi` the current posterior, `p(c | O_j)` the trained object models (Eq. 4's histograms) and
//! `w` the mean number of features per reading so far (1 before any reading), so that one predicted
//! reading moves the posterior as a reading does under Eq. 15-16.
//!
//! The prediction `q_x` mixes two things the recogniser knows, never the object's pose or shape:
//! - the appearance-only prediction `m(c) = sum_j pi_j p(c | O_j)`, what the current belief expects
//!   of a touch anywhere; with `q_x = m` the score is the mutual information of identity and the
//!   next cluster, the same for every candidate;
//! - the clusters of the readings already taken within [`InformationGain::neighbourhood_m`] of `x`
//!   (their per-reading normalised histograms, averaged to `e_x`): what this part of the surface
//!   showed before.
//!
//! `q_x = (kappa m + n_x e_x) / (kappa + n_x)`, with `n_x` such readings and `kappa` =
//! [`PRIOR_READINGS`]. An unexplored neighbourhood (`n_x = 0`) is predicted by the belief alone; an
//! explored one by what it showed, so candidates near readings whose clusters tell the still
//! likely objects apart score high (touch there again), candidates near readings of clusters all
//! likely objects share (a flat face) score low, and unexplored places sit in between at the
//! mutual information. The assumptions: a touch lands near its target, nearby readings predict the
//! next (the surface does not change within a neighbourhood, which a perturbation of the object
//! breaks), and readings are independent given the object, as Eq. 15 already assumes. Whether an
//! iteration touches at all is the planner's to judge: it ranks candidates by this score times its
//! own estimate of that chance (`explore::active`, [`TouchOdds`](crate::explore::TouchOdds)), so
//! unexplored empty space, which scores the mutual information, does not win over the surface.
//!
//! Cost per planner iteration: `H(pi | c)` for every cluster once, `O(k J)` for `k` clusters and
//! `J` objects, then per candidate `O(r + k)` for `r` readings so far; no MuJoCo, no descriptor.
//! `benches/recognize.rs` measures it against a plain planner iteration.
//!
//! [`explore_recognizing`] runs the planner one touch at a time, updates the posterior after each
//! converged reading and applies the confidence stop. [`TouchEpisode`] hands the choice of each
//! touch to a caller instead (a learned policy, a Gymnasium environment): it owns the scene, the
//! planner and the belief of one object's exploration, and touches toward the candidate it is told.

mod episode;
mod recipe;
mod stop;

pub use episode::{EpisodeConfig, TouchAction, TouchEpisode};
pub use recipe::{ArmData, ArmTraining, ArmTrainingError, ArmTrainingObserver, ArmTrainingRecipe};
pub use stop::{REPORTED_STOPS, StopRecord, reported_stops, stops};

use std::collections::BTreeMap;

use glam::DVec3;

use crate::control::ControlError;
use crate::dataset::{Perturbed, Reading};
use crate::explore::Planner;
use crate::explore::active::{ActiveGuidance, ConfidenceStop, TouchScorer};
use crate::locate::GainOf;
use crate::recognize::bag::BagOfFeatures;
use crate::recognize::decision::entropy_nats;
use crate::recognize::object_model::{ClusterHistogram, ObjectModels};
use crate::recognize::posterior::{Belief, ModelPosterior};
use crate::recognize::{FusedModel, RecognizeError, Recognizer, Tempering, TrainedModel};
use crate::sim::Scene;
use crate::tactile::TactileImage;
use crate::valid::RangeError;

/// `kappa`: how many readings' worth of weight the belief's own prediction has against the readings
/// of a neighbourhood (see the module docs). One: a single nearby reading already counts as much as
/// the belief, two outweigh it.
pub const PRIOR_READINGS: f64 = 1.0;

/// The expected-information-gain scorer's state: the posterior and the readings so far.
#[derive(Debug, Clone)]
pub struct InformationGain<'a> {
    models: &'a ObjectModels,
    probabilities: Vec<f64>,
    /// The belief the next reading updates: `probabilities` with its evidence reweighed from
    /// `w(n)` to `w(n + 1)` (equal to it under Eq. 15).
    next_prior: Vec<f64>,
    features: usize,
    /// Readings recorded, with a pad pose or without.
    observed: usize,
    /// Pad location and normalised cluster histogram of every reading observed.
    readings: Vec<(DVec3, Vec<f64>)>,
    /// The posterior's tempering (`recognize::calibration`): how much the next reading will move it.
    tempering: Tempering,
    /// Readings within this distance of a candidate predict what a touch there shows, metres.
    pub neighbourhood_m: f64,
}

impl<'a> InformationGain<'a> {
    /// No reading yet: a uniform posterior, updated as Eq. 15-16 update it.
    pub fn new(models: &'a ObjectModels, neighbourhood_m: f64) -> Self {
        let n = models.objects().len();
        Self {
            models,
            probabilities: vec![1.0 / n as f64; n],
            next_prior: vec![1.0 / n as f64; n],
            features: 0,
            observed: 0,
            readings: Vec::new(),
            tempering: Tempering::EQ15,
            neighbourhood_m,
        }
    }

    /// The same scorer for a posterior tempered by `tempering`.
    pub fn with_tempering(mut self, tempering: Tempering) -> Self {
        self.tempering = tempering;
        self
    }

    /// Records one reading: its cluster histogram, where it was taken (readings without a pad pose
    /// predict nothing about places) and the posterior after it.
    pub fn record(&mut self, location_m: Option<DVec3>, reading: &ClusterHistogram, posterior: &[f64]) {
        self.features += reading.features();
        self.observed += 1;
        if let Some(l) = location_m
            && reading.features() > 0
        {
            self.readings.push((l, reading.distribution()));
        }
        self.probabilities = posterior.to_vec();
        let reweigh = self.tempering.weight(self.observed + 1) / self.tempering.weight(self.observed);
        let log_prior: Vec<f64> = posterior.iter().map(|p| reweigh * p.ln()).collect();
        let lse = crate::recognize::gmm::log_sum_exp(&log_prior);
        self.next_prior = log_prior.iter().map(|l| (l - lse).exp()).collect();
    }

    /// The posterior the scores start from.
    pub fn probabilities(&self) -> &[f64] {
        &self.probabilities
    }

    /// `m(c) = sum_j pi_j p_w(c | O_j)`: the cluster a touch anywhere (near no earlier reading) is
    /// expected to show, under the clusters' likelihood as the next reading weighs it
    /// ([`entropies_after`](Self::entropies_after)).
    pub fn belief_prediction(&self) -> Vec<f64> {
        let log_p = self.weighed_log_likelihoods(self.reading_weight(0));
        let mut m = vec![0.0; self.models.clusters()];
        for (pi, log_p) in self.next_prior.iter().zip(&log_p) {
            for (mc, l) in m.iter_mut().zip(log_p) {
                *mc += pi * l.exp();
            }
        }
        m
    }

    /// `w`: how much the next reading's features weigh in the posterior, near `nearby` earlier
    /// readings ([`entropies_after`](Self::entropies_after)).
    fn reading_weight(&self, nearby: usize) -> f64 {
        let per_reading = if self.observed == 0 || self.features == 0 {
            1.0
        } else {
            self.features as f64 / self.observed as f64
        };
        self.tempering.weight(self.observed + 1) * per_reading / (1.0 + nearby as f64)
    }

    /// `ln p_w(c | O_j) = w ln p(c | O_j) - ln sum_c' p(c' | O_j)^w` for every object `j` and
    /// cluster `c`: the object models raised to `w` and normalised, a likelihood the update by `w`
    /// is exact Bayes under, so that the expected gain of a touch predicted by the belief is a
    /// mutual information, never negative (`p_1` is Eq. 4's `p(c | O_j)` itself).
    fn weighed_log_likelihoods(&self, w: f64) -> Vec<Vec<f64>> {
        (0..self.models.objects().len())
            .map(|j| {
                let raised: Vec<f64> = self.models.log_probabilities(j).iter().map(|l| w * l).collect();
                let lse = crate::recognize::gmm::log_sum_exp(&raised);
                raised.iter().map(|l| l - lse).collect()
            })
            .collect()
    }

    /// `q_x`: the belief's prediction `m` mixed with the clusters of the readings near `target_m`.
    pub fn predicted_clusters(&self, target_m: DVec3, m: &[f64]) -> Vec<f64> {
        self.neighbourhood(target_m, m).0
    }

    /// `q_x` and `n_x`, the readings within [`neighbourhood_m`](Self::neighbourhood_m) of `target_m`.
    fn neighbourhood(&self, target_m: DVec3, m: &[f64]) -> (Vec<f64>, usize) {
        let mut q: Vec<f64> = m.iter().map(|v| v * PRIOR_READINGS).collect();
        let mut nearby = 0;
        for (location, distribution) in &self.readings {
            if location.distance(target_m) <= self.neighbourhood_m {
                q.iter_mut().zip(distribution).for_each(|(a, b)| *a += b);
                nearby += 1;
            }
        }
        let weight = PRIOR_READINGS + nearby as f64;
        q.iter_mut().for_each(|v| *v /= weight);
        (q, nearby)
    }

    /// `H(pi | c)` for every cluster `c`, nats, for a touch near `nearby` earlier readings.
    ///
    /// The predicted reading moves the belief as the posterior would: the evidence so far
    /// reweighed from `w(n)` to `w(n + 1)` and the reading's features at `w(n + 1)`
    /// (`recognize::calibration`; both 1 under Eq. 15). A touch of a place already touched
    /// `n_x` times mostly repeats what those touches showed (neighbouring readings are
    /// correlated, which is why the calibrated posterior's `beta` is below 1), so its evidence
    /// counts `1 / (1 + n_x)` of a fresh place's: without the discount the scorer returns to the
    /// one telling place it found and the belief stops improving.
    pub fn entropies_after(&self, nearby: usize) -> Vec<f64> {
        let log_p = self.weighed_log_likelihoods(self.reading_weight(nearby));
        let log_pi: Vec<f64> = self.next_prior.iter().map(|p| p.ln()).collect();
        let mut log_post = vec![0.0; log_pi.len()];
        (0..self.models.clusters())
            .map(|c| {
                for (j, l) in log_post.iter_mut().enumerate() {
                    *l = log_pi[j] + log_p[j][c];
                }
                let lse = crate::recognize::gmm::log_sum_exp(&log_post);
                let post: Vec<f64> = log_post.iter().map(|l| (l - lse).exp()).collect();
                entropy_nats(&post)
            })
            .collect()
    }

    /// `EIG(x)` for a prediction `q` given [`entropies_after`](Self::entropies_after), nats.
    pub fn expected_gain_nats(&self, q: &[f64], entropies_after: &[f64]) -> f64 {
        let expected: f64 = q.iter().zip(entropies_after).map(|(q, h)| q * h).sum();
        entropy_nats(&self.next_prior) - expected
    }
}

impl TouchScorer for InformationGain<'_> {
    fn score(&self, candidates_m: &[DVec3]) -> Vec<f64> {
        let m = self.belief_prediction();
        // `H(pi | c)` depends on a candidate only through its count of nearby readings.
        let mut after: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
        candidates_m
            .iter()
            .map(|&x| {
                let (q, nearby) = self.neighbourhood(x, &m);
                let entropies = after
                    .entry(nearby)
                    .or_insert_with(|| self.entropies_after(nearby));
                self.expected_gain_nats(&q, entropies)
            })
            .collect()
    }
}

/// A recogniser that also scores where to touch next: the model's posterior (Eq. 16, fed with
/// images, [`ModelPosterior`]) and the [`InformationGain`] state fed with the same readings. A
/// fused model (several descriptors, their likelihoods multiplied, `recognize::fusion`) gives the
/// belief; its first model's clusters give the gain's predictions.
pub struct ActiveRecognition<'a> {
    bag: &'a BagOfFeatures,
    posterior: ModelPosterior<'a>,
    gain: InformationGain<'a>,
    /// What the contact of a touch is scored for (`locate::predict`), added to the appearance
    /// gain; `None` (the default): appearance alone. On the demo's seeds the contact's gain chose
    /// touches that recognised worse (docs/measurements.md, "Touches chosen for where they
    /// land"), so it is the comparison, not the default.
    contact_gain: Option<GainOf>,
}

impl<'a> ActiveRecognition<'a> {
    /// The recogniser of one model, describing images with the model's descriptor.
    pub fn new(model: &'a TrainedModel, neighbourhood_m: f64) -> Result<Self, RecognizeError> {
        Ok(Self::with(
            &model.bag,
            model.posterior()?,
            model.bag.tempering(),
            neighbourhood_m,
        ))
    }

    /// The recogniser of a fused model, describing images with each model's descriptor.
    pub fn fused(model: &'a FusedModel, neighbourhood_m: f64) -> Result<Self, RecognizeError> {
        Ok(Self::with(
            &model.fused[0].bag,
            model.image_posterior()?,
            model.tempering,
            neighbourhood_m,
        ))
    }

    /// The recogniser of a model of any kind ([`new`](Self::new), [`fused`](Self::fused), or with
    /// the contacts) of an object `motion` perturbs after every touch.
    pub fn of(
        model: &'a Recognizer,
        neighbourhood_m: f64,
        motion: Perturbed,
    ) -> Result<Self, RecognizeError> {
        match model {
            Recognizer::Single(m) => Self::new(m, neighbourhood_m),
            Recognizer::Fused(f) => Self::fused(f, neighbourhood_m),
            // The gain predicts the appearance of a touch (the first appearance model's), and its
            // contact only when asked (`with_contact_gain`: measured, it chose worse touches);
            // the belief is the fused one, contacts included.
            Recognizer::Geometric(g) => {
                let bag = &g.appearance().parts()[0].bag;
                Ok(Self::with(
                    bag,
                    model.posterior_for(motion)?,
                    g.tempering(),
                    neighbourhood_m,
                ))
            }
        }
    }

    fn with(
        bag: &'a BagOfFeatures,
        posterior: ModelPosterior<'a>,
        tempering: Tempering,
        neighbourhood_m: f64,
    ) -> Self {
        Self {
            bag,
            posterior,
            gain: InformationGain::new(bag.models(), neighbourhood_m).with_tempering(tempering),
            contact_gain: None,
        }
    }

    /// The same recogniser scoring a touch's contact for `of` too, or its appearance alone
    /// (`None`); a model that does not weigh contacts scores appearance alone either way.
    pub fn with_contact_gain(self, of: Option<GainOf>) -> Self {
        Self {
            contact_gain: of,
            ..self
        }
    }

    /// Describes one converged reading's image, adds it to the posterior and returns the belief.
    pub fn observe(&mut self, image: &TactileImage) -> Result<Belief, RecognizeError> {
        let features = self.posterior.describe(image);
        let mut reading = self.bag.models().empty_histogram();
        self.bag.add_features(&features[0], &mut reading, "the reading")?;
        let belief = self.posterior.observe_described(image, features)?;
        // The gain predicts by Bayes' rule, which the tempered belief follows and its confidence
        // map does not (`recognize::calibration`): it starts from the belief before the map.
        self.gain.record(
            image.pose().map(|p| p.center_m),
            &reading,
            belief.decision.evidence(),
        );
        Ok(belief)
    }

    /// Counts a touch attempt that gave no reading (the belief of a perturbed object widens by
    /// one more move before the next reading, `ModelPosterior::missed`).
    pub fn missed(&mut self) {
        self.posterior.missed();
    }

    pub fn belief(&self) -> Belief {
        self.posterior.belief()
    }

    /// What scores candidate touches: the appearance gain, plus the contact's where the model
    /// weighs contacts (the [`TouchScorer`] impl).
    pub fn scorer(&self) -> &dyn TouchScorer {
        self
    }
}

/// A touch's expected gain: what its appearance would tell (`InformationGain`) plus what its
/// contact would (`locate::predict`), each about identity given the belief so far. The fused
/// posterior multiplies the two likelihoods (`recognize::geometric`), treating them as
/// independent given the object; so does the sum of their gains, an approximation where they
/// overlap (a flat face looks flat and lies on a plane), and the score only ranks candidates.
impl TouchScorer for ActiveRecognition<'_> {
    fn score(&self, candidates_m: &[DVec3]) -> Vec<f64> {
        let mut scores = self.gain.score(candidates_m);
        if let (Some(of), Some(fused)) = (self.contact_gain, self.posterior.as_geometric()) {
            let contacts = fused.contact_gains_nats(candidates_m, of);
            scores.iter_mut().zip(contacts).for_each(|(s, c)| *s += c);
        }
        scores
    }
}

/// How [`explore_recognizing`] explores.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TouchPlan {
    /// Converged touches at most (the budget).
    pub budget: usize,
    /// `Some(n)`: the active strategy with `n` candidates per iteration; `None`: the planner's
    /// local/global rule.
    pub active_candidates: Option<usize>,
    /// The confidence stop: end once one guess has held its probability at the stop's threshold
    /// over its last touches.
    pub stop_at_confidence: Option<ConfidenceStop>,
}

/// One converged touch and the belief after it.
#[derive(Debug, Clone, PartialEq)]
pub struct Touch {
    pub reading: Reading,
    pub belief: Belief,
    /// Its attempt among the exploration's touch attempts, converged or not (from 0).
    pub attempt: usize,
}

/// What [`explore_recognizing`] did.
pub struct TouchRun {
    pub touches: Vec<Touch>,
    /// Reading attempts, converged or not.
    pub attempts: usize,
    /// Planner iterations spent, with or without a reading.
    pub iterations: usize,
    /// Whether the confidence stop ended the run (else the budget was spent, or the planner ran
    /// out of iterations before a touch).
    pub stopped_confident: bool,
}

/// What can end [`explore_recognizing`] early, or refuse a [`TouchEpisode`] or one of its touches.
#[derive(Debug, thiserror::Error)]
pub enum TouchError {
    #[error(transparent)]
    Explore(#[from] ControlError),
    #[error(transparent)]
    Recognize(#[from] RecognizeError),
    /// The episode's configuration failed its check.
    #[error(transparent)]
    Config(#[from] RangeError),
    /// A touch toward a candidate the episode did not offer.
    #[error(
        "touch toward candidate {index}: the episode offers {candidates} candidates (indices below {candidates})"
    )]
    NoSuchCandidate { index: usize, candidates: usize },
    /// The object to explore is not one the model recognises.
    #[error("object '{object}' is not in the model (it knows {known})")]
    UnknownObject { object: String, known: String },
}

/// Explores `object` in `scene` one converged touch at a time, recognising as it goes: after each
/// touch the posterior is updated (and shown to `on_touch`); the run ends when the confidence stop
/// fires, the budget is spent, or the planner finds no touch within its iteration budget. The
/// planner's random draws do not depend on the stop, so a run with the stop is the run without it
/// cut short.
pub fn explore_recognizing<R>(
    planner: &mut Planner<R>,
    scene: &mut Scene,
    object: &str,
    recognition: &mut ActiveRecognition<'_>,
    plan: TouchPlan,
    on_touch: &mut dyn FnMut(&Touch),
) -> Result<TouchRun, TouchError>
where
    R: crate::control::ReadTactile,
{
    let mut run = TouchRun {
        touches: Vec::new(),
        attempts: 0,
        iterations: 0,
        stopped_confident: false,
    };
    // Each touch's guess and its probability, what the confidence stop watches.
    let mut trace = Vec::new();
    while run.touches.len() < plan.budget {
        let guidance = plan.active_candidates.map(|candidates| ActiveGuidance {
            scorer: recognition.scorer(),
            candidates,
        });
        let report = planner.explore_guided(scene, object, 1, guidance, &mut || {})?;
        let first_attempt = run.attempts;
        run.attempts += report.readings.len();
        run.iterations += report.iterations;
        if !report.readings.iter().any(Reading::is_converged) {
            break;
        }
        for (attempt, reading) in (first_attempt..).zip(report.readings) {
            if !reading.is_converged() {
                recognition.missed();
                continue;
            }
            let belief = recognition.observe(&reading.image)?;
            let touch = Touch {
                reading,
                belief,
                attempt,
            };
            on_touch(&touch);
            trace.push((touch.belief.guess(), max_probability(&touch.belief)));
            let confident = plan.stop_at_confidence.is_some_and(|stop| stop.fires(&trace));
            run.touches.push(touch);
            if confident {
                run.stopped_confident = true;
                return Ok(run);
            }
        }
    }
    Ok(run)
}

/// The posterior's largest probability.
pub fn max_probability(belief: &Belief) -> f64 {
    belief.probabilities()[belief.guess()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recognize::object_model::PseudoCount;

    /// Two objects that differ only in clusters 2 and 3; clusters 0 and 1 they share.
    fn toy_models() -> ObjectModels {
        let histogram = |counts: [f64; 4]| {
            let mut h = ClusterHistogram::new(4);
            for (c, n) in counts.iter().enumerate() {
                for _ in 0..*n as usize {
                    let mut m = [0.0; 4];
                    m[c] = 1.0;
                    h.add(&m);
                }
            }
            h
        };
        ObjectModels::fit(
            vec!["a".into(), "b".into()],
            &[
                histogram([40.0, 40.0, 18.0, 2.0]),
                histogram([40.0, 40.0, 2.0, 18.0]),
            ],
            PseudoCount::new(1e-9).unwrap(),
        )
        .unwrap()
    }

    fn one_feature(c: usize) -> ClusterHistogram {
        let mut h = ClusterHistogram::new(4);
        let mut m = [0.0; 4];
        m[c] = 1.0;
        h.add(&m);
        h
    }

    /// With no reading every candidate scores the mutual information of identity and one cluster,
    /// computed by hand: H(pi) = ln 2; clusters 0, 1 (p = 0.4 each) leave the posterior uniform;
    /// clusters 2, 3 (p = 0.1 each) move it to (0.9, 0.1).
    #[test]
    fn without_readings_every_candidate_scores_the_mutual_information() {
        let models = toy_models();
        let gain = InformationGain::new(&models, 0.01);
        let h09 = -(0.9f64 * 0.9f64.ln() + 0.1 * 0.1f64.ln());
        let expected = 2f64.ln() - (0.8 * 2f64.ln() + 0.2 * h09);
        let scores = gain.score(&[DVec3::ZERO, DVec3::X]);
        for s in scores {
            assert!((s - expected).abs() < 1e-6, "{s} vs {expected}");
        }
    }

    /// The known answer: a candidate beside a reading of a discriminating cluster beats one beside a
    /// reading of a shared cluster, and an unexplored one lies between.
    #[test]
    fn the_candidate_whose_predicted_clusters_discriminate_wins() {
        let models = toy_models();
        let mut gain = InformationGain::new(&models, 0.01);
        let uniform = [0.5, 0.5];
        let shared = DVec3::new(0.1, 0.0, 0.0);
        let telling = DVec3::new(-0.1, 0.0, 0.0);
        for _ in 0..3 {
            gain.record(Some(shared), &one_feature(0), &uniform);
        }
        gain.record(Some(telling), &one_feature(2), &uniform);
        let candidates = [
            shared + DVec3::splat(0.002),
            DVec3::new(0.0, 0.1, 0.0),
            telling + DVec3::splat(0.002),
        ];
        let scores = gain.score(&candidates);
        assert!(scores[2] > scores[1] && scores[1] > scores[0], "{scores:?}");
        assert_eq!(crate::explore::active::best_candidate(&scores), Some(2));
        // Near the shared readings the prediction is 3/4 cluster 0, which says nothing.
        let q = gain.predicted_clusters(candidates[0], &gain.belief_prediction());
        assert!((q[0] - (0.4 + 3.0) / 4.0).abs() < 1e-6, "{q:?}");
    }

    /// A place touched six times over, all showing a telling cluster, loses to an unexplored one:
    /// a seventh touch there mostly repeats them (the discount), while once it wins. Hand-computed:
    /// the discounted weight 1/7 moves the uniform belief only to about (0.58, 0.42).
    #[test]
    fn repeated_touches_of_one_place_are_discounted() {
        let models = toy_models();
        let uniform = [0.5, 0.5];
        let telling = DVec3::new(-0.1, 0.0, 0.0);
        let candidates = [telling + DVec3::splat(0.002), DVec3::new(0.0, 0.1, 0.0)];
        let mut once = InformationGain::new(&models, 0.01);
        once.record(Some(telling), &one_feature(2), &uniform);
        let scores = once.score(&candidates);
        assert!(scores[0] > scores[1], "{scores:?}");
        let mut often = InformationGain::new(&models, 0.01);
        for _ in 0..6 {
            often.record(Some(telling), &one_feature(2), &uniform);
        }
        let scores = often.score(&candidates);
        assert!(scores[1] > scores[0], "{scores:?}");
        assert!(scores[0] < 0.02, "{scores:?}");
    }

    /// A tempered posterior (evidence worth less than Eq. 15's) expects less of a touch.
    #[test]
    fn a_tempered_posterior_expects_less_of_a_touch() {
        let models = toy_models();
        let plain = InformationGain::new(&models, 0.01);
        let tempered = plain.clone().with_tempering(Tempering::new(0.3, 1.0).unwrap());
        let x = [DVec3::ZERO];
        assert!(tempered.score(&x)[0] < plain.score(&x)[0]);
    }

    /// Once the posterior is certain nothing is left to learn anywhere.
    #[test]
    fn a_certain_posterior_expects_no_gain() {
        let models = toy_models();
        let mut gain = InformationGain::new(&models, 0.01);
        gain.record(Some(DVec3::ZERO), &one_feature(2), &[1.0, 0.0]);
        for s in gain.score(&[DVec3::ZERO, DVec3::ONE]) {
            assert!(s.abs() < 1e-12, "{s}");
        }
    }
}
