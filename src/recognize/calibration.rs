//! A calibrated posterior (beyond the paper). Eq. 15 multiplies the readings' likelihoods as if
//! they were independent given the object, and Eq. 16's softmax trusts the codebook's histograms
//! as they are. Neither holds: successive touches of one exploration see neighbouring surface, so
//! ten readings carry less than ten readings' evidence, and a codebook can be sharper or flatter
//! than the data (the Gaussian mixture's near-hard memberships make it overconfident, the
//! neighbour codebook's smooth shares underconfident). Measured on the 3D set, a stop at p = 0.95
//! was right 50-71% of the time with Eq. 15.
//!
//! [`Tempering`] weighs the log-likelihood after `n` readings by `w(n) = tau n^(beta - 1)`:
//!
//! ```text
//! p(O_j | r_1..r_n)  ∝  p(O_j) prod_i p(r_i | O_j)^w(n)
//! ```
//!
//! so the evidence of `n` readings counts as `n_eff(n) = n w(n) = tau n^beta` independent ones:
//! `tau` corrects the codebook's sharpness, `beta < 1` the readings' correlation (evidence that
//! grows slower than the count of readings). A floor `epsilon` then keeps a share of the belief
//! uniform, `p = (1 - epsilon) p_tempered + epsilon / J`: the share of explorations the model gets
//! wrong however much evidence it sees (the arm's touches of one object that resemble another's
//! training data), which no reweighing of the evidence can express; it caps the largest
//! probability at `1 - epsilon (J - 1) / J`. `tau = beta = 1, epsilon = 0` is Eq. 15-16 exactly
//! ([`Tempering::EQ15`]). The guess (Eq. 4) never changes: `w(n) > 0` scales every object's
//! log-likelihood alike and the floor adds the same to every object.
//!
//! A tempering fitted on the arm's explorations (the [`Tempering::fit_with_confidence_map`] of
//! `taction train --calibration`, the `active` experiment and the demo) also carries a
//! [`ConfidenceMap`]: the power `w(n)` and the floor cannot bend the reliability curve, and the
//! Gaussian mixture's, measured on the planner test data of fifteen seeds, is S-shaped: beliefs of
//! 0.45-0.85 right 10-20 points less often than they say, those of 0.2-0.4 more often, those above
//! 0.95 about right (ECE 0.045-0.097 by curve). The map moves the top probability to the accuracy
//! the calibration trials showed at that confidence (isotonic, in ten equal-count bins) by raising
//! the whole belief to one power, so that the order of the objects, and the guess, stay.
//!
//! [`Tempering::fit`] chooses `tau` and `beta` on validation trials, the data model selection
//! already holds out, by the mean negative log-probability of the true object over every prefix
//! `r_1..r_n` of every trial (a proper scoring rule, so the fitted beliefs are calibrated in the
//! limit of data). For each `epsilon` and `beta` of a grid, a golden-section search finds `tau`
//! (without the floor the loss is convex in `ln tau`, a log-softmax of a linear function). Validation trials of the kind the
//! model will be judged on (the arm's explorations, not independent sampler readings) are what
//! let `beta` see the correlation, and they must be as long as the runs to be judged: `w(n)` is
//! only fitted at the counts the trials reach. Fitted on the arm's explorations of the 3D set cut
//! into 10-touch trials, the posterior of 100-touch runs was overconfident (Polar-Fourier and GMM,
//! 144 planner test runs at L = 1 and 0.5, fixed and perturbed: ECE 0.193, a stop at 0.95 right
//! 78% of the time); fitted on the whole 100-touch explorations, ECE 0.074 and 98%.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::recognize::RecognizeError;
use crate::recognize::exp::{Lanes, exp};
use crate::recognize::gmm::{log_sum_exp, log_sum_exp_of_parts};
use crate::recognize::object_model::guess_of;
use crate::recognize::trial::Trial;

/// `w(n) = tau n^(beta - 1)`, the weight of the log-likelihood after `n` readings (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TemperingFields", into = "TemperingFields")]
pub struct Tempering {
    tau: f64,
    beta: f64,
    floor: f64,
    confidence_map: Option<ConfidenceMap>,
}

/// The file form of a [`Tempering`], checked on load. A tempering without a map writes the fields
/// it wrote before maps existed, and a file without one reads as before.
#[derive(Serialize, Deserialize)]
struct TemperingFields {
    tau: f64,
    beta: f64,
    #[serde(default)]
    floor: f64,
    /// The [`ConfidenceMap`]'s points, `[confidence, accuracy]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    confidence_map: Option<Vec<[f64; 2]>>,
}

impl TryFrom<TemperingFields> for Tempering {
    type Error = RecognizeError;
    fn try_from(f: TemperingFields) -> Result<Self, RecognizeError> {
        let tempering = Self::new(f.tau, f.beta)?.with_floor(f.floor)?;
        Ok(match f.confidence_map {
            Some(points) => tempering.with_confidence_map(ConfidenceMap::new(&points)?),
            None => tempering,
        })
    }
}

impl From<Tempering> for TemperingFields {
    fn from(t: Tempering) -> Self {
        Self {
            tau: t.tau,
            beta: t.beta,
            floor: t.floor,
            confidence_map: t.confidence_map.map(|m| m.points().collect()),
        }
    }
}

