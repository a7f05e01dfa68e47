//! Readings on disk: the hand-off from exploration (Sec. III-A, V-A3) to recognition (Sec. IV-A).
//!
//! A [`Dataset`] is a [`DatasetHeader`] (what produced the readings, with which sensor, on which
//! objects) and the [`Reading`]s themselves, each a tactile image with the pad pose it was taken at,
//! the object's pose, and how the contact controllers ended.
//!
//! # File format (version 2)
//!
//! One UTF-8 text file, so a dataset is a single atomic unit (written to a temporary file in the
//! same folder, then renamed over the target) and any CSV reader can open it after skipping the
//! `#` lines:
//!
//! ```text
//! # taction dataset
//! # {"format_version":2,"sensor":{...},"object_set":"princeton","objects":["bunny",...],
//! #   "generator":"sampler","seed":7,"readings":11000}          <- one line of JSON
//! object,status,strategy,iterations,object_x_m,...,pad_up_z,cause,t_0_0,t_0_1,...,t_{rows-1}_{cols-1}
//! bunny,converged,sampler,4,0.1,...,,0,0.25,...
//! ...
//! # end 11000
//! ```
//!
//! - Line 2 is the header as JSON after `# `, plus `readings`, the number of data rows.
//! - Line 3 names the columns, in this order: `object` (a name from the header's `objects`),
//!   `status` ([`ContactStatus::name`]), `strategy` ([`Strategy::name`]), `iterations`,
//!   the object pose `object_x_m, object_y_m, object_z_m, object_qw, object_qx, object_qy,
//!   object_qz`, the pad pose `pad_x_m, pad_y_m, pad_z_m, pad_normal_x, pad_normal_y, pad_normal_z,
//!   pad_up_x, pad_up_y, pad_up_z` (all nine empty when the image carries no pose), `cause`
//!   ([`AttemptCause::name`]: the two bodies that touched as `arm_body/other_body`, or
//!   `covering_meets_table`; empty when the status says it all), then the `rows x cols` taxels
//!   row-major as `t_{row}_{col}`, row 0 being the pad's `+up` edge. Version 1 had no `cause`.
//! - The last line, `# end N`, repeats the row count, so a file cut anywhere (even inside the
//!   last number) is reported as truncated rather than read short.
//! - Numbers are written in shortest round-trip form, so reading back is bit-exact.
//!
//! Size: about 20 bytes per taxel at worst, i.e. ~150 MB for 10 objects x 1100 readings of 26x26
//! and ~8 MB at 6x6; reading parses ~100 MB/s.

use std::collections::BTreeMap;
use std::fmt;
use std::io::Write;
use std::path::Path;

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

use crate::atomic::{FileError, write_atomic};
use crate::control::ContactStatus;
pub use crate::explore::Reading;
use crate::explore::collect::{CollectMode, CollectPlan};
use crate::explore::{AttemptCause, CauseKind, Strategy};
use crate::sim::ObjectSpec;
use crate::sim::Pose;
use crate::tactile::{PadPose, SensorConfig, TactileImage};

/// What a dataset's header says produced it: `sampler` (or `sampler from above`), `planner L=0.5`.
pub fn generator_name(mode: &CollectMode) -> String {
    match mode {
        CollectMode::Sampler(c) if c.from_above_only => "sampler from above".to_string(),
        CollectMode::Sampler(_) => "sampler".to_string(),
        CollectMode::Planner(c) => format!("planner L={}", c.local_probability),
    }
}

/// The file format version this build writes and reads.
pub const FORMAT_VERSION: u32 = 2;

const MAGIC: &str = "# taction dataset";
const END_PREFIX: &str = "# end ";
/// Columns before the taxels.
const META_COLUMNS: [&str; 21] = [
    "object",
    "status",
    "strategy",
    "iterations",
    "object_x_m",
    "object_y_m",
    "object_z_m",
    "object_qw",
    "object_qx",
    "object_qy",
    "object_qz",
    "pad_x_m",
    "pad_y_m",
    "pad_z_m",
    "pad_normal_x",
    "pad_normal_y",
    "pad_normal_z",
    "pad_up_x",
    "pad_up_y",
    "pad_up_z",
    "cause",
];
const CAUSE_COLUMN: usize = 20;
const PAD_COLUMNS: std::ops::Range<usize> = 11..20;

/// Errors from building, reading or writing a dataset; each names the file, line and field.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: not a taction dataset: {what}")]
    NotADataset { path: String, what: String },
    #[error("{path}: dataset format version {found}, but this build reads version {expected}")]
    Version { path: String, found: u64, expected: u32 },
    #[error("{path}: line {line}: header: {what}")]
    Header { path: String, line: usize, what: String },
    #[error("{path}: truncated: {what}")]
    Truncated { path: String, what: String },
    #[error("{path}: line {line}: {fields} columns, expected {expected} ({meta} + {rows}x{cols} taxels)", meta = META_COLUMNS.len())]
    ColumnCount {
        path: String,
        line: u64,
        fields: usize,
        expected: usize,
        rows: usize,
        cols: usize,
    },
    #[error("{path}: line {line}: field '{field}': {what}")]
    Field {
        path: String,
        line: u64,
        field: String,
        what: String,
    },
    #[error("{path}: line {line}: {what}")]
    Csv { path: String, line: u64, what: String },
    #[error("invalid dataset: {0}")]
    Invalid(String),
    #[error("collecting readings: {0}")]
    Collect(#[from] crate::control::ControlError),
}

