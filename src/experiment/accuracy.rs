//! The tidy accuracy table of the paper's recognition figures (Fig. 7-13, 16, 17): one row per
//! observation, i.e. per (setting, trial, number of readings).

use serde::{Deserialize, Serialize};

use crate::recognize::AccuracyPoint;

/// One point of one recognition curve.
///
/// | column | meaning |
/// |---|---|
/// | `experiment` | the experiment's name, e.g. `noise` |
/// | `descriptor` | the descriptor's command-line name, e.g. `polar-fourier` |
/// | `parameter` | the setting the experiment varies, e.g. `noise_fraction`, `local_probability`, `object` (`fixed`/`perturbed`), `data` (`validation`/`exploration`); empty when nothing but the descriptor varies |
/// | `value` | that setting's value, as text: `0.1`, `perturbed` |
/// | `trial` | the repetition (0-based); the plot averages over trials |
/// | `n_readings` | number of readings of the unknown object used so far (1-based) |
/// | `accuracy` | fraction of test objects whose most probable identity after `n_readings` readings is correct, in [0, 1] (the "empirical probability of correctly identifying any unknown object", Sec. V-B2) |
/// | `reliability` | mean posterior probability given to the correct object, in [0, 1] (Sec. V-B1) |
/// | `seed` | the run's seed, as given with `--seed` |
/// | `stream_seed` | the seed the trial's randomness was drawn from (derived from `seed`), its 64 bits read as a signed integer so that every CSV reader takes it as an int64 (`as u64` gives it back) |
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AccuracyRow {
    pub experiment: String,
    pub descriptor: String,
    pub parameter: String,
    pub value: String,
    pub trial: u32,
    pub n_readings: u32,
    pub accuracy: f64,
    pub reliability: f64,
    pub seed: u64,
    pub stream_seed: i64,
}

/// Everything an [`AccuracyRow`] holds but the point itself: one curve of one trial.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyCurve {
    pub experiment: String,
    pub descriptor: String,
    pub parameter: String,
    pub value: String,
    pub trial: u32,
    /// The run's seed (`--seed`).
    pub seed: u64,
    /// The seed the trial's randomness was drawn from.
    pub stream_seed: u64,
}

impl AccuracyCurve {
    /// The rows of this curve, one per point of the evaluation (`recognize::evaluate`, whose
    /// accuracy counts every object and an unread one as a miss).
    pub fn rows<'a>(&self, points: impl IntoIterator<Item = &'a AccuracyPoint>) -> Vec<AccuracyRow> {
        points
            .into_iter()
            .map(|point| AccuracyRow {
                experiment: self.experiment.clone(),
                descriptor: self.descriptor.clone(),
                parameter: self.parameter.clone(),
                value: self.value.clone(),
                trial: self.trial,
                n_readings: point.n_readings as u32,
                accuracy: point.accuracy(),
                reliability: point.reliability,
                seed: self.seed,
                stream_seed: self.stream_seed as i64,
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curve_rows_carry_each_points_readings_accuracy_and_reliability() {
        let curve = AccuracyCurve {
            experiment: "noise".into(),
            descriptor: "mnti".into(),
            parameter: "noise_fraction".into(),
            value: "0.1".into(),
            trial: 2,
            seed: 9,
            stream_seed: u64::MAX - 1,
        };
        let point = |n_readings, correct, reliability| AccuracyPoint {
            n_readings,
            trials: 5,
            correct,
            reliability,
        };
        let rows = curve.rows(&[point(1, 1, 0.3), point(2, 2, 0.5)]);
        assert_eq!(rows.len(), 2);
        assert_eq!((rows[0].n_readings, rows[0].accuracy), (1, 0.2));
        assert_eq!(
            (
                rows[1].n_readings,
                rows[1].reliability,
                rows[1].trial,
                rows[1].seed
            ),
            (2, 0.5, 2, 9)
        );
        // A derived seed above i64::MAX is written as a negative int64 and read back unchanged.
        assert_eq!(rows[0].stream_seed, -2);
        assert_eq!(rows[0].stream_seed as u64, u64::MAX - 1);
    }
}
