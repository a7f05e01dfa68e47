//! How long a run of the paper's experiments will take, said before it starts and updated as it
//! goes, so that a user can decide whether a scale fits the afternoon.
//!
//! Each experiment's wall time was measured on the reference machine (2 cores, 2 threads) at
//! scales 0.05, 0.2 and 1.0 (the paper's, the default: about 24 minutes for the sixteen before
//! `free-object`, which adds about 35). Between two
//! measured scales the estimate interpolates in log-log (a power law through both); beyond 1.0 it
//! extends the last segment's power, held in [1, 3] (data collection grows linearly with the scale
//! and codebook fitting faster); below 0.05 it extends the first segment's, held in [0, 1]: at
//! small scales set-up (objects, scenes, one model per descriptor) outweighs the readings, so a run
//! at 0.05 takes about two thirds of one at 0.2 (132 against 205 s), not a quarter. Other thread counts scale it by
//! `2 / threads`. During
//! a run the remaining estimate is multiplied by the ratio of the time spent so far to the time
//! estimated for it, which absorbs a faster or slower machine.

use std::path::Path;

use super::scale::Scale;

/// Estimated seconds of finished work from which the run's pace corrects the rest.
pub const PACE_AFTER_S: f64 = 30.0;

/// Threads of the reference runs.
pub const REFERENCE_THREADS: usize = 2;

/// The scales of the reference timings.
const REFERENCE_SCALES: [f64; 3] = [0.05, 0.2, 1.0];

/// Wall seconds of each experiment at the [`REFERENCE_SCALES`] on the reference machine (seed 1,
/// the built-in sets, each experiment's own codebook; `reproduce` one experiment after another
/// into an empty folder, so datasets shared between experiments were collected by the first one
/// that needed them; docs/benchmarks.md has the runs). The 1.0 column is the run of 2026-12-02
/// (a slow day: the fifteen experiments before `fusion` took 1,134 s, 1,007 s on 2026-11-29), the 0.2 column a run of 2026-11-29, the 0.05 column a run of
/// the same day (`reproduce --scale 0.05`: 132 s in all, where a power law through 0.2 and 1.0 said
/// 45 s); `fusion`'s are its runs with the active curves on 2026-12-03 (0.05 and 0.2 alone, its
/// sampler datasets collected by itself: 36.2 s and 89.7 s; 1.0 in the shipped run, 406.2 s) at
/// 2026-12-02's pace, x 0.72, the ratio of the fifteen other experiments' 1,134 s that day to their
/// 1,576 s in the shipped run.
/// `free-object`'s are its runs alone on 2026-12-05 (every dataset its own, `fusion`'s model
/// data and mocap explorations included; 0.2 beside another run, so slow), an upper bound on its
/// share of `reproduce`, where `fusion` collects those first.
/// A single experiment run on its own also collects the datasets an earlier one would have
/// shared: at small scales it takes longer than its share here.
const REFERENCE_SECONDS: [(&str, [f64; 3]); 17] = [
    ("exploration", [0.7, 0.5, 0.5]),
    ("descriptors", [9.3, 17.7, 88.0]),
    ("strategy", [9.7, 11.2, 34.5]),
    ("validation", [9.0, 11.6, 45.7]),
    ("perturbation", [4.2, 3.6, 19.4]),
    ("thickness", [18.6, 20.9, 110.3]),
    ("resolution", [8.6, 11.7, 76.5]),
    ("noise", [18.1, 21.1, 103.1]),
    ("convergence", [0.4, 0.2, 0.4]),
    ("letters", [13.6, 51.6, 365.0]),
    ("real-frames", [0.4, 0.2, 0.2]),
    ("sim-to-real", [0.4, 0.8, 6.1]),
    ("training-size", [21.0, 35.0, 187.4]),
    ("active", [16.4, 15.3, 69.4]),
    ("end-to-end", [1.5, 3.8, 27.6]),
    ("fusion", [26.1, 64.6, 292.5]),
    ("free-object", [190.4, 879.6, 2246.7]),
];

/// The estimated wall seconds of experiment `name` at `scale` with `threads` threads; `None` for
/// an experiment without a reference timing.
pub fn estimated_seconds(name: &str, scale: Scale, threads: usize) -> Option<f64> {
    let &(_, seconds) = REFERENCE_SECONDS.iter().find(|(n, _)| *n == name)?;
    let at_scale = power_law_through(&REFERENCE_SCALES, &seconds, scale.fraction());
    Some(at_scale * REFERENCE_THREADS as f64 / threads.max(1) as f64)
}

/// `t(s)` through the points `(scales[i], seconds[i])` (scales ascending), a power law between
/// neighbours; outside them the nearest segment's power, held in [0, 1] below and [1, 3] above.
fn power_law_through(scales: &[f64; 3], seconds: &[f64; 3], s: f64) -> f64 {
    let power = |i: usize| (seconds[i + 1] / seconds[i]).ln() / (scales[i + 1] / scales[i]).ln();
    let (i, exponent) = if s < scales[0] {
        (0, power(0).clamp(0.0, 1.0))
    } else if s > scales[2] {
        (2, power(1).clamp(1.0, 3.0))
    } else if s <= scales[1] {
        (0, power(0))
    } else {
        (1, power(1))
    };
    seconds[i] * (s / scales[i]).powf(exponent)
}

/// Whether experiment `name` already finished in `out` (its assembled CSV exists), so that a
/// resumed run spends no time on it.
pub fn already_finished(out: &Path, name: &str) -> bool {
    out.join(name).join(format!("{name}.csv")).is_file()
}

/// One experiment of a run: its estimate, and whether it has finished.
#[derive(Debug, Clone)]
struct Part {
    name: String,
    estimate_s: f64,
    done: bool,
}

