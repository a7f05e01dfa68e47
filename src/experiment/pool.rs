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

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::accuracy::{AccuracyRow, ReliabilityRow};
use super::assemble::concatenate;
use super::error::ExperimentError;
use super::factor::Factors;
use super::files::{create_dir_all, read_json};
use super::layout::{ExperimentDir, experiments_in};
use super::name::{ExperimentName, SafeName};
use super::plot::{
    Ordered, PlotKind, PlotSpec, SummarisedCurve, calibration_labels, csv_error, render_plot,
    summarised_accuracy_figure,
};
use super::reference::{Compared, Comparison, ReferenceLevels, against};
use super::resample::{
    CurveKey, INTERVAL_LEVEL, PointSums, RESAMPLE_SEED, RESAMPLES, SeedSums, interval, pooled_accuracy,
    resamples,
};
use super::spec::{Manifest, to_json};
use super::tidy::{Cells, tidy_row};
use super::unit::DetailRow;
use crate::atomic::{remove_if_present, remove_stale_temporaries, write_if_changed};
use crate::recognize::{CONFIDENCE_BINS, ReliabilityBin, ReliabilityTable};

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

tidy_row! {
    /// One point of one curve over every seed.
    ///
    /// | column | meaning |
    /// |---|---|
    /// | `experiment`, `descriptor`, factor columns, `n_readings` | as in [`AccuracyRow`] |
    /// | `seeds` | runs pooled at this point |
    /// | `trials` | trials pooled (every seed's) |
    /// | `accuracy` | the mean of every trial's accuracy, all seeds together |
    /// | `accuracy_low`, `accuracy_high` | the [`INTERVAL_LEVEL`] percentile interval of that mean over [`RESAMPLES`] resamples of whole seeds (with replacement, each resample as many seeds as were given) |
    /// | `reliability` | the mean of every trial's reliability |
    /// | the experiment's own columns | each the mean of that column over every trial (`active`: the share of objects stopped, and stopped right, by each threshold) |
    #[derive(Debug, Clone, PartialEq)]
    pub struct PooledRow {
        pub experiment: String,
        pub descriptor: String,
        #[factors]
        pub factors: Factors,
        pub n_readings: u32,
        pub seeds: usize,
        pub trials: usize,
        pub accuracy: f64,
        pub accuracy_low: f64,
        pub accuracy_high: f64,
        pub reliability: f64,
        #[columns_named_at_run_time]
        pub extras: Vec<(String, f64)>,
    }
}

tidy_row! {
    /// One point of one curve of one seed: its trials' mean.
    ///
    /// | column | meaning |
    /// |---|---|
    /// | `experiment`, `descriptor`, factor columns | as in [`AccuracyRow`] |
    /// | `seed` | the run's seed |
    /// | `n_readings` | as in [`AccuracyRow`] |
    /// | `trials` | the run's trials at this point |
    /// | `accuracy`, `reliability` | the mean over those trials |
    #[derive(Debug, Clone, PartialEq)]
    pub struct BySeedRow {
        pub experiment: String,
        pub descriptor: String,
        #[factors]
        pub factors: Factors,
        pub seed: u64,
        pub n_readings: u32,
        pub trials: usize,
        pub accuracy: f64,
        pub reliability: f64,
    }
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
    let mut found: Vec<Vec<ExperimentDir>> = Vec::new();
    for input in inputs {
        let dirs = experiment_dirs(input)?;
        if dirs.is_empty() {
            return Err(ExperimentError::NoExperiments { dir: input.clone() });
        }
        found.push(dirs);
    }
    let names: Vec<&ExperimentName> = found[0].iter().map(ExperimentDir::name).collect();
    for (input, dirs) in inputs.iter().zip(&found).skip(1) {
        let here: Vec<&ExperimentName> = dirs.iter().map(ExperimentDir::name).collect();
        if let Some(missing) = names.iter().find(|n| !here.contains(n)) {
            return Err(not_in_both(missing, &inputs[0], input));
        }
        if let Some(extra) = here.iter().find(|n| !names.contains(n)) {
            return Err(not_in_both(extra, input, &inputs[0]));
        }
    }
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
        report.pooled.push(write(experiment, out)?);
    }
    Ok(report)
}

