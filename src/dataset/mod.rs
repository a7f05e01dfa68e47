//! The hand-off from exploration (Sec. III-A, V-A3) to recognition (Sec. IV-A): readings, and
//! readings on disk.
//!
//! A [`Dataset`] is a [`DatasetHeader`] (what produced the readings, with which sensor, on which
//! objects) and the [`Reading`]s themselves, each a tactile image with the pad pose it was taken at,
//! the object's pose, and how the contact controllers ended ([`ContactStatus`], [`Strategy`],
//! [`AttemptCause`]).
//!
//! This module is the vocabulary both sides share, and it knows no MuJoCo: the controllers and the
//! planner (`control`, `explore`) produce readings and `explore::collect` gathers them into a
//! dataset; recognition (`recognize`) reads them, from a simulated run or a real sensor's recording
//! alike. The file format is in `format.rs`, its export as npz or Parquet in `export.rs`
//! ([`Dataset::export`]); the counts `dataset show` prints in `summary.rs`; the
//! recorded frames of a real sensor, and their import as a dataset (`dataset import`), in
//! `recorded.rs` ([`import_real_csv`]) and, kept as image folders or `.npz`, `frame_files.rs`
//! ([`import_real`]); numpy's array format, both ways, in `npy.rs`.

mod export;
mod format;
mod frame_files;
pub(crate) mod npy;
mod reading;
pub(crate) mod recorded;
mod status;
mod strategy;
mod summary;

// A reading and how its contact ended.
pub use reading::{AttemptCause, CauseKind, Reading};
pub use status::ContactStatus;
pub use strategy::Strategy;

// The file: its columns and numbers, and the counts `dataset show` prints.
pub use format::{FORMAT_VERSION, column_names};
// The file for the ML toolchain: numpy's npz, Parquet.
pub use export::{ColumnType, ExportFormat, ExportFormatError, column_types};
pub use summary::DatasetSummary;

// A real sensor's recorded frames, and their import as a dataset.
pub use frame_files::{import_real, import_real_images, import_real_npz, is_frames_csv};
pub use recorded::{
    Calibration, FramePlace, MAX_TAXEL_PITCH_M, Normalisation, RealData, RealDataError, RealImport,
    RealReading, SYNTHETIC_MARK, TaxelPitch, TaxelPitchError, import_real_csv, parse_real_csv,
    recorded_sensor,
};

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::atomic::FileError;
use crate::bodies::FreeBody;
use crate::pose::StartPose;
use crate::tactile::{ConfigError, SensorConfig};
use crate::valid::Check;

/// Errors from building, reading or writing a dataset; each names the file, line and field.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: not a taction dataset: {what}")]
    NotADataset { path: String, what: String },
    #[error("{path}: dataset format version {found}, but this build reads versions 1 to {expected}")]
    Version { path: String, found: u64, expected: u32 },
    #[error("{path}: line {line}: header: {what}")]
    Header { path: String, line: usize, what: String },
    #[error("{path}: truncated: {what}")]
    Truncated { path: String, what: String },
    #[error("{path}: line {line}: {fields} columns, expected {expected} ({meta} + {rows}x{cols} taxels)")]
    ColumnCount {
        path: String,
        line: u64,
        fields: usize,
        expected: usize,
        /// The columns before the taxels in the file's format version.
        meta: usize,
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
    #[error("invalid dataset: {0}")]
    InvalidHeader(#[from] HeaderError),
    #[error("{path}: cannot write {format}: {what}")]
    Export {
        path: String,
        format: ExportFormat,
        what: String,
    },
}

impl From<FileError> for DatasetError {
    fn from(e: FileError) -> Self {
        Self::Io {
            path: e.path.display().to_string(),
            source: e.source,
        }
    }
}

/// The bounds of the perturbation after every reading (Sec. V-B4) as a dataset records them: a
/// turn of up to `max_rotation_deg` about a random axis, a shift of up to
/// `max_translation_fraction` of the object's width (`sim::PerturbationBounds` draws them).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Perturbed {
    pub max_rotation_deg: f64,
    pub max_translation_fraction: f64,
    /// A free object pushed toward each draw rather than put there (beyond the paper; the turn
    /// then about the vertical). Left out of the header when false, as every file before it.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub pushed: bool,
}

impl Perturbed {
    /// The object stays where it stands.
    pub const FIXED: Self = Self {
        max_rotation_deg: 0.0,
        max_translation_fraction: 0.0,
        pushed: false,
    };

