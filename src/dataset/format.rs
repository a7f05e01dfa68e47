//! A dataset on disk (version 5).
//!
//! One UTF-8 text file, so a dataset is a single atomic unit (written to a temporary file in the
//! same folder, then renamed over the target) and any CSV reader can open it after skipping the
//! `#` lines:
//!
//! ```text
//! # taction dataset
//! # {"format_version":5,"sensor":{...},"object_set":"princeton","objects":["bunny",...],
//! #   "generator":"sampler","seed":7,"readings":11000}          <- one line of JSON
//! object,status,strategy,iterations,object_x_m,...,pad_up_z,cause,touched_bodies,object_after_x_m,...,object_after_qz,contact,t_0_0,...
//! bunny,converged,sampler,4,0.1,...,,,,,,,,,,-1,0,0.25,...
//! bunny,collision,sampler,3,0.1,...,pad_on_object,sensor/object,,,,,,,,-1,0,0.31,...
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
//!   (what ended the attempt, [`CauseKind::name`], the names `collect` and `dataset show` print:
//!   `pad_on_object`, `arm_on_object`, `arm_on_table`, `arm_on_arm` for a `collision` of rigid
//!   bodies, `covering_on_table` for a `collision` of the covering with the table, `lost_contact`
//!   for a `no_contact` after pressing, `physics_fault` for an `aborted` attempt; empty when the
//!   status says it all), `touched_bodies` (for the four touches, the two bodies as
//!   `arm_body/other_body`, e.g. `sensor/object`, `link4/world`, the table being `world`; empty
//!   otherwise), a free object's pose when the reading was taken `object_after_x_m, ...,
//!   object_after_qz` (the touch may have moved it from `object_x_m, ...`; all seven empty where the
//!   object is fixed, as the paper's is, so no touch moves it), `contact` (the press a recorded
//!   frame is one frame of, a number from 0, shared by the frames of one press: a sequence imported
//!   as one contact, `dataset import`; -1 for a reading that is a contact of its own, as every
//!   simulated reading is), then the `rows x cols` taxels row-major as `t_{row}_{col}`, row 0 being
//!   the pad's `+up` edge.
//! - Older versions are read and brought up to this one: version 4 had no `contact` (every
//!   reading its own contact); version 3 had no pose after the touch
//!   (its objects were all fixed); version 2 had no `touched_bodies`, its
//!   `cause` held the bodies themselves (`sensor/object`, now `pad_on_object` with those bodies) or
//!   `covering_meets_table` (now `covering_on_table`); version 1 had no `cause`. Neither wrote
//!   `lost_contact`, which is given to their `no_contact` rows with iterations.
//! - The last line, `# end N`, repeats the row count, so a file cut anywhere (even inside the
//!   last number) is reported as truncated rather than read short.
//! - Numbers are written in shortest round-trip form, so reading back is bit-exact.
//! - pandas reads it as `pandas.read_csv(path, comment="#")`: the `#` lines are skipped, a field
//!   holding a `#` (an object's name) is quoted so it is not cut there, and the empty fields
//!   (`cause`, `touched_bodies`, the pad pose of an image without one) read as NaN. For numpy
//!   arrays, or Parquet, see [`Dataset::export`].
//!
//! Size: about 20 bytes per taxel at worst, i.e. ~150 MB for 10 objects x 1100 readings of 26x26
//! and ~8 MB at 6x6; reading parses ~100 MB/s.

use std::io::Write;
use std::path::Path;

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

use crate::atomic::write_atomic;
use crate::dataset::{
    AttemptCause, CauseKind, ContactStatus, Dataset, DatasetError, DatasetHeader, Reading, Strategy,
};
use crate::pose::PadPose;
use crate::pose::Pose;
use crate::tactile::TactileImage;
use crate::valid::Check;

/// The file format version this build writes; it reads this one and every earlier one.
pub const FORMAT_VERSION: u32 = 5;

