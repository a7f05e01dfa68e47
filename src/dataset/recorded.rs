//! Recorded readings of a real tactile sensor (Sec. V-E, V-F), imported from CSV: the counterpart
//! of the dataset format for frames that no simulation produced. The experiments on recorded frames
//! read them here (`paper::real_frames`, `sim-to-real`); [`RealData::to_dataset`] files them as a
//! [`Dataset`] of [`Strategy::Recorded`] readings, which `taction dataset import` writes so that
//! `train` and `recognize` take real data.
//!
//! # Format
//!
//! One frame per line. The first line that is not a comment is the header: `label` followed by one
//! column per taxel, named `r<row>c<col>` (0-based) in row-major order, which fixes the frame size:
//!
//! ```text
//! # comment lines start with '#'
//! label,r0c0,r0c1,...,r0c5,r1c0,...,r5c5
//! A,0,12,873,901,15,0,...
//! ```
//!
//! - `label`: the object the frame was taken from (e.g. `A`); non-empty. When the importer is given
//!   a set of allowed labels, any other label is an error.
//! - `contact` (optional, right after `label`: `label,contact,r0c0,...`): the press a frame was
//!   taken in, any name (`17`, `press-3`), for recordings that keep several frames across one
//!   press (a sequence). Frames of one label with the same name are one contact's frames and stay
//!   together, never split between training and test; they must be consecutive lines (a press is
//!   recorded in one go), a name coming back after other frames is an error. An empty field: the
//!   frame is a contact of its own, as every frame of a file without the column is. Contacts are
//!   numbered from 0 in the order of their first frame ([`RealReading::contact`]).
//! - taxel values: raw sensor units (any scale), finite and non-negative; row 0 is the pad's `up`
//!   edge, column 0 its left edge, as in [`TactileImage`].
//! - lines are frames in collection order (Fig. 17b uses that order); fields are separated by commas
//!   and trimmed, without quoting; blank lines and lines starting with `#` are skipped.
//! - a comment line starting with `# SYNTHETIC` says the frames are made up, not recorded (the
//!   shipped `data/real_letters_example.csv`): [`RealData::synthetic`], so that plots of them do not
//!   speak of a real sensor.
//!
//! Sensors of [`MIN_TAXELS_PER_SIDE`] to [`MAX_TAXELS_PER_SIDE`] taxels per side are accepted,
//! square or not (the paper's PPS sensor is 6x6; Sec. V-C compares 6x6 to 26x26; arrays on
//! grippers are often 16x16 to 44x44, or 28x50). Frames kept as a folder of class folders of
//! images or as an `.npz` are read by `frame_files.rs` into the same [`RealData`].
//!
//! When a per-taxel [`Calibration`] is given, every raw value `v` of taxel `(i, j)` first becomes
//! `gain(i, j) * (v - offset(i, j))`, clamped at 0 (a taxel reading below its no-load offset
//! carries no pressure), so that elements of different sensitivity read alike (Sec. V-F: the
//! real elements differ from each other). Without one, raw values must be non-negative.
//!
//! Import then divides every value by one number so that frames land in [0, 1] of the sensing
//! range ([`Normalisation`]): the largest value in the file, or a given range (`--range`), above
//! which a value is an error. Errors name the file, the line and the column.
//!
//! # Calibration format
//!
//! ```text
//! # comment lines start with '#'
//! taxel,gain,offset
//! r0c0,1.02,13
//! r0c1,0.97,9
//! ...
//! ```
//!
//! One line per taxel of the recording's grid, each taxel exactly once (any order); `gain` finite
//! and non-negative, `offset` finite, both in raw units of the recording.

use std::collections::BTreeSet;
use std::fmt;
use std::ops::RangeInclusive;
use std::path::Path;

use crate::dataset::{ContactStatus, Dataset, DatasetError, DatasetHeader, PadSize, Reading, Strategy};
use crate::pose::Pose;
use crate::tactile::{SensorConfig, TactileImage};
use crate::valid::checked_f64;

/// The comment that marks a file of made-up frames (module docs).
pub const SYNTHETIC_MARK: &str = "# SYNTHETIC";

/// How raw sensor units become fractions of the sensing range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Normalisation {
    /// Divide by the largest value in the file (the file's strongest reading becomes 1).
    FileMax,
    /// Divide by this full-scale value, in raw units; it must be finite and positive.
    Range(f64),
}