impl From<FileError> for DatasetError {
    fn from(e: FileError) -> Self {
        Self::Io {
            path: e.path.display().to_string(),
            source: e.source,
        }
    }
}

/// What a dataset holds and how it was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DatasetHeader {
    /// [`FORMAT_VERSION`] when built by this crate.
    pub format_version: u32,
    /// The sensor every image was taken with; its `rows x cols` is every image's shape.
    pub sensor: SensorConfig,
    /// Name of the object set (manifest) the objects come from.
    pub object_set: String,
    /// Object names in index order; every reading names one of them.
    pub objects: Vec<String>,
    /// What produced the readings, e.g. `sampler` or `planner L=0.8`.
    pub generator: String,
    /// The run's seed.
    pub seed: u64,
}

impl DatasetHeader {
    /// A header of the current format version.
    pub fn new(
        sensor: SensorConfig,
        object_set: impl Into<String>,
        objects: Vec<String>,
        generator: impl Into<String>,
        seed: u64,
    ) -> Self {
        Self {
            format_version: FORMAT_VERSION,
            sensor,
            object_set: object_set.into(),
            objects,
            generator: generator.into(),
            seed,
        }
    }

    /// Index of `object` in [`objects`](Self::objects).
    pub fn object_index(&self, object: &str) -> Option<usize> {
        self.objects.iter().position(|o| o == object)
    }

    fn validate(&self) -> Result<(), String> {
        if self.format_version != FORMAT_VERSION {
            return Err(format!(
                "format_version {} (this build writes {FORMAT_VERSION})",
                self.format_version
            ));
        }
        self.sensor.validate().map_err(|e| format!("sensor: {e}"))?;
        for (i, name) in self.objects.iter().enumerate() {
            if name.is_empty() {
                return Err(format!("object {i} has an empty name"));
            }
            if self.objects[..i].contains(name) {
                return Err(format!("object '{name}' is listed twice"));
            }
        }
        Ok(())
    }
}

/// A header and its readings; every reading's object is in the header and every image has the
/// sensor's shape (checked on construction, so code holding a `Dataset` can rely on it).
#[derive(Debug, Clone, PartialEq)]
pub struct Dataset {
    header: DatasetHeader,
    readings: Vec<Reading>,
}

/// The on-disk header line: the header plus the row count.
#[derive(Serialize, Deserialize)]
struct FileHeader {
    #[serde(flatten)]
    header: DatasetHeader,
    readings: usize,
}

impl Dataset {
    /// A dataset from readings in memory.
    pub fn new(header: DatasetHeader, readings: Vec<Reading>) -> Result<Self, DatasetError> {
        header.validate().map_err(DatasetError::Invalid)?;
        let mut dataset = Self {
            header,
            readings: Vec::with_capacity(readings.len()),
        };
        for reading in readings {
            dataset.push(reading)?;
        }
        Ok(dataset)
    }

    /// Appends a reading, checking its object and image shape against the header.
    pub fn push(&mut self, reading: Reading) -> Result<(), DatasetError> {
        let index = self.readings.len();
        if self.header.object_index(&reading.object).is_none() {
            return Err(DatasetError::Invalid(format!(
                "reading {index}: object '{}' is not in the header's objects ({})",
                reading.object,
                self.header.objects.join(", ")
            )));
        }
        let (rows, cols) = (self.header.sensor.rows, self.header.sensor.cols);
        if (reading.image.rows(), reading.image.cols()) != (rows, cols) {
            return Err(DatasetError::Invalid(format!(
                "reading {index}: image is {}x{}, the sensor is {rows}x{cols}",
                reading.image.rows(),
                reading.image.cols()
            )));
        }
        self.readings.push(reading);
        Ok(())
    }

    /// Collects `objects` (of the set with id `object_set`) as `plan` says on `threads` threads
    /// (0: all cores) and gathers the readings, object by object, into a dataset.
    pub fn collect(
        plan: &CollectPlan,
        object_set: &str,
        objects: &[ObjectSpec],
        threads: usize,
    ) -> Result<Dataset, DatasetError> {
        Self::collect_reporting(plan, object_set, objects, threads, &|| {})
    }

    /// [`collect`](Self::collect), running `on_converged` after each converged reading.
    pub fn collect_reporting(
        plan: &CollectPlan,
        object_set: &str,
        objects: &[ObjectSpec],
        threads: usize,
        on_converged: &(dyn Fn() + Sync),
    ) -> Result<Dataset, DatasetError> {
        let reports = plan.collect_reporting(objects, threads, on_converged)?;
        let header = DatasetHeader::new(
            plan.sensor,
            object_set,
            objects.iter().map(|o| o.name.clone()).collect(),
            generator_name(&plan.mode),
            plan.seed,
        );
        Dataset::new(header, reports.into_iter().flat_map(|r| r.readings).collect())
    }

