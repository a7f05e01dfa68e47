//! Writing a pooled experiment: its tables (the union of the runs' rows, the pooled and by-seed
//! curves, the summed reliability table, the differences from a reference), its plots over every
//! seed and `pool.json`. Everything written here was read and checked first (`read.rs`).

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::read::Curves;
use super::{INTERVAL_BAND_LABEL, PooledExperiment, Prepared};
use crate::atomic::{remove_if_present, remove_stale_temporaries, write_if_changed};
#[cfg(doc)]
use crate::experiment::accuracy::AccuracyRow;
use crate::experiment::error::ExperimentError;
use crate::experiment::files::create_dir_all;
use crate::experiment::layout::ExperimentDir;
use crate::experiment::name::ExperimentName;
use crate::experiment::plot::{
    Ordered, PlotKind, PlotSpec, SummarisedCurve, calibration_labels, csv_error, render_plot,
    summarised_accuracy_figure,
};
use crate::experiment::reference::{Compared, Comparison};
use crate::experiment::resample::{CurveKey, SeedSums, interval, pooled_accuracy};
#[cfg(doc)]
use crate::experiment::resample::{INTERVAL_LEVEL, RESAMPLES};
use crate::experiment::spec::to_json;
use crate::experiment::tidy::tidy_row;

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

impl PooledRow {
    /// The rows of `curves`, curve by curve, each point's interval from one shared set of
    /// resamples, `extras` the experiment's own columns.
    pub(super) fn of_curves(
        curves: &Curves,
        experiment: &ExperimentName,
        extras: &[String],
        draws: &[Vec<usize>],
    ) -> Vec<PooledRow> {
        let mut rows = Vec::new();
        for ((descriptor, factors), points) in &curves.curves.items {
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
}

impl BySeedRow {
    /// The rows of `curves`, curve by curve and seed by seed, `seeds` in the order of the runs.
    pub(super) fn of_curves(curves: &Curves, experiment: &ExperimentName, seeds: &[u64]) -> Vec<BySeedRow> {
        let mut rows = Vec::new();
        for ((descriptor, factors), points) in &curves.curves.items {
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

/// Writes a prepared experiment's tables, plots and `pool.json`.
pub(super) fn write(prepared: Prepared, out: &Path) -> Result<PooledExperiment, ExperimentError> {
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
    let compared = write_differences(&differences_csv, compared, &mut files)?;
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

/// Writes the differences from the reference to `path` when the curves were compared (adding it
/// to `files`), and removes an earlier pool's there when they were not: it would stand beside this
/// pool's tables as if it were theirs. Returns the comparisons, or why there are none.
fn write_differences(
    path: &Path,
    compared: Option<Compared>,
    files: &mut Vec<PathBuf>,
) -> Result<Option<Result<Vec<Comparison>, String>>, ExperimentError> {
    match compared {
        Some(Ok((differences, comparisons))) => {
            write_if_changed(path, &csv_bytes(&differences, path)?)?;
            files.push(path.to_path_buf());
            Ok(Some(Ok(comparisons)))
        }
        not_compared => {
            remove_if_present(path)?;
            Ok(not_compared.map(|c| c.map(|(_, comparisons)| comparisons)))
        }
    }
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

/// `rows` as CSV with a header; `path` names the destination in errors.
fn csv_bytes<R: Serialize>(rows: &[R], path: &Path) -> Result<Vec<u8>, ExperimentError> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    for row in rows {
        writer.serialize(row).map_err(|e| csv_error(path, e))?;
    }
    writer.into_inner().map_err(|e| csv_error(path, e.error()))
}
