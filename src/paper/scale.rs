//! How much of the paper's data a run collects (`--scale`).

use serde::{Deserialize, Serialize};

use crate::valid::checked_f64;

checked_f64! {
    /// The fraction of the paper's data sizes a run collects: 1.0 is Sec. V-B's protocol (1000
    /// training and 100 validation sampler readings per object, then 100 test readings per object,
    /// the test repeated 3 times), 0.1 a quick look. Positive and at most 10.
    pub struct Scale(fraction) where fraction > 0.0 && fraction <= 10.0;
    /// A `--scale` that is not a fraction of the paper's data sizes.
    pub enum ScaleError {
        OutOfRange = "--scale {0}: must be a number in (0, 10] (1.0 is the paper's data sizes)",
        NotANumber = "--scale '{0}': not a number",
    }
}

/// Readings per object at scale 1.0 (Sec. V-B).
pub const PAPER_TRAINING_READINGS: usize = 1000;
pub const PAPER_VALIDATION_READINGS: usize = 100;
pub const PAPER_TEST_READINGS: usize = 100;
/// "This testing stage was then repeated 3 times, and the results were averaged" (Sec. V-B).
pub const PAPER_TRIALS: usize = 3;

/// Readings per object and trials of one run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct DataCounts {
    pub training_per_object: usize,
    pub validation_per_object: usize,
    /// Test readings per object and trial: the accuracy curves run from 1 to this many readings.
    pub test_per_object: usize,
    pub trials: usize,
}

impl Scale {
    pub const PAPER: Scale = Scale(1.0);

    /// The fraction of the paper's data sizes (the same as [`Scale::get`]).
    pub fn fraction(self) -> f64 {
        self.0
    }

    /// The paper's counts times the scale, rounded, with floors that keep every part of the
    /// protocol meaningful at tiny scales: 20 training readings (enough for a codebook of a few
    /// clusters per object), 5 validation and 5 test readings per object.
    pub fn counts(self) -> DataCounts {
        let scaled = |n: usize, floor: usize| ((n as f64 * self.0).round() as usize).max(floor);
        DataCounts {
            training_per_object: scaled(PAPER_TRAINING_READINGS, 20),
            validation_per_object: scaled(PAPER_VALIDATION_READINGS, 5),
            test_per_object: scaled(PAPER_TEST_READINGS, 5),
            trials: PAPER_TRIALS,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_scale_is_the_papers_protocol_and_small_scales_keep_floors() {
        let paper = Scale::PAPER.counts();
        assert_eq!(
            (
                paper.training_per_object,
                paper.validation_per_object,
                paper.test_per_object,
                paper.trials
            ),
            (1000, 100, 100, 3)
        );
        let tenth = Scale::new(0.1).map(Scale::counts);
        assert_eq!(
            tenth.map(|c| (c.training_per_object, c.test_per_object)),
            Ok((100, 10))
        );
        let tiny = Scale::new(0.001).map(Scale::counts);
        assert_eq!(
            tiny.map(|c| (c.training_per_object, c.validation_per_object, c.test_per_object)),
            Ok((20, 5, 5))
        );
    }

    #[test]
    fn out_of_range_scales_are_rejected_with_the_flag_named() {
        for bad in ["0", "-1", "nan", "inf", "11", "x"] {
            let err = bad
                .parse::<Scale>()
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(err.contains("--scale"), "{bad}: {err}");
        }
        assert_eq!("0.25".parse::<Scale>().map(Scale::fraction), Ok(0.25));
    }
}
