//! The results index: `<out>/README.md` lists every experiment directory under the output root
//! with its description, CSV, plots and headline numbers. Rewritten by every run and merge, from
//! the files alone.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::assemble::{missing_detail, missing_units, plot_source};
use super::error::ExperimentError;
use super::figure::{Panel, format_number as number};
use super::files::read_json;
use super::layout::ExperimentDir;
use super::layout::{experiments_in, folders_holding};
use super::name::SafeName;
use super::plot::{PERFECT_CALIBRATION, PlotKind, build_figure};
use super::spec::Manifest;
use crate::atomic::write_if_changed;

/// The numbers of readings at which the index quotes accuracy.
pub const HEADLINE_READINGS: [u32; 4] = [10, 30, 60, 100];

/// The most x values a line plot's headline table shows (evenly spaced, ends included).
const MAX_LINE_COLUMNS: usize = 8;

/// (Re)writes `<out>/README.md`; returns its path.
pub fn write_index(out: &Path) -> Result<PathBuf, ExperimentError> {
    let mut text = String::from(
        "# Results\n\nOne directory per experiment: `<name>.csv` (tidy, one row per observation; beside a \
         recognition experiment's, `<name>_per_object.csv` with one row per test object and \
         `<name>_reliability.csv`, each curve's calibration in 10 bins of top probability with its ECE), its plots \
         (SVG and PNG), `config.json` (the run's configuration), `manifest.json` and `units/` (one file \
         per work unit, what resuming and `taction merge` use). This file is rewritten by every run.\n",
    );
    if out.join("PAPER.md").is_file() {
        text.push_str("\nThe paper's claims beside these numbers, figure by figure, with a verdict each: [PAPER.md](PAPER.md).\n");
    }
    picture_sections(&mut text, out)?;
    for dir in experiments_in(out)? {
        let manifest = Manifest::read(&dir.manifest())?;
        section(&mut text, &dir, &manifest)?;
    }
    let path = out.join("README.md");
    write_if_changed(&path, text.as_bytes())?;
    Ok(path)
}

fn section(text: &mut String, dir: &ExperimentDir, manifest: &Manifest) -> Result<(), ExperimentError> {
    let name = dir.name();
    let _ = write!(text, "\n## {name}\n\n{}\n\n", manifest.spec.description);
    if let Some(run) = run_line(dir) {
        let _ = write!(text, "{run}\n\n");
    }
    let missing = missing_units(dir, manifest).len();
    let csv = dir.csv();
    if missing > 0 || !csv.is_file() {
        let total = manifest.units.len();
        let _ = writeln!(text, "Incomplete: {} of {total} units done.", total - missing);
        return Ok(());
    }
    let _ = write!(text, "Data: [{name}.csv]({name}/{name}.csv)");
    let absent: Vec<&SafeName> = manifest
        .details
        .iter()
        .filter(|table| !detail_data(text, dir, manifest, table))
        .collect();
    text.push('\n');
    for table in &absent {
        absent_detail(text, dir, manifest, table);
    }
    for spec in &manifest.spec.plots {
        let source = plot_source(dir, spec);
        if !source.is_file() {
            continue;
        }
        let stem = &spec.stem;
        let _ = write!(
            text,
            "\n![{}]({name}/{stem}.svg)\n([PNG]({name}/{stem}.png))\n\n",
            spec.title
        );
        let figure = build_figure(spec, &source)?;
        for panel in &figure.panels {
            match spec.kind {
                PlotKind::Accuracy => accuracy_table(text, panel),
                PlotKind::Lines { .. } => line_table(text, panel),
                PlotKind::Reliability => calibration_list(text, panel),
            }
        }
    }
    Ok(())
}

/// What the run used, from its `config.json`: scale, seed, object set and codebook, those it has
/// (a quick look at scale 0.05 and the paper's 1.0 write the same files otherwise).
fn run_line(dir: &ExperimentDir) -> Option<String> {
    let config: serde_json::Value = read_json(&dir.config()).ok()?;
    let field = |value: Option<&serde_json::Value>| match value? {
        serde_json::Value::String(s) => Some(s.clone()),
        v @ serde_json::Value::Number(_) => Some(v.to_string()),
        _ => None,
    };
    let parts: Vec<String> = [
        ("scale", field(config.get("scale"))),
        ("seed", field(config.get("seed"))),
        ("object set", field(config.get("object_set"))),
        ("codebook", field(config.pointer("/training/codebook"))),
    ]
    .into_iter()
    .filter_map(|(label, value)| Some(format!("{label} {}", value?)))
    .collect();
    (!parts.is_empty()).then(|| format!("Run: {}.", parts.join(", ")))
}

