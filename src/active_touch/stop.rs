//! The confidence stop replayed on recognised trials: where a [`ConfidenceStop`] would have ended
//! each trial of an [`Evaluation`], and how often the stopped trials named the right object.
//!
//! A stop at p promises that the runs it ends name the right object at least a share p of the
//! time. The posterior a stop watches is the same with or without the stop (the readings do not
//! depend on it for a blind exploration), so a recognised test run shows where every stop would
//! have fired: `taction recognize` reports the stops of [`REPORTED_STOPS`] (`stop.csv`), and the
//! `active` experiment writes its stop columns from the same replay.

use serde::Serialize;

use crate::explore::active::{ConfidenceStop, Probability};
use crate::recognize::Evaluation;

/// The thresholds a recognition reports its stop at: the demo's 0.95 and one either side.
pub const REPORTED_STOPS: [f64; 3] = [0.9, 0.95, 0.99];

/// The stops at [`REPORTED_STOPS`], each held over the default touches
/// ([`ConfidenceStop::DEFAULT_HELD_READINGS`]).
pub fn reported_stops() -> [ConfidenceStop; 3] {
    REPORTED_STOPS.map(|p| {
        ConfidenceStop::new(Probability::new(p).expect("every reported stop is a probability in (0, 1]"))
    })
}

/// Where `stop` ends each of the `trials` of `evaluation` within `budget` readings: the readings
/// used and whether the guess there was right, or `None` when it never fires. The evaluation's
/// rows must start at one reading (a stop watches every touch).
pub fn stops(
    evaluation: &Evaluation,
    trials: usize,
    stop: ConfidenceStop,
    budget: usize,
) -> Vec<Option<(usize, bool)>> {
    (0..trials)
        .map(|t| {
            let touches: Vec<_> = evaluation.touches.iter().filter(|r| r.trial == t).collect();
            let trace: Vec<(usize, f64)> = touches.iter().map(|r| (r.object_guess, r.p_guess())).collect();
            stop.touches_used(&trace, budget).map(|k| {
                let at = touches[k - 1];
                (k, at.object_guess == at.object_true)
            })
        })
        .collect()
}

/// One stop over every trial of a recognition (a row of `stop.csv`).
///
/// | column | meaning |
/// |---|---|
/// | `threshold`, `held_readings` | the stop: one guess held at or above `threshold` over the last `held_readings` touches |
/// | `budget` | the readings a trial may use before it ends without a stop |
/// | `trials`, `stopped`, `right` | the trials, those the stop ended, and those it ended on the right object |
/// | `share_right` | `right / stopped`, the promise kept when at least `threshold`; empty when none stopped |
/// | `mean_touches` | the readings a stopped trial used, on average; empty when none stopped |
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StopRecord {
    pub threshold: f64,
    pub held_readings: usize,
    pub budget: usize,
    pub trials: usize,
    pub stopped: usize,
    pub right: usize,
    pub share_right: Option<f64>,
    pub mean_touches: Option<f64>,
}

impl StopRecord {
    /// The record of `stop` over the trials of `evaluation` ([`stops`]).
    pub fn of(evaluation: &Evaluation, trials: usize, stop: ConfidenceStop, budget: usize) -> Self {
        let ends = stops(evaluation, trials, stop, budget);
        let stopped: Vec<(usize, bool)> = ends.into_iter().flatten().collect();
        let right = stopped.iter().filter(|(_, right)| *right).count();
        let touches: usize = stopped.iter().map(|(k, _)| k).sum();
        let per_stop = |x: usize| (!stopped.is_empty()).then(|| x as f64 / stopped.len() as f64);
        Self {
            threshold: stop.threshold().get(),
            held_readings: stop.held_readings().get(),
            budget,
            trials,
            stopped: stopped.len(),
            right,
            share_right: per_stop(right),
            mean_touches: per_stop(touches),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explore::active::Probability;
    use crate::recognize::{ConfusionMatrix, TouchRow};

    /// An evaluation of two objects from each trial's guesses and their probabilities, in order.
    fn evaluation(trials: &[(usize, &[(usize, f64)])]) -> Evaluation {
        let objects = vec!["a".to_string(), "b".to_string()];
        let touches = trials
            .iter()
            .enumerate()
            .flat_map(|(trial, (object_true, trace))| {
                trace.iter().enumerate().map(move |(i, &(guess, p))| {
                    let mut probabilities = vec![1.0 - p; 2];
                    probabilities[guess] = p;
                    TouchRow {
                        trial,
                        object_true: *object_true,
                        n_readings: i + 1,
                        object_guess: guess,
                        entropy_nats: 0.0,
                        probabilities,
                    }
                })
            })
            .collect();
        Evaluation {
            confusion: ConfusionMatrix::new(objects.clone(), 4),
            objects,
            touches,
            accuracy: Vec::new(),
        }
    }

    #[test]
    fn a_stop_counts_the_trials_it_ends_and_those_it_ends_on_the_right_object() {
        let evaluation = evaluation(&[
            // Held at 0.96 and 0.97 on the right object: stops after 2 touches, right.
            (0, &[(0, 0.96), (0, 0.97), (0, 0.99), (0, 0.99)]),
            // Confident and wrong, but not held until touches 3-4: stops after 4, wrong.
            (0, &[(1, 0.97), (1, 0.5), (1, 0.96), (1, 0.99)]),
            // Two guesses at 0.99 that differ never hold.
            (1, &[(0, 0.99), (1, 0.99), (0, 0.99), (1, 0.99)]),
        ]);
        let stop = ConfidenceStop::new(Probability::new(0.95).unwrap());
        assert_eq!(
            stops(&evaluation, 3, stop, 4),
            [Some((2, true)), Some((4, false)), None]
        );
        let record = StopRecord::of(&evaluation, 3, stop, 4);
        assert_eq!((record.trials, record.stopped, record.right), (3, 2, 1));
        assert_eq!((record.share_right, record.mean_touches), (Some(0.5), Some(3.0)));
        assert_eq!(
            (record.threshold, record.held_readings, record.budget),
            (0.95, 2, 4)
        );
        // Within a budget of three touches the second trial never stops.
        let short = StopRecord::of(&evaluation, 3, stop, 3);
        assert_eq!(
            (short.stopped, short.right, short.mean_touches),
            (1, 1, Some(2.0))
        );
        // A stop no trial reaches has no share and no mean.
        let never = StopRecord::of(
            &evaluation,
            3,
            ConfidenceStop::new(Probability::new(1.0).unwrap()),
            4,
        );
        assert_eq!(
            (never.stopped, never.share_right, never.mean_touches),
            (0, None, None)
        );
    }
}
