//! Pooling runs of several seeds: `taction pool RUNS... --out DIR` gives a recognition experiment's
//! curves over every seed, with an interval that resamples whole seeds.
//!
//! One seed is one draw of everything random in a run: the datasets, the codebook's restarts, the
//! calibration explorations, every exploration's poses. A curve of one seed therefore carries the
//! noise of its models as well as of its test runs, and the seeds of one configuration differ by
//! more than its trials' spread suggests (docs/measurements.md, "Nine seeds": the `active`
//! experiment's ECE ranged 0.02-0.10 per seed and curve, 0.013-0.031 over the nine seeds pooled).
//! A claim about a strategy needs several seeds, and its interval must resample seeds, not runs:
//! runs of one seed share their model, so an interval over runs would be too narrow.
//!
//! The runs must be finished (`<experiment>.csv` assembled; merge a sharded run first) and must
//! differ in nothing but their seeds: `manifest.json` byte for byte, `config.json` apart from its
//! `seed` and `*_seed` fields. What is written, per experiment with recognition curves (one
//! [`PlotKind::Accuracy`] plot of its main table), in `<out>/<experiment>/`:
//!
//! | file | what |
//! |---|---|
//! | `<experiment>.csv` | every run's accuracy rows, in the order the runs were given (each row names its seed) |
//! | `<experiment>_pooled.csv` | one row per curve and number of readings ([`PooledRow`]) |
//! | `<experiment>_by_seed.csv` | one row per curve, seed and number of readings ([`BySeedRow`]) |
//! | `<experiment>_reliability.csv` | the reliability table of each curve, every seed's predictions summed ([`ReliabilityRow`]), when the runs have one |
//! | `<stem>.svg`, `.png` | the experiment's plots over every seed: accuracy with the interval as band, reliability diagrams, and line plots of the main table's own columns (their mean over every seed's rows) |
//! | `pool.json` | the runs and seeds pooled, the resampling, the reference compared with (`--against`, when this experiment's curves were), and the configuration they share |
//!
//! With `--against`, each curve is also compared with a reference curve, seed by seed
//! ([`super::reference`]: `<experiment>_differences.csv`).
//!
//! Experiments without recognition curves (`convergence`) are reported as skipped; picture folders
//! (`exploration`, Fig. 1's run) hold no manifest and are not experiments here.

mod read;
mod write;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;

use self::read::{Curves, experiments, pool_reliability, read_runs, shared_manifest};
pub use self::write::{BySeedRow, PooledRow};
use super::accuracy::ReliabilityRow;
use super::assemble::concatenate;
use super::error::ExperimentError;
use super::layout::ExperimentDir;
use super::name::{ExperimentName, SafeName};
use super::plot::{PlotKind, PlotSpec};
use super::reference::{Compared, Comparison, ReferenceLevels, against};
use super::resample::{INTERVAL_LEVEL, RESAMPLE_SEED, RESAMPLES, resamples};
use super::spec::Manifest;

/// What the bands of a pooled accuracy plot are.
pub const INTERVAL_BAND_LABEL: &str = "band: 90% interval, seeds resampled";

/// One experiment pooled.
#[derive(Debug, Clone, PartialEq)]
pub struct PooledExperiment {
    pub name: ExperimentName,
    /// The runs' seeds, in the order the runs were given.
    pub seeds: Vec<u64>,
    /// Every file written, tables first.
    pub files: Vec<PathBuf>,
    /// Each curve of the pooled reliability diagrams, named with its pooled ECE.
    pub calibration: Vec<String>,
    /// With a reference curve: each curve compared with it, or why none was.
    pub compared: Option<Result<Vec<Comparison>, String>>,
}

/// What a pool produced.
#[derive(Debug, Clone, PartialEq)]
pub struct PoolReport {
    pub pooled: Vec<PooledExperiment>,
    /// Experiments found in every run but not pooled, with the reason.
    pub skipped: Vec<(ExperimentName, String)>,
}

