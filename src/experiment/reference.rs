//! A reference curve and every other curve's difference from it, paired by seed: `taction pool
//! RUNS... --out DIR --against strategy=blind,local_probability=1`.
//!
//! A claim such as "active touch is at least as accurate as blind exploration" compares two curves
//! of the same runs. Their seeds share everything random (datasets, codebooks, calibration), so
//! the two curves of one seed move together, and the difference's interval must resample whole
//! seeds for both curves at once: each resample draws seeds with replacement and takes the
//! difference of the two pooled means over those seeds. Two intervals read side by side, each
//! resampled alone, would count the seeds' shared noise twice.
//!
//! Each curve is compared with the curve of the same descriptor and the same levels of every factor
//! the reference does not name (`object_motion = fixed` against the reference's fixed curve). What
//! is written, beside the pooled tables ([`crate::experiment::pool()`]):
//!
//! | file | what |
//! |---|---|
//! | `<experiment>_differences.csv` | one row per compared curve and number of readings both curves have ([`DifferenceRow`]), with the first number of readings at which the curve reaches the reference's accuracy there |
//!
//! and a summary per compared curve ([`Comparison`]), which `taction pool` prints.

use std::fmt;
use std::str::FromStr;

use super::factor::{Factor, Factors};
use super::resample::{CurveKey, PointSums, TIE_TOLERANCE, level_or_ahead, paired_interval, pooled_accuracy};
use super::tidy::tidy_row;

/// The levels of the reference curves, as `--against` names them: some of the experiment's factors
/// and optionally the descriptor (`descriptor=mnti`). Each curve's reference is the curve of its
/// own levels with these replaced, so `strategy=blind` names one reference per object motion.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReferenceLevels {
    descriptor: Option<String>,
    levels: Vec<(Factor, String)>,
}

impl ReferenceLevels {
    /// The reference of the curve `(descriptor, factors)`: its own descriptor and levels, those the
    /// reference names replaced; `None` when the curve lacks a factor the reference names.
    fn of(&self, (descriptor, factors): &CurveKey) -> Option<CurveKey> {
        if self.levels.iter().any(|(f, _)| factors.level(*f).is_none()) {
            return None;
        }
        let descriptor = self.descriptor.clone().unwrap_or_else(|| descriptor.clone());
        let levels = factors
            .iter()
            .map(|(f, level)| match self.levels.iter().find(|(g, _)| *g == f) {
                Some((_, reference)) => (f, reference.clone()),
                None => (f, level.to_string()),
            });
        Some((descriptor, Factors::new(levels)))
    }

    /// The levels the curves take of each column the reference names, for a message.
    fn levels_taken(&self, curves: &[(CurveKey, PointSums)]) -> String {
        let mut named: Vec<String> = Vec::new();
        let mut list = |column: &str, level: &dyn Fn(&CurveKey) -> Option<String>| {
            let mut levels: Vec<String> = Vec::new();
            for (key, _) in curves {
                if let Some(l) = level(key).filter(|l| !levels.contains(l)) {
                    levels.push(l);
                }
            }
            named.push(format!("{column} {}", levels.join(", ")));
        };
        if self.descriptor.is_some() {
            list("descriptor", &|(d, _)| Some(d.clone()));
        }
        for (factor, _) in &self.levels {
            list(factor.column(), &|(_, f)| f.level(*factor).map(str::to_string));
        }
        named.join("; ")
    }

    /// The factors named that no curve of an experiment has, for its note of why nothing was
    /// compared.
    fn missing_factors(&self, curves: &[(CurveKey, PointSums)]) -> Vec<Factor> {
        self.levels
            .iter()
            .map(|(f, _)| *f)
            .filter(|&f| !curves.iter().any(|((_, factors), _)| factors.level(f).is_some()))
            .collect()
    }
}

/// `descriptor=mnti,strategy=blind`: as `--against` takes it.
impl fmt::Display for ReferenceLevels {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let descriptor = self.descriptor.iter().map(|d| format!("descriptor={d}"));
        let levels = self
            .levels
            .iter()
            .map(|(factor, level)| format!("{factor}={level}"));
        f.write_str(&descriptor.chain(levels).collect::<Vec<_>>().join(","))
    }
}