const MAGIC: &str = "# taction dataset";
const END_PREFIX: &str = "# end ";
/// The columns before the taxels, in file order: the one definition the writer and the reader
/// both follow (names by [`Meta::name`], positions by [`Meta::index`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Meta {
    Object,
    Status,
    Strategy,
    Iterations,
    ObjectX,
    ObjectY,
    ObjectZ,
    ObjectQw,
    ObjectQx,
    ObjectQy,
    ObjectQz,
    PadX,
    PadY,
    PadZ,
    PadNormalX,
    PadNormalY,
    PadNormalZ,
    PadUpX,
    PadUpY,
    PadUpZ,
    Cause,
    TouchedBodies,
    ObjectAfterX,
    ObjectAfterY,
    ObjectAfterZ,
    ObjectAfterQw,
    ObjectAfterQx,
    ObjectAfterQy,
    ObjectAfterQz,
    Contact,
}

impl Meta {
    pub(super) const ALL: [Meta; 30] = [
        Self::Object,
        Self::Status,
        Self::Strategy,
        Self::Iterations,
        Self::ObjectX,
        Self::ObjectY,
        Self::ObjectZ,
        Self::ObjectQw,
        Self::ObjectQx,
        Self::ObjectQy,
        Self::ObjectQz,
        Self::PadX,
        Self::PadY,
        Self::PadZ,
        Self::PadNormalX,
        Self::PadNormalY,
        Self::PadNormalZ,
        Self::PadUpX,
        Self::PadUpY,
        Self::PadUpZ,
        Self::Cause,
        Self::TouchedBodies,
        Self::ObjectAfterX,
        Self::ObjectAfterY,
        Self::ObjectAfterZ,
        Self::ObjectAfterQw,
        Self::ObjectAfterQx,
        Self::ObjectAfterQy,
        Self::ObjectAfterQz,
        Self::Contact,
    ];