/// A `--range` that is neither `max` nor a full-scale value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("'{0}' is neither 'max' nor a finite positive full-scale value")]
pub struct NormalisationError(pub String);

impl std::str::FromStr for Normalisation {
    type Err = NormalisationError;

    /// `max` for [`Normalisation::FileMax`], or a full-scale value in raw units for
    /// [`Normalisation::Range`] (the `--range` flag).
    fn from_str(s: &str) -> Result<Self, NormalisationError> {
        if s.trim() == "max" {
            return Ok(Self::FileMax);
        }
        match s.trim().parse::<f64>() {
            Ok(range) if range.is_finite() && range > 0.0 => Ok(Self::Range(range)),
            _ => Err(NormalisationError(s.to_string())),
        }
    }
}

/// The smallest sensor side accepted, in taxels: a 2x2 grid still has a centre of pressure and a
/// spread, what every descriptor needs.
pub const MIN_TAXELS_PER_SIDE: usize = 2;
/// The largest sensor side accepted, in taxels: large resistive and capacitive arrays on grippers
/// (32x32, 44x44, 28x50) fit with room to spare.
pub const MAX_TAXELS_PER_SIDE: usize = 128;
/// The accepted sensor sides, in taxels.
pub const TAXELS_PER_SIDE: RangeInclusive<usize> = MIN_TAXELS_PER_SIDE..=MAX_TAXELS_PER_SIDE;

/// Import settings.
#[derive(Debug, Clone, PartialEq)]
pub struct RealImport {
    pub normalisation: Normalisation,
    /// When set, the only labels accepted.
    pub allowed_labels: Option<BTreeSet<String>>,
    /// Per-taxel gain and offset applied to raw values before normalisation.
    pub calibration: Option<Calibration>,
}

impl Default for RealImport {
    fn default() -> Self {
        Self {
            normalisation: Normalisation::FileMax,
            allowed_labels: None,
            calibration: None,
        }
    }
}

/// Per-taxel gain and offset of a recording (format in the module docs), row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// Where it came from, for errors.
    pub origin: String,
    pub rows: usize,
    pub cols: usize,
    pub gain: Vec<f64>,
    pub offset: Vec<f64>,
}

/// A calibration line `r<row>c<col>,gain,offset` as `(line, row, col, gain, offset)`; the gain
/// must not be negative.
fn parse_calibration_line(
    record: &[&str],
    line: u64,
    origin: &str,
) -> Result<(u64, usize, usize, f64, f64), RealDataError> {
    let invalid = |what: String| RealDataError::Invalid {
        origin: origin.to_string(),
        line,
        what,
    };
    if record.len() != 3 {
        return Err(invalid(format!(
            "{} columns, expected 3 (taxel,gain,offset)",
            record.len()
        )));
    }
    let (row, col) = parse_taxel_name(record[0])
        .ok_or_else(|| invalid(format!("taxel '{}' is not r<row>c<col>", record[0])))?;
    let number = |column: &str, text: &str| -> Result<f64, RealDataError> {
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(invalid(format!("{column} '{text}' is not a finite number"))),
        }
    };
    let gain = number("gain", record[1])?;
    if gain < 0.0 {
        return Err(invalid(format!("gain {gain} is negative")));
    }
    let offset = number("offset", record[2])?;
    Ok((line, row, col, gain, offset))
}

