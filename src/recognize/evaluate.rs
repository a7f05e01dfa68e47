//! Recognition touch by touch over a test set (Sec. V-B2: "the empirical probability of correctly
//! identifying any unknown object given that number of samples of its surface").

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use rayon::prelude::*;

use crate::atomic::write_atomic;
use crate::describe::Feature;
use crate::recognize::RecognizeError;
use crate::recognize::bag::BagOfFeatures;
use crate::recognize::confusion::{ConfusionMatrix, csv_row};
use crate::recognize::posterior::Belief;
use crate::recognize::trial::Trial;

/// An inclusive range of reading counts `first..=last`, `1 <= first <= last`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadingRange {
    first: usize,
    last: usize,
}

impl ReadingRange {
    pub fn new(first: usize, last: usize) -> Result<Self, RecognizeError> {
        if first == 0 || first > last {
            return Err(RecognizeError::InvalidParameter {
                name: "readings",
                what: format!("{first}..{last} is not a range of reading counts with 1 <= first <= last"),
            });
        }
        Ok(Self { first, last })
    }

    pub fn first(self) -> usize {
        self.first
    }

    pub fn last(self) -> usize {
        self.last
    }

    pub fn contains(self, n: usize) -> bool {
        (self.first..=self.last).contains(&n)
    }
}

impl FromStr for ReadingRange {
    type Err = RecognizeError;
    /// `A..B` (both included) or `N` (meaning `1..N`).
    fn from_str(s: &str) -> Result<Self, RecognizeError> {
        let number = |t: &str| {
            t.trim()
                .parse::<usize>()
                .map_err(|_| RecognizeError::InvalidParameter {
                    name: "readings",
                    what: format!("'{t}' is not a reading count"),
                })
        };
        let (first, last) = match s.split_once("..") {
            Some((a, b)) => (number(a)?, number(b.strip_prefix('=').unwrap_or(b))?),
            None => (1, number(s)?),
        };
        Self::new(first, last)
    }
}

impl fmt::Display for ReadingRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}..{}", self.first, self.last)
    }
}

/// The belief after `n_readings` readings of one trial.
#[derive(Debug, Clone, PartialEq)]
pub struct TouchRow {
    pub trial: usize,
    pub object_true: usize,
    pub n_readings: usize,
    pub object_guess: usize,
    /// Entropy of the posterior, nats.
    pub entropy_nats: f64,
    /// The whole posterior, one probability per object of the model.
    pub probabilities: Vec<f64>,
}

impl TouchRow {
    /// Probability the posterior gives the true object.
    pub fn p_true(&self) -> f64 {
        self.probabilities[self.object_true]
    }

    /// Probability the posterior gives its guess, its largest (what a confidence stop watches).
    pub fn p_guess(&self) -> f64 {
        self.probabilities[self.object_guess]
    }
}

/// Accuracy after `n_readings` readings over every trial: the one definition `taction recognize`
/// and the paper's experiments report (Sec. V-B2, "correctly identifying any unknown object"). A
/// trial shorter than `n_readings` keeps its belief after its last reading; a trial with no reading
/// (an object the exploration never read) keeps the uniform prior: not identified, p(true) = 1/J.
/// Averaging only over the trials that reached n readings would flatter an exploration that
/// fails on the hard objects.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyPoint {
    pub n_readings: usize,
    /// Every trial.
    pub trials: usize,
    /// Trials whose most probable object after `n_readings` readings (or their last) is the true one.
    pub correct: usize,
    /// Mean probability on the true object: the paper's reliability (Sec. V-B1), the same name in
    /// every CSV and table.
    pub reliability: f64,
    /// Each trial's outcome, in trial order: what `correct` and `reliability` count.
    pub outcomes: Vec<TrialOutcome>,
}

/// One trial after `n_readings` readings (or its last, or none): whether its most probable object
/// is the true one, and the probability on the true one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrialOutcome {
    /// The true object, as an index of the model's objects.
    pub object: usize,
    pub correct: bool,
    pub p_true: f64,
}

impl AccuracyPoint {
    /// The point of `outcomes`, one per trial: the one place they are counted.
    pub fn new(n_readings: usize, outcomes: Vec<TrialOutcome>) -> Self {
        let p_true = outcomes.iter().fold(0.0, |sum, o| sum + o.p_true);
        Self {
            n_readings,
            trials: outcomes.len(),
            correct: outcomes.iter().filter(|o| o.correct).count(),
            reliability: p_true / outcomes.len() as f64,
            outcomes,
        }
    }

