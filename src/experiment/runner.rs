//! The runner: an experiment's units, resumable, parallel and shardable.

use std::collections::HashSet;
use std::fmt;
use std::num::NonZeroUsize;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;
use serde::Serialize;
use serde::de::DeserializeOwned;

use super::assemble::{Finished, finish, missing_units};
use super::error::{ExperimentError, UnitFailure};
use super::files::create_dir_all;
use super::index::write_index;
use super::layout::ExperimentDir;
use super::name::SafeName;
use super::progress::progress_bar;
use super::shard::Shard;
use super::spec::{ExperimentSpec, Manifest, check_unchanged, to_json, write_manifest, write_or_check};
use super::unit::{DetailTables, NoDetail, Unit, encode_table, read_rows};
use crate::atomic::{remove_stale_temporaries, write_atomic};

/// Where and how to run: the flags every experiment command shares.
#[derive(Debug, Clone, PartialEq, Eq, clap::Args)]
pub struct RunOptions {
    /// Output root; the experiment writes into `<out>/<experiment>/`.
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    /// Worker threads; results do not depend on it. Default: one per core. (The command line's
    /// `--threads` is defined with the other shared flags of the `taction` binary.)
    #[arg(skip)]
    pub threads: Option<NonZeroUsize>,
    /// Run only the k-th of n disjoint slices of the units (`1 <= k <= n`), e.g. `2/3`; combine the
    /// shards' output directories with `taction merge`.
    #[arg(long, default_value = "1/1")]
    pub shard: Shard,
}

impl RunOptions {
    /// The whole experiment into `out`, one thread per core.
    pub fn new(out: impl Into<PathBuf>) -> Self {
        Self {
            out: out.into(),
            threads: None,
            shard: Shard::WHOLE,
        }
    }

    fn thread_count(&self) -> usize {
        self.threads
            .or_else(|| std::thread::available_parallelism().ok())
            .map_or(1, NonZeroUsize::get)
    }
}

/// An experiment ready to run: what it is, its full configuration (written to `config.json`; it
/// should hold everything the rows depend on, such as the seed, and nothing they do not, such as
/// the thread count) and its units in their fixed order. `D` is its further tables, if it has any
/// ([`DetailTables`]: a [`super::unit::DetailRow`], or a pair of them).
pub struct Experiment<'a, R, C, D: DetailTables = NoDetail> {
    pub spec: ExperimentSpec,
    pub config: C,
    pub units: Vec<Unit<'a, R, D>>,
}

/// What a run did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunReport {
    pub dir: PathBuf,
    pub shard: Shard,
    /// Units in the whole experiment.
    pub total: usize,
    /// Units in this shard.
    pub in_shard: usize,
    /// Units of this shard found complete on disk and not rerun.
    pub reused: usize,
    /// Units run now.
    pub ran: usize,
    /// Units of the whole experiment still missing (other shards' work, or none).
    pub missing: usize,
    /// The assembled files, once every unit is present.
    pub finished: Option<Finished>,
    /// Wall time of running the pending units on the pool.
    pub units_wall: Duration,
    /// The pending units' own durations, summed over the workers (up to `units_wall` times the
    /// thread count).
    pub units_thread: Duration,
}

impl fmt::Display for RunReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: shard {}: ran {} and reused {} of its {} units; {} of {} units of the experiment done",
            self.dir.display(),
            self.shard,
            self.ran,
            self.reused,
            self.in_shard,
            self.total - self.missing,
            self.total
        )?;
        match &self.finished {
            Some(done) => {
                write!(f, "\nwrote {}", done.csv.display())?;
                for plot in done.details.iter().chain(&done.plots) {
                    write!(f, ", {}", plot.display())?;
                }
                if !done.calibration.is_empty() {
                    write!(f, "\ncalibration (10 bins): {}", done.calibration.join("; "))?;
                }
                for (table, missing) in &done.incomplete {
                    write!(
                        f,
                        "\nno {table} table: {missing} units were saved by a build before it (a run into a fresh folder writes it)"
                    )?;
                }
                Ok(())
            }
            None => write!(
                f,
                "\nrun the other shards, then `taction merge` their output directories"
            ),
        }
    }
}

/// Refuses, as [`run`] will, an output folder whose experiment `name` holds another configuration
/// than `config`. An experiment that prepares data before it runs (collection can take minutes)
/// checks first, so that a folder of another configuration is refused before any of that work.
pub fn check_resumable<C: Serialize>(
    options: &RunOptions,
    name: &SafeName,
    config: &C,
) -> Result<(), ExperimentError> {
    let dir = ExperimentDir::new(&options.out, name);
    check_unchanged(
        &dir.config(),
        &to_json(config, &dir.config())?,
        dir.root(),
        "configuration",
    )?;
    Ok(())
}