    pub fn header(&self) -> &DatasetHeader {
        &self.header
    }

    pub fn readings(&self) -> &[Reading] {
        &self.readings
    }

    pub fn len(&self) -> usize {
        self.readings.len()
    }

    pub fn is_empty(&self) -> bool {
        self.readings.is_empty()
    }

    /// The same header with only the [`Converged`](ContactStatus::Converged) readings: the ones
    /// recognition uses (Sec. III-B).
    pub fn converged_only(&self) -> Dataset {
        Dataset {
            header: self.header.clone(),
            readings: self
                .readings
                .iter()
                .filter(|r| r.status == ContactStatus::Converged)
                .cloned()
                .collect(),
        }
    }

    /// The objects that got fewer than `wanted` converged readings, in header order: what a run
    /// that produced less than asked must report.
    pub fn shortfalls(&self, wanted: usize) -> Vec<Shortfall> {
        self.by_object()
            .iter()
            .zip(&self.header.objects)
            .map(|(readings, object)| Shortfall {
                object: object.clone(),
                converged: readings
                    .iter()
                    .filter(|r| r.status == ContactStatus::Converged)
                    .count(),
                wanted,
            })
            .filter(|s| s.converged < wanted)
            .collect()
    }

    /// Readings grouped by object, in header order, each group in dataset order.
    pub fn by_object(&self) -> Vec<Vec<&Reading>> {
        let mut groups = vec![Vec::new(); self.header.objects.len()];
        for r in &self.readings {
            if let Some(i) = self.header.object_index(&r.object) {
                groups[i].push(r);
            }
        }
        groups
    }

    /// Counts per object and status, for `taction dataset show`.
    pub fn summary(&self) -> DatasetSummary {
        let mut per_object: Vec<BTreeMap<ContactStatus, usize>> =
            vec![BTreeMap::new(); self.header.objects.len()];
        for r in &self.readings {
            if let Some(i) = self.header.object_index(&r.object) {
                *per_object[i].entry(r.status).or_insert(0) += 1;
            }
        }
        let mut by_strategy = BTreeMap::new();
        for r in &self.readings {
            *by_strategy.entry(r.strategy.name()).or_insert(0) += 1;
        }
        let mut causes = vec![BTreeMap::new(); self.header.objects.len()];
        for r in &self.readings {
            if let Some(i) = self.header.object_index(&r.object) {
                let kind = match (&r.cause, r.status) {
                    (Some(cause), _) => FailureCause::Cause(cause.kind()),
                    (None, ContactStatus::NoContact) if r.iterations > 0 => FailureCause::LostContact,
                    _ => continue,
                };
                *causes[i].entry(kind).or_insert(0) += 1;
            }
        }
        DatasetSummary {
            header: self.header.clone(),
            per_object,
            causes,
            by_strategy,
        }
    }

    /// Writes the file format of the module docs atomically: a temporary file beside `path`,
    /// flushed to disk, then renamed over `path`.
    pub fn write(&self, path: &Path) -> Result<(), DatasetError> {
        let name = path.display().to_string();
        let io = |source| DatasetError::Io {
            path: name.clone(),
            source,
        };
        let file_header = FileHeader {
            header: self.header.clone(),
            readings: self.readings.len(),
        };
        let json = serde_json::to_string(&file_header)
            .map_err(|e| DatasetError::Invalid(format!("cannot encode the header: {e}")))?;
        let mut text = Vec::with_capacity(64 * (self.readings.len() + 1));
        writeln!(text, "{MAGIC}\n# {json}").map_err(io)?;
        {
            let mut csv = csv::WriterBuilder::new()
                .terminator(csv::Terminator::Any(b'\n'))
                .from_writer(&mut text);
            let csv_err = |e: csv::Error| DatasetError::Csv {
                path: name.clone(),
                line: 0,
                what: e.to_string(),
            };
            csv.write_record(column_names(self.header.sensor.rows, self.header.sensor.cols))
                .map_err(csv_err)?;
            let mut row: Vec<String> = Vec::new();
            for r in &self.readings {
                reading_row(r, &mut row);
                csv.write_record(&row).map_err(csv_err)?;
            }
            csv.flush().map_err(io)?;
        }
        writeln!(text, "{END_PREFIX}{}", self.readings.len()).map_err(io)?;
        Ok(write_atomic(path, &text)?)
    }

