//! The run framework of the experiments (Sec. V): resumable, parallel, shardable runs writing tidy
//! CSV, plots and an index. The paper's experiments themselves are in `crate::paper`.
//!
//! An experiment is a list of [`Unit`]s, each a stable [`UnitKey`] and a deterministic function
//! producing rows (any serde record; [`AccuracyRow`] for the recognition curves) and, for an
//! experiment with further tables ([`DetailTables`] of [`DetailRow`]s; [`PerObjectRow`] and
//! [`ReliabilityRow`] beside the recognition curves), their rows. [`run`] executes the units of one [`Shard`] on a thread pool, writing each
//! unit's rows atomically to `<out>/<experiment>/units/<key>.csv`, so a killed run resumes where it
//! stopped and never duplicates a row; once every unit is present it assembles `<experiment>.csv`
//! (and `<experiment>_<table>.csv`), draws the
//! experiment's plots and rewrites the index `<out>/README.md`. [`merge()`] combines the outputs of
//! separate shards into exactly the files of one unsharded run; [`pool()`] combines finished runs of
//! different seeds into curves over every seed with an interval that resamples seeds. The on-disk layout is in
//! `layout.rs`.
//!
//! The framework knows nothing of MuJoCo, the paper or recognition beyond the accuracy row it
//! plots: the experiments themselves (`crate::paper`) build the units.

pub(crate) mod accuracy;
pub(crate) mod assemble;
pub(crate) mod error;
pub(crate) mod factor;
pub(crate) mod figure;
pub(crate) mod files;
pub(crate) mod font;
pub(crate) mod index;
pub(crate) mod layout;
pub(crate) mod merge;
pub(crate) mod name;
pub(crate) mod plot;
pub(crate) mod pool;
pub(crate) mod progress;
pub(crate) mod reference;
pub(crate) mod resample;
pub(crate) mod runner;
pub(crate) mod shard;
pub(crate) mod spec;
pub(crate) mod tidy;
pub(crate) mod unit;

// An experiment: named units producing rows, run on a shard, resumed, merged.
pub use error::{ExperimentError, UnitFailure};
pub use factor::{Factor, FactorError, Factors};
pub use merge::{MergeReport, merge};
pub use name::{ExperimentName, KeyBuilder, NameError, SafeName, UnitKey};
pub use pool::{
    BySeedRow, INTERVAL_BAND_LABEL, PoolRecord, PoolReport, PooledExperiment, PooledRow, PooledRun, pool,
};
pub use reference::{Comparison, DifferenceRow, ReferenceLevels};
pub use resample::{INTERVAL_LEVEL, RESAMPLES, TIE_TOLERANCE};
pub use runner::{Experiment, RunOptions, RunReport, check_resumable, run};
pub use shard::{Shard, ShardError};
pub use spec::{ExperimentSpec, Manifest};
pub use unit::{BoxError, DetailRow, DetailTables, NoDetail, Unit};

// Its rows: recognition curves, per-object detail and reliability tables.
pub use accuracy::{AccuracyCurve, AccuracyRow, AttemptRow, PerObjectRow, ReliabilityRow, RepeatedObject};

// Its outputs on disk: the layout, the assembled tables, the index.
pub use assemble::Finished;
pub use index::write_index;
pub use layout::ExperimentDir;

// Plots: the spec of a plot, the figure it builds, its panels and series.
pub use figure::{BAND_LABEL, Figure, Panel, ReferenceLine, Series};
pub use plot::{
    ACCURACY_LABEL, Axis, PERFECT_CALIBRATION, PlotKind, PlotSpec, build_figure, reliability_figure,
};

// Progress of a long collection or exploration, on the terminal.
pub use progress::Progress;