impl FromStr for ReferenceLevels {
    type Err = String;

    /// `column=level` pairs joined by commas: each column a factor (or `descriptor`), at most once,
    /// each level as the tables write it (no space, no comma).
    fn from_str(text: &str) -> Result<Self, String> {
        let mut reference = Self {
            descriptor: None,
            levels: Vec::new(),
        };
        for pair in text.split(',') {
            let Some((column, level)) = pair.split_once('=') else {
                return Err(format!("'{pair}' is not column=level (e.g. strategy=blind)"));
            };
            let (column, level) = (column.trim(), level.trim());
            if level.is_empty() || level.contains(char::is_whitespace) || level.contains('=') {
                return Err(format!(
                    "'{column}': level '{level}' is empty or holds a space or '='"
                ));
            }
            if column == "descriptor" {
                if reference.descriptor.replace(level.to_string()).is_some() {
                    return Err("'descriptor' is given twice".to_string());
                }
                continue;
            }
            let Some(factor) = Factor::from_column(column) else {
                return Err(format!(
                    "'{column}' is neither 'descriptor' nor a factor (factors: {})",
                    Factor::ALL.map(Factor::column).join(", ")
                ));
            };
            if reference.levels.iter().any(|(f, _)| *f == factor) {
                return Err(format!("'{column}' is given twice"));
            }
            reference.levels.push((factor, level.to_string()));
        }
        Ok(reference)
    }
}

tidy_row! {
    /// One curve against its reference at one number of readings, over every seed.
    ///
    /// | column | meaning |
    /// |---|---|
    /// | `experiment`, `descriptor`, factor columns, `n_readings` | the compared curve, as in the pooled table |
    /// | `reference` | the reference as `--against` named it |
    /// | `seeds` | runs pooled |
    /// | `accuracy`, `reference_accuracy` | each curve's pooled accuracy (the mean over every trial of every seed) |
    /// | `difference` | `accuracy - reference_accuracy`, 0 within [`TIE_TOLERANCE`] (a tie whose sums were added in another order) |
    /// | `difference_low`, `difference_high` | the 90% percentile interval of the difference over resamples of whole seeds, the same seeds for both curves |
    /// | `seeds_level_or_ahead` | the seeds whose own accuracy is level with (within [`TIE_TOLERANCE`]) or ahead of their reference's |
    /// | `readings_to_reach` | the first number of readings at which the pooled curve reaches `reference_accuracy` (level within [`TIE_TOLERANCE`]); empty when it does not within the readings run |
    #[derive(Debug, Clone, PartialEq)]
    pub struct DifferenceRow {
        pub experiment: String,
        pub descriptor: String,
        #[factors]
        pub factors: Factors,
        pub reference: String,
        pub n_readings: u32,
        pub seeds: usize,
        pub accuracy: f64,
        pub reference_accuracy: f64,
        pub difference: f64,
        pub difference_low: f64,
        pub difference_high: f64,
        pub seeds_level_or_ahead: usize,
        pub readings_to_reach: Option<u32>,
    }
}

/// One curve against its reference over every number of readings both have.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    pub descriptor: String,
    pub factors: Factors,
    /// The numbers of readings both curves have.
    pub counts: usize,
    /// Those where the pooled curve is level with or ahead of the pooled reference.
    pub counts_level_or_ahead: usize,
    /// The last number of readings both curves have, and the reference's pooled accuracy there.
    pub reference_readings: u32,
    pub reference_accuracy: f64,
    /// The first number of readings at which the pooled curve reaches that accuracy.
    pub readings_to_reach: Option<u32>,
}

/// An experiment's curves against a reference: the differences' rows and a summary per compared
/// curve, or why there are none.
pub(super) type Compared = Result<(Vec<DifferenceRow>, Vec<Comparison>), String>;

