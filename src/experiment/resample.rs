//! Resampling whole seeds: the intervals of `taction pool` ([`super::pool()`]) and of its
//! differences against a reference curve ([`super::reference`]).
//!
//! Each point of a curve keeps every seed's sums ([`SeedSums`]); a resample draws as many seeds as
//! were given, with replacement, and pools the drawn seeds' trials. One fixed set of draws serves
//! every curve and every difference, so two curves compared are resampled on the same seeds.

use std::collections::BTreeMap;

use rand::RngExt;

use crate::stats::percentile;

use super::factor::Factors;

/// Resamples of the seeds behind each interval: enough that the 5th and 95th percentiles move by
/// well under a point between resamplings.
pub const RESAMPLES: usize = 2000;

/// The interval's coverage: the 5th to the 95th percentile of the resampled pooled accuracy.
pub const INTERVAL_LEVEL: f64 = 0.9;

/// The resampling's own seed: the same runs always give the same interval.
pub(super) const RESAMPLE_SEED: u64 = 1;

/// One seed's trials at one point of one curve, summed.
#[derive(Debug, Clone, Default)]
pub(super) struct SeedSums {
    pub trials: usize,
    /// The sums of the trials' accuracies, reliabilities and the experiment's own columns.
    pub accuracy: f64,
    pub reliability: f64,
    pub extras: Vec<f64>,
}

impl SeedSums {
    /// This seed's mean accuracy at the point.
    pub fn mean_accuracy(&self) -> f64 {
        self.accuracy / self.trials as f64
    }
}

/// A curve: its descriptor and factor levels.
pub(super) type CurveKey = (String, Factors);

/// Per number of readings, each seed's sums in the order the runs were given.
pub(super) type PointSums = BTreeMap<u32, Vec<SeedSums>>;

/// [`RESAMPLES`] draws of `seeds` seed indices each, with replacement.
pub(super) fn resamples(seeds: usize) -> Vec<Vec<usize>> {
    let mut rng = crate::rng::rng(RESAMPLE_SEED);
    (0..RESAMPLES)
        .map(|_| (0..seeds).map(|_| rng.random_range(0..seeds)).collect())
        .collect()
}

/// The [`INTERVAL_LEVEL`] percentile interval of the pooled accuracy of `sums` over `draws`.
pub(super) fn interval(sums: &[SeedSums], draws: &[Vec<usize>]) -> (f64, f64) {
    percentile_interval(
        draws
            .iter()
            .map(|draw| pooled_accuracy(sums, Some(draw)))
            .collect(),
    )
}

/// The [`INTERVAL_LEVEL`] percentile interval of `sums`' pooled accuracy minus `reference`'s over
/// `draws`, both curves on the same drawn seeds.
pub(super) fn paired_interval(sums: &[SeedSums], reference: &[SeedSums], draws: &[Vec<usize>]) -> (f64, f64) {
    percentile_interval(
        draws
            .iter()
            .map(|draw| pooled_accuracy(sums, Some(draw)) - pooled_accuracy(reference, Some(draw)))
            .collect(),
    )
}

/// How far apart two pooled accuracies may be and still be equal. An accuracy is a count of right
/// guesses over a count of runs, but it is pooled as a sum of per-trial fractions, whose rounding
/// depends on the order of the trials: two curves with the same counts can differ in the last bit
/// (491/540 as 0.9092592592592591 and as 0.9092592592592592), while two different fractions of at
/// most 10,000 runs each differ by at least 1e-8 (a curve of fifteen seeds pools 540 runs a point).
pub const TIE_TOLERANCE: f64 = 1e-9;

/// Whether accuracy `a` is at least `b`, a tie within [`TIE_TOLERANCE`] counting as level.
pub(super) fn level_or_ahead(a: f64, b: f64) -> bool {
    a >= b - TIE_TOLERANCE
}

/// The mean accuracy over every trial of the seeds `draw` names (with repeats), or of every seed.
pub(super) fn pooled_accuracy(sums: &[SeedSums], draw: Option<&[usize]>) -> f64 {
    let add = |(correct, trials): (f64, usize), s: &SeedSums| (correct + s.accuracy, trials + s.trials);
    let (correct, trials) = match draw {
        Some(draw) => draw.iter().map(|&s| &sums[s]).fold((0.0, 0), add),
        None => sums.iter().fold((0.0, 0), add),
    };
    correct / trials as f64
}

/// The [`INTERVAL_LEVEL`] percentile interval of resampled `values` (linear interpolation between
/// order statistics, numpy's default).
fn percentile_interval(mut values: Vec<f64>) -> (f64, f64) {
    values.sort_by(f64::total_cmp);
    let tail = (1.0 - INTERVAL_LEVEL) / 2.0;
    (percentile(&values, tail), percentile(&values, 1.0 - tail))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_interpolate_between_order_statistics_as_numpy_does() {
        let sorted = [1.0, 2.0, 3.0, 4.0];
        // numpy.percentile([1, 2, 3, 4], [5, 50, 95]) = [1.15, 2.5, 3.85]
        for (q, want) in [(0.05, 1.15), (0.5, 2.5), (0.95, 3.85), (0.0, 1.0), (1.0, 4.0)] {
            assert!((percentile(&sorted, q) - want).abs() < 1e-12, "{q}");
        }
    }

    #[test]
    fn one_seed_resampled_is_its_own_interval() {
        let sums = vec![SeedSums {
            trials: 3,
            accuracy: 2.0,
            ..SeedSums::default()
        }];
        let (low, high) = interval(&sums, &resamples(1));
        assert_eq!((low, high), (2.0 / 3.0, 2.0 / 3.0));
    }
}
