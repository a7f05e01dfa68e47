//! Reading and checking the runs to pool: every input's experiments, the files each experiment's
//! runs must share (`manifest.json` byte for byte, `config.json` apart from its seeds, the header of
//! `<experiment>.csv`), every accuracy row and reliability bin checked with its file and line, and
//! the rows summed per curve, point and seed. Nothing here writes: a run refused here leaves the
//! output untouched.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::experiment::accuracy::{AccuracyRow, ReliabilityRow};
use crate::experiment::error::ExperimentError;
use crate::experiment::factor::Factors;
use crate::experiment::files::read_json;
use crate::experiment::layout::{ExperimentDir, experiments_in};
use crate::experiment::name::{ExperimentName, SafeName};
use crate::experiment::plot::{Ordered, csv_error};
use crate::experiment::resample::{CurveKey, PointSums, SeedSums};
use crate::experiment::spec::Manifest;
use crate::experiment::tidy::Cells;
use crate::experiment::unit::DetailRow;
use crate::recognize::{CONFIDENCE_BINS, ReliabilityBin, ReliabilityTable};

/// Every input's experiments, the same in each: `found[input][experiment]`, in the order of the
/// first input's. Each input must hold at least one.
pub(super) fn experiments(inputs: &[PathBuf]) -> Result<Vec<Vec<ExperimentDir>>, ExperimentError> {
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
    Ok(found)
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

/// The manifest the runs share byte for byte (as JSON values), read from the first.
pub(super) fn shared_manifest(runs: &[&ExperimentDir]) -> Result<Manifest, ExperimentError> {
    let first = runs[0];
    let manifest_json: Value = read_json(&first.manifest())?;
    for other in &runs[1..] {
        if let Some(what) = first_difference(&manifest_json, &read_json::<Value>(&other.manifest())?, "") {
            return Err(mismatch(
                first.name(),
                first,
                other,
                format!("manifest.json {what}"),
            ));
        }
    }
    Manifest::read(&first.manifest())
}

/// The runs of one experiment read and checked: the configuration they share, and each run's rows.
pub(super) struct CheckedRuns<'a> {
    /// The first run's `config.json` without its seeds.
    pub(super) config: Value,
    /// The main table's columns after `stream_seed`: the experiment's own (`active`'s stop shares).
    pub(super) extras: Vec<String>,
    pub(super) runs: Vec<SeedRun<'a>>,
}

/// Reads every run of one experiment (see [`CheckedRuns`]); an error when they differ in more
/// than their seeds, share a seed or hold a row that is not a point of a curve of their seed.
pub(super) fn read_runs<'a>(runs: &[&'a ExperimentDir]) -> Result<CheckedRuns<'a>, ExperimentError> {
    let (config, seeds) = shared_config(runs)?;
    let columns = shared_columns(runs)?;
    let extras: Vec<String> = match columns.iter().position(|c| c == "stream_seed") {
        Some(last) => columns[last + 1..].to_vec(),
        None => Vec::new(),
    };
    let runs = runs
        .iter()
        .zip(&seeds)
        .map(|(&dir, &seed)| read_run(dir, seed, &extras))
        .collect::<Result<_, _>>()?;
    Ok(CheckedRuns { config, extras, runs })
}

/// One run of the experiment: its directory, seed, and assembled accuracy rows with the
/// experiment's own columns.
pub(super) struct SeedRun<'a> {
    pub(super) dir: &'a ExperimentDir,
    pub(super) seed: u64,
    pub(super) rows: Vec<(AccuracyRow, Vec<f64>)>,
}

/// Two runs of `name` that may not be pooled, and why.
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
pub(super) struct Curves {
    pub(super) curves: Ordered<CurveKey, PointSums>,
}

impl Curves {
    /// Sums every run's rows; every seed must have every point some seed has.
    pub(super) fn of(runs: &[SeedRun], extras: &[String]) -> Result<Self, ExperimentError> {
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
}

/// The largest bin count read back: far above any experiment's predictions, far below where sums
/// of counts could overflow.
const MAX_BIN_COUNT: u64 = 1 << 40;
/// A curve of a reliability table: experiment, descriptor, factor levels.
type ReliabilityKey = (String, String, Factors);
/// The reliability tables of the runs summed curve by curve, when the manifest has the table
/// (every run must then have assembled it, with the same curves): the table's name and rows.
pub(super) fn pool_reliability(
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