impl Calibration {
    /// Reads a calibration file.
    pub fn read(path: &Path) -> Result<Self, RealDataError> {
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| RealDataError::Io {
            origin: origin.clone(),
            source,
        })?;
        Self::parse(&text, &origin)
    }

    /// Parses calibration text; `origin` names the source in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self, RealDataError> {
        let invalid = |line: u64, what: String| RealDataError::Invalid {
            origin: origin.to_string(),
            line,
            what,
        };
        let mut header_seen = false;
        let mut entries: Vec<(u64, usize, usize, f64, f64)> = Vec::new();
        for (line, record) in records(text) {
            if !header_seen {
                if record != ["taxel", "gain", "offset"] {
                    return Err(RealDataError::Header {
                        origin: origin.to_string(),
                        line,
                        what: format!("expected 'taxel,gain,offset', got '{}'", record.join(",")),
                    });
                }
                header_seen = true;
                continue;
            }
            entries.push(parse_calibration_line(&record, line, origin)?);
        }
        if !header_seen {
            return Err(RealDataError::NoHeader {
                origin: origin.to_string(),
            });
        }
        if entries.is_empty() {
            return Err(invalid(
                text.lines().count() as u64,
                "no taxel lines after the header".to_string(),
            ));
        }
        Self::from_entries(&entries, origin)
    }

    /// The calibration of the grid `entries` fill (`(line, row, col, gain, offset)`): each taxel
    /// listed once, none missing.
    fn from_entries(entries: &[(u64, usize, usize, f64, f64)], origin: &str) -> Result<Self, RealDataError> {
        let invalid = |line: u64, what: String| RealDataError::Invalid {
            origin: origin.to_string(),
            line,
            what,
        };
        let rows = entries.iter().map(|e| e.1).max().unwrap_or(0) + 1;
        let cols = entries.iter().map(|e| e.2).max().unwrap_or(0) + 1;
        let mut gain = vec![f64::NAN; rows * cols];
        let mut offset = vec![f64::NAN; rows * cols];
        for &(line, row, col, g, o) in entries {
            let k = row * cols + col;
            if !gain[k].is_nan() {
                return Err(invalid(line, format!("taxel r{row}c{col} is listed twice")));
            }
            gain[k] = g;
            offset[k] = o;
        }
        if let Some(k) = gain.iter().position(|g| g.is_nan()) {
            return Err(RealDataError::Invalid {
                origin: origin.to_string(),
                line: entries.last().map_or(0, |e| e.0),
                what: format!(
                    "taxel r{}c{} is missing ({rows}x{cols} grid, every taxel needs a line)",
                    k / cols,
                    k % cols
                ),
            });
        }
        Ok(Self {
            origin: origin.to_string(),
            rows,
            cols,
            gain,
            offset,
        })
    }

    /// `gain * (raw - offset)` of taxel `k` (row-major), clamped at 0.
    fn apply(&self, k: usize, raw: f64) -> f64 {
        (self.gain[k] * (raw - self.offset[k])).max(0.0)
    }
}

/// `r<row>c<col>` as (row, col).
fn parse_taxel_name(name: &str) -> Option<(usize, usize)> {
    let (r, c) = name.strip_prefix('r')?.split_once('c')?;
    Some((r.parse().ok()?, c.parse().ok()?))
}

/// Where in its source a frame came from, as messages name it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FramePlace {
    /// A line of a frames CSV (1-based).
    Line(u64),
    /// The index of a frame in an `.npz`'s frames array (0-based, as numpy indexes it).
    Frame(usize),
    /// An image file of a folder of class folders, as a path below that folder (`A/003.png`).
    Image(String),
}

impl fmt::Display for FramePlace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Line(line) => write!(f, "line {line}"),
            Self::Frame(index) => write!(f, "frame {index}"),
            Self::Image(path) => f.write_str(path),
        }
    }
}

/// One imported frame.
#[derive(Debug, Clone, PartialEq)]
pub struct RealReading {
    pub label: String,
    /// Where in the source it came from.
    pub place: FramePlace,
    /// The contact (press) this frame is one of, numbered from 0 in the order of the contacts'
    /// first frames, when the source groups frames into contacts (module docs); `None`: a contact
    /// of its own.
    pub contact: Option<u32>,
    /// Values normalised to [0, 1]; no pad pose (a recording has none).
    pub image: TactileImage,
}

/// An imported file: frames of `rows x cols` taxels in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct RealData {
    pub rows: usize,
    pub cols: usize,
    pub readings: Vec<RealReading>,
    /// The file says its frames are made up ([`SYNTHETIC_MARK`]), not recorded by a sensor.
    pub synthetic: bool,
}

checked_f64! {
    /// The distance between neighbouring taxel centres of a recorded array, metres: what a
    /// recording's pad size follows from, and only its maker knows (`dataset import
    /// --taxel-pitch-m`). At most [`MAX_TAXEL_PITCH_M`], so that the largest grid's pad stays
    /// within the sensor's 1 m.
    pub struct TaxelPitch(pitch_m) where pitch_m > 0.0 && pitch_m <= MAX_TAXEL_PITCH_M;
    /// A taxel pitch out of range, or no number.
    pub enum TaxelPitchError {
        OutOfRange = "taxel pitch {0} m is out of range: want metres in (0, 0.0078125] (1 m over 128 taxels)",
        NotANumber = "'{0}' is not a taxel pitch in metres",
    }
}

