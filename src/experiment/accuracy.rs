//! The tidy tables of the paper's recognition figures (Fig. 7-13, 16, 17): the accuracy table, one
//! row per (setting, trial, number of readings), and beside it the per-object table, one row per
//! test object at each of those points.
//!
//! Both start with `experiment`, `descriptor` and the experiment's factor columns ([`Factor`]: one
//! column per thing the experiment varies, none when it varies only the descriptor), then `trial`.
//! The factor columns differ between experiments, so the rows are declared with `tidy_row!`
//! (`tidy.rs`), which writes and reads them by name.

#[cfg(doc)]
use super::factor::Factor;
use super::factor::Factors;
use super::tidy::tidy_row;
use super::unit::DetailRow;
use crate::recognize::{AccuracyPoint, Evaluation, ReliabilityTable};

tidy_row! {
    /// One point of one recognition curve.
    ///
    /// | column | meaning |
    /// |---|---|
    /// | `experiment` | the experiment's name, e.g. `noise` |
    /// | `descriptor` | the descriptor's command-line name, e.g. `polar-fourier` |
    /// | one column per factor | what the experiment varies besides the descriptor, one level per cell (see [`Factor`]): `noise_fraction` = `0.1`; `data` = `validation` and `resolution` = `6x6`; none in `descriptors`, `letters`, `real-frames`, `sim-to-real` |
    /// | `trial` | the repetition (0-based); the plot averages over trials |
    /// | `n_readings` | number of readings of the unknown object used so far (1-based) |
    /// | `accuracy` | fraction of test objects whose most probable identity after `n_readings` readings is correct, in [0, 1] (the "empirical probability of correctly identifying any unknown object", Sec. V-B2) |
    /// | `reliability` | mean posterior probability given to the correct object, in [0, 1] (Sec. V-B1) |
    /// | `seed` | the run's seed, as given with `--seed` |
    /// | `stream_seed` | the seed the trial's randomness was drawn from (derived from `seed`), its 64 bits read as a signed integer so that every CSV reader takes it as an int64 (`as u64` gives it back) |
    #[derive(Debug, Clone, PartialEq)]
    pub struct AccuracyRow {
        pub experiment: String,
        pub descriptor: String,
        #[factors]
        pub factors: Factors,
        pub trial: u32,
        pub n_readings: u32,
        pub accuracy: f64,
        pub reliability: f64,
        pub seed: u64,
        pub stream_seed: i64,
    }
    impl Deserialize;
}

tidy_row! {
    /// One test object of one point of one recognition curve: the rows whose mean `correct` is the
    /// accuracy row's `accuracy` and whose mean `p_true` its `reliability`.
    ///
    /// | column | meaning |
    /// |---|---|
    /// | `experiment`, `descriptor`, factor columns, `trial`, `n_readings` | as in [`AccuracyRow`] |
    /// | `object` | the test object's name (for recorded frames, its label) |
    /// | `correct` | 1 when the object's most probable identity after `n_readings` readings (or its last, when it has fewer; none for an object never read) is the object, else 0 |
    /// | `p_true` | the posterior probability given to the object itself (1 / objects for one never read) |
    #[derive(Debug, Clone, PartialEq)]
    pub struct PerObjectRow {
        pub experiment: String,
        pub descriptor: String,
        #[factors]
        pub factors: Factors,
        pub trial: u32,
        pub object: String,
        pub n_readings: u32,
        pub correct: bool,
        pub p_true: f64,
    }
    impl Deserialize;
}

impl DetailRow for PerObjectRow {
    const TABLE: Option<&'static str> = Some("per_object");
}