/// The experiments of `input`: the one it is (a folder holding `manifest.json`, such as
/// `results/active`), or those of the output root it is. An experiment's folder must carry its
/// experiment's name, as a run writes it: its tables are named after the experiment.
fn experiment_dirs(input: &Path) -> Result<Vec<ExperimentDir>, ExperimentError> {
    let manifest = input.join("manifest.json");
    if !manifest.is_file() {
        return experiments_in(input);
    }
    let name = Manifest::read(&manifest)?.spec.name;
    let folder = input.canonicalize().map_err(ExperimentError::io(input))?;
    let parent = folder.parent().unwrap_or(&folder);
    if folder.file_name().and_then(|n| n.to_str()) != Some(name.as_str()) {
        return Err(ExperimentError::Json {
            path: manifest,
            what: format!(
                "names experiment '{name}', but its folder is not named so; give the folder its \
                 experiment's name or pool its output root"
            ),
        });
    }
    Ok(vec![ExperimentDir::new(parent, &name)])
}

fn not_in_both(name: &ExperimentName, has: &Path, lacks: &Path) -> ExperimentError {
    ExperimentError::SeedRunMismatch {
        experiment: name.to_string(),
        first: has.to_path_buf(),
        second: lacks.to_path_buf(),
        what: "the first holds it, the second does not".to_string(),
    }
}

/// One run of the experiment: its directory, seed, and assembled accuracy rows with the
/// experiment's own columns.
struct SeedRun<'a> {
    dir: &'a ExperimentDir,
    seed: u64,
    rows: Vec<(AccuracyRow, Vec<f64>)>,
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
    let first = runs[0];
    let name = first.name();
    let manifest_json: Value = read_json(&first.manifest())?;
    for other in &runs[1..] {
        if let Some(what) = first_difference(&manifest_json, &read_json::<Value>(&other.manifest())?, "") {
            return Err(mismatch(name, first, other, format!("manifest.json {what}")));
        }
    }
    let manifest = Manifest::read(&first.manifest())?;
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
    let (config, seeds) = shared_config(runs)?;
    let columns = shared_columns(runs)?;
    let extras: Vec<String> = match columns.iter().position(|c| c == "stream_seed") {
        Some(last) => columns[last + 1..].to_vec(),
        None => Vec::new(),
    };
    let runs: Vec<SeedRun> = runs
        .iter()
        .zip(&seeds)
        .map(|(&dir, &seed)| read_run(dir, seed, &extras))
        .collect::<Result<_, _>>()?;
    let sources: Vec<PathBuf> = runs.iter().map(|r| r.dir.csv()).collect();
    let union = concatenate(&sources)?;
    let curves = Curves::of(&runs, &extras)?;
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
        config,
    };
    Ok(Ok(Prepared {
        name: name.clone(),
        pooled: curves.pooled(name, &extras, &draws),
        by_seed: curves.by_seed(name, &seeds),
        target,
        manifest,
        accuracy_plot,
        record,
        union,
        reliability,
        compared,
    }))
}