/// The largest [`TaxelPitch`]: 1 m (the sensor's largest pad side) over 128 taxels.
pub const MAX_TAXEL_PITCH_M: f64 = crate::tactile::config::MAX_LENGTH_M / MAX_TAXELS_PER_SIDE as f64;

/// The sensor recorded frames are filed under in a dataset: the recording's `rows x cols`, at
/// `pitch` when its maker gave it (the pad `cols x pitch` wide and `rows x pitch` high), the
/// default covering for that pad and its point-spread, no simulated noise. A recording without
/// its pitch tells nothing of its pad's size: the pad is then the paper's letters sensor's 2 mm
/// pitch as a placeholder, and [`PadSize::Unknown`] says so (a 6x6 recording gets exactly
/// [`SensorConfig::default`]).
pub fn recorded_sensor(rows: usize, cols: usize, pitch: Option<TaxelPitch>) -> (SensorConfig, PadSize) {
    let default = SensorConfig::default();
    match pitch {
        Some(pitch) => {
            let (width_m, height_m) = (pitch.get() * cols as f64, pitch.get() * rows as f64);
            let sensor = SensorConfig::of_pad(rows, cols, width_m, height_m, None, None);
            (sensor, PadSize::Known)
        }
        None => {
            let sensor = SensorConfig {
                rows,
                cols,
                pad_width_m: default.pad_width_m * (cols as f64 / default.cols as f64),
                pad_height_m: default.pad_height_m * (rows as f64 / default.rows as f64),
                ..default
            };
            (sensor, PadSize::Unknown)
        }
    }
}

impl RealData {
    /// What the frames are, for titles: `real sensor frames`, or `example frames (synthetic)`.
    pub fn frames_words(&self) -> &'static str {
        if self.synthetic {
            "example frames (synthetic)"
        } else {
            "real sensor frames"
        }
    }

    /// The frames as a dataset, the hand-off `train` and `recognize` read: one object per label
    /// (sorted), every frame a [`Strategy::Recorded`] reading in file order, without a pad pose,
    /// the object at the origin (a recording has neither). `file` gives each frame's image as
    /// filed and its status: [`ContactStatus::Converged`] for a frame that touched the object,
    /// [`ContactStatus::NoContact`] for one that did not (the caller's pruning and preprocessing).
    pub fn to_dataset(
        &self,
        object_set: &str,
        generator: &str,
        pitch: Option<TaxelPitch>,
        mut file: impl FnMut(&RealReading) -> (TactileImage, ContactStatus),
    ) -> Result<Dataset, DatasetError> {
        let (sensor, pad_size) = recorded_sensor(self.rows, self.cols, pitch);
        let header = DatasetHeader {
            pad_size,
            ..DatasetHeader::new(
                sensor,
                object_set,
                self.labels().into_iter().map(str::to_string).collect(),
                generator,
                0,
            )
        };
        let readings = self
            .readings
            .iter()
            .map(|frame| {
                let (image, status) = file(frame);
                Reading {
                    image,
                    object: frame.label.clone(),
                    object_pose: Pose::IDENTITY,
                    object_pose_after: None,
                    status,
                    iterations: 0,
                    strategy: Strategy::Recorded,
                    cause: None,
                    contact: frame.contact,
                }
            })
            .collect();
        Dataset::new(header, readings)
    }

    /// Recorded frames of a `grid` from any source, checked ([`checked_frame`]) and in source
    /// order, normalised ([`normalised`]).
    pub(crate) fn recorded(
        raw: Vec<RawFrame>,
        grid: (usize, usize),
        options: &RealImport,
        origin: &str,
    ) -> Result<Self, RealDataError> {
        Ok(Self {
            rows: grid.0,
            cols: grid.1,
            readings: normalised(raw, grid, options, origin)?,
            synthetic: false,
        })
    }

    /// The distinct labels, sorted.
    pub fn labels(&self) -> BTreeSet<&str> {
        self.readings.iter().map(|r| r.label.as_str()).collect()
    }

    /// Whether the source grouped frames into contacts of several frames (module docs).
    pub fn has_contacts(&self) -> bool {
        self.readings.iter().any(|r| r.contact.is_some())
    }

    /// Where the first frame labelled `label` came from, for messages about the label.
    pub fn first_place_of(&self, label: &str) -> Option<&FramePlace> {
        self.readings.iter().find(|r| r.label == label).map(|r| &r.place)
    }
}