/// The `curves` (each with its points' per-seed sums) against `reference` (see [`Compared`]);
/// none when the reference names a factor no curve has, or no curve but the reference curves has a
/// reference curve (the message then lists the levels the curves take).
pub(super) fn against(
    curves: &[(CurveKey, PointSums)],
    reference: &ReferenceLevels,
    experiment: &str,
    draws: &[Vec<usize>],
) -> Compared {
    let missing = reference.missing_factors(curves);
    if !missing.is_empty() {
        let names: Vec<&str> = missing.iter().map(|f| f.column()).collect();
        return Err(format!("its curves have no factor {}", names.join(", ")));
    }
    let (mut differences, mut comparisons) = (Vec::new(), Vec::new());
    for (key, points) in curves {
        let Some(reference_key) = reference.of(key).filter(|r| r != key) else {
            continue;
        };
        let Some((_, reference_points)) = curves.iter().find(|(k, _)| *k == reference_key) else {
            continue;
        };
        let rows = curve_differences((key, points), reference_points, reference, experiment, draws);
        comparisons.extend(comparison(key, &rows));
        differences.extend(rows);
    }
    if comparisons.is_empty() {
        return Err(format!(
            "no curve other than the reference has a reference curve at {reference} (the curves' levels: {})",
            reference.levels_taken(curves)
        ));
    }
    Ok((differences, comparisons))
}

/// The rows of one curve (`key`, its points' per-seed sums) against its reference curve's points,
/// at every reading count both have.
fn curve_differences(
    (key, points): (&CurveKey, &PointSums),
    reference_points: &PointSums,
    reference: &ReferenceLevels,
    experiment: &str,
    draws: &[Vec<usize>],
) -> Vec<DifferenceRow> {
    let mut differences = Vec::new();
    let pooled: Vec<(u32, f64)> = points
        .iter()
        .map(|(&n, sums)| (n, pooled_accuracy(sums, None)))
        .collect();
    for (&(n, accuracy), sums) in pooled.iter().zip(points.values()) {
        let Some(reference_sums) = reference_points.get(&n) else {
            continue;
        };
        let reference_accuracy = pooled_accuracy(reference_sums, None);
        let (difference_low, difference_high) = paired_interval(sums, reference_sums, draws);
        let difference = accuracy - reference_accuracy;
        differences.push(DifferenceRow {
            experiment: experiment.to_string(),
            descriptor: key.0.clone(),
            factors: key.1.clone(),
            reference: reference.to_string(),
            n_readings: n,
            seeds: sums.len(),
            accuracy,
            reference_accuracy,
            difference: if difference.abs() <= TIE_TOLERANCE {
                0.0
            } else {
                difference
            },
            difference_low,
            difference_high,
            seeds_level_or_ahead: sums
                .iter()
                .zip(reference_sums)
                .filter(|(s, r)| level_or_ahead(s.mean_accuracy(), r.mean_accuracy()))
                .count(),
            readings_to_reach: pooled
                .iter()
                .find(|&&(_, a)| level_or_ahead(a, reference_accuracy))
                .map(|&(m, _)| m),
        });
    }
    differences
}