tidy_row! {
    /// One point of one recognition curve counted in the arm's touch attempts rather than in its
    /// converged readings: what a touch that met nothing, ended in a collision or did not settle costs
    /// the recogniser (it reads converged readings only, Algorithm 1).
    ///
    /// | column | meaning |
    /// |---|---|
    /// | `experiment`, `descriptor`, factor columns, `trial` | as in [`AccuracyRow`] |
    /// | `n_attempts` | touch attempts the arm made on each object so far, converged or not (1-based) |
    /// | `accuracy` | fraction of test objects whose most probable identity after the converged readings of their first `n_attempts` attempts is right; an object with none is not identified |
    /// | `reliability` | mean posterior probability on the right object (1 / objects for an object with no converged reading yet) |
    #[derive(Debug, Clone, PartialEq)]
    pub struct AttemptRow {
        pub experiment: String,
        pub descriptor: String,
        #[factors]
        pub factors: Factors,
        pub trial: u32,
        pub n_attempts: u32,
        pub accuracy: f64,
        pub reliability: f64,
    }
    impl Deserialize;
}

impl DetailRow for AttemptRow {
    const TABLE: Option<&'static str> = Some("attempts");
}

tidy_row! {
    /// One confidence bin of one curve's reliability table, pooled over all the curve's trials
    /// (`recognize::ReliabilityTable`: every belief after every number of readings of every trial is a
    /// prediction; its confidence is its top probability). A curve's rows are its table's 10 bins, all
    /// from one unit (each recognition experiment evaluates a curve's trials in one unit).
    ///
    /// | column | meaning |
    /// |---|---|
    /// | `experiment`, `descriptor`, factor columns | as in [`AccuracyRow`] (no `trial`: pooled over trials) |
    /// | `bin` | 0-9: confidences in [`confidence_low`, `confidence_high`), the last bin with 1.0 |
    /// | `confidence_low`, `confidence_high` | the bin's bounds, b/10 and (b+1)/10 |
    /// | `count` | the predictions in the bin |
    /// | `mean_confidence` | their mean top probability; empty when `count` is 0 |
    /// | `accuracy` | the fraction of them whose guess is the true object; empty when `count` is 0 |
    /// | `ece` | the curve's expected calibration error, `sum_b (count_b / N) abs(accuracy_b - mean_confidence_b)`, the same on each of its rows; empty for a curve without predictions |
    #[derive(Debug, Clone, PartialEq)]
    pub struct ReliabilityRow {
        pub experiment: String,
        pub descriptor: String,
        #[factors]
        pub factors: Factors,
        pub bin: u32,
        pub confidence_low: f64,
        pub confidence_high: f64,
        pub count: u64,
        pub mean_confidence: Option<f64>,
        pub accuracy: Option<f64>,
        pub ece: Option<f64>,
    }
    impl Deserialize;
}

impl ReliabilityRow {
    /// The rows of one curve's `table`, one per bin, each with the table's ECE.
    pub fn of_table(
        experiment: &str,
        descriptor: &str,
        factors: &Factors,
        table: &ReliabilityTable,
    ) -> Vec<ReliabilityRow> {
        let ece = table.ece();
        table
            .bins()
            .iter()
            .enumerate()
            .map(|(b, bin)| {
                let (low, high) = ReliabilityTable::bounds(b);
                ReliabilityRow {
                    experiment: experiment.to_string(),
                    descriptor: descriptor.to_string(),
                    factors: factors.clone(),
                    bin: b as u32,
                    confidence_low: low,
                    confidence_high: high,
                    count: bin.count as u64,
                    mean_confidence: bin.mean_confidence(),
                    accuracy: bin.accuracy(),
                    ece,
                }
            })
            .collect()
    }
}

impl DetailRow for ReliabilityRow {
    const TABLE: Option<&'static str> = Some("reliability");
}

/// Everything an [`AccuracyRow`] holds but the point itself: one curve of one trial.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyCurve {
    pub experiment: String,
    pub descriptor: String,
    pub factors: Factors,
    pub trial: u32,
    /// The run's seed (`--seed`).
    pub seed: u64,
    /// The seed the trial's randomness was drawn from.
    pub stream_seed: u64,
}

