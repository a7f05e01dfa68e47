//! Where a run's time goes, experiment by experiment and phase by phase: the table a speed-up
//! is planned from and judged by (`<out>/timings.csv`, printed at the end of `reproduce`).
//!
//! An experiment's wall time splits into its phases as they run:
//!
//! | column | what | clock |
//! |---|---|---|
//! | `datasets_s` | preparing its datasets: collected now (in parallel over objects), or read from `<out>/data` | wall |
//! | `units_s` | running its pending units on the worker pool (training, testing, exploring with a model in the loop) | wall |
//! | `rest_s` | the remainder: loading objects and recordings, assembling the CSV, drawing the plots | wall |
//! | `unit_thread_s` | the units' own durations summed over the workers | thread |
//! | `training_thread_s` | of which fitting models (PCA, codebook grid with restarts, calibration), summed over the workers | thread |
//!
//! Units run in parallel, so the two thread columns can exceed `units_s` (by up to the thread
//! count); `training_thread_s / unit_thread_s` is the share of the unit phase spent fitting. A
//! dataset or model an earlier experiment of the run (or an earlier run) left in the store costs
//! only its reading, which is what the later experiment is charged.

use std::path::Path;
use std::time::Duration;

use serde::Serialize;

use super::PaperOutput;
use crate::experiment::runner::SummedTime;
use crate::experiment::unit::{BoxError, rows_to_csv};

/// The file of a run's per-phase timings, in the output root.
pub const TIMINGS_FILE: &str = "timings.csv";

/// Time spent in the data store's phases, summed since the store was made; shared by every
/// experiment of a run and read before and after each one ([`PhaseClock::snapshot`]).
#[derive(Debug, Default)]
pub struct PhaseClock {
    datasets: SummedTime,
    training: SummedTime,
}

/// The [`PhaseClock`]'s sums at one moment.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PhaseSnapshot {
    datasets: Duration,
    training: Duration,
}

impl PhaseClock {
    /// Runs `work`, charging its wall time to dataset preparation.
    pub fn datasets<T>(&self, work: impl FnOnce() -> T) -> T {
        self.datasets.time(work)
    }

    /// Runs `work`, charging its duration on this thread to model training.
    pub fn training<T>(&self, work: impl FnOnce() -> T) -> T {
        self.training.time(work)
    }

    pub fn snapshot(&self) -> PhaseSnapshot {
        PhaseSnapshot {
            datasets: self.datasets.total(),
            training: self.training.total(),
        }
    }
}

/// One experiment's line of [`TIMINGS_FILE`] (the module's table says what each column is).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PhaseTimes {
    pub experiment: String,
    pub wall_s: f64,
    pub datasets_s: f64,
    pub units_s: f64,
    pub rest_s: f64,
    pub unit_thread_s: f64,
    pub training_thread_s: f64,
}

impl PhaseTimes {
    /// The phases of `experiment`, which took `wall` and produced `output`, from the clock's
    /// snapshots taken just before and just after it.
    pub fn of(
        experiment: &str,
        wall: Duration,
        before: PhaseSnapshot,
        after: PhaseSnapshot,
        output: &PaperOutput,
    ) -> Self {
        let datasets = after.datasets.saturating_sub(before.datasets);
        let (units, unit_thread) = match output {
            PaperOutput::Run(report) => (report.units_wall, report.units_thread),
            PaperOutput::Picture(_) => (Duration::ZERO, Duration::ZERO),
        };
        let rest = wall.saturating_sub(datasets).saturating_sub(units);
        Self {
            experiment: experiment.to_string(),
            wall_s: wall.as_secs_f64(),
            datasets_s: datasets.as_secs_f64(),
            units_s: units.as_secs_f64(),
            rest_s: rest.as_secs_f64(),
            unit_thread_s: unit_thread.as_secs_f64(),
            training_thread_s: after.training.saturating_sub(before.training).as_secs_f64(),
        }
    }
}

/// Writes `rows` to `<out>/timings.csv` (replacing an earlier run's: the file describes the run
/// that wrote it, and an experiment a resumed run found finished costs it nothing).
pub fn write_timings(out: &Path, rows: &[PhaseTimes]) -> Result<(), BoxError> {
    let path = out.join(TIMINGS_FILE);
    let bytes = rows_to_csv(rows, &path)?;
    crate::atomic::write_atomic(&path, &bytes)?;
    Ok(())
}

/// The timings as a Markdown table with a total line (as the headline table), for the end of
/// `reproduce`.
pub fn timings_table(rows: &[PhaseTimes]) -> String {
    let total = PhaseTimes {
        experiment: "total".into(),
        wall_s: rows.iter().map(|r| r.wall_s).sum(),
        datasets_s: rows.iter().map(|r| r.datasets_s).sum(),
        units_s: rows.iter().map(|r| r.units_s).sum(),
        rest_s: rows.iter().map(|r| r.rest_s).sum(),
        unit_thread_s: rows.iter().map(|r| r.unit_thread_s).sum(),
        training_thread_s: rows.iter().map(|r| r.training_thread_s).sum(),
    };
    let mut table = String::from(
        "| experiment | wall s | datasets s | units s | rest s | unit thread-s | training thread-s |\n\
         |---|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows.iter().chain(std::iter::once(&total)) {
        table.push_str(&format!(
            "| {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |\n",
            r.experiment, r.wall_s, r.datasets_s, r.units_s, r.rest_s, r.unit_thread_s, r.training_thread_s
        ));
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clock_charges_each_phase_its_own_work() {
        let clock = PhaseClock::default();
        let before = clock.snapshot();
        let value = clock.training(|| {
            std::thread::sleep(Duration::from_millis(20));
            7
        });
        assert_eq!(value, 7);
        clock.datasets(|| std::thread::sleep(Duration::from_millis(5)));
        let after = clock.snapshot();
        let training = after.training - before.training;
        let datasets = after.datasets - before.datasets;
        assert!(training >= Duration::from_millis(20), "{training:?}");
        assert!(datasets >= Duration::from_millis(5), "{datasets:?}");
        // Neither phase is charged the other's sleep.
        assert!(datasets < training, "{datasets:?} vs {training:?}");
    }

    #[test]
    fn a_picture_has_no_unit_phase_and_the_rest_is_what_phases_leave() {
        let before = PhaseSnapshot::default();
        let after = PhaseSnapshot {
            datasets: Duration::from_secs(3),
            training: Duration::from_secs(1),
        };
        let times = PhaseTimes::of(
            "exploration",
            Duration::from_secs(5),
            before,
            after,
            &PaperOutput::Picture("x.png".into()),
        );
        assert_eq!((times.units_s, times.unit_thread_s), (0.0, 0.0));
        assert_eq!(times.rest_s, 2.0);
        let table = timings_table(&[times.clone(), times]);
        let last = table.lines().last().unwrap_or_default();
        assert_eq!(last, "| total | 10.0 | 6.0 | 0.0 | 4.0 | 0.0 | 2.0 |", "{table}");
    }
}
