//! What each experiment plots, read back from its assembled CSV so that a merge can plot without the
//! experiment's code. Two kinds: the paper's recognition curves (accuracy vs readings, Fig. 7-13,
//! 16, 17) and a generic line plot (e.g. Fig. 14, controller convergence vs noise).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::accuracy::{AccuracyRow, ReliabilityRow};
use super::error::ExperimentError;
use super::factor::Factors;
use super::figure::{BAND_LABEL, Figure, Panel, ReferenceLine, Series};
use super::layout::ExperimentDir;
use super::name::SafeName;
use super::unit::DetailRow;
use crate::recognize::ReliabilityTable;

/// One axis of a line plot: the CSV column it reads and its label (with units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    pub column: String,
    pub label: String,
}

impl Axis {
    pub fn new(column: &str, label: &str) -> Self {
        Self {
            column: column.to_string(),
            label: label.to_string(),
        }
    }
}

/// What to draw from the assembled CSV.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlotKind {
    /// Accuracy (the fraction correct, as in the CSV) against the number of readings from
    /// [`AccuracyRow`] columns: one line per (descriptor, factor levels), the mean over trials at each
    /// `n_readings` with the lowest and highest trial as a band. When both the descriptor
    /// and the levels vary, one panel per descriptor with one line per levels (the layout of Fig.
    /// 11-13); otherwise one panel.
    Accuracy,
    /// `y` against `x` from named columns: one line per distinct combination of the `series`
    /// columns (one line if none), the mean of `y` over rows sharing (series, x), with a marker per
    /// point; one panel per `y` axis.
    Lines {
        x: Axis,
        y: Vec<Axis>,
        series: Vec<String>,
    },
    /// A reliability diagram from [`ReliabilityRow`] columns: per curve (descriptor, factor
    /// levels), accuracy against mean confidence at each non-empty confidence bin, the curve named
    /// with its ECE, and the diagonal of perfect calibration as reference.
    Reliability,
}

/// One plot of an experiment, written as `<stem>.svg` and `<stem>.png` beside its CSV.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlotSpec {
    pub stem: SafeName,
    pub title: String,
    pub kind: PlotKind,
    /// The number of objects told apart, when the plot shows accuracy: chance level (1 / objects)
    /// is drawn as a dashed line. Absent in manifests written before it existed.
    #[serde(default)]
    pub objects: Option<usize>,
    /// A line's name in the legend, `{column}` standing for the line's cell in that column, e.g.
    /// `data = {data} {resolution}`. Absent: an accuracy plot names a line by its factors
    /// (`factor = level`, joined by commas), a line plot by its series columns.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub legend: Option<String>,
    /// The detail table the plot reads (`<experiment>_<table>.csv`); absent: the main table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<SafeName>,
}

impl PlotSpec {
    pub fn accuracy(stem: SafeName, title: &str) -> Self {
        Self {
            stem,
            title: title.to_string(),
            kind: PlotKind::Accuracy,
            objects: None,
            legend: None,
            table: None,
        }
    }

    /// Names each line by `template` (see [`PlotSpec::legend`]).
    pub fn with_legend(mut self, template: &str) -> Self {
        self.legend = Some(template.to_string());
        self
    }

    /// Draws chance level for `objects` objects (none for fewer than two).
    pub fn with_chance(mut self, objects: usize) -> Self {
        self.objects = (objects >= 2).then_some(objects);
        self
    }

    pub fn lines(stem: SafeName, title: &str, x: Axis, y: Vec<Axis>, series: &[&str]) -> Self {
        let series = series.iter().map(|s| s.to_string()).collect();
        Self {
            stem,
            title: title.to_string(),
            kind: PlotKind::Lines { x, y, series },
            objects: None,
            legend: None,
            table: None,
        }
    }

    /// The reliability diagram of the experiment's `reliability` table ([`ReliabilityRow`]).
    pub fn reliability(stem: SafeName, title: &str) -> Result<Self, ExperimentError> {
        Ok(Self {
            stem,
            title: title.to_string(),
            kind: PlotKind::Reliability,
            objects: None,
            legend: None,
            table: ReliabilityRow::TABLE.map(SafeName::new).transpose()?,
        })
    }
}