/// Per-object rows need one test sequence per object and trial.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{experiment}, {descriptor}, trial {trial}: object '{object}' is tested twice; per-object rows need one test sequence per object"
)]
pub struct RepeatedObject {
    pub experiment: String,
    pub descriptor: String,
    pub trial: u32,
    pub object: String,
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
                factors: self.factors.clone(),
                trial: self.trial,
                n_readings: point.n_readings as u32,
                accuracy: point.accuracy(),
                reliability: point.reliability,
                seed: self.seed,
                stream_seed: self.stream_seed as i64,
            })
            .collect()
    }

    /// The curve's reliability rows: `table` pooled over all its trials (so `trial` and the seeds
    /// are not columns), one row per bin, each with the table's ECE.
    pub fn reliability_rows(&self, table: &ReliabilityTable) -> Vec<ReliabilityRow> {
        ReliabilityRow::of_table(&self.experiment, &self.descriptor, &self.factors, table)
    }

    /// The per-object rows of `evaluation`: at every point, each trial's outcome (the outcomes the
    /// point's accuracy counts) under its object's name, objects in trial order.
    pub fn object_rows(&self, evaluation: &Evaluation) -> Result<Vec<PerObjectRow>, RepeatedObject> {
        let mut rows = Vec::new();
        for point in &evaluation.accuracy {
            for (i, outcome) in point.outcomes.iter().enumerate() {
                let object = &evaluation.objects[outcome.object];
                if point.outcomes[..i].iter().any(|o| o.object == outcome.object) {
                    return Err(RepeatedObject {
                        experiment: self.experiment.clone(),
                        descriptor: self.descriptor.clone(),
                        trial: self.trial,
                        object: object.clone(),
                    });
                }
                rows.push(PerObjectRow {
                    experiment: self.experiment.clone(),
                    descriptor: self.descriptor.clone(),
                    factors: self.factors.clone(),
                    trial: self.trial,
                    object: object.clone(),
                    n_readings: point.n_readings as u32,
                    correct: outcome.correct,
                    p_true: outcome.p_true,
                });
            }
        }
        Ok(rows)
    }
}