impl std::fmt::Display for Tempering {
    /// `tau = 1.234, beta = 0.35, floor = 0.000`, and the map's size when there is one.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "tau = {:.3}, beta = {:.2}, floor = {:.3}",
            self.tau, self.beta, self.floor
        )?;
        if let Some(map) = self.confidence_map {
            write!(f, ", confidence map of {} points", map.len)?;
        }
        Ok(())
    }
}

impl Default for Tempering {
    /// Eq. 15: a model file written before calibration existed recognises as it did.
    fn default() -> Self {
        Self::EQ15
    }
}

/// The `beta` grid [`Tempering::fit`] searches: from evidence that hardly grows with the readings'
/// count (0.05: touches that repeat what the first ones felt) to slightly faster than independent
/// readings (1.2). Fitted on the arm's whole 100-touch explorations of the 3D set, `beta` came out
/// at 0.3, the end of a grid that began there, so the grid reaches lower.
const BETA_GRID: [f64; 24] = [
    0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95,
    1.0, 1.05, 1.1, 1.15, 1.2,
];

/// The range of `ln tau` the golden-section search covers: a thousandth to a hundred times Eq. 15.
const LN_TAU_RANGE: (f64, f64) = (-6.907_755_278_982_137, 4.605_170_185_988_092);

/// Golden-section steps: the bracket shrinks by 0.618 each, to 1e-12 of its width after 60.
const GOLDEN_STEPS: usize = 60;

/// The floors [`Tempering::fit`] tries: the share of the belief that stays uniform.
const FLOOR_GRID: [f64; 8] = [0.0, 0.005, 0.01, 0.02, 0.03, 0.05, 0.08, 0.12];

impl Tempering {
    /// Eq. 15-16 as the paper writes them: every reading counts fully.
    pub const EQ15: Self = Self {
        tau: 1.0,
        beta: 1.0,
        floor: 0.0,
        confidence_map: None,
    };

    /// `tau > 0`, `beta > 0`, both finite.
    pub fn new(tau: f64, beta: f64) -> Result<Self, RecognizeError> {
        if !(tau > 0.0 && tau.is_finite()) {
            return Err(RecognizeError::InvalidParameter {
                name: "tempering tau",
                what: format!("{tau} is not a positive finite weight"),
            });
        }
        if !(beta > 0.0 && beta.is_finite()) {
            return Err(RecognizeError::InvalidParameter {
                name: "tempering beta",
                what: format!("{beta} is not a positive finite exponent"),
            });
        }
        Ok(Self {
            tau,
            beta,
            floor: 0.0,
            confidence_map: None,
        })
    }

    /// The same tempering with its top probability moved by `map` ([`ConfidenceMap`]).
    pub fn with_confidence_map(self, map: ConfidenceMap) -> Self {
        Self {
            confidence_map: Some(map),
            ..self
        }
    }

    /// The [`ConfidenceMap`], when one was fitted.
    pub fn confidence_map(self) -> Option<ConfidenceMap> {
        self.confidence_map
    }

    /// The same tempering with a share `floor` in `[0, 1)` of the belief kept uniform.
    pub fn with_floor(self, floor: f64) -> Result<Self, RecognizeError> {
        if !(0.0..1.0).contains(&floor) {
            return Err(RecognizeError::InvalidParameter {
                name: "tempering floor",
                what: format!("{floor} is not a share in [0, 1)"),
            });
        }
        Ok(Self { floor, ..self })
    }

    /// `epsilon`: the share of the belief that stays uniform whatever the evidence.
    pub fn floor(self) -> f64 {
        self.floor
    }

    /// `p(O_j | r_1..r_n)` for every object from the untempered log-likelihoods `ln p(r_1..r_n | O_j)`
    /// after `readings` readings: [`evidence_probabilities`](Self::evidence_probabilities) with
    /// the [`ConfidenceMap`] applied when there is one.
    pub fn probabilities(self, log_likelihood: &[f64], readings: usize) -> Vec<f64> {
        self.mapped(self.evidence_probabilities(log_likelihood, readings))
    }

    /// The belief `p` moved by the [`ConfidenceMap`] (unchanged without one).
    pub fn mapped(self, mut p: Vec<f64>) -> Vec<f64> {
        if let Some(map) = self.confidence_map {
            map.apply(&mut p);
        }
        p
    }

    /// `(1 - epsilon) softmax(w(n) l) + epsilon / J`: the tempered posterior before the map, the
    /// belief a further reading updates by Bayes' rule (what active touch predicts from).
    pub fn evidence_probabilities(self, log_likelihood: &[f64], readings: usize) -> Vec<f64> {
        let (weighted, lse) = self.tempered(log_likelihood, readings);
        weighted
            .iter()
            .map(|&l| self.probability(l, lse, weighted.len()))
            .collect()
    }

    /// [`probabilities`](Self::probabilities)`[object]` alone, the same bits.
    fn probability_of(self, log_likelihood: &[f64], readings: usize, object: usize) -> f64 {
        let (weighted, lse) = self.tempered(log_likelihood, readings);
        self.probability(weighted[object], lse, weighted.len())
    }

    /// `w(n) l` and its log-sum-exp.
    fn tempered(self, log_likelihood: &[f64], readings: usize) -> (Vec<f64>, f64) {
        let w = self.weight(readings);
        let weighted: Vec<f64> = log_likelihood.iter().map(|l| w * l).collect();
        let lse = log_sum_exp(&weighted);
        (weighted, lse)
    }