/// Draws `spec` from the assembled `csv` into `dir`; returns the figure and the SVG and PNG paths.
pub fn render_plot(
    spec: &PlotSpec,
    csv: &Path,
    dir: &ExperimentDir,
) -> Result<(Figure, Vec<PathBuf>), ExperimentError> {
    let figure = build_figure(spec, csv)?;
    let svg = dir.plot(&spec.stem, "svg");
    let png = dir.plot(&spec.stem, "png");
    figure.write_svg(&svg)?;
    figure.write_png(&png)?;
    Ok((figure, vec![svg, png]))
}

/// The figure `spec` describes, from the rows of `csv`.
pub fn build_figure(spec: &PlotSpec, csv: &Path) -> Result<Figure, ExperimentError> {
    let panels = match &spec.kind {
        PlotKind::Accuracy => accuracy_panels(csv, spec.objects, spec.legend.as_deref())?,
        PlotKind::Lines { x, y, series } => line_panels(csv, x, y, series, spec.legend.as_deref())?,
        PlotKind::Reliability => vec![reliability_panel(read_reliability_series(
            csv,
            spec.legend.as_deref(),
        )?)],
    };
    Ok(Figure {
        title: spec.title.clone(),
        panels,
    })
}

/// Means of `y` per x, with the lowest and highest y (keyed by the bits of x, which come from the
/// same text for the same setting).
#[derive(Default)]
struct Means {
    sums: BTreeMap<u64, Sum>,
}

#[derive(Clone, Copy)]
struct Sum {
    x: f64,
    total: f64,
    n: usize,
    low: f64,
    high: f64,
}

impl Means {
    fn add(&mut self, x: f64, y: f64) {
        let entry = self.sums.entry(x.to_bits()).or_insert(Sum {
            x,
            total: 0.0,
            n: 0,
            low: f64::INFINITY,
            high: f64::NEG_INFINITY,
        });
        entry.total += y;
        entry.n += 1;
        entry.low = entry.low.min(y);
        entry.high = entry.high.max(y);
    }

    fn sorted(&self) -> Vec<Sum> {
        let mut sums: Vec<Sum> = self.sums.values().copied().collect();
        sums.sort_by(|a, b| a.x.total_cmp(&b.x));
        sums
    }

    /// The series `label`: the means, and the band from lowest to highest when some point averages
    /// values that differ.
    fn series(&self, label: String) -> Series {
        let sums = self.sorted();
        let spread = sums.iter().any(|s| s.high > s.low);
        Series {
            label,
            points: sums.iter().map(|s| (s.x, s.total / s.n as f64)).collect(),
            band: if spread {
                sums.iter().map(|s| (s.x, s.low, s.high)).collect()
            } else {
                Vec::new()
            },
        }
    }
}

/// Items in order of first appearance, each with its accumulator.
pub(crate) struct Ordered<K, V> {
    pub items: Vec<(K, V)>,
}

impl<K: PartialEq, V: Default> Ordered<K, V> {
    pub fn new() -> Self {
        Self { items: Vec::new() }
    }

    /// The accumulator of `key`, a default one appended when `key` is new.
    pub fn entry(&mut self, key: K) -> &mut V {
        let i = match self.items.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                self.items.push((key, V::default()));
                self.items.len() - 1
            }
        };
        &mut self.items[i].1
    }
}

/// The y axis of accuracy plots: the CSVs' `accuracy` column as it is.
pub const ACCURACY_LABEL: &str = "accuracy (fraction correct)";

pub(crate) fn csv_error(path: &Path, e: impl std::fmt::Display) -> ExperimentError {
    ExperimentError::Csv {
        path: path.to_path_buf(),
        what: e.to_string(),
    }
}