    /// The columns before the taxels in a file of format `version` (a prefix of [`ALL`](Self::ALL):
    /// each version added columns at the end).
    pub(super) fn of_version(version: u32) -> &'static [Meta] {
        match version {
            1 => &Self::ALL[..=Self::PadUpZ.index()],
            2 => &Self::ALL[..=Self::Cause.index()],
            3 => &Self::ALL[..=Self::TouchedBodies.index()],
            4 => &Self::ALL[..=Self::ObjectAfterQz.index()],
            _ => &Self::ALL,
        }
    }

    /// The pad pose's nine columns, `pad_x_m` to `pad_up_z`: all set, or all empty (an image
    /// without a pose).
    pub(super) fn pad() -> &'static [Meta] {
        &Self::ALL[Self::PadX.index()..=Self::PadUpZ.index()]
    }

    /// The column's position in a row (the taxels follow at `Meta::ALL.len()`).
    pub(super) fn index(self) -> usize {
        self as usize
    }

    pub(super) fn name(self) -> &'static str {
        match self {
            Self::Object => "object",
            Self::Status => "status",
            Self::Strategy => "strategy",
            Self::Iterations => "iterations",
            Self::ObjectX => "object_x_m",
            Self::ObjectY => "object_y_m",
            Self::ObjectZ => "object_z_m",
            Self::ObjectQw => "object_qw",
            Self::ObjectQx => "object_qx",
            Self::ObjectQy => "object_qy",
            Self::ObjectQz => "object_qz",
            Self::PadX => "pad_x_m",
            Self::PadY => "pad_y_m",
            Self::PadZ => "pad_z_m",
            Self::PadNormalX => "pad_normal_x",
            Self::PadNormalY => "pad_normal_y",
            Self::PadNormalZ => "pad_normal_z",
            Self::PadUpX => "pad_up_x",
            Self::PadUpY => "pad_up_y",
            Self::PadUpZ => "pad_up_z",
            Self::Cause => "cause",
            Self::TouchedBodies => "touched_bodies",
            Self::ObjectAfterX => "object_after_x_m",
            Self::ObjectAfterY => "object_after_y_m",
            Self::ObjectAfterZ => "object_after_z_m",
            Self::ObjectAfterQw => "object_after_qw",
            Self::ObjectAfterQx => "object_after_qx",
            Self::ObjectAfterQy => "object_after_qy",
            Self::ObjectAfterQz => "object_after_qz",
            Self::Contact => "contact",
        }
    }

    /// The object pose's seven columns, `object_x_m` to `object_qz`.
    pub(super) fn object_pose() -> &'static [Meta] {
        &Self::ALL[Self::ObjectX.index()..=Self::ObjectQz.index()]
    }

    /// A free object's pose after the touch, seven columns `object_after_x_m` to
    /// `object_after_qz`: all set, or all empty (a fixed object).
    pub(super) fn object_pose_after() -> &'static [Meta] {
        &Self::ALL[Self::ObjectAfterX.index()..=Self::ObjectAfterQz.index()]
    }

    /// The columns that may be empty together: the pad's pose (an image without one) and the
    /// object's pose after the touch (a fixed object).
    pub(super) fn is_optional_pose(self) -> bool {
        Self::pad().contains(&self) || Self::object_pose_after().contains(&self)
    }

    /// This column of `r`, as written.
    pub(super) fn field(self, r: &Reading) -> String {
        match self {
            Self::Object => r.object.clone(),
            Self::Status => r.status.name().to_string(),
            Self::Strategy => r.strategy.name().to_string(),
            Self::Cause => r
                .cause
                .as_ref()
                .map(AttemptCause::name)
                .unwrap_or_default()
                .to_string(),
            Self::TouchedBodies => r
                .cause
                .as_ref()
                .and_then(AttemptCause::touched_bodies)
                .unwrap_or_default(),
            Self::Iterations | Self::Contact => self.integer(r).to_string(),
            _ => self.number(r).map(format_f64).unwrap_or_default(),
        }
    }

    /// This integer column of `r`: the iterations, or the contact (-1 for a reading that is a
    /// contact of its own); 0 for the other columns.
    pub(super) fn integer(self, r: &Reading) -> i64 {
        match self {
            Self::Iterations => i64::from(r.iterations),
            Self::Contact => r.contact_number(),
            _ => 0,
        }
    }

    /// This pose column of `r` as a number: `None` for a pad pose column of an image without a
    /// pose, for the pose after the touch of a fixed object, and for the columns that are not
    /// poses.
    pub(super) fn number(self, r: &Reading) -> Option<f64> {
        let position = r.object_pose.position_m;
        let rotation = r.object_pose.rotation;
        let pad = |value: fn(&PadPose) -> f64| r.image.pose().map(value);
        let after = |value: fn(&Pose) -> f64| r.object_pose_after.as_ref().map(value);
        match self {
            Self::ObjectX => Some(position.x),
            Self::ObjectY => Some(position.y),
            Self::ObjectZ => Some(position.z),
            Self::ObjectQw => Some(rotation.w),
            Self::ObjectQx => Some(rotation.x),
            Self::ObjectQy => Some(rotation.y),
            Self::ObjectQz => Some(rotation.z),
            Self::PadX => pad(|p| p.center_m.x),
            Self::PadY => pad(|p| p.center_m.y),
            Self::PadZ => pad(|p| p.center_m.z),
            Self::PadNormalX => pad(|p| p.normal.x),
            Self::PadNormalY => pad(|p| p.normal.y),
            Self::PadNormalZ => pad(|p| p.normal.z),
            Self::PadUpX => pad(|p| p.up.x),
            Self::PadUpY => pad(|p| p.up.y),
            Self::PadUpZ => pad(|p| p.up.z),
            Self::ObjectAfterX => after(|p| p.position_m.x),
            Self::ObjectAfterY => after(|p| p.position_m.y),
            Self::ObjectAfterZ => after(|p| p.position_m.z),
            Self::ObjectAfterQw => after(|p| p.rotation.w),
            Self::ObjectAfterQx => after(|p| p.rotation.x),
            Self::ObjectAfterQy => after(|p| p.rotation.y),
            Self::ObjectAfterQz => after(|p| p.rotation.z),
            Self::Object
            | Self::Status
            | Self::Strategy
            | Self::Iterations
            | Self::Cause
            | Self::TouchedBodies
            | Self::Contact => None,
        }
    }
}

/// The on-disk header line: the header plus the row count.
#[derive(Serialize, Deserialize)]
struct FileHeader {
    #[serde(flatten)]
    header: DatasetHeader,
    readings: usize,
}

impl Dataset {
    /// Writes the file format of the module docs atomically: a temporary file beside `path`,
    /// flushed to disk, then renamed over `path`.
    pub fn write(&self, path: &Path) -> Result<(), DatasetError> {
        let text = self.to_file_bytes(&path.display().to_string())?;
        Ok(write_atomic(path, &text)?)
    }

