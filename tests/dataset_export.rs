//! `Dataset::export` (issue 37): the npz read back through a minimal NPY reader of this file
//! (shapes, dtypes, values bit for bit, strings), the NPY header against the bytes `numpy.save`
//! writes, and the Parquet file through the parquet crate's reader.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::Read;
use std::path::Path;

use glam::{DQuat, DVec3};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::record::Field;
use taction::dataset::{
    AttemptCause, ContactStatus, Dataset, DatasetHeader, ExportFormat, Reading, Strategy,
};
use taction::pose::{PadPose, Pose};
use taction::tactile::{SensorConfig, TactileImage};

/// A 2x3 sensor (rows != cols, so a transposed image shows), three readings: with a pad pose,
/// without one, and a collision naming its bodies; an object name beyond ASCII.
fn dataset() -> Dataset {
    let sensor = SensorConfig::square(2, 3, 0.012, 0.0012);
    let objects = vec!["mug \"é\"".to_string(), "c".to_string()];
    let header = DatasetHeader::new(sensor, "toy", objects, "sampler", 42);
    let reading = |object: &str, k: f64, with_pad: bool, status: ContactStatus| {
        let values = vec![0.0, 1.0, 0.1 + 0.2, 1e-300, k / 7.0, 0.5];
        let mut image = TactileImage::new(2, 3, values).unwrap();
        if with_pad {
            image = image.with_pose(PadPose {
                center_m: DVec3::new(0.1, -0.0, 1e-17 * k),
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
            // The two frames of `c` one press; the mug's reading a contact of its own.
            contact: (object == "c").then_some(0),
        }
    };
    let readings = vec![
        reading("mug \"é\"", 1.0, true, ContactStatus::Converged),
        reading("c", 2.0, false, ContactStatus::NoContact),
        reading("c", 3.0, true, ContactStatus::Collision),
    ];
    Dataset::new(header, readings).unwrap()
}

/// The CSV's line 2 after `# `: the header JSON every export carries.
fn csv_header_json(dataset: &Dataset, dir: &Path) -> String {
    let path = dir.join("d.csv");
    dataset.write(&path).unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .nth(1)
        .unwrap()
        .strip_prefix("# ")
        .unwrap()
        .to_string()
}

/// One `.npy` array as read by [`parse_npy`].
#[derive(Debug)]
struct Npy {
    descr: String,
    shape: Vec<usize>,
    data: Vec<u8>,
}

/// A minimal NPY 1.0 reader: magic, version, header dict (C order), data aligned to 64 bytes.
fn parse_npy(bytes: &[u8]) -> Npy {
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    assert_eq!((10 + header_len) % 64, 0, "data not aligned");
    let dict = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(dict.ends_with('\n'));
    let between = |start: &str, end: &str| {
        let from = dict.find(start).unwrap() + start.len();
        dict[from..from + dict[from..].find(end).unwrap()].to_string()
    };
    assert!(dict.contains("'fortran_order': False"), "{dict}");
    let shape = between("'shape': (", ")")
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect();
    Npy {
        descr: between("'descr': '", "'"),
        shape,
        data: bytes[10 + header_len..].to_vec(),
    }
}

fn read_npz(path: &Path) -> BTreeMap<String, Npy> {
    let mut zip = zip::ZipArchive::new(File::open(path).unwrap()).unwrap();
    (0..zip.len())
        .map(|i| {
            let mut entry = zip.by_index(i).unwrap();
            let mut bytes = Vec::new();
            entry.read_to_end(&mut bytes).unwrap();
            let name = entry.name().strip_suffix(".npy").unwrap().to_string();
            (name, parse_npy(&bytes))
        })
        .collect()
}

impl Npy {
    fn f4(&self) -> Vec<u32> {
        assert_eq!(self.descr, "<f4");
        let chunks = self.data.chunks_exact(4);
        chunks
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()).to_bits())
            .collect()
    }

    fn f8(&self) -> Vec<u64> {
        assert_eq!(self.descr, "<f8");
        let chunks = self.data.chunks_exact(8);
        chunks
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()).to_bits())
            .collect()
    }

    fn i8(&self) -> Vec<i64> {
        assert_eq!(self.descr, "<i8");
        self.data
            .chunks_exact(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    /// Fixed-width UTF-32LE texts, NUL-padded.
    fn texts(&self) -> Vec<String> {
        let width: usize = self.descr.strip_prefix("<U").unwrap().parse().unwrap();
        let chars = self
            .data
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()));
        let chars: Vec<char> = chars.map(|c| char::from_u32(c).unwrap()).collect();
        chars
            .chunks(width)
            .map(|text| text.iter().filter(|&&c| c != '\0').collect())
            .collect()
    }
}