    /// One object's probability from its tempered log-likelihood `weighted`, their log-sum-exp
    /// `lse` over `objects` objects.
    fn probability(self, weighted: f64, lse: f64, objects: usize) -> f64 {
        (1.0 - self.floor) * exp(weighted - lse) + self.floor / objects.max(1) as f64
    }

    /// `tau`: the codebook's sharpness correction.
    pub fn tau(self) -> f64 {
        self.tau
    }

    /// `beta`: how the evidence grows with the readings' count.
    pub fn beta(self) -> f64 {
        self.beta
    }

    /// `w(n)`, the weight of the log-likelihood after `readings` readings (1 before any: there is
    /// no evidence to weigh).
    pub fn weight(self, readings: usize) -> f64 {
        if readings == 0 {
            1.0
        } else {
            self.tau * (readings as f64).powf(self.beta - 1.0)
        }
    }

    /// `n_eff(n) = tau n^beta`: how many independent readings `readings` readings are worth.
    pub fn effective_readings(self, readings: usize) -> f64 {
        self.weight(readings) * readings as f64
    }

    /// Chooses `tau` and `beta` by the mean negative log-probability of the true object over
    /// every prefix of `trials` (module docs). Without any evidence (no trial with a reading) it
    /// is [`EQ15`](Self::EQ15). Deterministic: a fixed grid and a fixed number of steps.
    pub fn fit(trials: &[EvidencePath]) -> Self {
        Self::fit_scored(trials).0
    }

    /// [`fit`](Self::fit) and the mean log loss it reaches (infinite without evidence): what
    /// comparing two kinds of evidence by how well their fitted posteriors predict needs.
    pub(crate) fn fit_scored(trials: &[EvidencePath]) -> (Self, f64) {
        if trials.iter().all(|t| t.log_likelihoods.is_empty()) {
            return (Self::EQ15, f64::INFINITY);
        }
        let prefixes = Prefixes::of(trials);
        // Each grid point's search is independent: they run in parallel, and the best is taken
        // in grid order, as a loop over the grid would (the same model for any thread count).
        let grid: Vec<(f64, f64)> = FLOOR_GRID
            .iter()
            .flat_map(|&floor| BETA_GRID.iter().map(move |&beta| (floor, beta)))
            .collect();
        let searched: Vec<(f64, Self)> = grid
            .par_iter()
            .map(|&(floor, beta)| {
                let at = |ln_tau: f64| Self {
                    tau: ln_tau.exp(),
                    beta,
                    floor,
                    confidence_map: None,
                };
                let (ln_tau, loss) = golden_minimum(LN_TAU_RANGE, |t| prefixes.mean_log_loss(at(t)));
                (loss, at(ln_tau))
            })
            .collect();
        let mut best = (f64::INFINITY, Self::EQ15);
        for (loss, tempering) in searched {
            if loss < best.0 {
                best = (loss, tempering);
            }
        }
        (best.1, best.0)
    }

    /// [`fit`](Self::fit), then the [`ConfidenceMap`] of the fitted tempering's top probability
    /// onto the right guesses over every prefix of `trials` (none with fewer than
    /// `MAP_MIN_PREFIXES`, 100, prefixes). For calibration trials of the kind the model will be
    /// judged on: the arm's explorations.
    pub fn fit_with_confidence_map(trials: &[EvidencePath]) -> Self {
        Self::fit(trials).with_confidence_map_of(trials)
    }

    /// This tempering with the [`ConfidenceMap`] of its top probability onto the right guesses
    /// over every prefix of `trials` ([`fit_with_confidence_map`](Self::fit_with_confidence_map)).
    pub(crate) fn with_confidence_map_of(self, trials: &[EvidencePath]) -> Self {
        let tempering = self;
        let beliefs = trials
            .iter()
            .flat_map(|t| {
                t.log_likelihoods.iter().enumerate().map(move |(i, l)| {
                    let top = tempering
                        .evidence_probabilities(l, i + 1)
                        .into_iter()
                        .fold(0.0, f64::max);
                    (top, guess_of(l) == t.object)
                })
            })
            .collect();
        match ConfidenceMap::fit(beliefs) {
            Some(map) => tempering.with_confidence_map(map),
            None => tempering,
        }
    }
}

/// Equal-count bins of the calibration beliefs a [`ConfidenceMap`] is fitted on: as many as the
/// reliability table has (`recognize::reliability`), the bins the ECE is judged in.
pub const MAP_BINS: usize = 10;

/// Fewest calibration prefixes a map is fitted from: ten a bin.
pub const MAP_MIN_PREFIXES: usize = 10 * MAP_BINS;

/// The highest top probability a [`ConfidenceMap`] raises a belief to. A map lowers a belief
/// anywhere, but raises it only below the confidences a stop is asked for (0.9 and up): its top
/// bin averages every belief from about 0.9 to 1 and cannot tell them apart, and a map free to
/// raise them, replayed on the neighbour codebook's planner test data of fourteen seeds, made the
/// stop at 0.95 fire on L = 1 fixed runs that were right 94.6% of the time (95.8% without a map).
pub const RAISE_CEILING: f64 = 0.9;

/// Bisection steps of [`ConfidenceMap::apply`]'s power: the bracket shrinks to 1e-18 of its width.
const POWER_STEPS: usize = 60;

/// The largest power [`ConfidenceMap::apply`] raises a belief to (a bracket that doubles from 1).
const MAX_POWER: f64 = 1024.0;