    /// The bytes [`write`](Self::write) puts in a file (what `Dataset.to_pandas` in Python parses
    /// as `pandas.read_csv(..., comment="#")` would); `name` names the destination in errors.
    pub fn to_file_bytes(&self, name: &str) -> Result<Vec<u8>, DatasetError> {
        let io = |source| DatasetError::Io {
            path: name.to_string(),
            source,
        };
        let json = self.header_json()?;
        let mut text = Vec::with_capacity(64 * (self.readings.len() + 1));
        writeln!(text, "{MAGIC}\n# {json}").map_err(io)?;
        {
            let mut csv = csv::WriterBuilder::new()
                .terminator(csv::Terminator::Any(b'\n'))
                .comment(Some(b'#'))
                .from_writer(&mut text);
            let csv_err = |e: csv::Error| DatasetError::Csv {
                path: name.to_string(),
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
        Ok(text)
    }

    /// The header as line 2 of the file holds it (after `# `): the [`DatasetHeader`] as JSON,
    /// plus `readings`, the number of readings.
    pub(super) fn header_json(&self) -> Result<String, DatasetError> {
        let file_header = FileHeader {
            header: self.header.clone(),
            readings: self.readings.len(),
        };
        serde_json::to_string(&file_header)
            .map_err(|e| DatasetError::Invalid(format!("cannot encode the header: {e}")))
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

    /// The format version the file at `path` was written in. Reading brings an older file's header
    /// up to this build's version, so `header().format_version` of what [`read`](Self::read)
    /// returns is always [`FORMAT_VERSION`]; `taction dataset show` tells both.
    pub fn file_format_version(path: &Path) -> Result<u32, DatasetError> {
        use std::io::BufRead;
        let name = path.display().to_string();
        let io = |source| DatasetError::Io {
            path: name.clone(),
            source,
        };
        let mut head = String::new();
        let mut reader = std::io::BufReader::new(std::fs::File::open(path).map_err(io)?);
        for _ in 0..2 {
            reader.read_line(&mut head).map_err(io)?;
        }
        let (header_line, _) = split_magic_and_header(head.trim_end_matches('\n'), &name)?;
        parse_header(header_line, &name).map(|(_, version)| version)
    }

    /// Parses the text of a dataset file; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Dataset, DatasetError> {
        let path = || origin.to_string();
        let (header_line, body) = split_magic_and_header(text, origin)?;
        let (header, version) = parse_header(header_line, origin)?;
        let body = body.ok_or_else(|| DatasetError::Truncated {
            path: path(),
            what: "the file ends after the header (no column names)".into(),
        })?;
        let body = strip_trailer(body, header.readings, origin)?;
        let FileHeader {
            header,
            readings: declared,
        } = header;
        let readings = parse_body(body, &header, version, declared, origin)?;
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
            DatasetError::InvalidHeader(e) => DatasetError::Header {
                path: path(),
                line: 2,
                what: e.to_string(),
            },
            other => other,
        })
    }
}

/// The header line after the magic line, and the rest of the file (`None`: nothing after the
/// header line).
fn split_magic_and_header<'t>(
    text: &'t str,
    origin: &str,
) -> Result<(&'t str, Option<&'t str>), DatasetError> {
    let mut lines = text.splitn(3, '\n');
    let magic = lines.next().unwrap_or_default();
    if magic.trim_end() != MAGIC {
        return Err(DatasetError::NotADataset {
            path: origin.to_string(),
            what: format!(
                "line 1 should be '{MAGIC}', found '{}'",
                truncate_for_message(magic)
            ),
        });
    }
    let header_line = lines.next().ok_or_else(|| DatasetError::Truncated {
        path: origin.to_string(),
        what: "the file ends after line 1 (no header)".into(),
    })?;
    Ok((header_line, lines.next()))
}

/// `body` without its last line, which must declare the header's `declared` readings.
fn strip_trailer<'t>(body: &'t str, declared: usize, origin: &str) -> Result<&'t str, DatasetError> {
    let trailer = format!("{END_PREFIX}{declared}\n");
    body.strip_suffix(&trailer)
        .ok_or_else(|| DatasetError::Truncated {
            path: origin.to_string(),
            what: format!(
                "the last line should be '{}' (the header declares {declared} readings)",
                trailer.trim_end()
            ),
        })
}