/// What is wrong with a real-data file; `origin` is its path, `line` 1-based.
#[derive(Debug, thiserror::Error)]
pub enum RealDataError {
    #[error("{origin}: {source}")]
    Io { origin: String, source: std::io::Error },
    #[error("{origin}: line {line}: {what}")]
    Invalid { origin: String, line: u64, what: String },
    #[error("{origin}: {at}: {what}")]
    Frame {
        origin: String,
        at: FramePlace,
        what: String,
    },
    #[error("{origin}: {what}")]
    Source { origin: String, what: String },
    #[error("{origin}: line {line}: bad header: {what}")]
    Header { origin: String, line: u64, what: String },
    #[error("{origin}: no header line (label,r0c0,...)")]
    NoHeader { origin: String },
    #[error("{origin}: line {line}: {got} columns, expected {expected} ({leading} + {rows}x{cols} taxels)")]
    ColumnCount {
        origin: String,
        line: u64,
        got: usize,
        expected: usize,
        leading: &'static str,
        rows: usize,
        cols: usize,
    },
    #[error("{origin}: {at}: empty label")]
    EmptyLabel { origin: String, at: FramePlace },
    #[error("{origin}: {at}: unknown label '{label}' (allowed: {allowed})")]
    UnknownLabel {
        origin: String,
        at: FramePlace,
        label: String,
        allowed: String,
    },
    #[error("{origin}: line {line}: column {column}: '{text}' is not a number")]
    NotANumber {
        origin: String,
        line: u64,
        column: String,
        text: String,
    },
    #[error("{origin}: {at}: column {column}: {value} is not finite")]
    NotFinite {
        origin: String,
        at: FramePlace,
        column: String,
        value: f64,
    },
    #[error("{origin}: {at}: column {column}: {value} is negative")]
    Negative {
        origin: String,
        at: FramePlace,
        column: String,
        value: f64,
    },
    #[error("{origin}: {at}: column {column}: {value} exceeds the range {range}")]
    AboveRange {
        origin: String,
        at: FramePlace,
        column: String,
        value: f64,
        range: f64,
    },
    #[error("{origin}: the range must be finite and positive, got {range}")]
    BadRange { origin: String, range: f64 },
    #[error("{origin}: no frames")]
    NoFrames { origin: String },
    #[error("{origin}: every value is zero; nothing to normalise by")]
    AllZero { origin: String },
}

/// Reads and normalises a real-data file (format in the module docs).
pub fn import_real_csv(path: &Path, options: &RealImport) -> Result<RealData, RealDataError> {
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| RealDataError::Io {
        origin: origin.clone(),
        source,
    })?;
    parse_real_csv(&text, &origin, options)
}

/// Parses real-data CSV text; `origin` names the source in errors.
pub fn parse_real_csv(text: &str, origin: &str, options: &RealImport) -> Result<RealData, RealDataError> {
    if let Normalisation::Range(range) = options.normalisation
        && !(range.is_finite() && range > 0.0)
    {
        return Err(RealDataError::BadRange {
            origin: origin.to_string(),
            range,
        });
    }
    let mut header: Option<CsvLayout> = None;
    let mut raw: Vec<RawFrame> = Vec::new();
    for (line, record) in records(text) {
        match &header {
            None => header = Some(calibrated_header(&record, line, origin, options)?),
            Some(layout) => raw.push(parse_frame(&record, line, layout, options, origin)?),
        }
    }
    let Some(CsvLayout { rows, cols, .. }) = header else {
        return Err(RealDataError::NoHeader {
            origin: origin.to_string(),
        });
    };
    let synthetic = text
        .lines()
        .any(|line| line.trim_start().starts_with(SYNTHETIC_MARK));
    Ok(RealData {
        synthetic,
        ..RealData::recorded(raw, (rows, cols), options, origin)?
    })
}