/// Adds the experiment's detail table `table` to the data line when it is assembled; whether it is.
fn detail_data(text: &mut String, dir: &ExperimentDir, manifest: &Manifest, table: &SafeName) -> bool {
    let name = dir.name();
    let here = missing_detail(dir, manifest, table).is_empty() && dir.detail_csv(table).is_file();
    if here {
        let _ = write!(text, ", [{name}_{table}.csv]({name}/{name}_{table}.csv)");
    }
    here
}

/// Says why detail table `table` is not there: units saved before their experiment had it lack its
/// rows, which cannot be made up from the main rows.
fn absent_detail(text: &mut String, dir: &ExperimentDir, manifest: &Manifest, table: &SafeName) {
    let name = dir.name();
    let missing = missing_detail(dir, manifest, table).len();
    let _ = writeln!(
        text,
        "\n`{name}_{table}.csv` is not here: {missing} of {} units were saved before their `{table}` rows \
         were written, and those rows cannot be derived from the averaged ones; a run into a fresh \
         folder (or after deleting `{name}/units/`) writes them.",
        manifest.units.len()
    );
}

/// A picture experiment (Fig. 1) is one drawing, not a run of units: its folder holds
/// `<name>.png`, the `<name>.csv` it was drawn from and [`PICTURE_FILE`] with its description.
pub const PICTURE_FILE: &str = "picture.json";

/// What [`PICTURE_FILE`] holds.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PictureSpec {
    pub description: String,
    pub title: String,
}

fn picture_sections(text: &mut String, out: &Path) -> Result<(), ExperimentError> {
    for name in folders_holding(out, PICTURE_FILE)? {
        let spec_path = out.join(name.as_str()).join(PICTURE_FILE);
        let spec: PictureSpec = read_json(&spec_path)?;
        let _ = write!(
            text,
            "\n## {name}\n\n{}\n\nData: [{name}.csv]({name}/{name}.csv)\n\n![{}]({name}/{name}.png)\n",
            spec.description, spec.title
        );
    }
    Ok(())
}

fn table_title(text: &mut String, panel: &Panel) {
    if !panel.title.is_empty() {
        let _ = write!(text, "\n{}:\n\n", panel.title);
    }
}

/// The headline readings a panel reaches, plus its last number of readings when that is not one of
/// them (a run below the paper's scale stops short of 100).
fn headline_columns(panel: &Panel) -> Vec<u32> {
    let reached = |n: f64| panel.series.iter().any(|s| s.points.iter().any(|(x, _)| *x == n));
    let mut columns: Vec<u32> = HEADLINE_READINGS
        .into_iter()
        .filter(|&n| reached(n as f64))
        .collect();
    let last = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .fold(0.0, f64::max);
    if last >= 1.0 && last.fract() == 0.0 && !columns.contains(&(last as u32)) {
        columns.push(last as u32);
        columns.sort_unstable();
    }
    columns
}

fn accuracy_table(text: &mut String, panel: &Panel) {
    table_title(text, panel);
    let columns = headline_columns(panel);
    let _ = write!(text, "| accuracy (%) at n readings |");
    for n in &columns {
        let _ = write!(text, " {n} |");
    }
    let _ = write!(text, "\n|---|{}\n", "---:|".repeat(columns.len()));
    for series in &panel.series {
        let _ = write!(text, "| {} |", series.label);
        for &n in &columns {
            match series.points.iter().find(|(x, _)| *x == n as f64) {
                Some((_, y)) => {
                    let _ = write!(text, " {:.1} |", 100.0 * y);
                }
                None => text.push_str(" - |"),
            }
        }
        text.push('\n');
    }
}

/// A reliability plot's curves, each named with its ECE (the diagonal, the reference, left out).
fn calibration_list(text: &mut String, panel: &Panel) {
    table_title(text, panel);
    for series in panel.series.iter().filter(|s| s.label != PERFECT_CALIBRATION) {
        let _ = writeln!(text, "- {}", series.label);
    }
}

fn line_table(text: &mut String, panel: &Panel) {
    text.push('\n');
    let mut xs: Vec<f64> = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    if xs.len() > MAX_LINE_COLUMNS {
        let last = xs.len() - 1;
        xs = (0..MAX_LINE_COLUMNS)
            .map(|i| xs[i * last / (MAX_LINE_COLUMNS - 1)])
            .collect();
    }
    let _ = write!(text, "| {} \\ {} |", panel.y_label, panel.x_label);
    for x in &xs {
        let _ = write!(text, " {} |", number(*x));
    }
    let _ = write!(text, "\n|---|{}\n", "---:|".repeat(xs.len()));
    for series in &panel.series {
        let _ = write!(text, "| {} |", series.label);
        for x in &xs {
            match series.points.iter().find(|p| p.0 == *x) {
                Some((_, y)) => {
                    let _ = write!(text, " {} |", number(*y));
                }
                None => text.push_str(" - |"),
            }
        }
        text.push('\n');
    }
}