#[test]
fn npz_holds_every_array_bit_exact_in_file_order_and_no_temporary_is_left() {
    let dir = tempfile::tempdir().unwrap();
    let data = dataset();
    let path = dir.path().join("d.npz");
    data.export(&path, ExportFormat::Npz).unwrap();
    let arrays = read_npz(&path);
    let names: Vec<&str> = arrays.keys().map(String::as_str).collect();
    let expected = [
        "cause",
        "contact",
        "header",
        "images",
        "iterations",
        "object",
        "object_pose",
        "object_pose_after",
        "pad_pose",
        "status",
        "strategy",
        "touched_bodies",
    ];
    assert_eq!(names, expected);
    let readings = data.readings();

    let images = &arrays["images"];
    assert_eq!(images.shape, [3, 2, 3]);
    let want: Vec<u32> = readings
        .iter()
        .flat_map(|r| r.image.values().iter().map(|&v| (v as f32).to_bits()))
        .collect();
    assert_eq!(images.f4(), want);

    let pad = &arrays["pad_pose"];
    assert_eq!(pad.shape, [3, 9]);
    let pad_values = pad.f8();
    let p = readings[2].image.pose().unwrap();
    let third: Vec<u64> = [p.center_m, p.normal, p.up]
        .iter()
        .flat_map(|v| v.to_array())
        .map(f64::to_bits)
        .collect();
    assert_eq!(pad_values[18..], third);
    assert!(
        pad_values[9..18].iter().all(|&b| f64::from_bits(b).is_nan()),
        "no pose: NaN"
    );
    assert_eq!(pad_values[2], (1e-17f64).to_bits());
    assert_eq!(pad_values[1], (-0.0f64).to_bits(), "the sign of zero survives");

    let object_pose = &arrays["object_pose"];
    assert_eq!(object_pose.shape, [3, 7]);
    let o = readings[1].object_pose;
    let (t, q) = (o.position_m, o.rotation);
    let second: Vec<u64> = [t.x, t.y, t.z, q.w, q.x, q.y, q.z].map(f64::to_bits).to_vec();
    assert_eq!(object_pose.f8()[7..14], second);

    let after = &arrays["object_pose_after"];
    assert_eq!(after.shape, [3, 7]);
    let o = readings[0].object_pose_after.expect("a free object's reading");
    let (t, q) = (o.position_m, o.rotation);
    let first: Vec<u64> = [t.x, t.y, t.z, q.w, q.x, q.y, q.z].map(f64::to_bits).to_vec();
    assert_eq!(after.f8()[..7], first);
    assert!(
        after.f8()[7..14].iter().all(|&b| f64::from_bits(b).is_nan()),
        "a fixed object: NaN"
    );

    assert_eq!(arrays["iterations"].shape, [3]);
    assert_eq!(arrays["iterations"].i8(), [1, 2, 3]);
    assert_eq!(arrays["contact"].i8(), [-1, 0, 0], "-1: a contact of its own");
    let texts = |name: &str| {
        assert_eq!(arrays[name].shape, [3], "{name}");
        arrays[name].texts()
    };
    assert_eq!(arrays["object"].descr, "<U7", "width in characters, not bytes");
    assert_eq!(texts("object"), ["mug \"é\"", "c", "c"]);
    assert_eq!(texts("status"), ["converged", "no_contact", "collision"]);
    assert_eq!(texts("strategy"), ["local", "recorded", "local"]);
    assert_eq!(texts("cause"), ["", "", "arm_on_table"]);
    assert_eq!(texts("touched_bodies"), ["", "", "link4/world"]);

    let header = &arrays["header"];
    assert!(header.shape.is_empty(), "a 0-d array");
    assert_eq!(header.texts(), [csv_header_json(&data, dir.path())]);

    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "only d.npz and d.csv: {left:?}");
}