    /// Reads a file written by [`write`](Self::write); errors name the file, line and field.
    pub fn read(path: &Path) -> Result<Dataset, DatasetError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| DatasetError::Io {
            path: name.clone(),
            source,
        })?;
        let text = std::str::from_utf8(&bytes).map_err(|e| DatasetError::NotADataset {
            path: name.clone(),
            what: format!("not UTF-8 text ({e})"),
        })?;
        Self::parse(text, &name)
    }

    /// Parses the text of a dataset file; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Dataset, DatasetError> {
        let path = || origin.to_string();
        let mut lines = text.splitn(3, '\n');
        let magic = lines.next().unwrap_or_default();
        if magic.trim_end() != MAGIC {
            return Err(DatasetError::NotADataset {
                path: path(),
                what: format!(
                    "line 1 should be '{MAGIC}', found '{}'",
                    truncate_for_message(magic)
                ),
            });
        }
        let header_line = lines.next().ok_or_else(|| DatasetError::Truncated {
            path: path(),
            what: "the file ends after line 1 (no header)".into(),
        })?;
        let header = parse_header(header_line, origin)?;
        let body = lines.next().ok_or_else(|| DatasetError::Truncated {
            path: path(),
            what: "the file ends after the header (no column names)".into(),
        })?;
        let trailer = format!("{END_PREFIX}{}\n", header.readings);
        let Some(body) = body.strip_suffix(&trailer) else {
            return Err(DatasetError::Truncated {
                path: path(),
                what: format!(
                    "the last line should be '{}' (the header declares {} readings)",
                    trailer.trim_end(),
                    header.readings
                ),
            });
        };
        let FileHeader {
            header,
            readings: declared,
        } = header;
        let (rows, cols) = (header.sensor.rows, header.sensor.cols);
        let expected_columns = column_names(rows, cols);
        let mut csv = csv::ReaderBuilder::new()
            .has_headers(true)
            .flexible(true)
            .from_reader(body.as_bytes());
        // The CSV body starts on line 3 of the file.
        let file_line = |csv_line: u64| csv_line + 2;
        let columns = csv
            .headers()
            .map_err(|e| DatasetError::Csv {
                path: path(),
                line: 3,
                what: e.to_string(),
            })?
            .clone();
        if columns.len() != expected_columns.len()
            || columns.iter().zip(&expected_columns).any(|(a, b)| a != b)
        {
            let first_bad = columns.iter().zip(&expected_columns).position(|(a, b)| a != b);
            return Err(DatasetError::Header {
                path: path(),
                line: 3,
                what: match first_bad {
                    Some(i) => format!(
                        "column {} is '{}', expected '{}'",
                        i + 1,
                        &columns[i],
                        expected_columns[i]
                    ),
                    None => format!(
                        "{} column names, expected {} ({} + {rows}x{cols} taxels)",
                        columns.len(),
                        expected_columns.len(),
                        META_COLUMNS.len()
                    ),
                },
            });
        }
        let mut readings = Vec::with_capacity(declared);
        let mut record = csv::StringRecord::new();
        loop {
            let more = csv.read_record(&mut record).map_err(|e| DatasetError::Csv {
                path: path(),
                line: e.position().map_or(0, |p| file_line(p.line())),
                what: e.to_string(),
            })?;
            if !more {
                break;
            }
            let line = file_line(record.position().map_or(0, |p| p.line()));
            if record.len() != expected_columns.len() {
                return Err(DatasetError::ColumnCount {
                    path: path(),
                    line,
                    fields: record.len(),
                    expected: expected_columns.len(),
                    rows,
                    cols,
                });
            }
            let reading = parse_reading(&record, &header, &expected_columns).map_err(|(field, what)| {
                DatasetError::Field {
                    path: path(),
                    line,
                    field,
                    what,
                }
            })?;
            readings.push(reading);
        }
        if readings.len() != declared {
            return Err(DatasetError::Truncated {
                path: path(),
                what: format!(
                    "the header declares {declared} readings, the file has {}",
                    readings.len()
                ),
            });
        }
        Dataset::new(header, readings).map_err(|e| match e {
            DatasetError::Invalid(what) => DatasetError::Header {
                path: path(),
                line: 2,
                what,
            },
            other => other,
        })
    }
}

fn parse_header(line: &str, origin: &str) -> Result<FileHeader, DatasetError> {
    let header_err = |what: String| DatasetError::Header {
        path: origin.to_string(),
        line: 2,
        what,
    };
    let json = line
        .strip_prefix("# ")
        .ok_or_else(|| header_err("should start with '# ' then JSON".into()))?;
    let value: serde_json::Value =
        serde_json::from_str(json).map_err(|e| header_err(format!("bad JSON: {e}")))?;
    let version = value.get("format_version").and_then(serde_json::Value::as_u64);
    match version {
        Some(v) if v == u64::from(FORMAT_VERSION) => {}
        Some(found) => {
            return Err(DatasetError::Version {
                path: origin.to_string(),
                found,
                expected: FORMAT_VERSION,
            });
        }
        None => return Err(header_err("no unsigned integer 'format_version'".into())),
    }
    let header: FileHeader = serde_json::from_value(value).map_err(|e| header_err(e.to_string()))?;
    header.header.validate().map_err(header_err)?;
    Ok(header)
}

fn truncate_for_message(s: &str) -> String {
    s.chars().take(40).collect()
}