/// The readings of the CSV `body` (column names, then one row a reading) of a file of format
/// `version`; errors name the file's line (the body starts on line 3).
fn parse_body(
    body: &str,
    header: &DatasetHeader,
    version: u32,
    declared: usize,
    origin: &str,
) -> Result<Vec<Reading>, DatasetError> {
    let path = || origin.to_string();
    let (rows, cols) = (header.sensor.rows, header.sensor.cols);
    let metas = Meta::of_version(version);
    let expected_columns = columns_of(metas, rows, cols);
    let mut csv = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_reader(body.as_bytes());
    let file_line = |csv_line: u64| csv_line + 2;
    let columns = csv
        .headers()
        .map_err(|e| DatasetError::Csv {
            path: path(),
            line: 3,
            what: e.to_string(),
        })?
        .clone();
    check_column_names(&columns, &expected_columns, (metas.len(), rows, cols), origin)?;
    let mut readings = Vec::with_capacity(declared);
    let mut record = csv::StringRecord::new();
    while csv.read_record(&mut record).map_err(|e| DatasetError::Csv {
        path: path(),
        line: e.position().map_or(0, |p| file_line(p.line())),
        what: e.to_string(),
    })? {
        let line = file_line(record.position().map_or(0, |p| p.line()));
        if record.len() != expected_columns.len() {
            return Err(DatasetError::ColumnCount {
                path: path(),
                line,
                fields: record.len(),
                expected: expected_columns.len(),
                meta: metas.len(),
                rows,
                cols,
            });
        }
        let row = Row {
            record: &record,
            columns: &expected_columns,
            version,
        };
        let reading = parse_reading(&row, header).map_err(|(field, what)| DatasetError::Field {
            path: path(),
            line,
            field,
            what,
        })?;
        readings.push(reading);
    }
    Ok(readings)
}

/// The body's column names against this version's (`layout`: the columns before the taxels,
/// then the sensor's rows and columns): the first that differs, or the count.
fn check_column_names(
    columns: &csv::StringRecord,
    expected: &[String],
    layout: (usize, usize, usize),
    origin: &str,
) -> Result<(), DatasetError> {
    if columns.len() == expected.len() && columns.iter().zip(expected).all(|(a, b)| a == b) {
        return Ok(());
    }
    let (meta, rows, cols) = layout;
    let first_bad = columns.iter().zip(expected).position(|(a, b)| a != b);
    Err(DatasetError::Header {
        path: origin.to_string(),
        line: 3,
        what: match first_bad {
            Some(i) => format!(
                "column {} is '{}', expected '{}'",
                i + 1,
                &columns[i],
                expected[i]
            ),
            None => format!(
                "{} column names, expected {} ({meta} + {rows}x{cols} taxels)",
                columns.len(),
                expected.len(),
            ),
        },
    })
}

/// The header line and the file's format version; an older version's header is brought up to this
/// one (its rows are read by their own version's layout).
fn parse_header(line: &str, origin: &str) -> Result<(FileHeader, u32), DatasetError> {
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
    let version = match value.get("format_version").and_then(serde_json::Value::as_u64) {
        Some(v) if (1..=u64::from(FORMAT_VERSION)).contains(&v) => v as u32,
        Some(found) => {
            return Err(DatasetError::Version {
                path: origin.to_string(),
                found,
                expected: FORMAT_VERSION,
            });
        }
        None => return Err(header_err("no unsigned integer 'format_version'".into())),
    };
    let mut header: FileHeader = serde_json::from_value(value).map_err(|e| header_err(e.to_string()))?;
    header.header.format_version = FORMAT_VERSION;
    header.header.check().map_err(|e| header_err(e.to_string()))?;
    Ok((header, version))
}

fn truncate_for_message(s: &str) -> String {
    s.chars().take(40).collect()
}

/// The column names of the module docs for a `rows x cols` sensor.
pub fn column_names(rows: usize, cols: usize) -> Vec<String> {
    columns_of(&Meta::ALL, rows, cols)
}