#[test]
fn the_npy_header_is_the_bytes_numpy_save_writes() {
    let dir = tempfile::tempdir().unwrap();
    let one = Dataset::new(dataset().header().clone(), dataset().readings()[..1].to_vec()).unwrap();
    let path = dir.path().join("one.npz");
    one.export(&path, ExportFormat::Npz).unwrap();
    let mut zip = zip::ZipArchive::new(File::open(&path).unwrap()).unwrap();
    let mut bytes = Vec::new();
    zip.by_name("images.npy")
        .unwrap()
        .read_to_end(&mut bytes)
        .unwrap();
    // `numpy.save(f, numpy.zeros((1, 2, 3), "<f4"))`: 128 header bytes, then 6 x 4 data bytes.
    let dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 2, 3), }";
    let mut numpy = b"\x93NUMPY\x01\x00\x76\x00".to_vec();
    numpy.extend(dict.as_bytes());
    numpy.resize(127, b' ');
    numpy.push(b'\n');
    assert_eq!(bytes.len(), 128 + 6 * 4);
    assert_eq!(bytes[..128], numpy[..]);
    let mut status = Vec::new();
    zip.by_name("status.npy")
        .unwrap()
        .read_to_end(&mut status)
        .unwrap();
    assert!(
        status.starts_with(
            b"\x93NUMPY\x01\x00\x76\x00{'descr': '<U9', 'fortran_order': False, 'shape': (1,), }"
        )
    );
    assert_eq!(
        status[128..],
        *b"c\0\0\0o\0\0\0n\0\0\0v\0\0\0e\0\0\0r\0\0\0g\0\0\0e\0\0\0d\0\0\0"
    );
}

#[test]
fn parquet_reads_back_with_the_parquet_reader() {
    let dir = tempfile::tempdir().unwrap();
    let data = dataset();
    let path = dir.path().join("d.parquet");
    data.export(&path, ExportFormat::Parquet).unwrap();
    let reader = SerializedFileReader::new(File::open(&path).unwrap()).unwrap();
    let meta = reader.metadata().file_metadata();
    assert_eq!(meta.num_rows(), 3);
    let columns: Vec<String> = meta
        .schema_descr()
        .columns()
        .iter()
        .map(|c| c.name().to_string())
        .collect();
    assert_eq!(columns, taction::dataset::column_names(2, 3));
    let header = meta
        .key_value_metadata()
        .and_then(|kv| kv.iter().find(|kv| kv.key == "taction_header"))
        .and_then(|kv| kv.value.clone());
    assert_eq!(header, Some(csv_header_json(&data, dir.path())));

    let rows: Vec<parquet::record::Row> = reader.get_row_iter(None).unwrap().map(Result::unwrap).collect();
    let field = |row: usize, name: &str| {
        rows[row]
            .get_column_iter()
            .find(|(n, _)| n.as_str() == name)
            .map(|(_, f)| f.clone())
            .unwrap()
    };
    assert_eq!(field(0, "object"), Field::Str("mug \"é\"".into()));
    assert_eq!(field(2, "cause"), Field::Str("arm_on_table".into()));
    assert_eq!(field(1, "cause"), Field::Str(String::new()));
    assert_eq!(field(2, "iterations"), Field::Long(3));
    assert_eq!(
        (field(0, "contact"), field(2, "contact")),
        (Field::Long(-1), Field::Long(0))
    );
    assert_eq!(field(1, "pad_x_m"), Field::Null, "no pose: null");
    assert_eq!(field(0, "pad_x_m"), Field::Double(0.1));
    assert_eq!(field(1, "object_y_m"), Field::Double(2.0 / 3.0));
    assert_eq!(field(1, "object_after_y_m"), Field::Null, "a fixed object: null");
    assert_eq!(field(0, "object_after_y_m"), Field::Double(1.0 / 3.0));
    for (row, reading) in data.readings().iter().enumerate() {
        let want = (reading.image.get(1, 1) as f32).to_bits();
        assert!(matches!(field(row, "t_1_1"), Field::Float(v) if v.to_bits() == want));
    }
}

#[test]
fn export_formats_parse_their_names_and_refuse_others() {
    for format in ExportFormat::ALL {
        assert_eq!(format.to_string().parse::<ExportFormat>(), Ok(format));
    }
    let err = "csv".parse::<ExportFormat>().unwrap_err().to_string();
    assert_eq!(err, "'csv' is not an export format (npz or parquet)");
}

/// `pandas.read_csv(path, comment="#")` cuts a line at an unquoted `#`: the writer quotes a field
/// holding one, and reads it back unchanged.
#[test]
fn the_csv_quotes_a_name_holding_a_hash_for_readers_that_skip_comments() {
    let dir = tempfile::tempdir().unwrap();
    let original = dataset();
    let mut header = original.header().clone();
    header.objects[1] = "cup #2".into();
    let readings = original
        .readings()
        .iter()
        .cloned()
        .map(|mut r| {
            if r.object == "c" {
                r.object = "cup #2".into();
            }
            r
        })
        .collect();
    let data = Dataset::new(header, readings).unwrap();
    let path = dir.path().join("d.csv");
    data.write(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let body: Vec<&str> = text.lines().skip(3).filter(|l| !l.starts_with('#')).collect();
    assert!(body[1].starts_with("\"cup #2\",no_contact,"), "{}", body[1]);
    assert_eq!(Dataset::read(&path).unwrap(), data);
}