/// `pool.json`: what was pooled and how.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoolRecord {
    pub experiment: ExperimentName,
    /// Each run's experiment directory and seed, in the order given.
    pub runs: Vec<PooledRun>,
    pub resamples: usize,
    pub interval_level: f64,
    pub resample_seed: u64,
    /// The reference curve the others were compared with (`--against`), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub against: Option<String>,
    /// The configuration every run shares: the first run's `config.json` without its seeds.
    pub config: Value,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PooledRun {
    pub dir: PathBuf,
    pub seed: u64,
}

/// Pools the runs `inputs` into `out`, experiment by experiment: each input the output root of
/// one finished run (its `--out`) or one experiment's folder in it (`results/active`). Every input
/// must hold the same experiments. With `reference`, every curve is also compared with its
/// reference curve; at least one experiment must have curves to compare.
pub fn pool(
    inputs: &[PathBuf],
    out: &Path,
    reference: Option<&ReferenceLevels>,
) -> Result<PoolReport, ExperimentError> {
    if inputs.len() < 2 {
        return Err(ExperimentError::PoolNeedsSeeds { given: inputs.len() });
    }
    let found = experiments(inputs)?;
    let names: Vec<&ExperimentName> = found[0].iter().map(ExperimentDir::name).collect();
    let mut report = PoolReport {
        pooled: Vec::new(),
        skipped: Vec::new(),
    };
    let mut prepared = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let runs: Vec<&ExperimentDir> = found.iter().map(|dirs| &dirs[i]).collect();
        match prepare(&runs, out, reference)? {
            Ok(experiment) => prepared.push(experiment),
            Err(why) => report.skipped.push(((*name).clone(), why)),
        }
    }
    if let Some(reference) = reference
        && !prepared.is_empty()
        && !prepared.iter().any(|p| matches!(p.compared, Some(Ok(_))))
    {
        let why = prepared
            .iter()
            .filter_map(|p| match &p.compared {
                Some(Err(why)) => Some(format!("{}: {why}", p.name)),
                _ => None,
            })
            .collect();
        return Err(ExperimentError::NothingAgainst {
            reference: reference.to_string(),
            why,
        });
    }
    for experiment in prepared {
        report.pooled.push(write::write(experiment, out)?);
    }
    Ok(report)
}

/// One experiment read, checked and pooled, with nothing written yet: every run's files are read
/// and checked before any output is written.
struct Prepared {
    name: ExperimentName,
    target: ExperimentDir,
    manifest: Manifest,
    accuracy_plot: PlotSpec,
    record: PoolRecord,
    /// The union of the runs' accuracy tables.
    union: Vec<u8>,
    pooled: Vec<PooledRow>,
    by_seed: Vec<BySeedRow>,
    /// The summed reliability table's name and rows, when the runs have the table.
    reliability: Option<(SafeName, Vec<ReliabilityRow>)>,
    /// With a reference curve: the curves' differences from it and their reach, or why none.
    compared: Option<Compared>,
}