/// A monotone map from the tempered posterior's top probability to the share of right guesses at
/// that confidence (module docs), fitted on calibration beliefs by the pool-adjacent-violators
/// algorithm over ten equal-count bins (`MAP_BINS`): piecewise linear between the pooled bins' mean
/// confidence and accuracy, constant above the last, running to chance below the first
/// ([`target`](Self::target)), raising no belief above 0.9 (`RAISE_CEILING`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConfidenceMap {
    confidence: [f64; MAP_BINS],
    accuracy: [f64; MAP_BINS],
    len: usize,
}

impl ConfidenceMap {
    /// From its points `[confidence, accuracy]`: one to ten (`MAP_BINS`) of them, in `[0, 1]`, the
    /// confidences increasing and the accuracies not decreasing.
    pub fn new(points: &[[f64; 2]]) -> Result<Self, RecognizeError> {
        let invalid = |what: String| RecognizeError::InvalidParameter {
            name: "confidence map",
            what,
        };
        if points.is_empty() || points.len() > MAP_BINS {
            return Err(invalid(format!(
                "{} points; a map has 1 to {MAP_BINS}",
                points.len()
            )));
        }
        if let Some([c, a]) = points
            .iter()
            .find(|[c, a]| !((0.0..=1.0).contains(c) && (0.0..=1.0).contains(a)))
        {
            return Err(invalid(format!("point [{c}, {a}] is not in [0, 1] x [0, 1]")));
        }
        if let Some(w) = points
            .windows(2)
            .find(|w| !(w[0][0] < w[1][0] && w[0][1] <= w[1][1]))
        {
            return Err(invalid(format!(
                "points {:?} then {:?}: confidences must increase and accuracies not decrease",
                w[0], w[1]
            )));
        }
        let mut map = Self {
            confidence: [0.0; MAP_BINS],
            accuracy: [0.0; MAP_BINS],
            len: points.len(),
        };
        for (i, [c, a]) in points.iter().enumerate() {
            map.confidence[i] = *c;
            map.accuracy[i] = *a;
        }
        Ok(map)
    }

    /// The map of `beliefs` (top probability, whether the guess was right), or `None` with fewer
    /// than `MAP_MIN_PREFIXES` of them or a top probability outside `[0, 1]`. The beliefs are
    /// sorted by confidence (ties in their given order) and cut into `MAP_BINS` bins of equal
    /// count; neighbouring bins whose accuracies fall, or whose mean confidences are equal, are
    /// pooled until the accuracies rise with the confidence.
    pub fn fit(mut beliefs: Vec<(f64, bool)>) -> Option<Self> {
        let n = beliefs.len();
        if n < MAP_MIN_PREFIXES || beliefs.iter().any(|(p, _)| !(0.0..=1.0).contains(p)) {
            return None;
        }
        beliefs.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Per pooled block: (count, sum of confidences, right guesses).
        let mut blocks: Vec<(f64, f64, f64)> = Vec::with_capacity(MAP_BINS);
        for b in 0..MAP_BINS {
            let bin = &beliefs[b * n / MAP_BINS..(b + 1) * n / MAP_BINS];
            let (confidence, right) = bin.iter().fold((0.0, 0.0), |(c, r), &(p, ok)| {
                (c + p, r + f64::from(u8::from(ok)))
            });
            blocks.push((bin.len() as f64, confidence, right));
            while let [.., (n1, c1, r1), (n2, c2, r2)] = blocks[..] {
                if r1 / n1 > r2 / n2 || c1 / n1 >= c2 / n2 {
                    blocks.pop();
                    if let Some(last) = blocks.last_mut() {
                        *last = (n1 + n2, c1 + c2, r1 + r2);
                    }
                } else {
                    break;
                }
            }
        }
        let points: Vec<[f64; 2]> = blocks.iter().map(|&(n, c, r)| [c / n, r / n]).collect();
        Self::new(&points).ok()
    }

    /// The points `[confidence, accuracy]`, by confidence.
    pub fn points(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        (0..self.len).map(|i| [self.confidence[i], self.accuracy[i]])
    }

    /// The top probability a belief over `objects` objects of top probability `top` is moved
    /// to: the accuracy the map gives it, at most `max(top, RAISE_CEILING)`. Between the points
    /// the map is linear, above the last constant, and below the first it runs to chance,
    /// `(1 / J, 1 / J)`: a belief no better than a uniform one is right no more often than a guess,
    /// and the calibration trials say nothing of confidences below theirs.
    pub fn target(&self, top: f64, objects: usize) -> f64 {
        let (c, a) = (&self.confidence[..self.len], &self.accuracy[..self.len]);
        let chance = 1.0 / objects.max(1) as f64;
        let between = |(c0, a0): (f64, f64), (c1, a1): (f64, f64)| a0 + (top - c0) / (c1 - c0) * (a1 - a0);
        let mapped = match c.iter().position(|&x| x > top) {
            Some(0) if chance < c[0] && top > chance => between((chance, chance), (c[0], a[0])),
            Some(0) => a[0].min(chance.max(top)),
            None => a[self.len - 1],
            Some(i) => between((c[i - 1], a[i - 1]), (c[i], a[i])),
        };
        mapped.min(top.max(RAISE_CEILING))
    }