/// Runs `experiment` as `options` say.
///
/// 1. Removes temporaries left by killed runs; writes `manifest.json` and `config.json`. A resumed
///    run must have the same units in the same order and the same configuration, or it would mix
///    results; its description and plots may change.
/// 2. Takes this shard's units; a unit whose `units/<key>.csv` exists and reads back as rows of `R`
///    is reused, one that does not read back is an error naming the file. (Its detail file is not
///    required: units saved before their experiment had a detail table are kept as they are, and
///    that table is then not assembled.)
/// 3. Runs the rest on a pool of `--threads` workers, writing each unit's rows atomically as soon
///    as it finishes (its detail tables first), so a run killed at any point loses only the units in
///    flight. After a unit
///    fails no new unit starts; the finished ones are kept and the error names every failed unit.
/// 4. When every unit of the experiment is present (from any shard), assembles the CSV and the
///    plots, then rewrites the index `<out>/README.md`.
pub fn run<R, C, D>(
    experiment: &Experiment<'_, R, C, D>,
    options: &RunOptions,
) -> Result<RunReport, ExperimentError>
where
    R: Serialize + DeserializeOwned,
    C: Serialize,
    D: DetailTables,
{
    let spec = &experiment.spec;
    let units = &experiment.units;
    check_units(spec, units)?;
    let dir = ExperimentDir::new(&options.out, &spec.name);
    let details = D::names()
        .into_iter()
        .map(SafeName::new)
        .collect::<Result<Vec<_>, _>>()?;
    prepare_folders(options, &dir, &details)?;
    let manifest = record_experiment(experiment, &dir, details.clone())?;

    let ShardUnits { in_shard, pending } = pending_in_shard::<R, D>(units, options, &dir)?;
    let reused = in_shard - pending.len();
    let started = Instant::now();
    let Ran { ran, units_thread } = run_pending(&pending, options, &dir, &details, &spec.name.to_string())?;
    let units_wall = started.elapsed();

    let missing = missing_units(&dir, &manifest).len();
    let finished = if missing == 0 {
        Some(finish(&dir, &manifest)?)
    } else {
        None
    };
    write_index(&options.out)?;
    Ok(RunReport {
        dir: dir.root().to_path_buf(),
        shard: options.shard,
        total: units.len(),
        in_shard,
        reused,
        ran,
        missing,
        finished,
        units_wall,
        units_thread,
    })
}

/// An experiment has units, each key once.
fn check_units<R, D: DetailTables>(
    spec: &ExperimentSpec,
    units: &[Unit<'_, R, D>],
) -> Result<(), ExperimentError> {
    if units.is_empty() {
        return Err(ExperimentError::NoUnits {
            experiment: spec.name.to_string(),
        });
    }
    let mut seen = HashSet::new();
    if let Some(dup) = units.iter().find(|u| !seen.insert(u.key())) {
        return Err(ExperimentError::DuplicateUnit {
            experiment: spec.name.to_string(),
            key: dup.key().clone(),
        });
    }
    Ok(())
}

/// Step 1: the folders the run writes into, cleared of temporaries left by killed runs.
fn prepare_folders(
    options: &RunOptions,
    dir: &ExperimentDir,
    details: &[SafeName],
) -> Result<(), ExperimentError> {
    let mut folders = vec![options.out.clone(), dir.root().to_path_buf(), dir.units_dir()];
    folders.extend(details.iter().map(|table| dir.detail_units_dir(table)));
    for folder in &folders {
        create_dir_all(folder)?;
        remove_stale_temporaries(folder)?;
    }
    Ok(())
}

/// Step 1: `manifest.json` and `config.json`, written, or checked against a resumed run's.
fn record_experiment<R, C: Serialize, D: DetailTables>(
    experiment: &Experiment<'_, R, C, D>,
    dir: &ExperimentDir,
    details: Vec<SafeName>,
) -> Result<Manifest, ExperimentError> {
    let manifest = Manifest {
        spec: experiment.spec.clone(),
        details,
        units: experiment.units.iter().map(|u| u.key().clone()).collect(),
    };
    write_manifest(
        &dir.manifest(),
        &manifest,
        &manifest.to_json(&dir.manifest())?,
        dir.root(),
    )?;
    write_or_check(
        &dir.config(),
        &to_json(&experiment.config, &dir.config())?,
        dir.root(),
        "configuration",
    )?;
    Ok(manifest)
}

/// Step 2: this shard's unit count, and those of its units not yet saved (a saved one must read
/// back as rows of `R`).
fn pending_in_shard<'u, 'a, R: DeserializeOwned, D: DetailTables>(
    units: &'u [Unit<'a, R, D>],
    options: &RunOptions,
    dir: &ExperimentDir,
) -> Result<ShardUnits<'u, 'a, R, D>, ExperimentError> {
    let mut in_shard = 0;
    let mut pending = Vec::new();
    for (_, unit) in units
        .iter()
        .enumerate()
        .filter(|(i, _)| options.shard.contains(*i))
    {
        in_shard += 1;
        let path = dir.unit_csv(unit.key());
        if path.exists() {
            read_rows::<R>(&path)?;
        } else {
            pending.push(unit);
        }
    }
    Ok(ShardUnits { in_shard, pending })
}