/// The estimate of a whole run, kept up to date as its experiments finish.
#[derive(Debug, Clone)]
pub struct RunEstimate {
    parts: Vec<Part>,
    spent_s: f64,
    estimated_spent_s: f64,
}

impl RunEstimate {
    /// The estimate for `names` at `scale` with `threads`, counting experiments finished in `out`
    /// as free.
    pub fn new(names: &[&str], scale: Scale, threads: usize, out: &Path) -> Self {
        let parts = names
            .iter()
            .map(|&name| {
                let estimate_s = if already_finished(out, name) {
                    0.0
                } else {
                    estimated_seconds(name, scale, threads).unwrap_or(0.0)
                };
                Part {
                    name: name.to_string(),
                    estimate_s,
                    done: false,
                }
            })
            .collect();
        Self {
            parts,
            spent_s: 0.0,
            estimated_spent_s: 0.0,
        }
    }

    /// Seconds the whole run is estimated to take before it starts.
    pub fn total_s(&self) -> f64 {
        self.parts.iter().map(|p| p.estimate_s).sum()
    }

    /// Records that `name` finished after `seconds`.
    pub fn finished(&mut self, name: &str, seconds: f64) {
        if let Some(part) = self.parts.iter_mut().find(|p| p.name == name && !p.done) {
            part.done = true;
            self.spent_s += seconds;
            self.estimated_spent_s += part.estimate_s;
        }
    }

    /// Seconds still to go: the unfinished experiments' estimates times the run's pace so far
    /// (time spent over time estimated for it, between 1/4 and 4), once the finished part was
    /// estimated at [`PACE_AFTER_S`] or more (a few seconds of work say little about the machine).
    pub fn remaining_s(&self) -> f64 {
        let pace = if self.estimated_spent_s >= PACE_AFTER_S {
            (self.spent_s / self.estimated_spent_s).clamp(0.25, 4.0)
        } else {
            1.0
        };
        pace * self
            .parts
            .iter()
            .filter(|p| !p.done)
            .map(|p| p.estimate_s)
            .sum::<f64>()
    }
}

/// A duration for people: seconds under two minutes, minutes under two hours, else hours.
pub fn human_duration(seconds: f64) -> String {
    // `+ 0.0` turns the -0 an empty sum gives into 0.
    let seconds = seconds.max(0.0) + 0.0;
    if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else if seconds < 7200.0 {
        format!("{:.0} min", seconds / 60.0)
    } else {
        format!("{:.1} h", seconds / 3600.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scale(s: f64) -> Scale {
        Scale::new(s).expect("a valid scale")
    }

    #[test]
    fn the_estimate_passes_through_every_reference_timing_and_halves_with_twice_the_threads() {
        for &(name, seconds) in &REFERENCE_SECONDS {
            let at = |s: f64, threads: usize| estimated_seconds(name, scale(s), threads).unwrap_or(f64::NAN);
            for (&s, &t) in REFERENCE_SCALES.iter().zip(&seconds) {
                assert!((at(s, 2) - t).abs() < 1e-9 * t.max(1.0), "{name} at {s}");
                assert!((at(s, 4) - t / 2.0).abs() < 1e-9 * t.max(1.0), "{name} at {s}");
            }
            // Beyond the paper's scale at least linear and at most cubic; below 0.05 never more
            // than the 0.05 timing and never less than linear shrinking gives.
            let whole = seconds[2];
            assert!(
                at(2.0, 2) >= 2.0 * whole - 1e-9 && at(2.0, 2) <= 8.0 * whole + 1e-9,
                "{name}"
            );
            let smallest = seconds[0];
            assert!(
                at(0.01, 2) <= smallest + 1e-9 && at(0.01, 2) >= smallest / 5.0 - 1e-9,
                "{name}"
            );
        }
        let run_at = |s: f64| -> f64 {
            REFERENCE_SECONDS
                .iter()
                .filter_map(|(name, _)| estimated_seconds(name, scale(s), 2))
                .sum()
        };
        assert!(
            // The sixteen before `free-object` 23.8 minutes, `free-object` 37.4 on its own.
            (61.1 * 60.0..61.4 * 60.0).contains(&run_at(1.0)),
            "{} s at scale 1.0",
            run_at(1.0)
        );
        assert!(
            (340.0..351.0).contains(&run_at(0.05)),
            "{} s at scale 0.05",
            run_at(0.05)
        );
        assert_eq!(estimated_seconds("no-such-experiment", scale(1.0), 2), None);
    }

    #[test]
    fn a_run_that_goes_twice_as_slow_as_estimated_doubles_the_rest() {
        let dir = std::env::temp_dir().join(format!("taction-estimate-{}", std::process::id()));
        let mut run = RunEstimate::new(&["thickness", "noise"], scale(1.0), 2, &dir);
        let thickness = estimated_seconds("thickness", scale(1.0), 2).unwrap_or(f64::NAN);
        assert!(thickness >= PACE_AFTER_S);
        let noise = estimated_seconds("noise", scale(1.0), 2).unwrap_or(f64::NAN);
        assert!((run.total_s() - thickness - noise).abs() < 1e-9);
        assert!((run.remaining_s() - thickness - noise).abs() < 1e-9);
        run.finished("thickness", 2.0 * thickness);
        assert!((run.remaining_s() - 2.0 * noise).abs() < 1e-9);
        run.finished("noise", noise);
        assert_eq!(run.remaining_s(), 0.0);
        assert_eq!(human_duration(90.0), "90 s");
        assert_eq!(human_duration(-0.0), "0 s");
        assert_eq!(human_duration(600.0), "10 min");
        assert_eq!(human_duration(9000.0), "2.5 h");
    }
}