    pub fn is_fixed(&self) -> bool {
        self.max_rotation_deg == 0.0 && self.max_translation_fraction == 0.0
    }

    fn is_valid(&self) -> bool {
        (0.0..=180.0).contains(&self.max_rotation_deg) && (0.0..=1.0).contains(&self.max_translation_fraction)
    }
}

/// What a dataset holds and how it was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DatasetHeader {
    /// [`FORMAT_VERSION`], whether built by this crate or read from a file of an earlier version
    /// (which is brought up to this one as it is read).
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
    /// Where each object started ([`StartPose`]): written in the file only when not canonical,
    /// so that a file of a canonical start is byte for byte what it was before start poses
    /// existed, and a file without it (every earlier one) reads as canonical.
    #[serde(default, skip_serializing_if = "StartPose::is_canonical")]
    pub start_pose: StartPose,
    /// How far the object was moved after every reading (Sec. V-B4), what a recogniser of
    /// contact positions must discount: written only when it moved, so that every file of a fixed
    /// object is what it was, and a file without it reads as fixed.
    #[serde(default, skip_serializing_if = "Perturbed::is_fixed")]
    pub perturbation: Perturbed,
    /// Whether [`sensor`](Self::sensor)'s pad size is the sensor's: a recording imported without
    /// its taxel pitch tells only its grid, and its pad fields are then placeholders
    /// ([`recorded_sensor`]). Written only when unknown, so every other file is what it was, and
    /// a file without it (every simulated one) reads as known.
    #[serde(default, skip_serializing_if = "PadSize::is_known")]
    pub pad_size: PadSize,
    /// What the object was made of where it stood on a free joint (issue 74); `None`, left out
    /// of the file, for a mocap object, the paper's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_object: Option<FreeBody>,
}

/// Whether a dataset's pad size was measured or is unknown (a recording imported without its
/// taxel pitch).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PadSize {
    /// The sensor's own: every simulated dataset's, and a recording's given its pitch.
    #[default]
    Known,
    /// Never given: the grid is the recording's, the size is not.
    Unknown,
}

impl PadSize {
    /// Whether the size is the sensor's own.
    pub fn is_known(&self) -> bool {
        *self == Self::Known
    }
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
            start_pose: StartPose::Canonical,
            perturbation: Perturbed::FIXED,
            pad_size: PadSize::Known,
            free_object: None,
        }
    }

    /// This header for readings whose objects started at `start_pose`.
    pub fn with_start_pose(self, start_pose: StartPose) -> Self {
        Self { start_pose, ..self }
    }

    /// This header for readings of an object moved by `perturbation` after every reading.
    pub fn with_perturbation(self, perturbation: Perturbed) -> Self {
        Self { perturbation, ..self }
    }

    /// The header of readings of an object on a free joint made of `free_object` (`None`: mocap).
    pub fn with_free_object(self, free_object: Option<FreeBody>) -> Self {
        Self { free_object, ..self }
    }

    /// Index of `object` in [`objects`](Self::objects).
    pub fn object_index(&self, object: &str) -> Option<usize> {
        self.objects.iter().position(|o| o == object)
    }
}

/// What is wrong with a [`DatasetHeader`], naming the field ([`field`](Self::field)).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HeaderError {
    #[error("format_version {found} (this build writes {FORMAT_VERSION})")]
    FormatVersion { found: u32 },
    #[error("sensor: {0}")]
    Sensor(ConfigError),
    #[error("object {index} has an empty name")]
    EmptyObjectName { index: usize },
    #[error("object '{name}' is listed twice")]
    DuplicateObject { name: String },
    #[error("perturbation {0:?} is outside [0, 180] deg and [0, 1] of the width")]
    Perturbation(Perturbed),
}

impl HeaderError {
    /// The header field at fault.
    pub fn field(&self) -> &'static str {
        match self {
            Self::FormatVersion { .. } => "format_version",
            Self::Sensor(_) => "sensor",
            Self::EmptyObjectName { .. } | Self::DuplicateObject { .. } => "objects",
            Self::Perturbation(_) => "perturbation",
        }
    }
}

impl Check for DatasetHeader {
    type Error = HeaderError;