    pub fn accuracy(&self) -> f64 {
        if self.trials == 0 {
            0.0
        } else {
            self.correct as f64 / self.trials as f64
        }
    }
}

/// Everything `taction recognize` writes.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    pub objects: Vec<String>,
    /// One row per trial and reading count in the range.
    pub touches: Vec<TouchRow>,
    /// One row per reading count in the range up to the longest trial ([`AccuracyPoint`]).
    pub accuracy: Vec<AccuracyPoint>,
    /// Each trial's final guess (after `min(last, trial length)` readings) against the truth,
    /// labelled with `min(last, longest trial)`: the readings the decisions actually used.
    pub confusion: ConfusionMatrix,
}

/// Runs every trial through an [`OnlinePosterior`](crate::recognize::OnlinePosterior), recording
/// the belief at every reading count in `range`. Trials run in parallel; rows come out in trial
/// order.
pub fn evaluate(
    bag: &BagOfFeatures,
    trials: &[Trial],
    range: ReadingRange,
) -> Result<Evaluation, RecognizeError> {
    evaluate_with(bag.objects(), trials, range, || {
        let mut posterior = bag.posterior();
        move |reading: &Vec<Feature>| posterior.observe(reading)
    })
}

/// [`evaluate`] for any recogniser over `objects`: `start` gives, per trial, a fresh posterior that
/// takes one reading and returns the belief after it.
pub fn evaluate_with<R, P>(
    objects: &[String],
    trials: &[Trial<R>],
    range: ReadingRange,
    start: impl Fn() -> P + Sync,
) -> Result<Evaluation, RecognizeError>
where
    R: Sync,
    P: FnMut(&R) -> Result<Belief, RecognizeError>,
{
    let per_trial = trial_beliefs(trials, range, start)?;
    let longest = per_trial.iter().map(Vec::len).max().unwrap_or(0);
    let accuracy = accuracy_points(objects.len(), trials, &per_trial, range, longest);
    let (touches, confusion) = touches_and_confusion(objects, trials, per_trial, range, longest);
    Ok(Evaluation {
        objects: objects.to_vec(),
        touches,
        accuracy,
        confusion,
    })
}

/// Every trial's belief after 1, 2, ... readings (up to the range's end), trials in parallel, in
/// trial order.
fn trial_beliefs<R, P>(
    trials: &[Trial<R>],
    range: ReadingRange,
    start: impl Fn() -> P + Sync,
) -> Result<Vec<Vec<TouchRow>>, RecognizeError>
where
    R: Sync,
    P: FnMut(&R) -> Result<Belief, RecognizeError>,
{
    let per_trial: Vec<Result<Vec<TouchRow>, RecognizeError>> = trials
        .par_iter()
        .enumerate()
        .map(|(t, trial)| {
            let mut observe = start();
            let mut beliefs = Vec::new();
            for reading in trial.readings.iter().take(range.last) {
                let belief = observe(reading)?;
                beliefs.push(TouchRow {
                    trial: t,
                    object_true: trial.object,
                    n_readings: belief.readings,
                    object_guess: belief.guess(),
                    entropy_nats: belief.entropy_nats(),
                    probabilities: belief.probabilities().to_vec(),
                });
            }
            Ok(beliefs)
        })
        .collect();
    per_trial.into_iter().collect()
}

/// One [`AccuracyPoint`] per reading count of `range` up to the `longest` trial: each trial's
/// outcome after `n` readings, or after its last, or (no reading at all) the uniform prior over
/// `objects` objects.
fn accuracy_points<R>(
    objects: usize,
    trials: &[Trial<R>],
    per_trial: &[Vec<TouchRow>],
    range: ReadingRange,
    longest: usize,
) -> Vec<AccuracyPoint> {
    let prior = 1.0 / objects.max(1) as f64;
    let mut accuracy: Vec<AccuracyPoint> = Vec::new();
    for n in range.first..=range.last.min(longest) {
        let outcomes = trials
            .iter()
            .zip(per_trial)
            .map(|(trial, beliefs)| {
                // The belief after n readings, or after the trial's last; none before any reading.
                match n.min(beliefs.len()).checked_sub(1).map(|i| &beliefs[i]) {
                    Some(b) => TrialOutcome {
                        object: trial.object,
                        correct: b.object_guess == b.object_true,
                        p_true: b.p_true(),
                    },
                    None => TrialOutcome {
                        object: trial.object,
                        correct: false,
                        p_true: prior,
                    },
                }
            })
            .collect();
        accuracy.push(AccuracyPoint::new(n, outcomes));
    }
    accuracy
}

