//! Calibration: does the posterior mean what it says? A belief that gives its guess probability
//! 0.9 should be right nine times in ten (beyond the paper, which reports accuracy and the mean
//! probability on the true object, Sec. V-B1/V-B2, but not whether the top probability can be
//! trusted; a confidence stop and the demo's "dragon, p = 0.945" rely on it).
//!
//! Definitions, the same for `taction recognize` and every experiment:
//!
//! - A **prediction** is one belief after `n` readings of one trial ([`TouchRow`]); its
//!   **confidence** is its largest posterior probability ([`TouchRow::p_guess`]), and it is
//!   **right** when that guess is the true object. A table pools every [`TouchRow`] of an
//!   [`Evaluation`]: every trial, every reading count in its range (a trial with no reading has no
//!   row and adds no prediction).
//! - **Bins**: [`CONFIDENCE_BINS`] = 10 equal-width bins over [0, 1]; bin `b` holds confidences in
//!   `[b/10, (b+1)/10)`, the last bin also 1.0. Per bin: the count, the mean confidence and the
//!   accuracy (the fraction right); an empty bin has neither (empty CSV fields, never NaN).
//! - **ECE** (expected calibration error) = `sum_b (count_b / N) |accuracy_b - mean_confidence_b|`
//!   over the bins, `N` all predictions; [`None`] for a table without predictions.
//!
//! A table keeps per bin the count, the summed confidence and the number right, so tables of
//! several trials, units or curves pool exactly by summation ([`ReliabilityTable::merge`]).

use crate::recognize::confusion::csv_row;
use crate::recognize::evaluate::{Evaluation, TouchRow};

/// The number of equal-width confidence bins over [0, 1].
pub const CONFIDENCE_BINS: usize = 10;

/// One confidence bin's predictions: how many, their summed confidence, how many were right.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReliabilityBin {
    pub count: usize,
    pub confidence_sum: f64,
    pub correct: usize,
}

impl ReliabilityBin {
    /// The mean confidence of the bin's predictions; `None` for an empty bin.
    pub fn mean_confidence(&self) -> Option<f64> {
        (self.count > 0).then(|| self.confidence_sum / self.count as f64)
    }

    /// The fraction of the bin's predictions that were right; `None` for an empty bin.
    pub fn accuracy(&self) -> Option<f64> {
        (self.count > 0).then(|| self.correct as f64 / self.count as f64)
    }
}

/// Predictions binned by confidence (see the module documentation for the definitions).
///
/// ```
/// use taction::recognize::ReliabilityTable;
/// let mut table = ReliabilityTable::default();
/// table.add(0.9, true);
/// table.add(0.7, false);
/// // (1/2)|1 - 0.9| + (1/2)|0 - 0.7| = 0.4
/// assert!((table.ece().unwrap() - 0.4).abs() < 1e-12);
/// assert_eq!(ReliabilityTable::default().ece(), None);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReliabilityTable {
    bins: [ReliabilityBin; CONFIDENCE_BINS],
}

impl ReliabilityTable {
    /// The table of every prediction of `touches`.
    pub fn of<'a>(touches: impl IntoIterator<Item = &'a TouchRow>) -> Self {
        let mut table = Self::default();
        for row in touches {
            table.add(row.p_guess(), row.object_guess == row.object_true);
        }
        table
    }

    /// The table of these bins (sums pooled elsewhere, e.g. read back from a reliability CSV).
    pub fn from_bins(bins: [ReliabilityBin; CONFIDENCE_BINS]) -> Self {
        Self { bins }
    }

    /// Bin `b`'s bounds, `[b/10, (b+1)/10)` (the last one closed), as written in the CSVs.
    pub fn bounds(bin: usize) -> (f64, f64) {
        let width = CONFIDENCE_BINS as f64;
        (bin as f64 / width, (bin + 1) as f64 / width)
    }

    /// The bin of `confidence`: compared with the written bounds themselves, so a confidence equal
    /// to a bound lands in the bin that bound opens. A probability outside [0, 1] (none of the
    /// posterior's) lands in the first or last bin.
    pub fn bin_of(confidence: f64) -> usize {
        (1..CONFIDENCE_BINS)
            .filter(|&b| confidence >= Self::bounds(b).0)
            .count()
    }

    /// Adds one prediction of `confidence` that was `right` or not.
    pub fn add(&mut self, confidence: f64, right: bool) {
        let bin = &mut self.bins[Self::bin_of(confidence)];
        bin.count += 1;
        bin.confidence_sum += confidence;
        bin.correct += usize::from(right);
    }

    /// Pools `other`'s predictions into this table.
    pub fn merge(&mut self, other: &ReliabilityTable) {
        for (bin, more) in self.bins.iter_mut().zip(&other.bins) {
            bin.count += more.count;
            bin.confidence_sum += more.confidence_sum;
            bin.correct += more.correct;
        }
    }

    /// The bins, lowest confidence first.
    pub fn bins(&self) -> &[ReliabilityBin; CONFIDENCE_BINS] {
        &self.bins
    }

    /// Every prediction of the table, `N`.
    pub fn predictions(&self) -> usize {
        self.bins.iter().map(|b| b.count).sum()
    }

    /// The expected calibration error, `sum_b (count_b / N) |accuracy_b - mean_confidence_b|`;
    /// `None` without predictions.
    pub fn ece(&self) -> Option<f64> {
        let n = self.predictions();
        (n > 0).then(|| {
            self.bins
                .iter()
                .filter_map(|b| {
                    Some(b.count as f64 / n as f64 * (b.accuracy()? - b.mean_confidence()?).abs())
                })
                .sum()
        })
    }

    /// `bin,confidence_low,confidence_high,count,mean_confidence,accuracy`, one row per bin, empty
    /// bins with count 0 and the last two fields empty (strict CSV readers and pandas read them as
    /// missing).
    pub fn to_csv_string(&self) -> String {
        let mut rows = vec![csv_row(&[
            "bin",
            "confidence_low",
            "confidence_high",
            "count",
            "mean_confidence",
            "accuracy",
        ])];
        let text = |value: Option<f64>| value.map_or_else(String::new, |v| v.to_string());
        for (b, bin) in self.bins.iter().enumerate() {
            let (low, high) = Self::bounds(b);
            rows.push(csv_row(&[
                &b.to_string(),
                &low.to_string(),
                &high.to_string(),
                &bin.count.to_string(),
                &text(bin.mean_confidence()),
                &text(bin.accuracy()),
            ]));
        }
        rows.concat()
    }
}