/// `template` with every `{column}` replaced by `cell(column)`; `Err(column)` names a column `cell`
/// does not know.
fn fill_legend(template: &str, cell: impl Fn(&str) -> Option<String>) -> Result<String, String> {
    let mut label = String::new();
    let mut rest = template;
    while let Some(open) = rest.find('{') {
        label.push_str(&rest[..open]);
        let Some(close) = rest[open..].find('}') else {
            break;
        };
        let column = &rest[open + 1..open + close];
        label.push_str(&cell(column).ok_or_else(|| column.to_string())?);
        rest = &rest[open + close + 1..];
    }
    label.push_str(rest);
    Ok(label)
}

/// The recognition curves of `csv`: accuracy per number of readings, averaged over trials, per
/// descriptor and setting (in the order they first appear), and the largest number of readings.
type AccuracyCurves = Ordered<(String, Factors), Means>;

fn accuracy_panels(
    csv: &Path,
    objects: Option<usize>,
    legend: Option<&str>,
) -> Result<Vec<Panel>, ExperimentError> {
    let (curves, max_n) = read_accuracy_curves(csv)?;
    arrange_accuracy_panels(csv, &curves, max_n, objects, legend, Means::series)
}

/// The panels of accuracy curves, whatever summarises each (`series` makes a curve's line and band
/// under its label): when both the descriptor and the factor levels vary, one panel per descriptor
/// with one line per levels (the layout of Fig. 11-13); otherwise one panel. `csv` names the
/// source in errors of the `legend` template.
fn arrange_accuracy_panels<V>(
    csv: &Path,
    curves: &Ordered<(String, Factors), V>,
    max_n: u32,
    objects: Option<usize>,
    legend: Option<&str>,
    series: impl Fn(&V, String) -> Series,
) -> Result<Vec<Panel>, ExperimentError> {
    let mut descriptors: Vec<&str> = Vec::new();
    let mut settings: Vec<&Factors> = Vec::new();
    for ((d, f), _) in &curves.items {
        if !descriptors.contains(&d.as_str()) {
            descriptors.push(d);
        }
        if !settings.contains(&f) {
            settings.push(f);
        }
    }
    let setting = |descriptor: &str, factors: &Factors| setting_label(csv, legend, descriptor, factors);
    let panel = |title: String, series: Vec<Series>| accuracy_panel(title, series, max_n, objects);
    if descriptors.len() > 1 && settings.len() > 1 {
        descriptors
            .iter()
            .map(|&descriptor| {
                let lines = curves
                    .items
                    .iter()
                    .filter(|((d, _), _)| d == descriptor)
                    .map(|((d, f), v)| Ok(series(v, setting(d, f)?)))
                    .collect::<Result<_, ExperimentError>>()?;
                Ok(panel(descriptor.to_string(), lines))
            })
            .collect()
    } else {
        let lines = curves
            .items
            .iter()
            .map(|((d, f), v)| {
                Ok(series(
                    v,
                    if settings.len() > 1 {
                        setting(d, f)?
                    } else {
                        d.clone()
                    },
                ))
            })
            .collect::<Result<_, ExperimentError>>()?;
        Ok(vec![panel(String::new(), lines)])
    }
}

/// One accuracy curve summarised elsewhere (`pool`): its points `(n_readings, accuracy)` and its
/// band `(n_readings, low, high)`, both sorted by the number of readings.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct SummarisedCurve {
    pub points: Vec<(f64, f64)>,
    pub band: Vec<(f64, f64, f64)>,
}

/// The accuracy figure of `spec` (its title, legend template and chance level) drawn from curves
/// already summarised, each under its descriptor and factor levels, laid out as
/// [`PlotKind::Accuracy`] lays out an experiment's curves; `band_label` says what the bands are,
/// `csv` names the source in errors.
pub(crate) fn summarised_accuracy_figure(
    spec: &PlotSpec,
    csv: &Path,
    curves: &Ordered<(String, Factors), SummarisedCurve>,
    band_label: &'static str,
) -> Result<Figure, ExperimentError> {
    let max_n = curves
        .items
        .iter()
        .flat_map(|(_, curve)| curve.points.iter().map(|&(n, _)| n as u32))
        .max()
        .unwrap_or(1);
    let mut panels = arrange_accuracy_panels(
        csv,
        curves,
        max_n,
        spec.objects,
        spec.legend.as_deref(),
        |curve: &SummarisedCurve, label| Series {
            label,
            points: curve.points.clone(),
            band: curve.band.clone(),
        },
    )?;
    for panel in &mut panels {
        panel.band_label = band_label;
    }
    Ok(Figure {
        title: spec.title.clone(),
        panels,
    })
}

