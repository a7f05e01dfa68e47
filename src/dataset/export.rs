//! A dataset in the formats the ML toolchain reads (issue 37): numpy's `.npz` and Apache Parquet,
//! one row per reading in file order, written atomically like the CSV (`format.rs`).
//!
//! **npz** (`numpy.load(path)`, no `allow_pickle` needed): a zip of `.npy` arrays (NPY format 1.0,
//! little-endian, strings as fixed-width unicode):
//!
//! | array | dtype | shape | what |
//! | --- | --- | --- | --- |
//! | `images` | `<f4` | `[N, rows, cols]` | the tactile images, row 0 the pad's `+up` edge as [`TactileImage`](crate::tactile::TactileImage) stores it |
//! | `pad_pose` | `<f8` | `[N, 9]` | centre xyz (m), normal xyz, up xyz: the CSV's `pad_x_m` ... `pad_up_z`; NaN where a reading has no pose |
//! | `object_pose` | `<f8` | `[N, 7]` | x, y, z (m), qw, qx, qy, qz: the CSV's `object_x_m` ... `object_qz` |
//! | `object_pose_after` | `<f8` | `[N, 7]` | a free object's pose when the reading was taken, the CSV's `object_after_x_m` ... `object_after_qz`; NaN where the object is fixed |
//! | `iterations` | `<i8` | `[N]` | the contact controller's iterations |
//! | `contact` | `<i8` | `[N]` | the press a recorded frame is one frame of (the CSV's `contact`), -1 for a reading that is a contact of its own |
//! | `object`, `status`, `strategy`, `cause`, `touched_bodies` | `<U..` | `[N]` | the CSV's names; `cause` and `touched_bodies` empty when none |
//! | `header` | `<U..` | `[]` | the header JSON of the CSV's line 2 (`json.loads(str(z["header"]))`) |
//!
//! **Parquet** (`pandas.read_parquet(path)`): the CSV's columns under the CSV's names and in its
//! order, one row group: the names as UTF-8 strings, `iterations` int64, the poses float64 (the
//! nine pad pose columns null where a reading has no pose, the seven of the object's pose after
//! the touch null where the object is fixed), `contact` int64, then one float32 column per taxel,
//! `t_{row}_{col}` row-major, so `df.filter(regex="^t_").to_numpy().reshape(-1, rows, cols)` gives
//! the images. Snappy-compressed; the header JSON is the file's key-value metadata
//! `taction_header` (`pyarrow.parquet.read_schema(path).metadata[b"taction_header"]`).
//!
//! Every column has one type wherever the dataset goes ([`column_types`]): the Parquet file's,
//! the `.npz`'s arrays and the Python package's `Dataset.to_pandas()` all follow it (taxels
//! float32, every pose column float64 even where the object never moved, `iterations` and
//! `contact` int64).

use std::fmt;
use std::path::Path;
use std::str::FromStr;
use std::sync::Arc;

use parquet::basic::{Compression, LogicalType, Repetition, Type as PhysicalType};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, FloatType, Int64Type};
use parquet::errors::ParquetError;
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::{SerializedColumnWriter, SerializedFileWriter};
use parquet::schema::types::{Type as SchemaType, TypePtr};

use crate::atomic::write_atomic;
use crate::dataset::format::{Meta, column_names};
use crate::dataset::npy::{Npy, npz_bytes};
use crate::dataset::{Dataset, DatasetError, Reading};

/// A format [`Dataset::export`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ExportFormat {
    /// numpy's `.npz`: a zip of `.npy` arrays, read by `numpy.load`.
    Npz,
    /// Apache Parquet: one column per CSV column, read by `pandas.read_parquet`.
    Parquet,
}

impl ExportFormat {
    pub const ALL: [ExportFormat; 2] = [Self::Npz, Self::Parquet];

    /// The name `--format` takes, also the file extension.
    pub fn name(self) -> &'static str {
        match self {
            Self::Npz => "npz",
            Self::Parquet => "parquet",
        }
    }
}

impl fmt::Display for ExportFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A `--format` that names no [`ExportFormat`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{0}' is not an export format (npz or parquet)")]
pub struct ExportFormatError(pub String);

impl FromStr for ExportFormat {
    type Err = ExportFormatError;

    /// [`name`](Self::name), e.g. `npz`.
    fn from_str(s: &str) -> Result<Self, ExportFormatError> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == s.trim())
            .ok_or_else(|| ExportFormatError(s.to_string()))
    }
}