/// This shard's share of the units: how many it has, and those of them not yet saved.
struct ShardUnits<'u, 'a, R, D: DetailTables> {
    in_shard: usize,
    pending: Vec<&'u Unit<'a, R, D>>,
}

/// Durations of work done on any thread, summed: the runner's units, and the paper's phases
/// (`paper::timing`), which may run on several workers at once.
#[derive(Debug, Default)]
pub(crate) struct SummedTime {
    ns: AtomicU64,
}

impl SummedTime {
    /// Runs `work`, adding its duration on this thread to the sum.
    pub(crate) fn time<T>(&self, work: impl FnOnce() -> T) -> T {
        let started = Instant::now();
        let result = work();
        let ns = u64::try_from(started.elapsed().as_nanos()).unwrap_or(u64::MAX);
        self.ns.fetch_add(ns, Ordering::Relaxed);
        result
    }

    pub(crate) fn total(&self) -> Duration {
        Duration::from_nanos(self.ns.load(Ordering::Relaxed))
    }
}

/// What [`run_pending`] did: the units it ran and their durations summed.
struct Ran {
    ran: usize,
    units_thread: Duration,
}

/// Step 3: the pending units on a pool of `--threads` workers; no unit starts after one failed.
/// The units run now, or the error naming every failed one.
fn run_pending<R, D>(
    pending: &[&Unit<'_, R, D>],
    options: &RunOptions,
    dir: &ExperimentDir,
    details: &[SafeName],
    name: &str,
) -> Result<Ran, ExperimentError>
where
    R: Serialize + DeserializeOwned,
    D: DetailTables,
{
    let threads = options.thread_count();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| ExperimentError::ThreadPool {
            threads,
            what: e.to_string(),
        })?;
    let progress = progress_bar(pending.len(), name, "units");
    let stop = AtomicBool::new(false);
    let units_thread = SummedTime::default();
    let outcomes: Vec<Option<Result<(), UnitFailure>>> = pool.install(|| {
        pending
            .par_iter()
            .map(|unit| {
                if stop.load(Ordering::Relaxed) {
                    return None;
                }
                let outcome = units_thread.time(|| run_unit(unit, dir, details));
                if outcome.is_err() {
                    stop.store(true, Ordering::Relaxed);
                }
                progress.inc(1);
                Some(outcome)
            })
            .collect()
    });
    progress.finish_and_clear();
    let ran = outcomes.iter().filter(|o| matches!(o, Some(Ok(())))).count();
    let failures: Vec<UnitFailure> = outcomes.into_iter().flatten().filter_map(Result::err).collect();
    if !failures.is_empty() {
        return Err(ExperimentError::UnitsFailed { failures });
    }
    Ok(Ran {
        ran,
        units_thread: units_thread.total(),
    })
}

/// Runs one unit and saves its detail tables (when the experiment has any), then its rows, each
/// after checking they read back as they will on resume: a header and every row (so rows must be
/// structs with named fields, not tuples or scalars).
fn run_unit<R: Serialize + DeserializeOwned, D: DetailTables>(
    unit: &Unit<'_, R, D>,
    dir: &ExperimentDir,
    details: &[SafeName],
) -> Result<(), UnitFailure> {
    let fail = |what: String| UnitFailure {
        key: unit.key().clone(),
        what,
    };
    let (rows, detail_rows) = unit.run().map_err(fail)?;
    let paths: Vec<PathBuf> = details
        .iter()
        .map(|table| dir.detail_unit_csv(table, unit.key()))
        .collect();
    let tables = D::encode(&detail_rows, &paths).map_err(fail)?;
    let main = dir.unit_csv(unit.key());
    let main_bytes = encode_table("main", &rows, &main).map_err(fail)?;
    for (path, bytes) in paths.iter().zip(&tables).chain([(&main, &main_bytes)]) {
        write_atomic(path, bytes).map_err(|e| fail(e.to_string()))?;
    }
    Ok(())
}