/// Reads `csv`'s accuracy rows, each checked (fractions in [0, 1], at least one reading).
fn read_accuracy_curves(csv: &Path) -> Result<(AccuracyCurves, u32), ExperimentError> {
    let mut reader = csv::Reader::from_path(csv).map_err(|e| csv_error(csv, e))?;
    let mut curves: AccuracyCurves = Ordered::new();
    let mut max_n = 1u32;
    for (i, row) in reader.deserialize::<AccuracyRow>().enumerate() {
        let row = row.map_err(|e| csv_error(csv, e))?;
        let line = i + 2;
        for (name, v) in [("accuracy", row.accuracy), ("reliability", row.reliability)] {
            if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                return Err(csv_error(
                    csv,
                    format!("line {line}: {name} {v} is not a fraction in [0, 1]"),
                ));
            }
        }
        if row.n_readings == 0 {
            return Err(csv_error(
                csv,
                format!("line {line}: n_readings must be at least 1"),
            ));
        }
        max_n = max_n.max(row.n_readings);
        curves
            .entry((row.descriptor, row.factors))
            .add(row.n_readings as f64, row.accuracy);
    }
    if curves.items.is_empty() {
        return Err(csv_error(csv, "no rows to plot"));
    }
    Ok((curves, max_n))
}

/// A curve's legend: its factor levels, or the `legend` template filled from its descriptor and
/// factor columns.
fn setting_label(
    csv: &Path,
    legend: Option<&str>,
    descriptor: &str,
    factors: &Factors,
) -> Result<String, ExperimentError> {
    match legend {
        None => Ok(factors.to_string()),
        Some(template) => fill_legend(template, |column| {
            if column == "descriptor" {
                return Some(descriptor.to_string());
            }
            factors
                .iter()
                .find(|(f, _)| f.column() == column)
                .map(|(_, level)| level.to_string())
        })
        .map_err(|column| ExperimentError::MissingColumn {
            path: csv.to_path_buf(),
            column,
            available: std::iter::once("descriptor")
                .chain(factors.factors().map(|f| f.column()))
                .collect::<Vec<_>>()
                .join(", "),
        }),
    }
}

/// The label of a reliability diagram's diagonal.
pub const PERFECT_CALIBRATION: &str = "perfect calibration";

/// The curves of a reliability diagram, each named with its ECE (`pf (ECE 0.042)`): every series
/// but the diagonal.
pub(crate) fn calibration_labels(figure: &Figure) -> impl Iterator<Item = String> + '_ {
    figure.panels.iter().flat_map(|panel| {
        let curves = panel.series.iter().filter(|s| s.label != PERFECT_CALIBRATION);
        curves.map(|s| s.label.clone())
    })
}

/// A reliability diagram of `curves`, each a name and its table: what `taction recognize` draws
/// (the experiments draw theirs from their `reliability` table, [`PlotKind::Reliability`]).
pub fn reliability_figure(title: &str, curves: &[(String, &ReliabilityTable)]) -> Figure {
    let series = curves
        .iter()
        .map(|(name, table)| {
            let points = table
                .bins()
                .iter()
                .filter_map(|bin| Some((bin.mean_confidence()?, bin.accuracy()?)))
                .collect();
            calibration_series(name, table.ece(), points)
        })
        .collect();
    Figure {
        title: title.to_string(),
        panels: vec![reliability_panel(series)],
    }
}

/// One curve of a reliability diagram, named with its ECE.
fn calibration_series(name: &str, ece: Option<f64>, points: Vec<(f64, f64)>) -> Series {
    let ece = ece.map_or_else(|| "no predictions".to_string(), |e| format!("{e:.3}"));
    Series {
        label: format!("{name} (ECE {ece})"),
        points,
        band: Vec::new(),
    }
}