impl AccuracyCurve {
    /// The curve counted in touch attempts: `attempts[i]` says, attempt by attempt, whether trial
    /// `i` of `evaluation` (trials in the same order) converged there; after `n` attempts a trial
    /// holds the belief of its converged readings so far (`evaluation`'s point at that count), an
    /// object not yet read the uniform prior, and a trial past its last attempt keeps its last
    /// belief. One row per attempt count from 1 to `last` (the longest trial of every repetition
    /// of the curve, so that the plot averages each count over every repetition).
    pub fn attempt_rows(
        &self,
        evaluation: &Evaluation,
        attempts: &[Vec<bool>],
        last: usize,
    ) -> Result<Vec<AttemptRow>, String> {
        let prior = 1.0 / evaluation.objects.len().max(1) as f64;
        let mut read = vec![0usize; attempts.len()];
        let mut rows = Vec::with_capacity(last);
        for n in 1..=last {
            let (mut correct, mut p_true) = (0usize, 0.0);
            for (i, trial) in attempts.iter().enumerate() {
                read[i] += usize::from(trial.get(n - 1) == Some(&true));
                if read[i] == 0 {
                    p_true += prior;
                    continue;
                }
                let outcome = evaluation
                    .accuracy
                    .iter()
                    .find(|p| p.n_readings == read[i])
                    .and_then(|p| p.outcomes.get(i))
                    .ok_or_else(|| {
                        format!(
                            "{}, trial {}: attempt log {i} has more converged readings than its evaluation",
                            self.factors, self.trial
                        )
                    })?;
                correct += usize::from(outcome.correct);
                p_true += outcome.p_true;
            }
            let trials = attempts.len().max(1) as f64;
            rows.push(AttemptRow {
                experiment: self.experiment.clone(),
                descriptor: self.descriptor.clone(),
                factors: self.factors.clone(),
                trial: self.trial,
                n_attempts: n as u32,
                accuracy: correct as f64 / trials,
                reliability: p_true / trials,
            });
        }
        Ok(rows)
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    use super::*;
    use crate::experiment::factor::Factor;
    use crate::recognize::evaluate::TrialOutcome;

    fn curve() -> AccuracyCurve {
        AccuracyCurve {
            experiment: "noise".into(),
            descriptor: "mnti".into(),
            factors: Factors::new([(Factor::NoiseFraction, "0.1")]),
            trial: 2,
            seed: 9,
            stream_seed: u64::MAX - 1,
        }
    }

    /// A point of five trials, `correct` of them right, every one with `p_true`.
    fn point(n_readings: usize, correct: usize, p_true: f64) -> AccuracyPoint {
        AccuracyPoint::new(
            n_readings,
            (0..5)
                .map(|object| TrialOutcome {
                    object,
                    correct: object < correct,
                    p_true,
                })
                .collect(),
        )
    }

    #[test]
    fn curve_rows_carry_each_points_readings_accuracy_and_reliability() {
        let rows = curve().rows(&[point(1, 1, 0.3), point(2, 2, 0.5)]);
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

    fn csv_of<R: Serialize>(rows: &[R]) -> String {
        let mut writer = csv::Writer::from_writer(Vec::new());
        for row in rows {
            writer.serialize(row).unwrap();
        }
        String::from_utf8(writer.into_inner().unwrap()).unwrap()
    }

    fn read<R: for<'de> Deserialize<'de>>(text: &str) -> Result<Vec<R>, csv::Error> {
        csv::Reader::from_reader(text.as_bytes()).deserialize().collect()
    }

    #[test]
    fn rows_write_one_column_per_factor_and_read_back() {
        let mut two = curve();
        two.factors = Factors::new([(Factor::Data, "validation"), (Factor::Resolution, "6x6")]);
        let rows = two.rows(&[point(1, 1, 0.3)]);
        let text = csv_of(&rows);
        assert!(
            text.starts_with("experiment,descriptor,data,resolution,trial,n_readings,accuracy,"),
            "{text}"
        );
        assert_eq!(read::<AccuracyRow>(&text).unwrap(), rows);
        let mut none = curve();
        none.factors = Factors::none();
        let text = csv_of(&none.rows(&[point(1, 1, 0.3)]));
        assert!(text.starts_with("experiment,descriptor,trial,"), "{text}");
        assert_eq!(read::<AccuracyRow>(&text).unwrap()[0].factors, Factors::none());
    }

    #[test]
    fn packed_or_unknown_factor_columns_are_refused() {
        let mut packed = curve();
        packed.factors = Factors::new([(Factor::Data, "validation 6x6")]);
        let mut writer = csv::Writer::from_writer(Vec::new());
        let e = writer
            .serialize(&packed.rows(&[point(1, 1, 0.3)])[0])
            .unwrap_err();
        assert!(e.to_string().contains("one level per cell"), "{e}");
        let old = "experiment,descriptor,parameter,value,trial,n_readings,accuracy,reliability,seed,stream_seed\n\
                   noise,mnti,noise_fraction,0.1,0,1,0.5,0.5,1,2\n";
        let e = read::<AccuracyRow>(old).unwrap_err().to_string();
        assert!(e.contains("'parameter'") && e.contains("no factor"), "{e}");
    }

    #[test]
    fn reliability_rows_write_empty_bins_as_empty_fields_and_read_back() {
        let mut table = ReliabilityTable::default();
        table.add(0.95, true);
        table.add(0.55, false);
        let rows = curve().reliability_rows(&table);
        assert_eq!(rows.len(), 10);
        let text = csv_of(&rows);
        assert!(
            text.starts_with(
                "experiment,descriptor,noise_fraction,bin,confidence_low,confidence_high,count,mean_confidence,accuracy,ece\n"
            ),
            "{text}"
        );
        // (1/2)|1 - 0.95| + (1/2)|0 - 0.55| = 0.3
        assert!(
            text.contains("\nnoise,mnti,0.1,0,0.0,0.1,0,,,0.30000000000000004\n"),
            "{text}"
        );
        assert_eq!(read::<ReliabilityRow>(&text).unwrap(), rows);
        let none = curve().reliability_rows(&ReliabilityTable::default());
        assert!(none.iter().all(|r| r.ece.is_none() && r.count == 0));
        assert_eq!(read::<ReliabilityRow>(&csv_of(&none)).unwrap(), none);
    }

    #[test]
    fn per_object_rows_average_to_the_accuracy_row() {
        let objects = ["a", "b", "c", "d", "e"].map(String::from).to_vec();
        let points = vec![point(1, 1, 0.3), point(2, 4, 0.7)];
        let evaluation = Evaluation {
            objects: objects.clone(),
            touches: Vec::new(),
            accuracy: points.clone(),
            confusion: crate::recognize::ConfusionMatrix::new(objects, 2),
        };
        let per_object = curve().object_rows(&evaluation).unwrap();
        assert_eq!(per_object.len(), 10);
        for row in curve().rows(&points) {
            let at: Vec<&PerObjectRow> = per_object
                .iter()
                .filter(|r| r.n_readings == row.n_readings)
                .collect();
            let correct = at.iter().filter(|r| r.correct).count() as f64 / at.len() as f64;
            assert_eq!(correct, row.accuracy);
        }
        let text = csv_of(&per_object);
        assert!(
            text.starts_with("experiment,descriptor,noise_fraction,trial,object,n_readings,correct,p_true\n"),
            "{text}"
        );
        assert!(text.contains("\nnoise,mnti,0.1,2,a,1,1,0.3\n"), "{text}");
        assert_eq!(read::<PerObjectRow>(&text).unwrap(), per_object);
        let mut twice = evaluation;
        twice.accuracy[0].outcomes[1].object = 0;
        assert!(curve().object_rows(&twice).is_err());
    }

    #[test]
    fn attempt_rows_hold_each_objects_belief_between_its_converged_attempts() {
        let objects = ["a", "b", "c", "d", "e"].map(String::from).to_vec();
        let evaluation = Evaluation {
            objects: objects.clone(),
            touches: Vec::new(),
            accuracy: vec![point(1, 1, 0.3), point(2, 4, 0.7)],
            confusion: crate::recognize::ConfusionMatrix::new(objects, 2),
        };
        // Object a misses its first attempt, b converges once, c-e converge twice in a row.
        let (t, f) = (true, false);
        let logs = vec![vec![f, t, t], vec![t], vec![t, t], vec![t, t], vec![t, t]];
        let rows = curve().attempt_rows(&evaluation, &logs, 4).unwrap();
        let points: Vec<(u32, f64, f64)> = rows
            .iter()
            .map(|r| (r.n_attempts, r.accuracy, r.reliability))
            .collect();
        let expected = [(1, 0.0, 0.28), (2, 0.6, 0.54), (3, 0.6, 0.62), (4, 0.6, 0.62)];
        for ((n, accuracy, reliability), (n_, accuracy_, reliability_)) in points.into_iter().zip(expected) {
            assert_eq!((n, accuracy), (n_, accuracy_));
            assert!((reliability - reliability_).abs() < 1e-12, "{n}: {reliability}");
        }
        assert_eq!(rows.len(), 4);
        let text = csv_of(&rows);
        assert!(
            text.starts_with("experiment,descriptor,noise_fraction,trial,n_attempts,accuracy,reliability\n"),
            "{text}"
        );
        assert_eq!(read::<AttemptRow>(&text).unwrap(), rows);
        // A log with more converged attempts than the evaluation has readings is refused.
        let mut long = logs;
        long[1] = vec![t, t, t];
        assert!(curve().attempt_rows(&evaluation, &long, 3).is_err());
    }
}