/// Writes a prepared experiment's tables, plots and `pool.json`.
fn write(prepared: Prepared, out: &Path) -> Result<PooledExperiment, ExperimentError> {
    let Prepared {
        name,
        target,
        manifest,
        accuracy_plot,
        record,
        union,
        pooled,
        by_seed,
        reliability,
        compared,
    } = prepared;
    for folder in [out, target.root()] {
        create_dir_all(folder)?;
        remove_stale_temporaries(folder)?;
    }
    let union_csv = target.csv();
    write_if_changed(&union_csv, &union)?;
    let pooled_csv = target.root().join(format!("{name}_pooled.csv"));
    write_if_changed(&pooled_csv, &csv_bytes(&pooled, &pooled_csv)?)?;
    let by_seed_csv = target.root().join(format!("{name}_by_seed.csv"));
    write_if_changed(&by_seed_csv, &csv_bytes(&by_seed, &by_seed_csv)?)?;
    let mut files = vec![union_csv.clone(), pooled_csv.clone(), by_seed_csv];
    let differences_csv = target.root().join(format!("{name}_differences.csv"));
    let compared = match compared {
        Some(Ok((differences, comparisons))) => {
            write_if_changed(&differences_csv, &csv_bytes(&differences, &differences_csv)?)?;
            files.push(differences_csv);
            Some(Ok(comparisons))
        }
        // An earlier pool's differences would stand beside this pool's tables as if they were its.
        not_compared => {
            remove_if_present(&differences_csv)?;
            not_compared.map(|c| c.map(|(_, comparisons)| comparisons))
        }
    };
    let reliability_csv = match &reliability {
        Some((table, rows)) => {
            let path = target.detail_csv(table);
            write_if_changed(&path, &csv_bytes(rows, &path)?)?;
            files.push(path.clone());
            Some(path)
        }
        None => None,
    };

    let tables = PooledTables {
        union: &union_csv,
        pooled: &pooled_csv,
        pooled_rows: &pooled,
        reliability: reliability_csv.as_deref(),
    };
    let plots = PooledPlots {
        specs: &manifest.spec.plots,
        accuracy: &accuracy_plot,
        seeds: record.runs.len(),
    };
    let (plot_files, calibration) = write_pooled_plots(&plots, &tables, &target)?;
    files.extend(plot_files);

    let record_path = target.root().join("pool.json");
    write_if_changed(&record_path, &to_json(&record, &record_path)?)?;
    files.push(record_path);
    Ok(PooledExperiment {
        name,
        seeds: record.runs.iter().map(|r| r.seed).collect(),
        files,
        calibration,
        compared,
    })
}

/// The pooled tables a plot may read.
struct PooledTables<'a> {
    union: &'a Path,
    pooled: &'a Path,
    pooled_rows: &'a [PooledRow],
    reliability: Option<&'a Path>,
}

/// The experiment's plots, its accuracy plot among them, over `seeds` pooled runs.
struct PooledPlots<'a> {
    specs: &'a [PlotSpec],
    accuracy: &'a PlotSpec,
    seeds: usize,
}

/// Draws every plot that reads a pooled table (the accuracy plot with the seeds' interval as a
/// band); returns the files written and each reliability curve's label with its pooled ECE.
fn write_pooled_plots(
    plots: &PooledPlots<'_>,
    tables: &PooledTables<'_>,
    target: &ExperimentDir,
) -> Result<(Vec<PathBuf>, Vec<String>), ExperimentError> {
    let mut files = Vec::new();
    let mut calibration = Vec::new();
    for spec in plots.specs {
        let titled = PlotSpec {
            title: format!("{} ({} seeds pooled)", spec.title, plots.seeds),
            ..spec.clone()
        };
        match (&spec.kind, &spec.table) {
            (PlotKind::Accuracy, None) if spec == plots.accuracy => {
                let figure = summarised_accuracy_figure(
                    &titled,
                    tables.pooled,
                    &pooled_curves(tables.pooled_rows),
                    INTERVAL_BAND_LABEL,
                )?;
                let (svg, png) = (target.plot(&spec.stem, "svg"), target.plot(&spec.stem, "png"));
                figure.write_svg(&svg)?;
                figure.write_png(&png)?;
                files.extend([svg, png]);
            }
            (PlotKind::Reliability, Some(_)) => {
                if let Some(table) = tables.reliability {
                    let (figure, paths) = render_plot(&titled, table, target)?;
                    calibration.extend(calibration_labels(&figure));
                    files.extend(paths);
                }
            }
            (PlotKind::Lines { .. }, None) => files.extend(render_plot(&titled, tables.union, target)?.1),
            // Other plots read tables that are not pooled (per-object rows).
            _ => {}
        }
    }
    Ok((files, calibration))
}