/// Per curve (descriptor, factor levels): its ECE and its non-empty bins as (bin, mean confidence,
/// accuracy).
type CalibrationCurves = Ordered<(String, Factors), (Option<f64>, Vec<(u32, f64, f64)>)>;

/// The reliability rows of `csv`, one series per curve (descriptor, factor levels) in order of
/// first appearance, named as accuracy plots name their lines and, since the diagram is one panel
/// where an accuracy plot has one per descriptor, led by the descriptor when there are several
/// (else the ECE list of the index named two curves alike); a curve's bin seen twice (a curve
/// split over units) is an error.
fn read_reliability_series(csv: &Path, legend: Option<&str>) -> Result<Vec<Series>, ExperimentError> {
    let mut reader = csv::Reader::from_path(csv).map_err(|e| csv_error(csv, e))?;
    let mut curves: CalibrationCurves = Ordered::new();
    for (i, row) in reader.deserialize::<ReliabilityRow>().enumerate() {
        let row = row.map_err(|e| csv_error(csv, e))?;
        let (ece, points) = curves.entry((row.descriptor, row.factors));
        if points.iter().any(|(bin, _, _)| *bin == row.bin) {
            return Err(csv_error(
                csv,
                format!("line {}: bin {} of this curve is there twice", i + 2, row.bin),
            ));
        }
        *ece = row.ece;
        if let (Some(confidence), Some(accuracy)) = (row.mean_confidence, row.accuracy) {
            points.push((row.bin, confidence, accuracy));
        }
    }
    if curves.items.is_empty() {
        return Err(csv_error(csv, "no rows to plot"));
    }
    let descriptors = curves
        .items
        .iter()
        .map(|((d, _), _)| d)
        .collect::<std::collections::BTreeSet<_>>();
    curves
        .items
        .iter()
        .map(|((descriptor, factors), (ece, points))| {
            let name = match (factors.len(), legend) {
                (0, None) => descriptor.clone(),
                (_, None) if descriptors.len() > 1 => format!("{descriptor}: {factors}"),
                (_, Some(template)) if descriptors.len() > 1 && !template.contains("{descriptor}") => {
                    format!(
                        "{descriptor}: {}",
                        setting_label(csv, legend, descriptor, factors)?
                    )
                }
                _ => setting_label(csv, legend, descriptor, factors)?,
            };
            let mut points = points.clone();
            points.sort_by_key(|(bin, _, _)| *bin);
            Ok(calibration_series(
                &name,
                *ece,
                points.iter().map(|&(_, c, a)| (c, a)).collect(),
            ))
        })
        .collect()
}

/// A reliability diagram: accuracy against mean confidence over [0, 1], the diagonal of perfect
/// calibration first.
fn reliability_panel(curves: Vec<Series>) -> Panel {
    let diagonal = Series {
        label: PERFECT_CALIBRATION.to_string(),
        points: vec![(0.0, 0.0), (1.0, 1.0)],
        band: Vec::new(),
    };
    Panel {
        title: String::new(),
        x_label: "mean confidence (top probability)".to_string(),
        y_label: ACCURACY_LABEL.to_string(),
        x_range: (0.0, 1.0),
        y_range: (0.0, 1.0),
        series: std::iter::once(diagonal).chain(curves).collect(),
        markers: true,
        legend: true,
        integer_x: false,
        reference: None,
        band_label: BAND_LABEL,
    }
}

/// A panel of accuracy against readings (1 to `max_n`), with chance at 1/`objects`.
fn accuracy_panel(title: String, series: Vec<Series>, max_n: u32, objects: Option<usize>) -> Panel {
    Panel {
        title,
        x_label: "number of readings".to_string(),
        y_label: ACCURACY_LABEL.to_string(),
        x_range: if max_n > 1 {
            (1.0, max_n as f64)
        } else {
            (0.5, 1.5)
        },
        y_range: (0.0, 1.0),
        series,
        markers: max_n <= 12,
        legend: true,
        integer_x: true,
        reference: objects.map(|n| ReferenceLine {
            y: 1.0 / n as f64,
            label: format!("chance (1/{n})"),
        }),
        band_label: BAND_LABEL,
    }
}

