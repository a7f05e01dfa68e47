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
use crate::recognize::evaluate::Trial;
use crate::recognize::exp::{Lanes, exp};
use crate::recognize::gmm::{log_sum_exp, log_sum_exp_of_parts};

/// `w(n) = tau n^(beta - 1)`, the weight of the log-likelihood after `n` readings (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TemperingFields", into = "TemperingFields")]
pub struct Tempering {
    tau: f64,
    beta: f64,
    floor: f64,
}

/// The file form of a [`Tempering`], checked on load.
#[derive(Serialize, Deserialize)]
struct TemperingFields {
    tau: f64,
    beta: f64,
    #[serde(default)]
    floor: f64,
}

impl TryFrom<TemperingFields> for Tempering {
    type Error = RecognizeError;
    fn try_from(f: TemperingFields) -> Result<Self, RecognizeError> {
        Self::new(f.tau, f.beta)?.with_floor(f.floor)
    }
}

impl From<Tempering> for TemperingFields {
    fn from(t: Tempering) -> Self {
        Self {
            tau: t.tau,
            beta: t.beta,
            floor: t.floor,
        }
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
        })
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
    /// after `readings` readings: `(1 - epsilon) softmax(w(n) l) + epsilon / J`.
    pub fn probabilities(self, log_likelihood: &[f64], readings: usize) -> Vec<f64> {
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
        if trials.iter().all(|t| t.log_likelihoods.is_empty()) {
            return Self::EQ15;
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
        best.1
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