fn mismatch(
    name: &ExperimentName,
    first: &ExperimentDir,
    second: &ExperimentDir,
    what: impl Into<String>,
) -> ExperimentError {
    ExperimentError::SeedRunMismatch {
        experiment: name.to_string(),
        first: first.root().to_path_buf(),
        second: second.root().to_path_buf(),
        what: what.into(),
    }
}

/// Whether a configuration field is a seed (the run's `seed`, a derived `training.seed`, a sensor's
/// `noise_seed`): the one thing pooled runs may differ in.
fn is_seed_field(key: &str) -> bool {
    key == "seed" || key.ends_with("_seed")
}

/// `value` without its seed fields, at any depth.
fn without_seeds(value: &Value) -> Value {
    match value {
        Value::Object(map) => Value::Object(
            map.iter()
                .filter(|(k, _)| !is_seed_field(k))
                .map(|(k, v)| (k.clone(), without_seeds(v)))
                .collect(),
        ),
        Value::Array(items) => Value::Array(items.iter().map(without_seeds).collect()),
        other => other.clone(),
    }
}

/// The first place where `a` and `b` differ, as a path of keys and indices with both values.
fn first_difference(a: &Value, b: &Value, at: &str) -> Option<String> {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            keys.into_iter().find_map(|k| {
                let here = format!("{at}/{k}");
                match (x.get(k), y.get(k)) {
                    (Some(u), Some(v)) => first_difference(u, v, &here),
                    (u, v) => Some(format!("{here}: {} vs {}", shown(u), shown(v))),
                }
            })
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (u, v))| first_difference(u, v, &format!("{at}/{i}"))),
        _ if a == b => None,
        _ => Some(format!(
            "{}: {} vs {}",
            if at.is_empty() { "/" } else { at },
            shown(Some(a)),
            shown(Some(b))
        )),
    }
}

fn shown(value: Option<&Value>) -> String {
    let text = value.map_or_else(|| "absent".to_string(), Value::to_string);
    match text.char_indices().nth(60) {
        Some((cut, _)) => format!("{}...", &text[..cut]),
        None => text,
    }
}

/// The configuration the runs share (the first's without its seeds) and each run's seed; an error
/// when they differ in more than their seeds or share a seed.
fn shared_config(runs: &[&ExperimentDir]) -> Result<(Value, Vec<u64>), ExperimentError> {
    let name = runs[0].name();
    let mut configs = Vec::new();
    let mut seeds: Vec<u64> = Vec::new();
    for &run in runs {
        let path = run.config();
        let value: Value = read_json(&path)?;
        let seed = value
            .get("seed")
            .and_then(Value::as_u64)
            .ok_or_else(|| ExperimentError::Json {
                path: path.clone(),
                what: "no top-level 'seed' (a run's seed) to tell the pooled runs apart".to_string(),
            })?;
        if let Some(i) = seeds.iter().position(|&s| s == seed) {
            return Err(ExperimentError::RepeatedSeed {
                experiment: name.to_string(),
                seed,
                first: runs[i].root().to_path_buf(),
                second: run.root().to_path_buf(),
            });
        }
        seeds.push(seed);
        configs.push(without_seeds(&value));
    }
    for (run, config) in runs.iter().zip(&configs).skip(1) {
        if let Some(what) = first_difference(&configs[0], config, "") {
            return Err(mismatch(name, runs[0], run, format!("config.json {what}")));
        }
    }
    Ok((configs.swap_remove(0), seeds))
}