/// The columns a line plot reads from its CSV, by position.
struct LineColumns<'a> {
    headers: csv::StringRecord,
    x: usize,
    ys: Vec<usize>,
    series: Vec<usize>,
    series_names: &'a [String],
}

impl<'a> LineColumns<'a> {
    fn find(
        csv: &Path,
        headers: csv::StringRecord,
        x: &Axis,
        ys: &[Axis],
        series: &'a [String],
    ) -> Result<Self, ExperimentError> {
        let column = |name: &str| column_index(csv, &headers, name);
        let x_col = column(&x.column)?;
        let y_cols = ys
            .iter()
            .map(|y| column(&y.column))
            .collect::<Result<Vec<_>, _>>()?;
        let series_cols = series.iter().map(|s| column(s)).collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            headers,
            x: x_col,
            ys: y_cols,
            series: series_cols,
            series_names: series,
        })
    }

    /// The series a record belongs to: the `legend` template filled from its columns, else the
    /// series columns' values.
    fn label(
        &self,
        csv: &Path,
        record: &csv::StringRecord,
        legend: Option<&str>,
    ) -> Result<String, ExperimentError> {
        let headers = &self.headers;
        Ok(match legend {
            Some(template) => fill_legend(template, |name| {
                headers
                    .iter()
                    .position(|h| h == name)
                    .map(|c| record.get(c).unwrap_or("").to_string())
            })
            .map_err(|column| ExperimentError::MissingColumn {
                path: csv.to_path_buf(),
                column,
                available: headers.iter().collect::<Vec<_>>().join(", "),
            })?,
            None => match self.series.as_slice() {
                [] => String::new(),
                [one] => record.get(*one).unwrap_or("").to_string(),
                many => many
                    .iter()
                    .zip(self.series_names)
                    .map(|(&c, name)| format!("{name} = {}", record.get(c).unwrap_or("")))
                    .collect::<Vec<_>>()
                    .join(", "),
            },
        })
    }
}

/// The position of column `name` in `headers`, or an error listing the columns there are.
fn column_index(csv: &Path, headers: &csv::StringRecord, name: &str) -> Result<usize, ExperimentError> {
    headers
        .iter()
        .position(|h| h == name)
        .ok_or_else(|| ExperimentError::MissingColumn {
            path: csv.to_path_buf(),
            column: name.to_string(),
            available: headers.iter().collect::<Vec<_>>().join(", "),
        })
}

fn line_panels(
    csv: &Path,
    x: &Axis,
    ys: &[Axis],
    series: &[String],
    legend: Option<&str>,
) -> Result<Vec<Panel>, ExperimentError> {
    let mut reader = csv::Reader::from_path(csv).map_err(|e| csv_error(csv, e))?;
    let headers = reader.headers().map_err(|e| csv_error(csv, e))?.clone();
    let columns = LineColumns::find(csv, headers, x, ys, series)?;
    let curves = read_line_curves(csv, &mut reader, &columns, x, ys, legend)?;
    if curves.first().is_none_or(|c| c.items.is_empty()) {
        return Err(csv_error(csv, "no rows to plot"));
    }
    Ok(ys
        .iter()
        .zip(curves)
        .map(|(y, acc)| line_panel(x, y, ys.len(), acc, !columns.series.is_empty()))
        .collect())
}