    /// Moves the belief `p` (a distribution over the objects) so that its top probability is
    /// [`target`](Self::target)'s, at least `1 / J`: `p_j^g / sum_k p_k^g` with the power `g >= 0`
    /// found by bisection (the top's share grows with `g`, from `1 / J` at 0 through its own at 1),
    /// so the objects keep their order. A belief the power cannot reach (tied top objects) ends
    /// at the power `MAX_POWER`; one that is not a distribution is left alone.
    pub fn apply(&self, p: &mut [f64]) {
        let top = p.iter().copied().fold(0.0, f64::max);
        if p.len() < 2 || !(top > 0.0 && top <= 1.0) || p.iter().any(|q| !(0.0..=1.0).contains(q)) {
            return;
        }
        let target = self.target(top, p.len()).max(1.0 / p.len() as f64);
        if target == top {
            return;
        }
        let ln_top = top.ln();
        let ln_ratio: Vec<f64> = p.iter().map(|&q| q.ln() - ln_top).collect();
        let weights = |g: f64| -> Vec<f64> {
            ln_ratio
                .iter()
                .map(|&r| if r == f64::NEG_INFINITY { 0.0 } else { exp(g * r) })
                .collect()
        };
        // The top object's weight is exp(0) = 1 at every power.
        let share = |g: f64| 1.0 / weights(g).iter().sum::<f64>();
        let (mut low, mut high) = if target < top { (0.0, 1.0) } else { (1.0, 2.0) };
        while target > top && share(high) < target && high < MAX_POWER {
            low = high;
            high *= 2.0;
        }
        for _ in 0..POWER_STEPS {
            let mid = 0.5 * (low + high);
            if share(mid) < target {
                low = mid;
            } else {
                high = mid;
            }
        }
        let w = weights(0.5 * (low + high));
        let sum: f64 = w.iter().sum();
        for (q, w) in p.iter_mut().zip(w) {
            *q = w / sum;
        }
    }
}

/// One validation trial's evidence: its true object and, after each of its readings
/// `n = 1, 2, ...`, `ln p(r_1..r_n | O_j)` for every object `j` (Eq. 15, untempered).
#[derive(Debug, Clone, PartialEq)]
pub struct EvidencePath {
    pub object: usize,
    pub log_likelihoods: Vec<Vec<f64>>,
}

impl EvidencePath {
    /// The path of `trial`: each reading given to `observe`, which adds it to a posterior and
    /// returns the untempered log-likelihoods of everything observed so far.
    pub fn of<R>(
        trial: &Trial<R>,
        mut observe: impl FnMut(&R) -> Result<Vec<f64>, RecognizeError>,
    ) -> Result<Self, RecognizeError> {
        let log_likelihoods = trial
            .readings
            .iter()
            .map(&mut observe)
            .collect::<Result<_, _>>()?;
        Ok(Self {
            object: trial.object,
            log_likelihoods,
        })
    }
}

/// Every prefix `r_1..r_n` of every validation trial, in trial order, with their log-likelihoods
/// also laid out four prefixes side by side (`lanes`), so that the loss of a tempering can form
/// four prefixes' log-sum-exps at once: the fit evaluates it 11,904 times (62 steps of each of 192
/// searches), each over every prefix and object.
struct Prefixes<'a> {
    /// Per prefix: its readings `n`, its true object and `ln p(r_1..r_n | O_j)` for every object.
    each: Vec<(usize, usize, &'a [f64])>,
    /// Per group of four prefixes, per object `j`, the four prefixes' `ln p(r_1..r_n | O_j)` (the
    /// last group padded by repeating its last prefix). `None` where the prefixes do not all have
    /// the same objects or a log-likelihood is NaN.
    lanes: Option<Lanes>,
    objects: usize,
    /// The longest prefix.
    readings: usize,
}

impl<'a> Prefixes<'a> {
    fn of(trials: &'a [EvidencePath]) -> Self {
        let each: Vec<(usize, usize, &[f64])> = trials
            .iter()
            .flat_map(|t| {
                t.log_likelihoods
                    .iter()
                    .enumerate()
                    .map(|(i, l)| (i + 1, t.object, l.as_slice()))
            })
            .collect();
        let objects = each.first().map_or(0, |p| p.2.len());
        let lanes = each.iter().all(|p| p.2.len() == objects).then(|| {
            each.chunks(4)
                .flat_map(|group| (0..objects).map(move |j| std::array::from_fn(|l| lane(group, l).2[j])))
                .collect()
        });
        Self {
            readings: each.iter().map(|p| p.0).max().unwrap_or(0),
            lanes: lanes.and_then(Lanes::new),
            each,
            objects,
        }
    }

    /// `-ln p(true object | r_1..r_n)` under `tempering`, averaged over every prefix: the sum in
    /// prefix order, each probability [`Tempering::probability_of`]'s bits. The weights `w(n)`
    /// are computed once per count `n`, not once per prefix.
    fn mean_log_loss(&self, tempering: Tempering) -> f64 {
        let weights: Vec<f64> = (0..=self.readings).map(|n| tempering.weight(n)).collect();
        let mut sum = 0.0;
        for (g, group) in self.each.chunks(4).enumerate() {
            let weight: [f64; 4] = std::array::from_fn(|l| weights[lane(group, l).0]);
            let rows = g * self.objects..(g + 1) * self.objects;
            let lanes = self
                .lanes
                .as_ref()
                .and_then(|lanes| lanes.scaled_max_and_exp_sum(rows, weight));
            for (l, &(readings, object, log_likelihood)) in group.iter().enumerate() {
                let p = match lanes {
                    Some((max, sums)) => {
                        let lse = log_sum_exp_of_parts(max[l], sums[l]);
                        tempering.probability(weight[l] * log_likelihood[object], lse, self.objects)
                    }
                    None => tempering.probability_of(log_likelihood, readings, object),
                };
                sum -= p.ln();
            }
        }
        sum / self.each.len().max(1) as f64
    }
}