/// The names of `metas`, then the taxels of a `rows x cols` sensor.
fn columns_of(metas: &[Meta], rows: usize, cols: usize) -> Vec<String> {
    let mut names: Vec<String> = metas.iter().map(|m| m.name().to_string()).collect();
    for r in 0..rows {
        for c in 0..cols {
            names.push(format!("t_{r}_{c}"));
        }
    }
    names
}

pub(crate) use crate::units::round_trip as format_f64;

fn reading_row(r: &Reading, row: &mut Vec<String>) {
    row.clear();
    row.extend(Meta::ALL.iter().map(|m| m.field(r)));
    row.extend(r.image.values().iter().map(|&v| format_f64(v)));
}

/// One CSV record of a file of format `version`, read by column; errors are `(column name, what is
/// wrong)`.
struct Row<'a> {
    record: &'a csv::StringRecord,
    columns: &'a [String],
    version: u32,
}

impl Row<'_> {
    /// The column's text; empty for a column the file's version did not have.
    fn text(&self, column: Meta) -> &str {
        match column.index() < self.first_taxel() {
            true => &self.record[column.index()],
            false => "",
        }
    }

    /// Where the taxels begin.
    fn first_taxel(&self) -> usize {
        Meta::of_version(self.version).len()
    }

    fn error(&self, index: usize, what: String) -> (String, String) {
        (self.columns[index].clone(), what)
    }

    fn number_at(&self, index: usize) -> Result<f64, (String, String)> {
        let text = self.record[index].trim();
        let v: f64 = text
            .parse()
            .map_err(|_| self.error(index, format!("'{text}' is not a number")))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.error(index, format!("{v} is not finite")))
        }
    }

    fn number(&self, column: Meta) -> Result<f64, (String, String)> {
        self.number_at(column.index())
    }

    fn vector(&self, [x, y, z]: [Meta; 3]) -> Result<DVec3, (String, String)> {
        Ok(DVec3::new(self.number(x)?, self.number(y)?, self.number(z)?))
    }

    /// An object pose from its seven `columns`: x, y, z (metres), qw, qx, qy, qz.
    fn pose(&self, columns: &[Meta]) -> Result<Pose, (String, String)> {
        let n = |i: usize| self.number(columns[i]);
        Ok(Pose {
            position_m: DVec3::new(n(0)?, n(1)?, n(2)?),
            rotation: DQuat::from_xyzw(n(4)?, n(5)?, n(6)?, n(3)?),
        })
    }

    /// The column's text as `parse` reads it, or an error listing the `name`s of `all` (built only
    /// then: this runs for every row of a dataset).
    fn named<T: Copy>(
        &self,
        column: Meta,
        what: &str,
        parse: fn(&str) -> Option<T>,
        (all, name): (&[T], fn(T) -> &'static str),
    ) -> Result<T, (String, String)> {
        let text = self.text(column);
        parse(text).ok_or_else(|| {
            let names: Vec<&str> = all.iter().map(|&v| name(v)).collect();
            self.error(
                column.index(),
                format!("unknown {what} '{text}' (expected one of {})", names.join(", ")),
            )
        })
    }
}

/// One record into a reading; the error names the field.
fn parse_reading(row: &Row, header: &DatasetHeader) -> Result<Reading, (String, String)> {
    let object = row.text(Meta::Object).to_string();
    if header.object_index(&object).is_none() {
        return Err(row.error(
            Meta::Object.index(),
            format!(
                "'{object}' is not one of the header's objects ({})",
                header.objects.join(", ")
            ),
        ));
    }
    let status = row.named(
        Meta::Status,
        "status",
        ContactStatus::from_name,
        (&ContactStatus::ALL, ContactStatus::name),
    )?;
    let strategy = row.named(
        Meta::Strategy,
        "strategy",
        Strategy::from_name,
        (&Strategy::ALL, Strategy::name),
    )?;
    let iterations: u32 = row.text(Meta::Iterations).trim().parse().map_err(|_| {
        row.error(
            Meta::Iterations.index(),
            format!("'{}' is not a non-negative integer", row.text(Meta::Iterations)),
        )
    })?;
    let object_pose = row.pose(Meta::object_pose())?;
    let object_pose_after = match row.version {
        ..=3 => None,
        _ if all_empty(row, Meta::object_pose_after())? => None,
        _ => Some(row.pose(Meta::object_pose_after())?),
    };
    let pad = parse_pad_pose(row)?;
    let cause = parse_cause(row, status, iterations)?;
    let contact = parse_contact(row)?;
    let image = parse_image(row, header)?;
    let image = match pad {
        Some(pad) => image.with_pose(pad),
        None => image,
    };
    Ok(Reading {
        image,
        object,
        object_pose,
        object_pose_after,
        status,
        iterations,
        strategy,
        cause,
        contact,
    })
}