    /// The version is this build's, the sensor in range, every object named once.
    fn check(&self) -> Result<(), HeaderError> {
        let Self {
            format_version,
            sensor,
            object_set: _,
            objects,
            generator: _,
            seed: _,
            // Its heading was checked where it was made (serde included).
            start_pose: _,
            perturbation,
            // Either value is a dataset's: the sensor's fields are checked the same way.
            pad_size: _,
            // Checked where it was made (serde included).
            free_object: _,
        } = self;
        if !perturbation.is_valid() {
            return Err(HeaderError::Perturbation(*perturbation));
        }
        if *format_version != FORMAT_VERSION {
            return Err(HeaderError::FormatVersion {
                found: *format_version,
            });
        }
        sensor.check().map_err(HeaderError::Sensor)?;
        for (index, name) in objects.iter().enumerate() {
            if name.is_empty() {
                return Err(HeaderError::EmptyObjectName { index });
            }
            if objects[..index].contains(name) {
                return Err(HeaderError::DuplicateObject { name: name.clone() });
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

impl Dataset {
    /// A dataset from readings in memory.
    pub fn new(header: DatasetHeader, readings: Vec<Reading>) -> Result<Self, DatasetError> {
        header.check()?;
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
        if let Some(contact) = reading.contact {
            self.check_contact(index, contact, &reading.object)?;
        }
        self.readings.push(reading);
        Ok(())
    }

    /// A contact's readings (format.rs: `contact`) are consecutive and of one object, and each new
    /// contact is numbered above every earlier one, so that a contact is one run of readings and
    /// a split at a contact's edge keeps it whole.
    fn check_contact(&self, index: usize, contact: u32, object: &str) -> Result<(), DatasetError> {
        if let Some(previous) = self.readings.last().filter(|r| r.contact == Some(contact)) {
            return match previous.object == object {
                true => Ok(()),
                false => Err(DatasetError::Invalid(format!(
                    "reading {index}: contact {contact} is of object '{object}', the reading before it of '{}'",
                    previous.object
                ))),
            };
        }
        match self.readings.iter().rev().find_map(|r| r.contact) {
            Some(last) if last >= contact => Err(DatasetError::Invalid(format!(
                "reading {index}: contact {contact} after contact {last}: a contact's readings are \
                 consecutive, and a new contact is numbered above every earlier one"
            ))),
            _ => Ok(()),
        }
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

    /// The [`Converged`](ContactStatus::Converged) readings, in dataset order: the ones
    /// recognition uses (Sec. III-B).
    pub fn converged(&self) -> impl Iterator<Item = &Reading> {
        self.readings.iter().filter(|r| r.is_converged())
    }

    /// The same header with only the [`converged`](Self::converged) readings.
    pub fn converged_only(&self) -> Dataset {
        Dataset {
            header: self.header.clone(),
            readings: self.converged().cloned().collect(),
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
                converged: readings.iter().filter(|r| r.is_converged()).count(),
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

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::format::format_f64;
    use super::*;
    use crate::pose::PadPose;
    use crate::pose::Pose;
    use crate::tactile::TactileImage;

    #[test]
    fn the_column_layout_lists_every_column_once_in_file_order() {
        let names = column_names(1, 2);
        for (i, column) in format::Meta::ALL.iter().enumerate() {
            assert_eq!(column.index(), i, "{column:?} is out of order");
            assert_eq!(names[i], column.name());
        }
        assert_eq!(&names[format::Meta::ALL.len()..], ["t_0_0", "t_0_1"]);
        let unique: std::collections::BTreeSet<&String> = names.iter().collect();
        assert_eq!(unique.len(), names.len());
    }

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
            // A free object's pose after the touch: shifted and turned, or none (fixed).
            object_pose_after: with_pad.then(|| Pose {
                position_m: DVec3::new(k + 0.1, 1.0 / 3.0, 1e-300),
                rotation: DQuat::from_rotation_x(k / 7.0),
            }),
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
            contact: None,
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

    /// The dataset with a collision of link4 on the table, a lost contact, and an aborted attempt.
    fn dataset_with_causes() -> Dataset {
        let mut d = dataset();
        d.readings[1].cause = Some(AttemptCause::LostContact);
        d.push(reading("c", ContactStatus::Collision, 4.0, true)).unwrap();
        let mut aborted = reading("c", ContactStatus::Aborted, 0.0, true);
        aborted.cause = Some(AttemptCause::PhysicsFault);
        d.push(aborted).unwrap();
        d
    }

    #[test]
    fn causes_round_trip_by_the_tables_names_and_a_bad_cause_is_named() {
        let d = dataset_with_causes();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.csv");
        d.write(&path).unwrap();
        assert_eq!(Dataset::read(&path).unwrap(), d);
        let s = d.summary();
        assert_eq!(s.causes[1][&CauseKind::LostContact], 1);
        assert_eq!(s.causes[1][&CauseKind::ArmOnTable], 1);
        assert_eq!(s.causes[1][&CauseKind::PhysicsFault], 1);
        assert!(s.causes[0].is_empty());
        let shown = s.to_string();
        let t = std::fs::read_to_string(&path).unwrap();
        // The file says what the table says: the cause's name, the bodies beside it.
        for (cause, bodies) in [
            ("arm_on_table", "link4/world"),
            ("lost_contact", ""),
            ("physics_fault", ""),
        ] {
            assert!(t.contains(&format!(",{cause},{bodies},")), "{cause}: {t}");
            assert!(shown.contains(cause), "{cause}: {shown}");
        }
        assert!(shown.contains("aborted"), "{shown}");
        for (from, to, field, what) in [
            (
                ",arm_on_table,link4/world,",
                ",arm_on_table,link4,",
                "'touched_bodies'",
                "'link4'",
            ),
            (
                ",arm_on_table,link4/world,",
                ",arm_on_table,sensor/object,",
                "'touched_bodies'",
                "pad_on_object",
            ),
            (
                ",arm_on_table,link4/world,",
                ",link4/world,,",
                "'cause'",
                "unknown cause 'link4/world'",
            ),
        ] {
            let e = parse_err(&t.replace(from, to));
            assert!(
                e.contains("line 7") && e.contains(field) && e.contains(what),
                "{e}"
            );
        }
    }

    /// `text` (a format 3 file) as format 2 wrote it: no `touched_bodies`, the bodies themselves in
    /// `cause`, `covering_meets_table`, and no `lost_contact`.
    /// `text`, a file of format `from`, as format `to` wrote it: without the `columns` it added.
    fn older(text: &str, (from, to): (u32, u32), columns: std::ops::Range<usize>) -> String {
        let lines: Vec<String> = text
            .lines()
            .map(|line| match line.starts_with('#') {
                true => line.replace(
                    &format!("\"format_version\":{from}"),
                    &format!("\"format_version\":{to}"),
                ),
                false => {
                    // Rows without a quoted comma in the object name split at commas into columns.
                    let offset = usize::from(line.starts_with('"'));
                    let mut fields: Vec<&str> = line.split(',').collect();
                    fields.drain(columns.start + offset..columns.end + offset);
                    fields.join(",")
                }
            })
            .collect();
        lines.join("\n") + "\n"
    }

    /// `text` (this version's file) as format 4 wrote it: no contact column.
    fn as_format_4(text: &str) -> String {
        let contact = format::Meta::Contact.index();
        older(text, (5, 4), contact..contact + 1)
    }

    /// `text` (this version's file) as format 3 wrote it: no pose after the touch.
    fn as_format_3(text: &str) -> String {
        let after = format::Meta::ObjectAfterX.index();
        older(&as_format_4(text), (4, 3), after..after + 7)
    }

    /// Readings in two contacts (frames 0 and 1 of object `c`, then frame 3) and one of its own.
    fn dataset_with_contacts() -> Dataset {
        let header = DatasetHeader::new(sensor(), "toy", vec!["a,\"b\"".into(), "c".into()], "sampler", 42);
        let readings = [
            ("c", Some(0), true),
            ("c", Some(0), false),
            ("a,\"b\"", None, true),
            ("c", Some(1), false),
        ]
        .into_iter()
        .enumerate()
        .map(|(k, (object, contact, with_pad))| Reading {
            contact,
            ..reading(object, ContactStatus::Converged, k as f64, with_pad)
        })
        .collect();
        Dataset::new(header, readings).unwrap()
    }

    #[test]
    fn contacts_round_trip_and_a_format_4_file_has_none() {
        let d = dataset_with_contacts();
        let text = String::from_utf8(d.to_file_bytes("d.csv").unwrap()).unwrap();
        assert_eq!(Dataset::parse(&text, "d.csv").unwrap(), d);
        let old = as_format_4(&text);
        assert!(!old.contains("contact,"), "{old}");
        let read = Dataset::parse(&old, "v4.csv").unwrap();
        assert!(read.readings.iter().all(|r| r.contact.is_none()));
        let contact = format::Meta::Contact.index();
        let row: Vec<&str> = text.lines().nth(3).unwrap().split(',').collect();
        let offset = usize::from(row[0].starts_with('"'));
        let mut broken = row.clone();
        broken[contact + offset] = "two";
        let e = parse_err(&text.replace(&row.join(","), &broken.join(",")));
        assert!(
            e.contains("line 4") && e.contains("'contact'") && e.contains("'two'"),
            "{e}"
        );
    }

    #[test]
    fn a_contact_is_one_run_of_readings_of_one_object() {
        let d = dataset_with_contacts();
        let header = d.header().clone();
        let mut readings = d.readings.clone();
        // Contact 0 again after its run ended: a contact does not come back.
        readings[3].contact = Some(0);
        let e = Dataset::new(header.clone(), readings).unwrap_err().to_string();
        assert!(
            e.contains("reading 3") && e.contains("contact 0 after contact 0"),
            "{e}"
        );
        // Contact 0's second frame of another object.
        let mut readings = d.readings.clone();
        readings[1].object = readings[2].object.clone();
        let other = readings[2].object.clone();
        let e = Dataset::new(header.clone(), readings).unwrap_err().to_string();
        assert!(
            e.contains("reading 1") && e.contains(&format!("of object '{other}'")),
            "{e}"
        );
        assert!(Dataset::new(header, d.readings.clone()).is_ok());
        // `dataset show` counts the presses and their frames; a dataset without any says nothing.
        assert_eq!(d.summary().presses, Some((2, 3)));
        assert!(
            d.summary()
                .to_string()
                .ends_with("\ncontacts: 3 frames in 2 presses, each press kept whole by every split")
        );
        assert!(!dataset().summary().to_string().contains("contacts"));
    }

    /// `d` as a file of format 3 or older holds it: every object fixed.
    fn without_poses_after(mut d: Dataset) -> Dataset {
        for r in &mut d.readings {
            r.object_pose_after = None;
        }
        d
    }

    #[test]
    fn a_format_3_file_is_read_with_every_object_fixed() {
        let d = dataset_with_causes();
        assert!(d.readings.iter().any(|r| r.object_pose_after.is_some()));
        let old = as_format_3(&String::from_utf8(d.to_file_bytes("d.csv").unwrap()).unwrap());
        assert!(!old.contains("object_after"), "{old}");
        let read = Dataset::parse(&old, "v3.csv").unwrap();
        assert_eq!(read.header().format_version, FORMAT_VERSION);
        assert_eq!(read, without_poses_after(d));
    }

    #[test]
    fn a_pose_after_the_touch_is_whole_or_absent() {
        let t = text();
        let lines: Vec<&str> = t.lines().collect();
        let after_qz = format::Meta::ObjectAfterQz.index();
        let row = (3..lines.len())
            .find(|&i| {
                !lines[i].starts_with('"') && lines[i].split(',').nth(after_qz).is_some_and(|v| !v.is_empty())
            })
            .expect("a free object's reading");
        let mut fields: Vec<&str> = lines[row].split(',').collect();
        fields[after_qz] = "";
        let broken = t.replace(lines[row], &fields.join(","));
        let e = parse_err(&broken);
        assert!(
            e.contains(&format!("line {}", row + 1))
                && e.contains("'object_after_qz'")
                && e.contains("empty, but other fields of its pose are set"),
            "{e}"
        );
    }

    fn as_format_2(text: &str) -> String {
        let text = as_format_3(text);
        let mut lines: Vec<String> = Vec::new();
        for line in text.lines() {
            let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
            let cause = format::Meta::Cause.index();
            if line.starts_with('#') {
                lines.push(line.replace("\"format_version\":3", "\"format_version\":2"));
                continue;
            }
            // Rows without a quoted comma in the object name split at commas into columns.
            let offset = usize::from(line.starts_with('"'));
            let (c, b) = (cause + offset, cause + offset + 1);
            let old = match (fields[c].as_str(), fields[b].as_str()) {
                ("cause", _) => "cause".to_string(),
                (_, bodies) if !bodies.is_empty() => bodies.to_string(),
                ("covering_on_table", _) => "covering_meets_table".to_string(),
                ("lost_contact", _) => String::new(),
                (other, _) => other.to_string(),
            };
            fields[c] = old;
            fields.remove(b);
            lines.push(fields.join(","));
        }
        lines.join("\n") + "\n"
    }

    #[test]
    fn a_format_2_file_is_read_in_this_formats_vocabulary() {
        let mut d = dataset_with_causes();
        // Format 2 had no physics faults, and no `aborted` status.
        d.readings.pop();
        d.readings[2].status = ContactStatus::Collision;
        d.readings[2].cause = Some(AttemptCause::CoveringOnTable);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.csv");
        d.write(&path).unwrap();
        let old = as_format_2(&std::fs::read_to_string(&path).unwrap());
        let mut d = without_poses_after(d);
        assert!(
            old.contains(",link4/world,") && !old.contains("touched_bodies") && !old.contains("lost_contact"),
            "{old}"
        );
        let mut read = Dataset::parse(&old, "old.csv").unwrap();
        assert_eq!(read.header().format_version, FORMAT_VERSION);
        assert_eq!(
            read, d,
            "causes mapped: link4/world -> arm_on_table, lost contact inferred"
        );
        d.readings[2].cause = Some(AttemptCause::Touched {
            body_a: "sensor".into(),
            body_b: "object".into(),
        });
        let old = old.replace(",covering_meets_table,", ",sensor/object,");
        read = Dataset::parse(&old, "old.csv").unwrap();
        assert_eq!(
            read.readings()[2].cause.as_ref().map(AttemptCause::name),
            Some("pad_on_object")
        );
        // Written again, it is this version.
        read.write(&path).unwrap();
        assert!(
            std::fs::read_to_string(&path)
                .unwrap()
                .contains(&format!("\"format_version\":{FORMAT_VERSION}"))
        );
        let e = parse_err(&old.replace(",sensor/object,", ",sensor,"));
        assert!(e.contains("'cause'") && e.contains("format 2"), "{e}");
    }

    #[test]
    fn a_format_1_file_without_causes_is_read() {
        let d = dataset();
        let cause = format::Meta::Cause.index();
        let old = older(&as_format_3(&text()), (3, 1), cause..cause + 2);
        let read = Dataset::parse(&old, "v1.csv").unwrap();
        assert_eq!(read.readings().len(), d.len());
        // "c" lost contact after 2 iterations, which version 1 did not say.
        assert_eq!(read.readings()[1].cause, Some(AttemptCause::LostContact));
        assert_eq!(read.readings()[0].cause, None);
    }

    #[test]
    fn wrong_column_count_names_the_line() {
        let t = text();
        let lines: Vec<&str> = t.lines().collect();
        let short = lines[4].rsplit_once(',').unwrap().0;
        let broken = t.replace(lines[4], short);
        let e = parse_err(&broken);
        assert!(
            e.contains("d.csv: line 5") && e.contains("35 columns, expected 36 (30 + 2x3 taxels)"),
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
        assert!(e.contains("expected one of converged, no_contact,"), "{e}");
        let e = parse_err(&t.replace(",recorded,", ",teleport,"));
        assert!(e.contains("'strategy'") && e.contains("'teleport'"), "{e}");
        let e = parse_err(&t.replace("\nc,no_contact", "\nd,no_contact"));
        assert!(e.contains("'object'") && e.contains("'d'"), "{e}");
    }

    #[test]
    fn a_pad_pose_with_one_field_missing_is_named() {
        let t = text();
        let mut lines: Vec<String> = t.lines().map(str::to_string).collect();
        // A row with a pad pose whose object name holds no quoted comma, so that splitting at
        // commas finds the columns.
        let pad_up_y = format::Meta::PadUpY.index();
        let row = (3..lines.len())
            .find(|&i| {
                !lines[i].starts_with('"') && lines[i].split(',').nth(pad_up_y).is_some_and(|v| !v.is_empty())
            })
            .expect("a reading with a pad pose");
        let mut fields: Vec<&str> = lines[row].split(',').collect();
        fields[pad_up_y] = "";
        lines[row] = fields.join(",");
        let e = parse_err(&(lines.join("\n") + "\n"));
        assert!(
            e.contains(&format!("line {}", row + 1))
                && e.contains("'pad_up_y'")
                && e.contains("empty, but other fields of its pose are set"),
            "{e}"
        );
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
            &t.replace("\"format_version\":5", "\"format_version\":7"),
            "d.csv",
        )
        .unwrap_err();
        assert!(
            matches!(
                e,
                DatasetError::Version {
                    found: 7,
                    expected: 5,
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