impl Dataset {
    /// Writes the dataset as `format` (module docs) to `path`, atomically: a temporary file beside
    /// `path`, then renamed over it.
    ///
    /// ```
    /// # use taction::dataset::{Dataset, DatasetHeader, ExportFormat};
    /// # use taction::tactile::SensorConfig;
    /// let header = DatasetHeader::new(SensorConfig::square(6, 6, 0.012, 0.0012), "shapes",
    ///     vec!["cube".into()], "sampler", 7);
    /// let dataset = Dataset::new(header, vec![]).unwrap();
    /// let dir = tempfile::tempdir().unwrap();
    /// dataset.export(&dir.path().join("d.npz"), ExportFormat::Npz).unwrap();
    /// ```
    pub fn export(&self, path: &Path, format: ExportFormat) -> Result<(), DatasetError> {
        let header_json = self.header_json()?;
        let bytes = match format {
            ExportFormat::Npz => npz(self, &header_json).map_err(|e| e.to_string()),
            ExportFormat::Parquet => parquet(self, header_json).map_err(|e| e.to_string()),
        }
        .map_err(|what| DatasetError::Export {
            path: path.display().to_string(),
            format,
            what,
        })?;
        Ok(write_atomic(path, &bytes)?)
    }
}

/// The values of the pose `columns` (a [`Meta`] range), row-major per reading, NaN where unset.
fn pose_values(readings: &[Reading], columns: &[Meta]) -> Vec<f64> {
    readings
        .iter()
        .flat_map(|r| columns.iter().map(|m| m.number(r).unwrap_or(f64::NAN)))
        .collect()
}

/// The text of column `meta` of every reading, as the CSV writes it.
fn texts(readings: &[Reading], meta: Meta) -> Vec<String> {
    readings.iter().map(|r| meta.field(r)).collect()
}

/// The `.npz` of the module docs, in memory.
fn npz(dataset: &Dataset, header_json: &str) -> Result<Vec<u8>, zip::result::ZipError> {
    let readings = dataset.readings();
    let n = readings.len();
    let (rows, cols) = (dataset.header().sensor.rows, dataset.header().sensor.cols);
    let images = readings
        .iter()
        .flat_map(|r| r.image.values().iter().map(|&v| v as f32));
    let text = |meta: Meta| Npy::unicode(vec![n], &texts(readings, meta));
    let arrays = [
        ("images", Npy::f4(vec![n, rows, cols], images)),
        (
            "pad_pose",
            Npy::f8(vec![n, 9], pose_values(readings, Meta::pad())),
        ),
        (
            "object_pose",
            Npy::f8(vec![n, 7], pose_values(readings, Meta::object_pose())),
        ),
        (
            "object_pose_after",
            Npy::f8(vec![n, 7], pose_values(readings, Meta::object_pose_after())),
        ),
        (
            "iterations",
            Npy::i8(vec![n], readings.iter().map(|r| Meta::Iterations.integer(r))),
        ),
        (
            "contact",
            Npy::i8(vec![n], readings.iter().map(|r| Meta::Contact.integer(r))),
        ),
        ("object", text(Meta::Object)),
        ("status", text(Meta::Status)),
        ("strategy", text(Meta::Strategy)),
        ("cause", text(Meta::Cause)),
        ("touched_bodies", text(Meta::TouchedBodies)),
        ("header", Npy::unicode(vec![], &[header_json.to_string()])),
    ];
    npz_bytes(arrays)
}

/// The one type of a dataset column in every export and in pandas (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnType {
    /// A name (UTF-8; empty where a reading has none, e.g. `cause`).
    Text,
    /// `iterations` and `contact`.
    Int64,
    /// The object's and the pad's pose (the pad's NaN, or null, where a reading has no pose).
    Float64,
    /// A taxel.
    Float32,
}

impl ColumnType {
    /// numpy's name of the type (`"str"` for text).
    pub fn numpy(self) -> &'static str {
        match self {
            Self::Text => "str",
            Self::Int64 => "int64",
            Self::Float64 => "float64",
            Self::Float32 => "float32",
        }
    }
}

/// Every column of a dataset of a `rows x cols` sensor, in the CSV's order ([`column_names`]),
/// with its type.
pub fn column_types(rows: usize, cols: usize) -> Vec<(String, ColumnType)> {
    let columns = ParquetColumn::all(rows * cols).map(ParquetColumn::column_type);
    column_names(rows, cols).into_iter().zip(columns).collect()
}

/// A column of the Parquet file: one of the CSV's columns before the taxels, or a taxel
/// (row-major index).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ParquetColumn {
    Meta(Meta),
    Taxel(usize),
}

impl ParquetColumn {
    /// Every column, in the CSV's order.
    fn all(taxels: usize) -> impl Iterator<Item = Self> {
        let metas = Meta::ALL.into_iter().map(Self::Meta);
        metas.chain((0..taxels).map(Self::Taxel))
    }