/// The column names of the module docs for a `rows x cols` sensor.
pub fn column_names(rows: usize, cols: usize) -> Vec<String> {
    let mut names: Vec<String> = META_COLUMNS.iter().map(|s| s.to_string()).collect();
    for r in 0..rows {
        for c in 0..cols {
            names.push(format!("t_{r}_{c}"));
        }
    }
    names
}

/// `v` in shortest round-trip form: plain decimals for ordinary magnitudes, exponent form for
/// tiny or huge ones (where plain decimals would run to hundreds of digits).
pub fn format_f64(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

fn reading_row(r: &Reading, row: &mut Vec<String>) {
    row.clear();
    row.push(r.object.clone());
    row.push(r.status.name().to_string());
    row.push(r.strategy.name().to_string());
    row.push(r.iterations.to_string());
    let p = &r.object_pose;
    let q = p.rotation;
    for v in [p.position_m.x, p.position_m.y, p.position_m.z, q.w, q.x, q.y, q.z] {
        row.push(format_f64(v));
    }
    match r.image.pose() {
        Some(pad) => {
            for v in [pad.center_m, pad.normal, pad.up]
                .iter()
                .flat_map(|v| v.to_array())
            {
                row.push(format_f64(v));
            }
        }
        None => row.extend(std::iter::repeat_n(String::new(), PAD_COLUMNS.len())),
    }
    row.push(r.cause.as_ref().map(AttemptCause::name).unwrap_or_default());
    row.extend(r.image.values().iter().map(|&v| format_f64(v)));
}

/// One record into a reading; the error names the field.
fn parse_reading(
    record: &csv::StringRecord,
    header: &DatasetHeader,
    columns: &[String],
) -> Result<Reading, (String, String)> {
    let field = |i: usize| (columns[i].clone(), record[i].to_string());
    let number = |i: usize| -> Result<f64, (String, String)> {
        let text = record[i].trim();
        let v: f64 = text
            .parse()
            .map_err(|_| (columns[i].clone(), format!("'{text}' is not a number")))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err((columns[i].clone(), format!("{v} is not finite")))
        }
    };
    let object = record[0].to_string();
    if header.object_index(&object).is_none() {
        let (f, v) = field(0);
        return Err((
            f,
            format!(
                "'{v}' is not one of the header's objects ({})",
                header.objects.join(", ")
            ),
        ));
    }
    let status = ContactStatus::from_name(&record[1]).ok_or_else(|| {
        let names: Vec<&str> = ContactStatus::ALL.iter().map(|s| s.name()).collect();
        (
            columns[1].clone(),
            format!(
                "unknown status '{}' (expected one of {})",
                &record[1],
                names.join(", ")
            ),
        )
    })?;
    let strategy = Strategy::from_name(&record[2]).ok_or_else(|| {
        let names: Vec<&str> = Strategy::ALL.iter().map(|s| s.name()).collect();
        (
            columns[2].clone(),
            format!(
                "unknown strategy '{}' (expected one of {})",
                &record[2],
                names.join(", ")
            ),
        )
    })?;
    let iterations: u32 = record[3].trim().parse().map_err(|_| {
        (
            columns[3].clone(),
            format!("'{}' is not a non-negative integer", &record[3]),
        )
    })?;
    let v = |a: usize| -> Result<DVec3, (String, String)> {
        Ok(DVec3::new(number(a)?, number(a + 1)?, number(a + 2)?))
    };
    let position_m = v(4)?;
    let rotation = DQuat::from_xyzw(number(8)?, number(9)?, number(10)?, number(7)?);
    let object_pose = Pose { position_m, rotation };
    let pad_empty: Vec<bool> = PAD_COLUMNS.map(|i| record[i].trim().is_empty()).collect();
    let pad = if pad_empty.iter().all(|&e| e) {
        None
    } else if let Some(k) = pad_empty.iter().position(|&e| e) {
        return Err((
            columns[PAD_COLUMNS.start + k].clone(),
            "empty, but other pad pose fields are set".into(),
        ));
    } else {
        Some(PadPose {
            center_m: v(11)?,
            normal: v(14)?,
            up: v(17)?,
        })
    };
    let cause_text = record[CAUSE_COLUMN].trim();
    let cause = if cause_text.is_empty() {
        None
    } else {
        Some(AttemptCause::from_name(cause_text).ok_or_else(|| {
            (
                columns[CAUSE_COLUMN].clone(),
                format!("'{cause_text}' is neither 'covering_meets_table' nor two bodies 'a/b'"),
            )
        })?)
    };
    let first_taxel = META_COLUMNS.len();
    let mut values = Vec::with_capacity(record.len() - first_taxel);
    for (i, column) in columns.iter().enumerate().take(record.len()).skip(first_taxel) {
        let value = number(i)?;
        if !(0.0..=1.0).contains(&value) {
            return Err((column.clone(), format!("{value} is outside [0, 1]")));
        }
        values.push(value);
    }
    let image = TactileImage::new(header.sensor.rows, header.sensor.cols, values)
        .map_err(|e| (columns[first_taxel].clone(), e.to_string()))?;
    let image = match pad {
        Some(pad) => image.with_pose(pad),
        None => image,
    };
    Ok(Reading {
        image,
        object,
        object_pose,
        status,
        iterations,
        strategy,
        cause,
    })
}