impl Evaluation {
    /// The reliability table of every prediction of this evaluation: every trial, every reading
    /// count of its range.
    pub fn reliability(&self) -> ReliabilityTable {
        ReliabilityTable::of(&self.touches)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A belief over three objects giving its guess `confidence`, right or not.
    fn row(trial: usize, n: usize, confidence: f64, right: bool) -> TouchRow {
        let rest = (1.0 - confidence) / 2.0;
        TouchRow {
            trial,
            object_true: if right { 0 } else { 1 },
            n_readings: n,
            object_guess: 0,
            entropy_nats: 0.0,
            probabilities: vec![confidence, rest, rest],
        }
    }

    #[test]
    fn ece_of_a_small_set_is_the_hand_computed_one() {
        // Bin 9: 0.95 right, 0.95 wrong -> mean 0.95, accuracy 0.5, gap 0.45, weight 2/5.
        // Bin 6: 0.65 right -> gap 0.35, weight 1/5. Bin 4: 0.45, 0.45 wrong -> gap 0.45, 2/5.
        let rows = [
            row(0, 1, 0.95, true),
            row(0, 2, 0.95, false),
            row(1, 1, 0.65, true),
            row(1, 2, 0.45, false),
            row(2, 1, 0.45, false),
        ];
        let table = ReliabilityTable::of(&rows);
        assert_eq!(table.predictions(), 5);
        assert_eq!((table.bins()[9].count, table.bins()[9].correct), (2, 1));
        assert_eq!(table.bins()[6].accuracy(), Some(1.0));
        assert_eq!(table.bins()[0].mean_confidence(), None);
        let expected = 0.4 * 0.45 + 0.2 * 0.35 + 0.4 * 0.45;
        assert!((table.ece().unwrap() - expected).abs() < 1e-12);
    }

    #[test]
    fn a_calibrated_source_has_an_ece_near_zero() {
        // Each bin's predictions right exactly as often as their confidence says, in the limit:
        // confidence c = (b + 0.5)/10, right for round(1000 c) of 1000 predictions.
        let mut table = ReliabilityTable::default();
        for b in 0..CONFIDENCE_BINS {
            let c = (b as f64 + 0.5) / 10.0;
            let right = (1000.0 * c).round() as usize;
            for i in 0..1000 {
                table.add(c, i < right);
            }
        }
        assert!(table.ece().unwrap() < 1e-9, "{:?}", table.ece());
    }

    #[test]
    fn merging_equals_pooling() {
        // Dyadic confidences: sums are exact in any order.
        let rows: Vec<TouchRow> = (0..40)
            .map(|i| {
                row(
                    i / 4,
                    i % 4 + 1,
                    [0.25, 0.5, 0.625, 0.875, 1.0][i % 5],
                    i % 3 != 0,
                )
            })
            .collect();
        let mut merged = ReliabilityTable::of(&rows[..17]);
        merged.merge(&ReliabilityTable::of(&rows[17..]));
        assert_eq!(merged, ReliabilityTable::of(&rows));
        assert_eq!(merged.ece(), ReliabilityTable::of(&rows).ece());
    }

    #[test]
    fn bounds_land_in_the_bin_they_open_and_one_in_the_last() {
        assert_eq!(ReliabilityTable::bin_of(1.0), 9);
        assert_eq!(ReliabilityTable::bin_of(0.0), 0);
        for b in 0..CONFIDENCE_BINS {
            let (low, high) = ReliabilityTable::bounds(b);
            assert_eq!(ReliabilityTable::bin_of(low), b);
            if b + 1 < CONFIDENCE_BINS {
                assert_eq!(ReliabilityTable::bin_of(high), b + 1);
            }
        }
        let mut table = ReliabilityTable::default();
        table.add(1.0, true);
        assert_eq!(table.bins()[9].count, 1);
        assert_eq!(table.ece(), Some(0.0));
    }

    #[test]
    fn csv_has_one_row_per_bin_with_empty_fields_for_empty_bins() {
        let table = ReliabilityTable::of(&[row(0, 1, 0.95, true)]);
        let text = table.to_csv_string();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "bin,confidence_low,confidence_high,count,mean_confidence,accuracy"
        );
        assert_eq!(lines.len(), 1 + CONFIDENCE_BINS);
        assert_eq!(lines[1], "0,0,0.1,0,,");
        assert_eq!(lines[10], "9,0.9,1,1,0.95,1");
        assert!(!text.contains("NaN"));
    }
}