    /// The column's type: names text, `iterations` and `contact` int64, poses float64, taxels
    /// float32.
    fn column_type(self) -> ColumnType {
        match self {
            Self::Taxel(_) => ColumnType::Float32,
            Self::Meta(Meta::Iterations | Meta::Contact) => ColumnType::Int64,
            Self::Meta(m) if m.is_optional_pose() || Meta::object_pose().contains(&m) => ColumnType::Float64,
            Self::Meta(_) => ColumnType::Text,
        }
    }

    /// How the column is stored: its [`ColumnType`], the pad pose optional (for images without
    /// one) and the object's pose after the touch (for a fixed object).
    fn storage(self) -> (PhysicalType, Repetition) {
        let physical = match self.column_type() {
            ColumnType::Text => PhysicalType::BYTE_ARRAY,
            ColumnType::Int64 => PhysicalType::INT64,
            ColumnType::Float64 => PhysicalType::DOUBLE,
            ColumnType::Float32 => PhysicalType::FLOAT,
        };
        let optional = matches!(self, Self::Meta(m) if m.is_optional_pose());
        let repetition = if optional {
            Repetition::OPTIONAL
        } else {
            Repetition::REQUIRED
        };
        (physical, repetition)
    }

    fn schema(self, name: &str) -> Result<TypePtr, ParquetError> {
        let (physical, repetition) = self.storage();
        let logical = (physical == PhysicalType::BYTE_ARRAY).then_some(LogicalType::String);
        let column = SchemaType::primitive_type_builder(name, physical)
            .with_repetition(repetition)
            .with_logical_type(logical)
            .build()?;
        Ok(Arc::new(column))
    }

    /// This column of every reading.
    fn write(
        self,
        column: &mut SerializedColumnWriter<'_>,
        readings: &[Reading],
    ) -> Result<(), ParquetError> {
        let meta = match self {
            Self::Taxel(taxel) => {
                let values: Vec<f32> = readings.iter().map(|r| r.image.values()[taxel] as f32).collect();
                column.typed::<FloatType>().write_batch(&values, None, None)?;
                return Ok(());
            }
            Self::Meta(meta) => meta,
        };
        match self.storage() {
            (PhysicalType::INT64, _) => {
                let values: Vec<i64> = readings.iter().map(|r| meta.integer(r)).collect();
                column.typed::<Int64Type>().write_batch(&values, None, None)?;
            }
            (PhysicalType::DOUBLE, repetition) => {
                let numbers: Vec<Option<f64>> = readings.iter().map(|r| meta.number(r)).collect();
                let values: Vec<f64> = numbers.iter().flatten().copied().collect();
                let defined: Vec<i16> = numbers.iter().map(|n| i16::from(n.is_some())).collect();
                let levels = (repetition == Repetition::OPTIONAL).then_some(defined.as_slice());
                column.typed::<DoubleType>().write_batch(&values, levels, None)?;
            }
            _ => {
                let values: Vec<ByteArray> = readings
                    .iter()
                    .map(|r| ByteArray::from(meta.field(r).into_bytes()))
                    .collect();
                column.typed::<ByteArrayType>().write_batch(&values, None, None)?;
            }
        }
        Ok(())
    }
}

/// The `.parquet` of the module docs, in memory.
fn parquet(dataset: &Dataset, header_json: String) -> Result<Vec<u8>, ParquetError> {
    let (rows, cols) = (dataset.header().sensor.rows, dataset.header().sensor.cols);
    let columns: Vec<ParquetColumn> = ParquetColumn::all(rows * cols).collect();
    let fields = column_names(rows, cols)
        .iter()
        .zip(&columns)
        .map(|(name, column)| column.schema(name))
        .collect::<Result<Vec<_>, _>>()?;
    let schema = SchemaType::group_type_builder("taction_dataset")
        .with_fields(fields)
        .build()?;
    let properties = WriterProperties::builder()
        .set_compression(Compression::SNAPPY)
        .set_key_value_metadata(Some(vec![KeyValue::new("taction_header".into(), header_json)]))
        .build();
    let mut writer = SerializedFileWriter::new(Vec::new(), Arc::new(schema), Arc::new(properties))?;
    let mut group = writer.next_row_group()?;
    for column in columns {
        let mut writer = group
            .next_column()?
            .ok_or_else(|| ParquetError::General(format!("{column:?} is not in the schema")))?;
        column.write(&mut writer, dataset.readings())?;
        writer.close()?;
    }
    group.close()?;
    writer.into_inner()
}