/// The row's contact: a number from 0, or -1 for a reading that is a contact of its own (as is
/// every row of a file before version 5, which has no such column).
fn parse_contact(row: &Row) -> Result<Option<u32>, (String, String)> {
    match row.text(Meta::Contact).trim() {
        "-1" => Ok(None),
        "" if row.version < 5 => Ok(None),
        text => text.parse().map(Some).map_err(|_| {
            row.error(
                Meta::Contact.index(),
                format!("'{text}' is not a contact number (an integer from 0, or -1 for none)"),
            )
        }),
    }
}

/// Whether the row's `columns` are all empty; an error names the first empty one when only some
/// are (a pose is whole, or absent).
fn all_empty(row: &Row, columns: &[Meta]) -> Result<bool, (String, String)> {
    let is_empty = |column: &&Meta| row.text(**column).trim().is_empty();
    if columns.iter().all(|column| is_empty(&column)) {
        return Ok(true);
    }
    match columns.iter().find(is_empty) {
        Some(column) => Err(row.error(
            column.index(),
            "empty, but other fields of its pose are set".into(),
        )),
        None => Ok(false),
    }
}

/// The row's pad pose: its nine columns all set, or all empty (`None`: an image without a pose).
fn parse_pad_pose(row: &Row) -> Result<Option<PadPose>, (String, String)> {
    if all_empty(row, Meta::pad())? {
        return Ok(None);
    }
    Ok(Some(PadPose {
        center_m: row.vector([Meta::PadX, Meta::PadY, Meta::PadZ])?,
        normal: row.vector([Meta::PadNormalX, Meta::PadNormalY, Meta::PadNormalZ])?,
        up: row.vector([Meta::PadUpX, Meta::PadUpY, Meta::PadUpZ])?,
    }))
}

/// The row's taxels, each in [0, 1], as an image of the header's sensor shape.
fn parse_image(row: &Row, header: &DatasetHeader) -> Result<TactileImage, (String, String)> {
    let len = row.record.len();
    let first_taxel = row.first_taxel();
    let mut values = Vec::with_capacity(len - first_taxel);
    for i in first_taxel..len {
        let value = row.number_at(i)?;
        if !(0.0..=1.0).contains(&value) {
            return Err(row.error(i, format!("{value} is outside [0, 1]")));
        }
        values.push(value);
    }
    TactileImage::new(header.sensor.rows, header.sensor.cols, values)
        .map_err(|e| row.error(first_taxel, e.to_string()))
}

/// The row's cause, in this format's vocabulary whatever the file's version (see the module docs).
fn parse_cause(
    row: &Row,
    status: ContactStatus,
    iterations: u32,
) -> Result<Option<AttemptCause>, (String, String)> {
    let cause = row.text(Meta::Cause).trim();
    match row.version {
        1 => Ok(Reading::inferred_cause(status, iterations)),
        2 if cause.is_empty() => Ok(Reading::inferred_cause(status, iterations)),
        2 => AttemptCause::from_format_2(cause).map(Some).ok_or_else(|| {
            row.error(
                Meta::Cause.index(),
                format!("'{cause}' is neither 'covering_meets_table' nor two bodies 'a/b' (format 2)"),
            )
        }),
        _ => {
            let bodies = row.text(Meta::TouchedBodies).trim();
            AttemptCause::from_columns(cause, bodies).map_err(|what| {
                // A known cause (or none) is right; its bodies are not.
                let column = match cause.is_empty() || CauseKind::from_name(cause).is_some() {
                    true => Meta::TouchedBodies,
                    false => Meta::Cause,
                };
                row.error(column.index(), what)
            })
        }
    }
}