/// The summary of one curve's rows against its reference: the last reading count's accuracies.
fn comparison(key: &CurveKey, rows: &[DifferenceRow]) -> Option<Comparison> {
    let last = rows.last()?;
    Some(Comparison {
        descriptor: key.0.clone(),
        factors: key.1.clone(),
        counts: rows.len(),
        counts_level_or_ahead: rows
            .iter()
            .filter(|r| level_or_ahead(r.accuracy, r.reference_accuracy))
            .count(),
        reference_readings: last.n_readings,
        reference_accuracy: last.reference_accuracy,
        readings_to_reach: last.readings_to_reach,
    })
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use super::*;
    use crate::experiment::{ExperimentError, pool};

    /// The accuracy of both trials of seed `s` at `n` readings: the reference curve
    /// (`noise_fraction = 0.1`) varies from seed to seed by half the range, the other curve
    /// (`0.2`) is the reference plus a quarter in every seed.
    const REFERENCE: [[f64; 3]; 3] = [[0.25, 0.5, 0.5], [0.5, 0.5, 0.75], [0.0, 0.25, 0.5]];

    /// Finished runs of a toy experiment with two curves, the reference (`noise_fraction = 0.1`)
    /// and another (`0.2`), one run per seed of `seeds`, `trials` trials each with the accuracy
    /// `accuracy(seed, other, trial, n)` at `n` readings (from 1 to `readings`).
    fn runs_of(
        root: &Path,
        seeds: u64,
        (trials, readings): (usize, usize),
        accuracy: impl Fn(u64, bool, usize, usize) -> f64,
    ) -> Vec<PathBuf> {
        let manifest = r#"{"name":"toy","description":"a toy","plots":[{"stem":"toy","title":"Toy","kind":"accuracy","objects":4}],"details":[],"units":["all"]}"#;
        (1..=seeds)
            .map(|seed| {
                let dir = root.join(format!("s{seed}/toy"));
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(dir.join("manifest.json"), manifest).unwrap();
                std::fs::write(dir.join("config.json"), format!(r#"{{"seed": {seed}}}"#)).unwrap();
                let mut csv = String::from(
                    "experiment,descriptor,noise_fraction,trial,n_readings,accuracy,reliability,seed,stream_seed\n",
                );
                for (level, other) in [("0.1", false), ("0.2", true)] {
                    for trial in 0..trials {
                        for n in 1..=readings {
                            let a = accuracy(seed, other, trial, n);
                            csv += &format!("toy,mnti,{level},{trial},{n},{a},0.5,{seed},7\n");
                        }
                    }
                }
                std::fs::write(dir.join("toy.csv"), csv).unwrap();
                dir
            })
            .collect()
    }

    /// Three runs whose other curve is the reference plus a quarter in every seed.
    fn runs(root: &Path) -> Vec<PathBuf> {
        runs_of(root, 3, (2, 3), |seed, other, _, n| {
            REFERENCE[seed as usize - 1][n - 1] + if other { 0.25 } else { 0.0 }
        })
    }

    fn rows(path: &Path) -> Vec<csv::StringRecord> {
        csv::Reader::from_path(path)
            .unwrap()
            .records()
            .map(Result::unwrap)
            .collect()
    }

    #[test]
    fn a_reference_reads_as_it_is_written_and_bad_ones_are_refused_naming_the_column() {
        let reference: ReferenceLevels = "strategy=blind, local_probability=1".parse().unwrap();
        assert_eq!(reference.to_string(), "strategy=blind,local_probability=1");
        let with_descriptor: ReferenceLevels = "descriptor=mnti".parse().unwrap();
        assert_eq!(with_descriptor.to_string(), "descriptor=mnti");
        for (text, says) in [
            ("strategy", "not column=level"),
            ("speed=3", "'speed' is neither 'descriptor' nor a factor"),
            ("strategy=blind,strategy=active", "'strategy' is given twice"),
            ("descriptor=a,descriptor=b", "'descriptor' is given twice"),
            ("strategy=", "level '' is empty"),
            ("strategy=a b", "holds a space"),
            ("strategy=a=b", "holds a space or '='"),
        ] {
            let e = text.parse::<ReferenceLevels>().unwrap_err();
            assert!(e.contains(says), "{text}: {e}");
        }
    }

    #[test]
    fn a_curve_a_quarter_above_its_reference_in_every_seed_differs_by_a_quarter_in_every_resample() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("pooled");
        let reference: ReferenceLevels = "noise_fraction=0.1".parse().unwrap();
        let report = pool(&runs(root.path()), &out, Some(&reference)).unwrap();

        let differences = rows(&out.join("toy/toy_differences.csv"));
        // experiment,descriptor,noise_fraction,reference,n_readings,seeds,accuracy,reference_accuracy,
        // difference,difference_low,difference_high,seeds_level_or_ahead,readings_to_reach
        assert_eq!(differences.len(), 3, "the reference itself is not compared");
        let number = |r: &csv::StringRecord, i: usize| r[i].parse::<f64>().unwrap();
        for (n, row) in differences.iter().enumerate() {
            assert_eq!(&row[2], "0.2");
            assert_eq!(&row[3], "noise_fraction=0.1");
            assert_eq!(row[4].parse::<usize>().unwrap(), n + 1);
            let reference_accuracy = REFERENCE.iter().map(|s| s[n]).sum::<f64>() / 3.0;
            assert!((number(row, 7) - reference_accuracy).abs() < 1e-12);
            // Paired by seed, every resample differs by the quarter exactly.
            for column in [8, 9, 10] {
                assert!((number(row, column) - 0.25).abs() < 1e-12, "{row:?}");
            }
            assert_eq!(&row[11], "3");
        }
        // Resampled alone, the curve's own interval spans the seeds' spread.
        let pooled = rows(&out.join("toy/toy_pooled.csv"));
        let (low, high) = (number(&pooled[3], 7), number(&pooled[3], 8));
        assert!(high - low > 0.1, "{low} {high}");
        // The reference reaches 0.25, 0.4167, 0.5833; the curve is at 0.5 after one reading and
        // 0.6667 after two.
        let reach: Vec<&str> = differences.iter().map(|r| &r[12]).collect();
        assert_eq!(reach, ["1", "1", "2"]);

        let Some(Ok(comparisons)) = &report.pooled[0].compared else {
            panic!("{:?}", report.pooled[0].compared);
        };
        assert_eq!(comparisons.len(), 1);
        let c = &comparisons[0];
        assert_eq!((c.counts, c.counts_level_or_ahead), (3, 3));
        assert_eq!((c.reference_readings, c.readings_to_reach), (3, Some(2)));
        let record = std::fs::read_to_string(out.join("toy/pool.json")).unwrap();
        assert!(record.contains(r#""against": "noise_fraction=0.1""#), "{record}");
    }

    #[test]
    fn a_reference_no_experiment_has_is_refused_naming_the_levels_there_are_before_anything_is_written() {
        let root = tempfile::tempdir().unwrap();
        let runs = runs(root.path());
        let out = root.path().join("pooled");
        for (text, says) in [
            ("strategy=blind", "toy: its curves have no factor strategy"),
            (
                "noise_fraction=0.3",
                "toy: no curve other than the reference has a reference curve at noise_fraction=0.3 \
                 (the curves' levels: noise_fraction 0.1, 0.2)",
            ),
        ] {
            let reference: ReferenceLevels = text.parse().unwrap();
            let e = pool(&runs, &out, Some(&reference)).unwrap_err();
            assert!(matches!(e, ExperimentError::NothingAgainst { .. }), "{e}");
            assert!(e.to_string().contains(says), "{e}");
            assert!(!out.exists(), "{} was written", out.display());
        }
    }

    #[test]
    fn equal_accuracies_summed_in_another_order_are_level() {
        let root = tempfile::tempdir().unwrap();
        // The reference's trials 0.1, 0.2, 0.3 and the other curve's 0.3, 0.2, 0.1 in every seed:
        // the same accuracy, whose sums differ in the last bit.
        let value = |other: bool, trial: usize| [0.1, 0.2, 0.3][if other { 2 - trial } else { trial }];
        let sum = |other: bool| (0..6).map(|t| value(other, t % 3)).fold(0.0, |a, v| a + v);
        assert_ne!(
            sum(false),
            sum(true),
            "the test wants sums that differ in rounding"
        );
        let runs = runs_of(root.path(), 2, (3, 1), |_, other, trial, _| value(other, trial));
        let out = root.path().join("pooled");
        let reference: ReferenceLevels = "noise_fraction=0.1".parse().unwrap();
        let report = pool(&runs, &out, Some(&reference)).unwrap();
        let differences = rows(&out.join("toy/toy_differences.csv"));
        assert_eq!(&differences[0][8], "0.0", "{:?}", differences[0]);
        assert_eq!((&differences[0][11], &differences[0][12]), ("2", "1"));
        let Some(Ok(comparisons)) = &report.pooled[0].compared else {
            panic!("{:?}", report.pooled[0].compared);
        };
        assert_eq!(comparisons[0].counts_level_or_ahead, 1);
    }

    #[test]
    fn a_pool_without_the_reference_leaves_no_earlier_differences_behind() {
        let root = tempfile::tempdir().unwrap();
        let runs = runs(root.path());
        let out = root.path().join("pooled");
        let reference: ReferenceLevels = "noise_fraction=0.1".parse().unwrap();
        pool(&runs, &out, Some(&reference)).unwrap();
        let differences = out.join("toy/toy_differences.csv");
        assert!(differences.is_file());
        pool(&runs, &out, None).unwrap();
        assert!(!differences.exists(), "{} was left", differences.display());
        let record = std::fs::read_to_string(out.join("toy/pool.json")).unwrap();
        assert!(!record.contains("against"), "{record}");
    }
}