/// An object that got fewer converged readings than asked.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Shortfall {
    pub object: String,
    pub converged: usize,
    pub wanted: usize,
}

impl fmt::Display for Shortfall {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} of {}", self.object, self.converged, self.wanted)
    }
}

/// One line naming every short object, e.g. `2 objects got fewer converged readings than asked:
/// camel 3 of 10, homer 0 of 10`.
pub fn describe_shortfalls(shortfalls: &[Shortfall]) -> String {
    let list: Vec<String> = shortfalls.iter().map(Shortfall::to_string).collect();
    format!(
        "{} object{} got fewer converged readings than asked: {}",
        shortfalls.len(),
        if shortfalls.len() == 1 { "" } else { "s" },
        list.join(", ")
    )
}

/// Counts for `taction dataset show`.
#[derive(Debug, Clone, PartialEq)]
pub struct DatasetSummary {
    pub header: DatasetHeader,
    /// Per object (header order): readings by status.
    pub per_object: Vec<BTreeMap<ContactStatus, usize>>,
    /// Per object (header order): failed attempts by what ended them.
    pub causes: Vec<BTreeMap<FailureCause, usize>>,
    /// Readings by strategy name.
    pub by_strategy: BTreeMap<&'static str, usize>,
}

/// What ended a failed attempt, as `collect` and `dataset show` count them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FailureCause {
    /// A recorded [`AttemptCause`], by kind.
    Cause(CauseKind),
    /// `no_contact` after the controllers had pressed (Orient or Press lifted the pad off a narrow
    /// feature), as opposed to an Approach that met nothing.
    LostContact,
}

impl FailureCause {
    pub const ALL: [FailureCause; 6] = [
        Self::Cause(CauseKind::PadOnObject),
        Self::Cause(CauseKind::ArmOnObject),
        Self::Cause(CauseKind::ArmOnTable),
        Self::Cause(CauseKind::ArmOnArm),
        Self::Cause(CauseKind::CoveringOnTable),
        Self::LostContact,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Self::Cause(kind) => kind.name(),
            Self::LostContact => "lost_contact",
        }
    }
}

impl DatasetSummary {
    pub fn total(&self) -> usize {
        self.per_object.iter().flat_map(|m| m.values()).sum()
    }
}