/// The header every run's `<experiment>.csv` shares.
fn shared_columns(runs: &[&ExperimentDir]) -> Result<Vec<String>, ExperimentError> {
    let mut columns: Option<Vec<String>> = None;
    for &run in runs {
        let path = run.csv();
        if !path.is_file() {
            return Err(ExperimentError::NotFinished {
                experiment: run.name().to_string(),
                dir: run.root().to_path_buf(),
                csv: path,
            });
        }
        let mut reader = csv::Reader::from_path(&path).map_err(|e| csv_error(&path, e))?;
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| csv_error(&path, e))?
            .iter()
            .map(str::to_string)
            .collect();
        match &columns {
            None => columns = Some(header),
            Some(first) if *first != header => {
                return Err(mismatch(
                    run.name(),
                    runs[0],
                    run,
                    format!(
                        "the columns of {}.csv differ ('{}' vs '{}')",
                        run.name(),
                        first.join(","),
                        header.join(",")
                    ),
                ));
            }
            Some(_) => {}
        }
    }
    Ok(columns.unwrap_or_default())
}

/// The accuracy rows of one run with its `extras` columns; every row must carry the run's seed.
fn read_run<'a>(
    dir: &'a ExperimentDir,
    seed: u64,
    extras: &[String],
) -> Result<SeedRun<'a>, ExperimentError> {
    let path = dir.csv();
    let mut reader = csv::Reader::from_path(&path).map_err(|e| csv_error(&path, e))?;
    let mut rows = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for (i, record) in reader.deserialize::<Cells>().enumerate() {
        let line = i + 2;
        let at_line = |what: String| csv_error(&path, format!("line {line}: {what}"));
        let record = record.map_err(|e| csv_error(&path, e))?;
        let row = AccuracyRow::from_cells(&record).map_err(at_line)?;
        if row.n_readings == 0 {
            return Err(at_line("n_readings must be at least 1".to_string()));
        }
        if !seen.insert((
            row.descriptor.clone(),
            row.factors.clone(),
            row.trial,
            row.n_readings,
        )) {
            return Err(at_line(format!(
                "{} {} trial {} at {} readings is given twice",
                row.descriptor, row.factors, row.trial, row.n_readings
            )));
        }
        for (column, value) in [("accuracy", row.accuracy), ("reliability", row.reliability)] {
            if !(value.is_finite() && (0.0..=1.0).contains(&value)) {
                return Err(at_line(format!("{column} {value} is not a fraction in [0, 1]")));
            }
        }
        if row.seed != seed {
            return Err(at_line(format!(
                "a row of seed {} in a run whose config.json says seed {seed}",
                row.seed
            )));
        }
        let values = extras
            .iter()
            .map(|column| {
                let value: f64 = record.number(column)?;
                if value.is_finite() {
                    Ok(value)
                } else {
                    Err(format!("column '{column}': {value} is not finite"))
                }
            })
            .collect::<Result<Vec<f64>, String>>()
            .map_err(at_line)?;
        rows.push((row, values));
    }
    if rows.is_empty() {
        return Err(csv_error(&path, "no rows"));
    }
    Ok(SeedRun { dir, seed, rows })
}

/// Every curve (descriptor and factor levels, in order of first appearance) with, per number of
/// readings, each seed's sums in the order the runs were given.
struct Curves {
    curves: Ordered<CurveKey, PointSums>,
}

impl Curves {
    /// Sums every run's rows; every seed must have every point some seed has.
    fn of(runs: &[SeedRun], extras: &[String]) -> Result<Self, ExperimentError> {
        let mut curves: Ordered<CurveKey, PointSums> = Ordered::new();
        let blank = SeedSums {
            extras: vec![0.0; extras.len()],
            ..SeedSums::default()
        };
        for (s, run) in runs.iter().enumerate() {
            for (row, values) in &run.rows {
                let point = curves
                    .entry((row.descriptor.clone(), row.factors.clone()))
                    .entry(row.n_readings)
                    .or_insert_with(|| vec![blank.clone(); runs.len()]);
                let sums = &mut point[s];
                sums.trials += 1;
                sums.accuracy += row.accuracy;
                sums.reliability += row.reliability;
                for (total, value) in sums.extras.iter_mut().zip(values) {
                    *total += value;
                }
            }
        }
        for ((descriptor, factors), points) in &curves.items {
            for (n, sums) in points {
                if let Some(s) = sums.iter().position(|sum| sum.trials == 0) {
                    return Err(csv_error(
                        &runs[s].dir.csv(),
                        format!(
                            "no rows for {descriptor} {factors} at {n} readings, which seed {} has",
                            runs[sums.iter().position(|sum| sum.trials > 0).unwrap_or(0)].seed
                        ),
                    ));
                }
            }
        }
        Ok(Self { curves })
    }