/// One frame as read: its label, where it came from, the name of its contact when the source
/// gives one, and its calibrated values, not yet normalised.
pub(crate) struct RawFrame {
    label: String,
    place: FramePlace,
    contact: Option<String>,
    values: Vec<f64>,
}

impl RawFrame {
    /// The frame as one of the contact named `contact` (`None`, or an empty name: a contact of
    /// its own).
    pub(crate) fn of_contact(self, contact: Option<String>) -> Self {
        Self {
            contact: contact.filter(|name| !name.is_empty()),
            ..self
        }
    }
}

/// A frames CSV's columns (module docs): the optional `contact` column, then a `rows x cols` grid
/// of taxel columns `names`.
struct CsvLayout {
    rows: usize,
    cols: usize,
    names: Vec<String>,
    contact: bool,
}

impl CsvLayout {
    /// The columns before the taxels, as messages name them.
    fn leading(&self) -> &'static str {
        match self.contact {
            true => "label, contact",
            false => "label",
        }
    }
}

/// The header line ([`parse_header`]), whose grid must be the calibration's when there is one.
fn calibrated_header(
    record: &[&str],
    line: u64,
    origin: &str,
    options: &RealImport,
) -> Result<CsvLayout, RealDataError> {
    let parsed = parse_header(record, line, origin)?;
    check_calibration_grid((parsed.rows, parsed.cols), options).map_err(|what| RealDataError::Header {
        origin: origin.to_string(),
        line,
        what,
    })?;
    Ok(parsed)
}

/// The calibration, when there is one, is of the frames' `grid`.
pub(crate) fn check_calibration_grid(grid: (usize, usize), options: &RealImport) -> Result<(), String> {
    match &options.calibration {
        Some(calibration) if (calibration.rows, calibration.cols) != grid => Err(format!(
            "the frames are {}x{} taxels but the calibration {} is {}x{}",
            grid.0, grid.1, calibration.origin, calibration.rows, calibration.cols
        )),
        _ => Ok(()),
    }
}

/// A frame line of a `layout`: a known, non-empty label, its contact's name when the layout has
/// the column, and one calibrated value a taxel.
fn parse_frame(
    record: &[&str],
    line: u64,
    layout: &CsvLayout,
    options: &RealImport,
    origin: &str,
) -> Result<RawFrame, RealDataError> {
    let CsvLayout {
        rows,
        cols,
        names,
        contact,
    } = layout;
    let first_taxel = 1 + usize::from(*contact);
    let expected = first_taxel + rows * cols;
    if record.len() != expected {
        return Err(RealDataError::ColumnCount {
            origin: origin.to_string(),
            line,
            got: record.len(),
            expected,
            leading: layout.leading(),
            rows: *rows,
            cols: *cols,
        });
    }
    let values = record[first_taxel..]
        .iter()
        .zip(names)
        .map(|(text, column)| {
            text.parse().map_err(|_| RealDataError::NotANumber {
                origin: origin.to_string(),
                line,
                column: column.clone(),
                text: text.to_string(),
            })
        })
        .collect::<Result<Vec<f64>, _>>()?;
    let frame = checked_frame(
        record[0].to_string(),
        FramePlace::Line(line),
        values,
        *cols,
        options,
        origin,
    )?;
    Ok(frame.of_contact(contact.then(|| record[1].to_string())))
}

/// One frame of raw values (row-major, `cols` a row) as read from any source: a known, non-empty
/// label, and every value finite, calibrated, not negative and within the range when one is
/// given.
pub(crate) fn checked_frame(
    label: String,
    place: FramePlace,
    mut values: Vec<f64>,
    cols: usize,
    options: &RealImport,
    origin: &str,
) -> Result<RawFrame, RealDataError> {
    if label.is_empty() {
        return Err(RealDataError::EmptyLabel {
            origin: origin.to_string(),
            at: place,
        });
    }
    if let Some(allowed) = &options.allowed_labels
        && !allowed.contains(&label)
    {
        let allowed = allowed.iter().cloned().collect::<Vec<_>>().join(", ");
        return Err(RealDataError::UnknownLabel {
            origin: origin.to_string(),
            at: place,
            label,
            allowed,
        });
    }
    for (k, value) in values.iter_mut().enumerate() {
        *value = checked_value(k, *value, options).map_err(|problem| {
            let (origin, at, column) = (origin.to_string(), place.clone(), taxel_name(k, cols));
            match problem {
                ValueProblem::NotFinite(value) => RealDataError::NotFinite {
                    origin,
                    at,
                    column,
                    value,
                },
                ValueProblem::Negative(value) => RealDataError::Negative {
                    origin,
                    at,
                    column,
                    value,
                },
                ValueProblem::AboveRange(value, range) => RealDataError::AboveRange {
                    origin,
                    at,
                    column,
                    value,
                    range,
                },
            }
        })?;
    }
    Ok(RawFrame {
        label,
        place,
        contact: None,
        values,
    })
}