impl fmt::Display for DatasetSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let h = &self.header;
        let s = &h.sensor;
        writeln!(
            f,
            "format version {}, object set '{}', generator '{}', seed {}",
            h.format_version, h.object_set, h.generator, h.seed
        )?;
        writeln!(
            f,
            "sensor: {}x{} taxels, pad {} x {}, covering {}, PSF sigma {}, {} rays/taxel ({}), noise {} (seed {})",
            s.rows,
            s.cols,
            crate::units::length(s.pad_width_m),
            crate::units::length(s.pad_height_m),
            crate::units::length(s.thickness_m),
            crate::units::length(s.psf_sigma_m),
            s.rays_per_taxel,
            match crate::tactile::config::rays_per_side(s.rays_per_taxel) {
                Some(k) => format!("{k}x{k} grid"),
                None => "not a square grid".to_string(),
            },
            crate::units::significant(s.noise_fraction),
            s.noise_seed
        )?;
        let width = h
            .objects
            .iter()
            .map(String::len)
            .max()
            .unwrap_or(0)
            .max("object".len());
        write!(f, "{:<width$} {:>8}", "object", "readings")?;
        for status in ContactStatus::ALL {
            write!(f, " {:>14}", status.name())?;
        }
        writeln!(f)?;
        let mut totals = [0usize; ContactStatus::ALL.len()];
        for (name, counts) in h.objects.iter().zip(&self.per_object) {
            write!(f, "{name:<width$} {:>8}", counts.values().sum::<usize>())?;
            for (i, status) in ContactStatus::ALL.iter().enumerate() {
                let n = counts.get(status).copied().unwrap_or(0);
                totals[i] += n;
                write!(f, " {n:>14}")?;
            }
            writeln!(f)?;
        }
        write!(f, "{:<width$} {:>8}", "total", self.total())?;
        for n in totals {
            write!(f, " {n:>14}")?;
        }
        writeln!(f)?;
        if self.causes.iter().any(|c| !c.is_empty()) {
            write!(f, "{:<width$} {:>8}", "causes", "")?;
            for cause in FailureCause::ALL {
                write!(f, " {:>17}", cause.name())?;
            }
            writeln!(f)?;
            for (name, counts) in h.objects.iter().zip(&self.causes) {
                write!(f, "{name:<width$} {:>8}", "")?;
                for cause in FailureCause::ALL {
                    write!(f, " {:>17}", counts.get(&cause).copied().unwrap_or(0))?;
                }
                writeln!(f)?;
            }
        }
        let strategies: Vec<String> = self.by_strategy.iter().map(|(k, v)| format!("{k} {v}")).collect();
        write!(
            f,
            "strategies: {}",
            if strategies.is_empty() {
                "none".to_string()
            } else {
                strategies.join(", ")
            }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sensor() -> SensorConfig {
        SensorConfig {
            rows: 2,
            cols: 3,
            pad_width_m: 0.012,
            pad_height_m: 0.012,
            thickness_m: 0.1 * 0.012,
            psf_sigma_m: 0.0005,
            rays_per_taxel: 4,
            noise_fraction: 0.1,
            noise_seed: 9,
        }
    }

    fn reading(object: &str, status: ContactStatus, k: f64, with_pad: bool) -> Reading {
        let values = vec![0.0, 1.0, 0.1 + 0.2, 1e-300, k / 7.0, 0.5];
        let mut image = TactileImage::new(2, 3, values).unwrap();
        if with_pad {
            image = image.with_pose(PadPose {
                center_m: DVec3::new(0.1, -0.0, 1e-17),
                normal: DVec3::Z,
                up: DVec3::Y,
            });
        }
        Reading {
            image,
            object: object.to_string(),
            object_pose: Pose {
                position_m: DVec3::new(k, 2.0 / 3.0, -1e20),
                rotation: DQuat::from_rotation_z(k),
            },
            status,
            iterations: k as u32,
            strategy: if with_pad {
                Strategy::Local
            } else {
                Strategy::Recorded
            },
            cause: (status == ContactStatus::Collision).then(|| AttemptCause::Touched {
                body_a: "link4".into(),
                body_b: "world".into(),
            }),
        }
    }

    fn dataset() -> Dataset {
        let header = DatasetHeader::new(sensor(), "toy", vec!["a,\"b\"".into(), "c".into()], "sampler", 42);
        Dataset::new(
            header,
            vec![
                reading("a,\"b\"", ContactStatus::Converged, 1.0, true),
                reading("c", ContactStatus::NoContact, 2.0, false),
                reading("c", ContactStatus::Converged, 3.0, true),
            ],
        )
        .unwrap()
    }

    fn text() -> String {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.csv");
        dataset().write(&path).unwrap();
        std::fs::read_to_string(path).unwrap()
    }

    fn parse_err(text: &str) -> String {
        Dataset::parse(text, "d.csv").unwrap_err().to_string()
    }

    #[test]
    fn write_then_read_is_bit_exact_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub").join("d.csv");
        let original = dataset();
        original.write(&path).unwrap();
        let back = Dataset::read(&path).unwrap();
        assert_eq!(back, original);
        let bits = |d: &Dataset| -> Vec<u64> {
            d.readings()
                .iter()
                .flat_map(|r| r.image.values().iter().map(|v| v.to_bits()))
                .collect()
        };
        assert_eq!(bits(&back), bits(&original));
        assert_eq!(
            back.readings()[0].image.pose().unwrap().center_m.y.to_bits(),
            (-0.0f64).to_bits()
        );
        let entries: Vec<_> = std::fs::read_dir(path.parent().unwrap()).unwrap().collect();
        assert_eq!(entries.len(), 1);
    }

    #[test]
    fn format_f64_round_trips_and_stays_short() {
        for v in [
            0.0,
            -0.0,
            1.0,
            0.1 + 0.2,
            1e-300,
            5e-324,
            1.7976931348623157e308,
            1e-5,
            9.999e-6,
            123456.789,
        ] {
            let s = format_f64(v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
            assert!(s.len() <= 24, "{s}");
        }
    }

    #[test]
    fn shortfalls_name_each_object_below_the_count() {
        let d = dataset();
        // "a,\"b\"" has one converged reading, "c" one of two.
        assert!(d.shortfalls(1).is_empty());
        let short = d.shortfalls(2);
        assert_eq!(short.len(), 2);
        assert_eq!(
            describe_shortfalls(&short),
            "2 objects got fewer converged readings than asked: a,\"b\" 1 of 2, c 1 of 2"
        );
    }

    #[test]
    fn converged_only_summary_and_grouping() {
        let d = dataset();
        assert_eq!(d.converged_only().len(), 2);
        let groups = d.by_object();
        assert_eq!((groups[0].len(), groups[1].len()), (1, 2));
        let s = d.summary();
        assert_eq!(s.total(), 3);
        assert_eq!(s.per_object[1][&ContactStatus::NoContact], 1);
        let shown = s.to_string();
        assert!(
            shown.contains("2x3 taxels") && shown.contains("no_contact") && shown.contains("local 2"),
            "{shown}"
        );
        // rays_per_taxel 4 is a 2x2 supersampling grid (it once printed as "4^2").
        assert!(shown.contains("4 rays/taxel (2x2 grid)"), "{shown}");
        let mut nine = s.clone();
        nine.header.sensor.rays_per_taxel = 9;
        assert!(nine.to_string().contains("9 rays/taxel (3x3 grid)"));
    }

    #[test]
    fn push_checks_object_and_shape() {
        let mut d = dataset();
        let e = d
            .push(reading("zebra", ContactStatus::Converged, 1.0, false))
            .unwrap_err()
            .to_string();
        assert!(e.contains("'zebra'"), "{e}");
        let mut bad = reading("c", ContactStatus::Converged, 1.0, false);
        bad.image = TactileImage::zeros(3, 2).unwrap();
        let e = d.push(bad).unwrap_err().to_string();
        assert!(e.contains("3x2") && e.contains("2x3"), "{e}");
        assert_eq!(d.len(), 3);
    }

    #[test]
    fn causes_round_trip_are_counted_and_a_bad_cause_is_named() {
        let mut d = dataset();
        d.push(reading("c", ContactStatus::Collision, 4.0, true)).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.csv");
        d.write(&path).unwrap();
        assert_eq!(Dataset::read(&path).unwrap(), d);
        let s = d.summary();
        // "c": the no_contact reading after 2 iterations lost contact; the collision is link4/world.
        assert_eq!(s.causes[1][&FailureCause::LostContact], 1);
        assert_eq!(s.causes[1][&FailureCause::Cause(CauseKind::ArmOnTable)], 1);
        assert!(s.causes[0].is_empty());
        assert!(s.to_string().contains("arm_on_table"), "{s}");
        let t = std::fs::read_to_string(&path).unwrap();
        let e = parse_err(&t.replace(",link4/world,", ",link4,"));
        assert!(
            e.contains("line 7") && e.contains("'cause'") && e.contains("'link4'"),
            "{e}"
        );
    }

    #[test]
    fn wrong_column_count_names_the_line() {
        let t = text();
        let lines: Vec<&str> = t.lines().collect();
        let short = lines[4].rsplit_once(',').unwrap().0;
        let broken = t.replace(lines[4], short);
        let e = parse_err(&broken);
        assert!(
            e.contains("d.csv: line 5") && e.contains("26 columns, expected 27 (21 + 2x3 taxels)"),
            "{e}"
        );
    }

    #[test]
    fn nan_taxel_names_the_line_and_field() {
        let t = text();
        let lines: Vec<&str> = t.lines().collect();
        let row = lines[3].rsplit_once(',').unwrap().0.to_string() + ",NaN";
        let e = parse_err(&t.replace(lines[3], &row));
        assert!(
            e.contains("line 4") && e.contains("'t_1_2'") && e.contains("not finite"),
            "{e}"
        );
        let row = lines[3].rsplit_once(',').unwrap().0.to_string() + ",1.5";
        let e = parse_err(&t.replace(lines[3], &row));
        assert!(e.contains("'t_1_2'") && e.contains("outside [0, 1]"), "{e}");
    }

    #[test]
    fn unknown_status_strategy_and_object_are_named() {
        let t = text();
        let e = parse_err(&t.replace(",no_contact,", ",slipped,"));
        assert!(
            e.contains("line 5") && e.contains("'status'") && e.contains("'slipped'"),
            "{e}"
        );
        let e = parse_err(&t.replace(",recorded,", ",teleport,"));
        assert!(e.contains("'strategy'") && e.contains("'teleport'"), "{e}");
        let e = parse_err(&t.replace("\nc,no_contact", "\nd,no_contact"));
        assert!(e.contains("'object'") && e.contains("'d'"), "{e}");
    }

    #[test]
    fn truncation_anywhere_is_detected() {
        let t = text();
        for cut in [t.len() - 1, t.len() - 12, t.len() / 2, t.find('\n').unwrap() + 5] {
            let e = Dataset::parse(&t[..cut], "d.csv").unwrap_err();
            assert!(
                matches!(e, DatasetError::Truncated { .. } | DatasetError::Header { .. }),
                "cut {cut}: {e}"
            );
        }
        let e = parse_err(&t.replace("# end 3", "# end 2"));
        assert!(e.contains("truncated"), "{e}");
        let dropped: String = {
            let lines: Vec<&str> = t.lines().collect();
            let mut kept: Vec<&str> = lines.clone();
            kept.remove(4);
            kept.join("\n") + "\n"
        };
        let e = parse_err(&dropped);
        assert!(e.contains("declares 3 readings, the file has 2"), "{e}");
    }

    #[test]
    fn wrong_version_and_wrong_magic_are_named() {
        let t = text();
        let e = Dataset::parse(
            &t.replace("\"format_version\":2", "\"format_version\":7"),
            "d.csv",
        )
        .unwrap_err();
        assert!(
            matches!(
                e,
                DatasetError::Version {
                    found: 7,
                    expected: 2,
                    ..
                }
            ),
            "{e}"
        );
        let e = parse_err(&t.replacen("# taction dataset", "object,status", 1));
        assert!(e.contains("not a taction dataset"), "{e}");
        let e = parse_err(&t.replace("t_0_1", "t_0_x"));
        assert!(e.contains("line 3") && e.contains("'t_0_x'"), "{e}");
    }
}