    /// The pooled rows, curve by curve, each point's interval from one shared set of resamples.
    fn pooled(&self, experiment: &ExperimentName, extras: &[String], draws: &[Vec<usize>]) -> Vec<PooledRow> {
        let mut rows = Vec::new();
        for ((descriptor, factors), points) in &self.curves.items {
            for (&n, sums) in points {
                let trials: usize = sums.iter().map(|s| s.trials).sum();
                let mean = |part: fn(&SeedSums) -> f64| sums.iter().map(part).sum::<f64>() / trials as f64;
                let (accuracy_low, accuracy_high) = interval(sums, draws);
                rows.push(PooledRow {
                    experiment: experiment.to_string(),
                    descriptor: descriptor.clone(),
                    factors: factors.clone(),
                    n_readings: n,
                    seeds: sums.len(),
                    trials,
                    accuracy: pooled_accuracy(sums, None),
                    accuracy_low,
                    accuracy_high,
                    reliability: mean(|s| s.reliability),
                    extras: extras
                        .iter()
                        .enumerate()
                        .map(|(e, column)| {
                            let total: f64 = sums.iter().map(|s| s.extras[e]).sum();
                            (column.clone(), total / trials as f64)
                        })
                        .collect(),
                });
            }
        }
        rows
    }

    fn by_seed(&self, experiment: &ExperimentName, seeds: &[u64]) -> Vec<BySeedRow> {
        let mut rows = Vec::new();
        for ((descriptor, factors), points) in &self.curves.items {
            for (s, &seed) in seeds.iter().enumerate() {
                for (&n, sums) in points {
                    let sum = &sums[s];
                    rows.push(BySeedRow {
                        experiment: experiment.to_string(),
                        descriptor: descriptor.clone(),
                        factors: factors.clone(),
                        seed,
                        n_readings: n,
                        trials: sum.trials,
                        accuracy: sum.mean_accuracy(),
                        reliability: sum.reliability / sum.trials as f64,
                    });
                }
            }
        }
        rows
    }
}

/// The curves of the pooled rows, as the accuracy figure draws them.
fn pooled_curves(rows: &[PooledRow]) -> Ordered<CurveKey, SummarisedCurve> {
    let mut curves = Ordered::new();
    for row in rows {
        let curve: &mut SummarisedCurve = curves.entry((row.descriptor.clone(), row.factors.clone()));
        let n = f64::from(row.n_readings);
        curve.points.push((n, row.accuracy));
        curve.band.push((n, row.accuracy_low, row.accuracy_high));
    }
    curves
}

/// The largest bin count read back: far above any experiment's predictions, far below where sums
/// of counts could overflow.
const MAX_BIN_COUNT: u64 = 1 << 40;

/// A curve of a reliability table: experiment, descriptor, factor levels.
type ReliabilityKey = (String, String, Factors);