/// The name of taxel `k` of a grid `cols` wide: `r<row>c<col>`, as the CSV header names it.
fn taxel_name(k: usize, cols: usize) -> String {
    format!("r{}c{}", k / cols.max(1), k % cols.max(1))
}

/// What is wrong with one raw value.
enum ValueProblem {
    NotFinite(f64),
    Negative(f64),
    AboveRange(f64, f64),
}

/// Taxel `k`'s `raw` value: finite, calibrated, not negative, and within the range when one is
/// given.
fn checked_value(k: usize, raw: f64, options: &RealImport) -> Result<f64, ValueProblem> {
    if !raw.is_finite() {
        return Err(ValueProblem::NotFinite(raw));
    }
    let value = match &options.calibration {
        Some(calibration) => calibration.apply(k, raw),
        None => raw,
    };
    if value < 0.0 {
        return Err(ValueProblem::Negative(value));
    }
    match options.normalisation {
        Normalisation::Range(range) if value > range => Err(ValueProblem::AboveRange(value, range)),
        _ => Ok(value),
    }
}

/// The frames of a `grid` divided by the range, or by the source's largest value: images in
/// [0, 1].
fn normalised(
    raw: Vec<RawFrame>,
    grid: (usize, usize),
    options: &RealImport,
    origin: &str,
) -> Result<Vec<RealReading>, RealDataError> {
    if raw.is_empty() {
        return Err(RealDataError::NoFrames {
            origin: origin.to_string(),
        });
    }
    let scale = match options.normalisation {
        Normalisation::Range(range) => range,
        Normalisation::FileMax => raw
            .iter()
            .flat_map(|frame| frame.values.iter().copied())
            .fold(0.0, f64::max),
    };
    if scale == 0.0 {
        return Err(RealDataError::AllZero {
            origin: origin.to_string(),
        });
    }
    let (rows, cols) = grid;
    let contacts = numbered_contacts(&raw, origin)?;
    raw.into_iter()
        .zip(contacts)
        .map(
            |(
                RawFrame {
                    label, place, values, ..
                },
                contact,
            )| {
                let values = values.into_iter().map(|v| v / scale).collect();
                match TactileImage::new(rows, cols, values) {
                    Ok(image) => Ok(RealReading {
                        label,
                        place,
                        contact,
                        image,
                    }),
                    Err(e) => Err(RealDataError::Frame {
                        origin: origin.to_string(),
                        at: place,
                        what: e.to_string(),
                    }),
                }
            },
        )
        .collect()
}

/// Each frame's contact number (module docs): the frames of one label under one contact name are
/// consecutive and share a number, counted from 0 in the order of the contacts' first frames; a
/// frame without a name is a contact of its own (`None`). A name coming back after other frames is
/// an error naming the frame.
fn numbered_contacts(raw: &[RawFrame], origin: &str) -> Result<Vec<Option<u32>>, RealDataError> {
    let mut finished: BTreeSet<(&str, &str)> = BTreeSet::new();
    let mut current: Option<((&str, &str), u32)> = None;
    let mut next = 0u32;
    let mut numbers = Vec::with_capacity(raw.len());
    for frame in raw {
        let Some(name) = frame.contact.as_deref() else {
            finished.extend(current.take().map(|(key, _)| key));
            numbers.push(None);
            continue;
        };
        let key = (frame.label.as_str(), name);
        match current {
            Some((open, number)) if open == key => numbers.push(Some(number)),
            _ => {
                finished.extend(current.take().map(|(key, _)| key));
                if finished.contains(&key) {
                    return Err(RealDataError::Frame {
                        origin: origin.to_string(),
                        at: frame.place.clone(),
                        what: format!(
                            "contact '{name}' of label '{}' comes back after other frames: a contact's frames are consecutive",
                            frame.label
                        ),
                    });
                }
                current = Some((key, next));
                numbers.push(Some(next));
                next += 1;
            }
        }
    }
    Ok(numbers)
}