/// The rows of `range` of every trial, and the confusion matrix of each trial's last decision in
/// the range.
fn touches_and_confusion<R>(
    objects: &[String],
    trials: &[Trial<R>],
    per_trial: Vec<Vec<TouchRow>>,
    range: ReadingRange,
    longest: usize,
) -> (Vec<TouchRow>, ConfusionMatrix) {
    let mut touches = Vec::new();
    // The decisions are taken after the range's end or the longest trial's last reading, whichever
    // comes first: a range beyond the data labels no decision with readings it never had.
    let mut confusion = ConfusionMatrix::new(objects.to_vec(), range.last.min(longest));
    for (trial, beliefs) in trials.iter().zip(per_trial) {
        let in_range: Vec<TouchRow> = beliefs
            .into_iter()
            .filter(|b| range.contains(b.n_readings))
            .collect();
        if let Some(last) = in_range.last() {
            confusion.add(trial.object, last.object_guess);
        }
        touches.extend(in_range);
    }
    (touches, confusion)
}

impl Evaluation {
    /// Accuracy after `n` readings, if any trial reached `n`.
    pub fn accuracy_at(&self, n: usize) -> Option<f64> {
        self.accuracy
            .iter()
            .find(|r| r.n_readings == n)
            .map(AccuracyPoint::accuracy)
    }

    /// `trial,object_true,n_readings,object_guess,p_true,entropy_nats`.
    pub fn posterior_csv(&self) -> String {
        let mut rows = vec![csv_row(&[
            "trial",
            "object_true",
            "n_readings",
            "object_guess",
            "p_true",
            "entropy_nats",
        ])];
        for r in &self.touches {
            rows.push(csv_row(&[
                &r.trial.to_string(),
                &self.objects[r.object_true],
                &r.n_readings.to_string(),
                &self.objects[r.object_guess],
                &r.p_true().to_string(),
                &r.entropy_nats.to_string(),
            ]));
        }
        rows.concat()
    }

    /// The whole posterior after every reading, long format:
    /// `trial,object_true,n_readings,object,probability`, one row per object, so that any object's
    /// curve is one filter away.
    pub fn posterior_long_csv(&self) -> String {
        let mut rows = vec![csv_row(&[
            "trial",
            "object_true",
            "n_readings",
            "object",
            "probability",
        ])];
        for r in &self.touches {
            let (trial, truth, n) = (
                r.trial.to_string(),
                &self.objects[r.object_true],
                r.n_readings.to_string(),
            );
            for (object, p) in self.objects.iter().zip(&r.probabilities) {
                rows.push(csv_row(&[&trial, truth, &n, object, &p.to_string()]));
            }
        }
        rows.concat()
    }

    /// `n_readings,trials,correct,accuracy,reliability`.
    pub fn accuracy_csv(&self) -> String {
        let mut out = String::from("n_readings,trials,correct,accuracy,reliability\n");
        for r in &self.accuracy {
            out.push_str(&format!(
                "{},{},{},{},{}\n",
                r.n_readings,
                r.trials,
                r.correct,
                r.accuracy(),
                r.reliability
            ));
        }
        out
    }

    /// Writes `posterior.csv`, `posterior_long.csv`, `accuracy.csv`, `confusion.csv` and
    /// `reliability.csv` (the [`reliability`](Self::reliability) table of every row of
    /// `posterior.csv`) into `dir` (created if missing), each atomically; returns their paths.
    pub fn write_csvs(&self, dir: &Path) -> Result<Vec<PathBuf>, RecognizeError> {
        let files = [
            ("posterior.csv", self.posterior_csv()),
            ("posterior_long.csv", self.posterior_long_csv()),
            ("accuracy.csv", self.accuracy_csv()),
            ("confusion.csv", self.confusion.to_csv_string()),
            ("reliability.csv", self.reliability().to_csv_string()),
        ];
        let mut paths = Vec::new();
        for (name, text) in files {
            let path = dir.join(name);
            write_atomic(&path, text.as_bytes())?;
            paths.push(path);
        }
        Ok(paths)
    }
}