/// Lane `l` of a group of up to four prefixes: a short last group repeats its last prefix in the
/// lanes it lacks (their results are not used).
fn lane<'g, 'a>(group: &'g [(usize, usize, &'a [f64])], l: usize) -> &'g (usize, usize, &'a [f64]) {
    &group[l.min(group.len() - 1)]
}

/// The minimum of a function convex on `[a, b]` by golden-section search: its argument and value.
fn golden_minimum((mut a, mut b): (f64, f64), f: impl Fn(f64) -> f64) -> (f64, f64) {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..GOLDEN_STEPS {
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = f(d);
        }
    }
    if fc <= fd { (c, fc) } else { (d, fd) }
}

/// How the posterior turns likelihoods into probabilities: the model's fitted [`Tempering`]
/// (the default) or the paper's Eq. 15-16 (`--posterior eq15`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PosteriorRule {
    #[default]
    Calibrated,
    Eq15,
}

impl PosteriorRule {
    /// The CLI's names.
    pub const NAMES: [&'static str; 2] = ["calibrated", "eq15"];

    /// `calibrated` or `eq15`.
    pub fn parse(text: &str) -> Result<Self, RecognizeError> {
        match text {
            "calibrated" => Ok(Self::Calibrated),
            "eq15" => Ok(Self::Eq15),
            other => Err(RecognizeError::InvalidParameter {
                name: "posterior",
                what: format!("'{other}' is not one of {}", Self::NAMES.join(", ")),
            }),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Calibrated => "calibrated",
            Self::Eq15 => "eq15",
        }
    }

    /// The tempering this rule applies to a model fitted with `fitted`.
    pub fn tempering(self, fitted: Tempering) -> Tempering {
        match self {
            Self::Calibrated => fitted,
            Self::Eq15 => Tempering::EQ15,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::stream;
    use rand::RngExt;

    #[test]
    fn eq15_weighs_every_reading_fully() {
        for n in [0, 1, 7, 100] {
            assert_eq!(Tempering::EQ15.weight(n), 1.0);
        }
        assert_eq!(Tempering::EQ15.effective_readings(30), 30.0);
        let t = Tempering::new(0.5, 0.5).unwrap();
        assert!((t.effective_readings(16) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(Tempering::new(0.0, 1.0).is_err());
        assert!(Tempering::new(1.0, f64::NAN).is_err());
        assert!(serde_json::from_str::<Tempering>(r#"{"tau":-1,"beta":1}"#).is_err());
    }

    /// The loss as the fit first computed it: one prefix at a time, `probability_of` each.
    fn loss_one_prefix_at_a_time(trials: &[EvidencePath], tempering: Tempering) -> f64 {
        let (mut sum, mut count) = (0.0, 0usize);
        for trial in trials {
            for (i, l) in trial.log_likelihoods.iter().enumerate() {
                sum -= tempering.probability_of(l, i + 1, trial.object).ln();
                count += 1;
            }
        }
        sum / count.max(1) as f64
    }

    #[test]
    fn the_loss_over_four_prefixes_at_once_is_the_loss_one_at_a_time() {
        let mut rng = stream(9, 0);
        for (objects, trials, readings) in [(1, 3, 2), (5, 7, 3), (12, 36, 100), (52, 13, 10)] {
            let paths: Vec<EvidencePath> = (0..trials)
                .map(|t| {
                    let mut sums = vec![0.0; objects];
                    let log_likelihoods = (0..readings)
                        .map(|_| {
                            for s in &mut sums {
                                *s += rng.random_range(-40.0..0.0);
                            }
                            sums.clone()
                        })
                        .collect();
                    EvidencePath {
                        object: t % objects,
                        log_likelihoods,
                    }
                })
                .collect();
            let prefixes = Prefixes::of(&paths);
            let lanes = prefixes.lanes.as_ref().map_or(0, Lanes::len);
            assert_eq!(lanes, (trials * readings).div_ceil(4) * objects);
            for (tau, beta, floor) in [
                (1.0, 1.0, 0.0),
                (0.01, 0.3, 0.05),
                (7.5, 1.2, 0.0),
                (100.0, 0.05, 0.12),
            ] {
                let tempering = Tempering::new(tau, beta).unwrap().with_floor(floor).unwrap();
                let lanes = prefixes.mean_log_loss(tempering);
                let one = loss_one_prefix_at_a_time(&paths, tempering);
                assert_eq!(
                    lanes.to_bits(),
                    one.to_bits(),
                    "{objects} objects, {tempering:?}: {lanes} {one}"
                );
            }
        }
    }

    /// Trials whose log-likelihoods are `k` times those of a calibrated model are fitted back to
    /// `tau = 1 / k`: overconfidence undone.
    #[test]
    fn fit_undoes_a_known_overconfidence() {
        let mut rng = stream(7, 0);
        let (objects, sharpness) = (4, 6.0);
        let mut trials = Vec::new();
        for t in 0..400 {
            let object = t % objects;
            let mut sums = vec![0.0; objects];
            let mut path = Vec::new();
            for _ in 0..5 {
                // A calibrated reading: the true object's log-likelihood is higher on average.
                for (j, s) in sums.iter_mut().enumerate() {
                    let mean = if j == object { 0.0 } else { -1.0 };
                    *s += mean + rng.random_range(-1.0..1.0);
                }
                path.push(sums.iter().map(|s| sharpness * s).collect());
            }
            trials.push(EvidencePath {
                object,
                log_likelihoods: path,
            });
        }
        let fitted = Tempering::fit(&trials);
        let truth = Tempering::new(1.0 / sharpness, 1.0).unwrap();
        let prefixes = Prefixes::of(&trials);
        let loss = |tempering| prefixes.mean_log_loss(tempering);
        assert!(loss(fitted) <= loss(truth) + 1e-9, "{fitted:?}");
        assert!(loss(fitted) < loss(Tempering::EQ15));
        assert!(fitted.tau() < 0.5, "{fitted:?}");
    }

    /// Trials that repeat one reading `n` times (perfectly correlated touches) are fitted with a
    /// small `beta`: the evidence does not grow with the count.
    #[test]
    fn fit_sees_correlated_readings() {
        let mut rng = stream(8, 0);
        let mut trials = Vec::new();
        for t in 0..300 {
            let object = t % 3;
            let one: Vec<f64> = (0..3)
                .map(|j| if j == object { 0.0 } else { -1.0 } + rng.random_range(-1.5..1.5))
                .collect();
            let path = (1..=10)
                .map(|n| one.iter().map(|v| v * n as f64).collect())
                .collect();
            trials.push(EvidencePath {
                object,
                log_likelihoods: path,
            });
        }
        let fitted = Tempering::fit(&trials);
        assert!(fitted.beta() <= 0.2, "{fitted:?}");
    }

    /// Trials of `objects` objects and `readings` readings whose evidence grows for one object,
    /// the true one with probability `right` (else the next): a model sure of guesses that are
    /// right only that often.
    fn sure_but_often_wrong(seed: u64, right: f64, objects: usize, readings: usize) -> Vec<EvidencePath> {
        let mut rng = stream(seed, 0);
        (0..400)
            .map(|t| {
                let object = t % objects;
                let favoured = if rng.random_bool(right) {
                    object
                } else {
                    (object + 1) % objects
                };
                let mut sums = vec![0.0; objects];
                let log_likelihoods = (0..readings)
                    .map(|_| {
                        for (j, s) in sums.iter_mut().enumerate() {
                            *s += if j == favoured { 0.3 } else { 0.0 } + rng.random_range(-1.0..1.0);
                        }
                        sums.clone()
                    })
                    .collect();
                EvidencePath {
                    object,
                    log_likelihoods,
                }
            })
            .collect()
    }

    /// The reliability table of `tempering`'s beliefs over every prefix of `trials`.
    fn reliability(
        trials: &[EvidencePath],
        tempering: Tempering,
    ) -> crate::recognize::reliability::ReliabilityTable {
        let mut table = crate::recognize::reliability::ReliabilityTable::default();
        for t in trials {
            for (i, l) in t.log_likelihoods.iter().enumerate() {
                let top = tempering.probabilities(l, i + 1).into_iter().fold(0.0, f64::max);
                table.add(top, guess_of(l) == t.object);
            }
        }
        table
    }

    /// Half the trials confidently wrong: no tempering of the evidence says "half" at every count
    /// (its floor stops at 0.12), the map does. Beliefs that end near certainty are moved to about
    /// 0.5, and on fresh trials of the same kind the reliability error falls by more than half.
    #[test]
    fn the_confidence_map_learns_how_often_a_sure_model_is_right() {
        let fitting = sure_but_often_wrong(1, 0.5, 4, 20);
        let plain = Tempering::fit(&fitting);
        let mapped = Tempering::fit_with_confidence_map(&fitting);
        let map = mapped.confidence_map().expect("8,000 prefixes make a map");
        assert_eq!(
            (mapped.tau(), mapped.beta(), mapped.floor()),
            (plain.tau(), plain.beta(), plain.floor())
        );
        assert!((0.4..0.6).contains(&map.target(0.999, 4)), "{map:?}");
        let fresh = sure_but_often_wrong(2, 0.5, 4, 20);
        let (before, after) = (reliability(&fresh, plain), reliability(&fresh, mapped));
        let (before, after) = (before.ece().unwrap(), after.ece().unwrap());
        assert!(after < 0.5 * before && after < 0.05, "ECE {before} -> {after}");
    }

    /// Random beliefs moved to a map's target keep the objects' order (the guess), sum to 1, and
    /// reach the target: lowered anywhere, raised at most to `RAISE_CEILING`.
    #[test]
    fn a_mapped_belief_keeps_its_order_and_reaches_its_target() {
        let map = ConfidenceMap::new(&[[0.4, 0.3], [0.6, 0.5], [0.8, 0.95], [0.99, 0.99]]).unwrap();
        // Below the first point, the line from chance (1/4 of 4 objects) to it.
        assert_eq!(map.target(0.25, 4), 0.25);
        assert!((map.target(0.325, 4) - 0.275).abs() < 1e-12);
        assert!((map.target(0.5, 4) - 0.4).abs() < 1e-12);
        assert!((map.target(0.7, 4) - 0.725).abs() < 1e-12);
        // Raised to 0.95 by the points, held at the ceiling; above it only lowered.
        assert_eq!(map.target(0.8, 4), RAISE_CEILING);
        assert_eq!(map.target(0.995, 4), 0.99);
        let mut rng = stream(3, 0);
        for _ in 0..2000 {
            let objects = rng.random_range(2..13);
            let sharpness = rng.random_range(0.1..20.0);
            let raw: Vec<f64> = (0..objects)
                .map(|_| (sharpness * rng.random_range(-1.0..1.0f64)).exp())
                .collect();
            let sum: f64 = raw.iter().sum();
            let p: Vec<f64> = raw.iter().map(|r| r / sum).collect();
            let mut q = p.clone();
            map.apply(&mut q);
            let top = p.iter().copied().fold(0.0, f64::max);
            let target = map.target(top, objects).max(1.0 / objects as f64);
            let new_top = q.iter().copied().fold(0.0, f64::max);
            assert!((q.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{q:?}");
            assert!((new_top - target).abs() < 1e-9, "{p:?} -> {q:?}, target {target}");
            for a in 0..objects {
                for b in 0..objects {
                    if p[a] < p[b] {
                        assert!(q[a] <= q[b], "{p:?} -> {q:?}");
                    }
                }
            }
        }
        // A zero stays zero; a belief that is not a distribution is left alone.
        let mut q = vec![0.995, 0.005, 0.0];
        map.apply(&mut q);
        assert_eq!(q[2], 0.0);
        assert!((q[0] - 0.99).abs() < 1e-9, "{q:?}");
        let mut nan = vec![f64::NAN, 0.5];
        map.apply(&mut nan);
        assert!(nan[0].is_nan() && nan[1] == 0.5);
    }

    /// The fit pools bins whose accuracy falls: six equal-count bins of known confidence and
    /// accuracy, one pair out of order, give the pooled points by hand.
    #[test]
    fn the_map_pools_bins_whose_accuracy_falls() {
        // Ten bins of 20 beliefs: confidence 0.1 * (b + 1) - 0.05, accuracy rising except bins
        // 4 and 5 (0.6 then 0.4, pooled to 0.5 at confidence 0.5).
        let accuracy = [0.1, 0.2, 0.3, 0.4, 0.6, 0.4, 0.7, 0.8, 0.9, 1.0];
        let beliefs: Vec<(f64, bool)> = (0..10)
            .flat_map(|b| {
                let right = (accuracy[b] * 20.0f64).round() as usize;
                (0..20).map(move |i| (0.1 * (b as f64 + 1.0) - 0.05, i < right))
            })
            .collect();
        let map = ConfidenceMap::fit(beliefs).unwrap();
        let points: Vec<[f64; 2]> = map.points().collect();
        assert_eq!(points.len(), 9, "{points:?}");
        assert!(
            (points[4][0] - 0.5).abs() < 1e-12 && (points[4][1] - 0.5).abs() < 1e-12,
            "{points:?}"
        );
        assert!(points.windows(2).all(|w| w[0][0] < w[1][0] && w[0][1] <= w[1][1]));
        assert!(ConfidenceMap::fit(vec![(0.5, true); MAP_MIN_PREFIXES - 1]).is_none());
        assert!(ConfidenceMap::fit(vec![(1.5, true); MAP_MIN_PREFIXES]).is_none());
    }

    /// A map goes to the model file and back; a file without one reads as a tempering without
    /// one (as every model written before maps existed), and broken points are refused by name.
    #[test]
    fn a_map_round_trips_and_broken_maps_are_refused() {
        let t = Tempering::new(1.5, 0.35)
            .unwrap()
            .with_confidence_map(ConfidenceMap::new(&[[0.3, 0.35], [0.9, 0.8]]).unwrap());
        let text = serde_json::to_string(&t).unwrap();
        assert_eq!(serde_json::from_str::<Tempering>(&text).unwrap(), t);
        let plain = Tempering::new(1.5, 0.35).unwrap();
        assert_eq!(
            serde_json::to_string(&plain).unwrap(),
            r#"{"tau":1.5,"beta":0.35,"floor":0.0}"#
        );
        for broken in [
            r#"{"tau":1,"beta":1,"confidence_map":[]}"#,
            r#"{"tau":1,"beta":1,"confidence_map":[[0.5,0.2],[0.4,0.3]]}"#,
            r#"{"tau":1,"beta":1,"confidence_map":[[0.5,0.6],[0.7,0.3]]}"#,
            r#"{"tau":1,"beta":1,"confidence_map":[[0.5,1.2]]}"#,
        ] {
            let error = serde_json::from_str::<Tempering>(broken).unwrap_err().to_string();
            assert!(error.contains("confidence map"), "{broken}: {error}");
        }
    }

    #[test]
    fn no_evidence_fits_eq15() {
        assert_eq!(Tempering::fit(&[]), Tempering::EQ15);
    }

    #[test]
    fn golden_section_finds_a_parabola_minimum() {
        let (x, fx) = golden_minimum((-3.0, 5.0), |x| (x - 1.25) * (x - 1.25) + 2.0);
        assert!((x - 1.25).abs() < 1e-6 && (fx - 2.0).abs() < 1e-12, "{x} {fx}");
    }

    #[test]
    fn rules_parse_by_name() {
        assert_eq!(PosteriorRule::parse("eq15").unwrap(), PosteriorRule::Eq15);
        assert_eq!(
            PosteriorRule::parse("calibrated").unwrap(),
            PosteriorRule::default()
        );
        assert!(PosteriorRule::parse("bayes").is_err());
        let t = Tempering::new(0.4, 0.7).unwrap();
        assert_eq!(PosteriorRule::Eq15.tempering(t), Tempering::EQ15);
        assert_eq!(PosteriorRule::Calibrated.tempering(t), t);
    }
}