/// One accumulator per y axis, per series label: the mean of y at each x over the records.
fn read_line_curves(
    csv: &Path,
    reader: &mut csv::Reader<std::fs::File>,
    columns: &LineColumns<'_>,
    x: &Axis,
    ys: &[Axis],
    legend: Option<&str>,
) -> Result<Vec<Ordered<String, Means>>, ExperimentError> {
    let mut curves: Vec<Ordered<String, Means>> = ys.iter().map(|_| Ordered::new()).collect();
    for (i, record) in reader.records().enumerate() {
        let record = record.map_err(|e| csv_error(csv, e))?;
        let line = i + 2;
        let number = |col: usize, name: &str| {
            let text = record.get(col).unwrap_or("");
            text.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    csv_error(
                        csv,
                        format!("line {line}: column '{name}': '{text}' is not a finite number"),
                    )
                })
        };
        let xv = number(columns.x, &x.column)?;
        let label = columns.label(csv, &record, legend)?;
        for ((y, &col), acc) in ys.iter().zip(&columns.ys).zip(curves.iter_mut()) {
            acc.entry(label.clone()).add(xv, number(col, &y.column)?);
        }
    }
    Ok(curves)
}

/// The panel of y axis `y` (titled by it when the figure has `y_count` > 1 panels), its range
/// padded around the points and 0; `by_series`: the curves are told apart by series columns.
fn line_panel(x: &Axis, y: &Axis, y_count: usize, acc: Ordered<String, Means>, by_series: bool) -> Panel {
    let series: Vec<Series> = acc
        .items
        .into_iter()
        .map(|(label, m)| m.series(if label.is_empty() { y.label.clone() } else { label }))
        .collect();
    let all = || series.iter().flat_map(|s| s.points.iter());
    let (xmin, xmax) = bounds(all().map(|p| p.0));
    let (ymin, ymax) = bounds(all().map(|p| p.1));
    // A band needs its legend entry even beside a lone line.
    let legend = by_series || series.iter().any(|s| !s.band.is_empty());
    Panel {
        title: if y_count > 1 {
            y.label.clone()
        } else {
            String::new()
        },
        x_label: x.label.clone(),
        y_label: y.label.clone(),
        x_range: padded(xmin, xmax, false),
        y_range: padded(ymin.min(0.0), ymax.max(0.0), true),
        // A marker at every point while they are few, as the accuracy plots do: on a curve of a
        // hundred points they hide the line.
        markers: series.iter().all(|s| s.points.len() <= 12),
        series,
        legend,
        integer_x: false,
        reference: None,
        band_label: BAND_LABEL,
    }
}

fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

/// A drawable range around `[lo, hi]`: 5 % margins (only above zero-anchored ranges when
/// `from_zero`), and a unit width when all values are equal.
fn padded(lo: f64, hi: f64, from_zero: bool) -> (f64, f64) {
    if hi <= lo {
        return (lo - 0.5, hi + 0.5);
    }
    let pad = 0.05 * (hi - lo);
    let lo = if from_zero && lo == 0.0 { 0.0 } else { lo - pad };
    (lo, hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two descriptors drawn under a legend that does not name them: one panel, so each curve's
    /// name leads with its descriptor; a legend that names it is taken as it is.
    #[test]
    fn reliability_curves_of_several_descriptors_are_named_apart() {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("toy_reliability.csv");
        let mut text = String::from(
            "experiment,descriptor,object_motion,bin,confidence_low,confidence_high,count,mean_confidence,accuracy,ece\n",
        );
        for descriptor in ["mnti", "polar-fourier"] {
            text.push_str(&format!("toy,{descriptor},fixed,9,0.9,1.0,2,0.95,1.0,0.05\n"));
        }
        std::fs::write(&csv, text).unwrap();
        let names = |legend: Option<&str>| -> Vec<String> {
            read_reliability_series(&csv, legend)
                .unwrap()
                .into_iter()
                .map(|s| s.label)
                .collect()
        };
        assert_eq!(
            names(Some("object = {object_motion}")),
            [
                "mnti: object = fixed (ECE 0.050)",
                "polar-fourier: object = fixed (ECE 0.050)"
            ]
        );
        assert_eq!(
            names(Some("{descriptor}, {object_motion}")),
            ["mnti, fixed (ECE 0.050)", "polar-fourier, fixed (ECE 0.050)"]
        );
        assert_eq!(
            names(None),
            [
                "mnti: object_motion = fixed (ECE 0.050)",
                "polar-fourier: object_motion = fixed (ECE 0.050)"
            ]
        );
    }
}
