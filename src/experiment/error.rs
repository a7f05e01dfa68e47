//! What can go wrong running, merging, assembling and plotting experiments; every variant names the
//! file, directory, unit or column concerned.

use std::path::PathBuf;

use super::name::{NameError, UnitKey};

/// One unit that failed, with its error text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnitFailure {
    pub key: UnitKey,
    pub what: String,
}

/// Errors of the experiment framework.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{}: {what}", path.display())]
    Json { path: PathBuf, what: String },
    #[error(transparent)]
    Name(#[from] NameError),
    #[error("experiment '{experiment}' has no work units")]
    NoUnits { experiment: String },
    #[error("experiment '{experiment}' lists unit '{key}' twice")]
    DuplicateUnit { experiment: String, key: UnitKey },
    #[error(
        "{} was written by an earlier run with different {what}{differing}; resuming would mix results: \
         use another --out or delete {}",
        path.display(),
        dir.display()
    )]
    ChangedSinceLastRun {
        path: PathBuf,
        dir: PathBuf,
        what: &'static str,
        /// ` (fields: a, b.c)`, the JSON fields that differ, when both sides are JSON.
        differing: String,
    },
    #[error("{}: corrupt unit file ({what}); delete it to rerun that unit", path.display())]
    CorruptUnit { path: PathBuf, what: String },
    #[error("{} of the units failed (finished units are saved; a rerun resumes): {}",
        failures.len(),
        failures.iter().map(|f| format!("{}: {}", f.key, f.what)).collect::<Vec<_>>().join("; "))]
    UnitsFailed { failures: Vec<UnitFailure> },
    #[error("cannot start {threads} worker threads: {what}")]
    ThreadPool { threads: usize, what: String },
    #[error("{}: {what}", path.display())]
    Csv { path: PathBuf, what: String },
    #[error("{}: no column '{column}' (columns: {available})", path.display())]
    MissingColumn {
        path: PathBuf,
        column: String,
        available: String,
    },
    #[error("{}: cannot draw the plot: {what}", path.display())]
    Plot { path: PathBuf, what: String },
    #[error(
        "no TrueType font for plot text: set TACTION_FONT to a .ttf file or install fonts-dejavu-core \
         (tried {})",
        tried.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    NoFont { tried: Vec<PathBuf> },
    #[error(
        "experiment '{experiment}': {file} differs between {} and {}; shards of one run must share it",
        first.display(),
        second.display()
    )]
    ShardMismatch {
        experiment: String,
        file: &'static str,
        first: PathBuf,
        second: PathBuf,
    },
    #[error("unit '{key}' differs between {} and {}", first.display(), second.display())]
    UnitConflict {
        key: UnitKey,
        first: PathBuf,
        second: PathBuf,
    },
    #[error(
        "experiment '{experiment}' in {} is incomplete: {missing} of {total} units missing (first: {first_missing})",
        dir.display()
    )]
    Incomplete {
        experiment: String,
        dir: PathBuf,
        missing: usize,
        total: usize,
        first_missing: UnitKey,
    },
    #[error("{}: no experiment output here (no <experiment>/manifest.json)", dir.display())]
    NoExperiments { dir: PathBuf },
    #[error("pooling needs at least two finished runs with different seeds, got {given}")]
    PoolNeedsSeeds { given: usize },
    #[error(
        "experiment '{experiment}' differs between {} and {}: {what}; only runs that differ in their \
         seeds pool",
        first.display(),
        second.display()
    )]
    SeedRunMismatch {
        experiment: String,
        first: PathBuf,
        second: PathBuf,
        what: String,
    },
    #[error(
        "experiment '{experiment}': seed {seed} in both {} and {}; pooled runs need different seeds",
        first.display(),
        second.display()
    )]
    RepeatedSeed {
        experiment: String,
        seed: u64,
        first: PathBuf,
        second: PathBuf,
    },
    #[error(
        "{}: holds an experiment's run (its manifest.json), which the pooled files would overwrite; \
         give another --out",
        dir.display()
    )]
    PoolIntoRun { dir: PathBuf },
    #[error(
        "{}: experiment '{experiment}' is not finished (no {}); finish the run, or merge its shards, \
         before pooling",
        dir.display(),
        csv.display()
    )]
    NotFinished {
        experiment: String,
        dir: PathBuf,
        csv: PathBuf,
    },
    #[error("--against {reference}: no experiment has curves to compare with it ({})", why.join("; "))]
    NothingAgainst { reference: String, why: Vec<String> },
}

impl ExperimentError {
    pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| Self::Io { path, source }
    }
}

impl From<crate::atomic::FileError> for ExperimentError {
    fn from(e: crate::atomic::FileError) -> Self {
        Self::Io {
            path: e.path,
            source: e.source,
        }
    }
}