/// The reliability tables of the runs summed curve by curve, when the manifest has the table
/// (every run must then have assembled it, with the same curves): the table's name and rows.
fn pool_reliability(
    runs: &[SeedRun],
    manifest: &Manifest,
) -> Result<Option<(SafeName, Vec<ReliabilityRow>)>, ExperimentError> {
    let Some(table) = manifest
        .details
        .iter()
        .find(|t| Some(t.as_str()) == ReliabilityRow::TABLE)
    else {
        return Ok(None);
    };
    let mut curves: Ordered<ReliabilityKey, ReliabilityTable> = Ordered::new();
    for (r, run) in runs.iter().enumerate() {
        let path = run.dir.detail_csv(table);
        if !path.is_file() {
            return Err(ExperimentError::NotFinished {
                experiment: run.dir.name().to_string(),
                dir: run.dir.root().to_path_buf(),
                csv: path,
            });
        }
        let tables = read_reliability(&path)?;
        let keys: Vec<&ReliabilityKey> = tables.iter().map(|(k, _)| k).collect();
        let known: Vec<&ReliabilityKey> = curves.items.iter().map(|(k, _)| k).collect();
        if r > 0 && keys != known {
            return Err(mismatch(
                run.dir.name(),
                runs[0].dir,
                run.dir,
                format!("their {} tables hold different curves", table.as_str()),
            ));
        }
        for (key, table) in tables {
            curves.entry(key).merge(&table);
        }
    }
    let rows = curves
        .items
        .iter()
        .flat_map(|((experiment, descriptor, factors), table)| {
            ReliabilityRow::of_table(experiment, descriptor, factors, table)
        })
        .collect();
    Ok(Some((table.clone(), rows)))
}

/// The curves of one run's reliability table, in order, each bin given once, with its count,
/// mean confidence and accuracy read back into sums: the number right exactly (a ratio of integers
/// far below 2^52), the summed confidence to rounding.
fn read_reliability(path: &Path) -> Result<Vec<(ReliabilityKey, ReliabilityTable)>, ExperimentError> {
    let mut reader = csv::Reader::from_path(path).map_err(|e| csv_error(path, e))?;
    let mut curves: Ordered<ReliabilityKey, [Option<ReliabilityBin>; CONFIDENCE_BINS]> = Ordered::new();
    for (i, row) in reader.deserialize::<ReliabilityRow>().enumerate() {
        let row = row.map_err(|e| csv_error(path, e))?;
        let at_line = |what: String| csv_error(path, format!("line {}: {what}", i + 2));
        let b = usize::try_from(row.bin)
            .ok()
            .filter(|&b| b < CONFIDENCE_BINS)
            .ok_or_else(|| at_line(format!("bin {} is not 0-9", row.bin)))?;
        if row.count > MAX_BIN_COUNT {
            return Err(at_line(format!("count {} is beyond {MAX_BIN_COUNT}", row.count)));
        }
        let fraction = |column: &str, value: Option<f64>| match value {
            Some(v) if v.is_finite() && (0.0..=1.0).contains(&v) => Ok(v),
            Some(v) => Err(at_line(format!("{column} {v} is not a fraction in [0, 1]"))),
            None if row.count == 0 => Ok(0.0),
            None => Err(at_line(format!(
                "{column} is empty in a bin of {} predictions",
                row.count
            ))),
        };
        let count = row.count as usize;
        let bin = ReliabilityBin {
            count,
            confidence_sum: fraction("mean_confidence", row.mean_confidence)? * count as f64,
            correct: (fraction("accuracy", row.accuracy)? * count as f64).round() as usize,
        };
        let bins = curves.entry((row.experiment, row.descriptor, row.factors));
        if bins[b].replace(bin).is_some() {
            return Err(at_line(format!("bin {b} of this curve is given twice")));
        }
    }
    curves
        .items
        .into_iter()
        .map(|(key, bins)| {
            let missing = bins.iter().position(Option::is_none);
            match missing {
                Some(b) => Err(csv_error(path, format!("{} {}: no bin {b}", key.1, key.2))),
                None => Ok((
                    key,
                    ReliabilityTable::from_bins(bins.map(Option::unwrap_or_default)),
                )),
            }
        })
        .collect()
}

/// `rows` as CSV with a header; `path` names the destination in errors.
fn csv_bytes<R: Serialize>(rows: &[R], path: &Path) -> Result<Vec<u8>, ExperimentError> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    for row in rows {
        writer.serialize(row).map_err(|e| csv_error(path, e))?;
    }
    writer.into_inner().map_err(|e| csv_error(path, e.error()))
}

#[cfg(test)]
mod tests {
    use super::*;

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
