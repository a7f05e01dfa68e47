//! Recognition touch by touch over a test set (Sec. V-B2: "the empirical probability of correctly
//! identifying any unknown object given that number of samples of its surface").

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use rayon::prelude::*;

use crate::dataset::write_atomic;
use crate::describe::Feature;
use crate::recognize::RecognizeError;
use crate::recognize::bag::BagOfFeatures;
use crate::recognize::confusion::{ConfusionMatrix, csv_row};
use crate::recognize::labelled::LabelledFeatures;

/// Consecutive readings of one object, given to the recogniser one at a time.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    /// The true object, as an index of the model's objects.
    pub object: usize,
    /// Each reading's features.
    pub readings: Vec<Vec<Feature>>,
}

/// Splits each object's readings, in order, into trials of `readings_per_trial` consecutive
/// readings (the last trial of an object may be shorter). Objects are matched to `model_objects`
/// by name; one the model does not know is an error.
pub fn make_trials(
    data: &LabelledFeatures,
    model_objects: &[String],
    readings_per_trial: usize,
) -> Result<Vec<Trial>, RecognizeError> {
    if readings_per_trial == 0 {
        return Err(RecognizeError::InvalidParameter {
            name: "readings per trial",
            what: "must be at least 1".into(),
        });
    }
    let mut trials = Vec::new();
    for (j, name) in data.objects().iter().enumerate() {
        let object =
            model_objects
                .iter()
                .position(|o| o == name)
                .ok_or_else(|| RecognizeError::UnknownObject {
                    object: name.clone(),
                    known: model_objects.to_vec(),
                })?;
        for chunk in data.readings(j).chunks(readings_per_trial) {
            trials.push(Trial {
                object,
                readings: chunk.to_vec(),
            });
        }
    }
    Ok(trials)
}

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
    type Err = String;
    /// `A..B` (both included) or `N` (meaning `1..N`).
    fn from_str(s: &str) -> Result<Self, String> {
        let number = |t: &str| {
            t.trim()
                .parse::<usize>()
                .map_err(|_| format!("'{t}' is not a reading count"))
        };
        let (first, last) = match s.split_once("..") {
            Some((a, b)) => (number(a)?, number(b.strip_prefix('=').unwrap_or(b))?),
            None => (1, number(s)?),
        };
        Self::new(first, last).map_err(|e| e.to_string())
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
    /// Probability the posterior gives the true object.
    pub p_true: f64,
    /// Entropy of the posterior, nats.
    pub entropy_nats: f64,
}

/// Accuracy over the trials that have at least `n_readings` readings.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyRow {
    pub n_readings: usize,
    pub trials: usize,
    pub correct: usize,
    /// Mean probability on the true object (the paper's "reliability").
    pub mean_p_true: f64,
}

impl AccuracyRow {
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
    /// One row per reading count in the range that at least one trial reaches.
    pub accuracy: Vec<AccuracyRow>,
    /// Each trial's final guess (after `min(last, trial length)` readings) against the truth.
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
    #[allow(clippy::type_complexity)]
    let per_trial: Vec<Result<(Vec<TouchRow>, Option<usize>), RecognizeError>> = trials
        .par_iter()
        .enumerate()
        .map(|(t, trial)| {
            let mut posterior = bag.posterior();
            let mut rows = Vec::new();
            let mut last_guess = None;
            for reading in trial.readings.iter().take(range.last) {
                let belief = posterior.observe(reading)?;
                if range.contains(belief.readings) {
                    rows.push(TouchRow {
                        trial: t,
                        object_true: trial.object,
                        n_readings: belief.readings,
                        object_guess: belief.guess(),
                        p_true: belief.probabilities()[trial.object],
                        entropy_nats: belief.entropy_nats(),
                    });
                    last_guess = Some(belief.guess());
                }
            }
            Ok((rows, last_guess))
        })
        .collect();
    let mut touches = Vec::new();
    let mut confusion = ConfusionMatrix::new(bag.objects().to_vec());
    for (trial, result) in trials.iter().zip(per_trial) {
        let (rows, last_guess) = result?;
        touches.extend(rows);
        if let Some(guess) = last_guess {
            confusion.add(trial.object, guess);
        }
    }
    let mut accuracy: Vec<AccuracyRow> = Vec::new();
    for n in range.first..=range.last {
        let at_n: Vec<&TouchRow> = touches.iter().filter(|r| r.n_readings == n).collect();
        if at_n.is_empty() {
            continue;
        }
        accuracy.push(AccuracyRow {
            n_readings: n,
            trials: at_n.len(),
            correct: at_n.iter().filter(|r| r.object_guess == r.object_true).count(),
            mean_p_true: at_n.iter().map(|r| r.p_true).sum::<f64>() / at_n.len() as f64,
        });
    }
    Ok(Evaluation {
        objects: bag.objects().to_vec(),
        touches,
        accuracy,
        confusion,
    })
}

impl Evaluation {
    /// Accuracy after `n` readings, if any trial reached `n`.
    pub fn accuracy_at(&self, n: usize) -> Option<f64> {
        self.accuracy
            .iter()
            .find(|r| r.n_readings == n)
            .map(AccuracyRow::accuracy)
    }

    /// `trial,object_true,n_readings,object_guess,p_true,entropy` (entropy in nats).
    pub fn posterior_csv(&self) -> String {
        let mut rows = vec![csv_row(&[
            "trial",
            "object_true",
            "n_readings",
            "object_guess",
            "p_true",
            "entropy",
        ])];
        for r in &self.touches {
            rows.push(csv_row(&[
                &r.trial.to_string(),
                &self.objects[r.object_true],
                &r.n_readings.to_string(),
                &self.objects[r.object_guess],
                &r.p_true.to_string(),
                &r.entropy_nats.to_string(),
            ]));
        }
        rows.concat()
    }

    /// `n_readings,trials,correct,accuracy,mean_p_true`.
    pub fn accuracy_csv(&self) -> String {
        let mut out = String::from("n_readings,trials,correct,accuracy,mean_p_true\n");
        for r in &self.accuracy {
            out.push_str(&format!(
                "{},{},{},{},{}\n",
                r.n_readings,
                r.trials,
                r.correct,
                r.accuracy(),
                r.mean_p_true
            ));
        }
        out
    }

    /// Writes `posterior.csv`, `accuracy.csv` and `confusion.csv` into `dir` (created if missing),
    /// each atomically; returns their paths.
    pub fn write_csvs(&self, dir: &Path) -> Result<Vec<PathBuf>, RecognizeError> {
        let files = [
            ("posterior.csv", self.posterior_csv()),
            ("accuracy.csv", self.accuracy_csv()),
            ("confusion.csv", self.confusion.to_csv_string()),
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