/// Reads `label,r0c0,...` or `label,contact,r0c0,...`: the taxel columns must be `r<i>c<j>` in
/// row-major order and fill a grid.
fn parse_header(record: &[&str], line: u64, origin: &str) -> Result<CsvLayout, RealDataError> {
    let bad = |what: String| RealDataError::Header {
        origin: origin.to_string(),
        line,
        what,
    };
    if record[0] != "label" {
        return Err(bad(format!(
            "the first column must be 'label', got '{}'",
            record[0]
        )));
    }
    let contact = record.get(1) == Some(&"contact");
    let first_taxel = 1 + usize::from(contact);
    let names: Vec<String> = record[first_taxel..].iter().map(|s| s.to_string()).collect();
    if names.is_empty() {
        return Err(bad("no taxel columns".to_string()));
    }
    let cells = names
        .iter()
        .map(|name| {
            parse_taxel_name(name).ok_or_else(|| bad(format!("taxel column '{name}' is not r<row>c<col>")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let rows = cells.iter().map(|c| c.0).max().unwrap_or(0) + 1;
    let cols = cells.iter().map(|c| c.1).max().unwrap_or(0) + 1;
    for (k, (&cell, name)) in cells.iter().zip(&names).enumerate() {
        if cell != (k / cols, k % cols) {
            return Err(bad(format!(
                "taxel column {} is '{name}', expected r{}c{} (row-major, {rows}x{cols})",
                k + first_taxel + 1,
                k / cols,
                k % cols
            )));
        }
    }
    if cells.len() != rows * cols {
        return Err(bad(format!(
            "{} taxel columns do not fill a {rows}x{cols} grid",
            cells.len()
        )));
    }
    check_grid(rows, cols).map_err(bad)?;
    Ok(CsvLayout {
        rows,
        cols,
        names,
        contact,
    })
}

/// A recording's grid is `rows x cols` taxels, each side within [`TAXELS_PER_SIDE`].
pub(crate) fn check_grid(rows: usize, cols: usize) -> Result<(), String> {
    if TAXELS_PER_SIDE.contains(&rows) && TAXELS_PER_SIDE.contains(&cols) {
        Ok(())
    } else {
        Err(format!(
            "a {rows}x{cols} sensor; accepted are {MIN_TAXELS_PER_SIDE} to {MAX_TAXELS_PER_SIDE} taxels per side"
        ))
    }
}

/// The lines of a CSV text that carry data, as (1-based line number, trimmed comma-separated
/// fields): blank lines and `#` comments are skipped.
fn records(text: &str) -> impl Iterator<Item = (u64, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(i, text_line)| {
        let trimmed = text_line.trim();
        (!trimmed.is_empty() && !trimmed.starts_with('#'))
            .then(|| (i as u64 + 1, trimmed.split(',').map(str::trim).collect()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The refusal's message spells the bound as a number (the macro's messages are literals):
    /// it must be the bound the check applies.
    #[test]
    fn a_refused_pitch_names_the_bound_the_check_applies() {
        let refused = TaxelPitch::new(MAX_TAXEL_PITCH_M * 1.5).map(TaxelPitch::get);
        let message = refused.map_err(|e| e.to_string()).unwrap_err();
        assert!(
            message.contains(&format!("(0, {MAX_TAXEL_PITCH_M}]")),
            "{message}"
        );
        assert_eq!(
            TaxelPitch::new(MAX_TAXEL_PITCH_M).map(TaxelPitch::get),
            Ok(MAX_TAXEL_PITCH_M)
        );
    }

    #[test]
    fn a_known_pitch_sizes_the_pad_and_keeps_the_default_noise_seed() {
        let pitch = TaxelPitch::new(0.0015).ok();
        let (sensor, size) = recorded_sensor(28, 50, pitch);
        assert_eq!(size, PadSize::Known);
        assert!((sensor.pad_width_m - 0.075).abs() < 1e-12 && (sensor.pad_height_m - 0.042).abs() < 1e-12);
        assert_eq!(sensor.noise_seed, SensorConfig::default().noise_seed);
    }
}
