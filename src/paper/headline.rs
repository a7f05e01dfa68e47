//! The headline table of a run: each recognition curve's accuracy at a few reading counts, the
//! mean over trials, read back from the assembled CSVs (so it also works after `merge`).

use std::collections::BTreeMap;
use std::path::Path;

use crate::experiment::accuracy::AccuracyRow;
use crate::experiment::error::ExperimentError;
use crate::experiment::layout::ExperimentDir;
use crate::experiment::name::SafeName;
use crate::experiment::unit::read_rows;

/// The reading counts of the headline table.
pub const HEADLINE_READINGS: [u32; 6] = [1, 10, 20, 30, 60, 100];

/// A Markdown table with one line per (experiment, descriptor, factor levels) of the experiments in
/// `names` that are complete under `out` (`setting` names the levels, `-` when the experiment varies
/// only the descriptor), and the mean accuracy over trials (in %) after each of
/// [`HEADLINE_READINGS`] readings (`-` where the curve is shorter).
pub fn headline_table(out: &Path, names: &[&str]) -> Result<String, ExperimentError> {
    let mut table = String::from("| experiment | descriptor | setting |");
    for n in HEADLINE_READINGS {
        table.push_str(&format!(" {n} |"));
    }
    table.push_str("\n|---|---|---|");
    table.push_str(&"---:|".repeat(HEADLINE_READINGS.len()));
    table.push('\n');
    for name in names {
        let dir = ExperimentDir::new(out, &SafeName::new(*name)?);
        let csv = dir.csv();
        if !csv.exists() {
            continue;
        }
        // (descriptor, factor levels) -> n -> (sum of accuracies, trials)
        let mut curves: BTreeMap<(String, String), BTreeMap<u32, (f64, u32)>> = BTreeMap::new();
        for row in read_rows::<AccuracyRow>(&csv)? {
            let setting = match row.factors.to_string() {
                levels if levels.is_empty() => "-".to_string(),
                levels => levels,
            };
            let point = curves
                .entry((row.descriptor, setting))
                .or_default()
                .entry(row.n_readings)
                .or_default();
            point.0 += row.accuracy;
            point.1 += 1;
        }
        for ((descriptor, setting), points) in curves {
            table.push_str(&format!("| {name} | {descriptor} | {setting} |"));
            for n in HEADLINE_READINGS {
                match points.get(&n) {
                    Some((sum, trials)) => table.push_str(&format!(" {:.1} |", 100.0 * sum / *trials as f64)),
                    None => table.push_str(" - |"),
                }
            }
            table.push('\n');
        }
    }
    Ok(table)
}