/// Reads and pools one experiment's `runs`; `Ok(Err(why))` when it has no recognition curves.
fn prepare(
    runs: &[&ExperimentDir],
    out: &Path,
    reference: Option<&ReferenceLevels>,
) -> Result<Result<Prepared, String>, ExperimentError> {
    let name = runs[0].name();
    let manifest = shared_manifest(runs)?;
    let Some(accuracy_plot) = manifest
        .spec
        .plots
        .iter()
        .find(|p| p.kind == PlotKind::Accuracy && p.table.is_none())
        .cloned()
    else {
        return Ok(Err(
            "no recognition curves (no accuracy plot of its main table)".to_string()
        ));
    };
    let target = ExperimentDir::new(out, name);
    if target.manifest().is_file() {
        return Err(ExperimentError::PoolIntoRun {
            dir: target.root().to_path_buf(),
        });
    }
    let read = read_runs(runs)?;
    let runs = read.runs;
    let seeds: Vec<u64> = runs.iter().map(|r| r.seed).collect();
    let sources: Vec<PathBuf> = runs.iter().map(|r| r.dir.csv()).collect();
    let union = concatenate(&sources)?;
    let curves = Curves::of(&runs, &read.extras)?;
    let draws = resamples(runs.len());
    let compared = reference.map(|r| against(&curves.curves.items, r, name.as_str(), &draws));
    let reliability = pool_reliability(&runs, &manifest)?;
    let record = PoolRecord {
        experiment: name.clone(),
        runs: runs
            .iter()
            .map(|r| PooledRun {
                dir: r.dir.root().to_path_buf(),
                seed: r.seed,
            })
            .collect(),
        resamples: RESAMPLES,
        interval_level: INTERVAL_LEVEL,
        resample_seed: RESAMPLE_SEED,
        against: reference
            .filter(|_| matches!(compared, Some(Ok(_))))
            .map(ReferenceLevels::to_string),
        config: read.config,
    };
    Ok(Ok(Prepared {
        name: name.clone(),
        pooled: PooledRow::of_curves(&curves, name, &read.extras, &draws),
        by_seed: BySeedRow::of_curves(&curves, name, &seeds),
        target,
        manifest,
        accuracy_plot,
        record,
        union,
        reliability,
        compared,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recognize::ReliabilityTable;

    /// Writes a finished run of the toy experiment under `root`: its manifest (an accuracy plot
    /// and a reliability table), `config` with `seed`, and the accuracy rows `trials[t][n - 1]`
    /// with an extra column `stopped` equal to the accuracy halved.
    fn write_run(root: &Path, seed: u64, config: &str, trials: &[&[f64]], reliability: Option<&str>) {
        let dir = root.join("toy");
        std::fs::create_dir_all(&dir).unwrap();
        let manifest = r#"{"name":"toy","description":"a toy","plots":[{"stem":"toy","title":"Toy","kind":"accuracy","objects":4},{"stem":"toy-reliability","title":"Calibration","kind":"reliability","objects":null,"table":"reliability"}],"details":["reliability"],"units":["all"]}"#;
        std::fs::write(dir.join("manifest.json"), manifest).unwrap();
        std::fs::write(
            dir.join("config.json"),
            format!(
                r#"{{"seed": {seed}, "training": {{"seed": {}}}, {config}}}"#,
                seed * 7919
            ),
        )
        .unwrap();
        let mut csv = String::from(
            "experiment,descriptor,noise_fraction,trial,n_readings,accuracy,reliability,seed,stream_seed,stopped\n",
        );
        for (t, points) in trials.iter().enumerate() {
            for (i, a) in points.iter().enumerate() {
                csv += &format!(
                    "toy,mnti,0.1,{t},{},{a},{},{seed},-5,{}\n",
                    i + 1,
                    a / 2.0,
                    a / 2.0
                );
            }
        }
        std::fs::write(dir.join("toy.csv"), csv).unwrap();
        if let Some(rows) = reliability {
            let header = "experiment,descriptor,noise_fraction,bin,confidence_low,confidence_high,count,mean_confidence,accuracy,ece\n";
            std::fs::write(dir.join("toy_reliability.csv"), format!("{header}{rows}")).unwrap();
        }
    }

    /// One bin of a toy reliability table, the other nine empty.
    fn reliability(bin: u32, count: u64, mean_confidence: f64, accuracy: f64) -> String {
        (0..10)
            .map(|b| {
                let (low, high) = ReliabilityTable::bounds(b);
                if b == bin as usize {
                    format!("toy,mnti,0.1,{b},{low:?},{high:?},{count},{mean_confidence},{accuracy},0.1\n")
                } else {
                    format!("toy,mnti,0.1,{b},{low:?},{high:?},0,,,0.1\n")
                }
            })
            .collect()
    }

    const SCALE: &str = r#""scale": 1.0"#;

    fn two_runs(root: &Path) -> Vec<PathBuf> {
        let (a, b) = (root.join("a"), root.join("b"));
        write_run(
            &a,
            1,
            SCALE,
            &[&[0.5, 1.0], &[1.0, 1.0]],
            Some(&reliability(9, 4, 0.95, 0.75)),
        );
        write_run(
            &b,
            2,
            SCALE,
            &[&[0.25, 0.5], &[0.25, 0.5]],
            Some(&reliability(9, 4, 0.95, 1.0)),
        );
        vec![a, b]
    }

    fn rows(path: &Path) -> Vec<csv::StringRecord> {
        csv::Reader::from_path(path)
            .unwrap()
            .records()
            .map(Result::unwrap)
            .collect()
    }

    #[test]
    fn pooled_curves_average_every_trial_of_every_seed_with_an_interval_between_the_seeds() {
        let root = tempfile::tempdir().unwrap();
        let runs = two_runs(root.path());
        let out = root.path().join("pooled");
        let report = pool(&runs, &out, None).unwrap();
        assert_eq!(report.pooled.len(), 1);
        assert_eq!(report.pooled[0].seeds, vec![1, 2]);
        let pooled = rows(&out.join("toy/toy_pooled.csv"));
        // experiment,descriptor,noise_fraction,n_readings,seeds,trials,accuracy,low,high,reliability,stopped
        let first: Vec<&str> = pooled[0].iter().collect();
        assert_eq!(&first[..6], ["toy", "mnti", "0.1", "1", "2", "4"]);
        let number = |r: &csv::StringRecord, i: usize| r[i].parse::<f64>().unwrap();
        // (0.5 + 1 + 0.25 + 0.25) / 4; seed 1's mean 0.75, seed 2's 0.25.
        assert_eq!(number(&pooled[0], 6), 0.5);
        let (low, high) = (number(&pooled[0], 7), number(&pooled[0], 8));
        assert!(
            (0.25..0.5).contains(&low) && high > 0.5 && high <= 0.75,
            "{low} {high}"
        );
        assert_eq!(number(&pooled[0], 9), 0.25);
        assert_eq!(number(&pooled[0], 10), 0.25);
        // n = 2: (1 + 1 + 0.5 + 0.5) / 4
        assert_eq!(number(&pooled[1], 6), 0.75);
        let by_seed = rows(&out.join("toy/toy_by_seed.csv"));
        let means: Vec<(String, f64)> = by_seed.iter().map(|r| (r[3].to_string(), number(r, 6))).collect();
        assert_eq!(
            means,
            [
                ("1".into(), 0.75),
                ("1".into(), 1.0),
                ("2".into(), 0.25),
                ("2".into(), 0.5)
            ]
        );
        // Every seed's rows, as they were.
        let union = std::fs::read_to_string(out.join("toy/toy.csv")).unwrap();
        assert_eq!(union.lines().count(), 1 + 4 + 4);
        assert!(out.join("toy/toy.svg").is_file() && out.join("toy/toy-reliability.png").is_file());
        let record: PoolRecord =
            serde_json::from_slice(&std::fs::read(out.join("toy/pool.json")).unwrap()).unwrap();
        assert_eq!(record.runs.iter().map(|r| r.seed).collect::<Vec<_>>(), [1, 2]);
        assert_eq!(record.config, serde_json::json!({"scale": 1.0, "training": {}}));
    }

    #[test]
    fn the_same_runs_pool_to_the_same_bytes() {
        let root = tempfile::tempdir().unwrap();
        let runs = two_runs(root.path());
        let (one, two) = (root.path().join("one"), root.path().join("two"));
        pool(&runs, &one, None).unwrap();
        pool(&runs, &two, None).unwrap();
        for file in [
            "toy.csv",
            "toy_pooled.csv",
            "toy_by_seed.csv",
            "toy_reliability.csv",
            "toy.svg",
        ] {
            assert_eq!(
                std::fs::read(one.join("toy").join(file)).unwrap(),
                std::fs::read(two.join("toy").join(file)).unwrap(),
                "{file}"
            );
        }
    }

    #[test]
    fn reliability_tables_sum_their_predictions() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("pooled");
        let report = pool(&two_runs(root.path()), &out, None).unwrap();
        let pooled = rows(&out.join("toy/toy_reliability.csv"));
        assert_eq!(pooled.len(), 10);
        // Eight predictions at mean confidence 0.95, seven right: ECE |7/8 - 0.95| = 0.075.
        assert_eq!(&pooled[9][6], "8");
        assert_eq!(pooled[9][8].parse::<f64>().unwrap(), 0.875);
        let ece: f64 = pooled[9][9].parse().unwrap();
        assert!((ece - 0.075).abs() < 1e-12, "{ece}");
        assert!(
            report.pooled[0].calibration[0].contains("ECE 0.075"),
            "{:?}",
            report.pooled[0].calibration
        );
    }

    #[test]
    fn runs_that_differ_in_more_than_their_seeds_are_refused_naming_the_field() {
        let root = tempfile::tempdir().unwrap();
        let (a, b) = (root.path().join("a"), root.path().join("b"));
        write_run(&a, 1, SCALE, &[&[0.5]], None);
        write_run(&b, 2, r#""scale": 0.3"#, &[&[0.5]], None);
        let e = pool(&[a.clone(), b], &root.path().join("out"), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("/scale: 1.0 vs 0.3"), "{e}");
        let c = root.path().join("c");
        write_run(&c, 1, SCALE, &[&[0.25]], None);
        let e = pool(&[a, c], &root.path().join("out"), None).unwrap_err();
        assert!(matches!(e, ExperimentError::RepeatedSeed { seed: 1, .. }), "{e}");
    }

    #[test]
    fn one_run_an_unfinished_run_or_a_missing_experiment_is_refused() {
        let root = tempfile::tempdir().unwrap();
        let runs = two_runs(root.path());
        let out = root.path().join("out");
        assert!(matches!(
            pool(&runs[..1], &out, None),
            Err(ExperimentError::PoolNeedsSeeds { given: 1 })
        ));
        std::fs::remove_file(runs[1].join("toy/toy.csv")).unwrap();
        assert!(matches!(
            pool(&runs, &out, None),
            Err(ExperimentError::NotFinished { .. })
        ));
        let empty = root.path().join("empty");
        std::fs::create_dir_all(&empty).unwrap();
        assert!(matches!(
            pool(&[runs[0].clone(), empty], &out, None),
            Err(ExperimentError::NoExperiments { .. })
        ));
    }

    #[test]
    fn a_run_with_an_accuracy_outside_0_1_is_refused_naming_its_line() {
        let root = tempfile::tempdir().unwrap();
        let runs = two_runs(root.path());
        let csv = runs[1].join("toy/toy.csv");
        let text = std::fs::read_to_string(&csv)
            .unwrap()
            .replace(",0.25,0.125,2,", ",NaN,0.125,2,");
        std::fs::write(&csv, text).unwrap();
        let e = pool(&runs, &root.path().join("out"), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("toy.csv") && e.contains("line 2: accuracy NaN"), "{e}");
    }

    #[test]
    fn pooled_files_never_go_into_a_run_given_or_not() {
        let root = tempfile::tempdir().unwrap();
        let runs = two_runs(root.path());
        let third = root.path().join("c");
        write_run(&third, 3, SCALE, &[&[0.5, 0.5]], None);
        let before = std::fs::read(runs[0].join("toy/toy.csv")).unwrap();
        let folders: Vec<PathBuf> = runs.iter().map(|r| r.join("toy")).collect();
        for out in [&runs[0], &runs[1], &third] {
            let e = pool(&folders, out, None).unwrap_err();
            assert!(matches!(e, ExperimentError::PoolIntoRun { .. }), "{e}");
        }
        assert_eq!(std::fs::read(runs[0].join("toy/toy.csv")).unwrap(), before);
        assert!(!third.join("toy/toy_pooled.csv").exists());
    }

    /// Pools `runs` into a fresh folder; the error's text, after checking nothing was written.
    fn refused(runs: &[PathBuf], root: &Path) -> String {
        let out = root.join("refused");
        let e = pool(runs, &out, None).unwrap_err().to_string();
        assert!(
            !out.join("toy").exists(),
            "nothing written before the refusal: {e}"
        );
        e
    }

    #[test]
    fn broken_rows_are_refused_naming_file_and_line_before_anything_is_written() {
        let root = tempfile::tempdir().unwrap();
        let runs = two_runs(root.path());
        let csv = runs[1].join("toy/toy.csv");
        let good = std::fs::read_to_string(&csv).unwrap();
        for (broken, want) in [
            (
                good.replace(",0,1,0.25,", ",0,0,0.25,"),
                "line 2: n_readings must be at least 1",
            ),
            (
                good.replace(",0.1,1,1,0.25,", ",0.1,0,1,0.25,"),
                "trial 0 at 1 readings is given twice",
            ),
        ] {
            std::fs::write(&csv, broken).unwrap();
            let e = refused(&runs, root.path());
            assert!(e.contains("toy.csv") && e.contains(want), "{e}");
        }
        std::fs::write(&csv, good).unwrap();
        let table = runs[1].join("toy/toy_reliability.csv");
        let good = std::fs::read_to_string(&table).unwrap();
        let header = good.lines().next().unwrap();
        let twice = good.replace("toy,mnti,0.1,1,", "toy,mnti,0.1,0,");
        let empty = good.replace("0.95,1,0.1", ",,0.1");
        let other = format!(
            "{header}\n{}",
            reliability(9, 4, 0.95, 1.0).replace("toy,mnti,", "toy,sift,")
        );
        for (broken, want) in [
            (twice, "bin 0 of this curve is given twice"),
            (empty, "mean_confidence is empty in a bin of 4 predictions"),
            (other, "different curves"),
        ] {
            std::fs::write(&table, broken).unwrap();
            let e = refused(&runs, root.path());
            assert!(e.contains(want), "{e}");
        }
    }

    #[test]
    fn manifests_that_differ_are_refused_naming_the_field_and_folders_must_carry_their_name() {
        let root = tempfile::tempdir().unwrap();
        let runs = two_runs(root.path());
        let manifest = runs[1].join("toy/manifest.json");
        let text = std::fs::read_to_string(&manifest).unwrap();
        std::fs::write(&manifest, text.replace("a toy", "another toy")).unwrap();
        let e = refused(&runs, root.path());
        assert!(e.contains("manifest.json /description"), "{e}");
        std::fs::write(&manifest, text).unwrap();
        let renamed = root.path().join("toy-seed-2");
        std::fs::rename(runs[1].join("toy"), &renamed).unwrap();
        let e = refused(&[runs[0].join("toy"), renamed], root.path());
        assert!(
            e.contains("names experiment 'toy', but its folder is not named so"),
            "{e}"
        );
    }

    #[test]
    fn an_experiment_folder_pools_as_its_output_root_does() {
        let root = tempfile::tempdir().unwrap();
        let runs = two_runs(root.path());
        let folders: Vec<PathBuf> = runs.iter().map(|r| r.join("toy")).collect();
        let (by_root, by_folder) = (root.path().join("r"), root.path().join("f"));
        pool(&runs, &by_root, None).unwrap();
        pool(&folders, &by_folder, None).unwrap();
        assert_eq!(
            std::fs::read(by_root.join("toy/toy_pooled.csv")).unwrap(),
            std::fs::read(by_folder.join("toy/toy_pooled.csv")).unwrap()
        );
    }
}
