//! numpy's `.npy` arrays and `.npz` archives of them, both ways: written for `dataset export`
//! (`export.rs`) and read for `dataset import` of frames kept as numpy arrays (`recorded.rs`).
//!
//! The reader takes what `numpy.save`, `numpy.savez` and `numpy.savez_compressed` write (NPY format
//! 1.0, 2.0 and 3.0): numbers of any byte order (`bool`, `int8`-`int64`, `uint8`-`uint64`,
//! `float32`, `float64`) and fixed-width unicode strings (`<U..`), in C or Fortran order, as `f64`
//! or `String`s in C order. Object arrays are pickles, which it refuses with the way round
//! (`numpy.array(labels, dtype=str)`): loading them would run code from the file.

use std::io::{Cursor, Read, Write};

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipArchive, ZipWriter};

/// The magic every `.npy` starts with.
const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// One array of an `.npz`: its NPY dtype (`descr`), shape (C order), and little-endian data.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Npy {
    descr: String,
    shape: Vec<usize>,
    data: Vec<u8>,
}

impl Npy {
    pub(crate) fn f4(shape: Vec<usize>, values: impl IntoIterator<Item = f32>) -> Self {
        let data = values.into_iter().flat_map(f32::to_le_bytes).collect();
        Self {
            descr: "<f4".into(),
            shape,
            data,
        }
    }

    pub(crate) fn f8(shape: Vec<usize>, values: impl IntoIterator<Item = f64>) -> Self {
        let data = values.into_iter().flat_map(f64::to_le_bytes).collect();
        Self {
            descr: "<f8".into(),
            shape,
            data,
        }
    }

    pub(crate) fn i8(shape: Vec<usize>, values: impl IntoIterator<Item = i64>) -> Self {
        let data = values.into_iter().flat_map(i64::to_le_bytes).collect();
        Self {
            descr: "<i8".into(),
            shape,
            data,
        }
    }

    /// Fixed-width unicode `<U{width}`, the longest text's length in characters (at least 1, as
    /// numpy makes it): UTF-32LE, each text padded with NULs, so no pickle is needed to load it.
    pub(crate) fn unicode(shape: Vec<usize>, texts: &[String]) -> Self {
        let width = texts.iter().map(|t| t.chars().count()).max().unwrap_or(0).max(1);
        let mut data = Vec::with_capacity(4 * width * texts.len());
        for text in texts {
            data.extend(text.chars().flat_map(|c| u32::from(c).to_le_bytes()));
            data.resize(data.len() + 4 * (width - text.chars().count()), 0);
        }
        Self {
            descr: format!("<U{width}"),
            shape,
            data,
        }
    }

    /// The NPY 1.0 header: magic `\x93NUMPY`, version 1.0, the dict's length (u16 LE), then the
    /// dict as numpy writes it, padded with spaces and a newline so the data starts at a multiple
    /// of 64 bytes (numpy's own padding rule, so the bytes equal `numpy.save`'s).
    fn header(&self) -> Vec<u8> {
        let shape = match self.shape.as_slice() {
            [n] => format!("({n},)"),
            dims => format!(
                "({})",
                dims.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")
            ),
        };
        let mut dict = format!(
            "{{'descr': '{}', 'fortran_order': False, 'shape': {shape}, }}",
            self.descr
        );
        const PREFIX: usize = 10;
        let padding = 64 - (PREFIX + dict.len() + 1) % 64;
        dict.extend(std::iter::repeat_n(' ', padding));
        dict.push('\n');
        let mut header = b"\x93NUMPY\x01\x00".to_vec();
        // A dict of one dtype and a shape of at most three numbers is far below u16::MAX.
        header.extend((dict.len() as u16).to_le_bytes());
        header.extend(dict.as_bytes());
        header
    }

    /// The `.npy` file: [`header`](Self::header), then the data.
    pub(crate) fn to_bytes(&self) -> Vec<u8> {
        let mut bytes = self.header();
        bytes.extend(&self.data);
        bytes
    }
}

/// `arrays` as an `.npz` (a zip of `<name>.npy` files, deflated), in memory.
pub(crate) fn npz_bytes<'a>(
    arrays: impl IntoIterator<Item = (&'a str, Npy)>,
) -> Result<Vec<u8>, zip::result::ZipError> {
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    for (name, array) in arrays {
        let bytes = array.to_bytes();
        let options = SimpleFileOptions::default()
            .compression_method(CompressionMethod::Deflated)
            .large_file(bytes.len() >= u32::MAX as usize);
        zip.start_file(format!("{name}.npy"), options)?;
        zip.write_all(&bytes)?;
    }
    Ok(zip.finish()?.into_inner())
}

/// An array read from an `.npy`: its shape and its elements in C (row-major) order.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyArray {
    pub shape: Vec<usize>,
    pub values: NpyValues,
}

/// An array's elements: numbers (every numeric dtype, as `f64`) or texts.
#[derive(Debug, Clone, PartialEq)]
pub enum NpyValues {
    Numbers(Vec<f64>),
    Texts(Vec<String>),
}

impl NpyArray {
    /// The dtype's kind in words, for messages.
    pub fn kind(&self) -> &'static str {
        match self.values {
            NpyValues::Numbers(_) => "numbers",
            NpyValues::Texts(_) => "strings",
        }
    }
}

/// What is wrong with an `.npy` (or an `.npz` member); the caller names the file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NpyError {
    #[error("not a numpy array: it does not start with numpy's magic \\x93NUMPY")]
    NotNpy,
    #[error("NPY format version {0}.{1}; this reader knows 1.0, 2.0 and 3.0")]
    Version(u8, u8),
    #[error("the header is cut short or is not numpy's dict: {0}")]
    Header(String),
    #[error(
        "dtype '{0}' holds Python objects (a pickle, which loading would run): save the labels as strings, numpy.array(labels, dtype=str)"
    )]
    Objects(String),
    #[error(
        "dtype '{0}' is not one this reader knows (bool, int8-int64, uint8-uint64, float32, float64, unicode strings)"
    )]
    Dtype(String),
    #[error("shape {shape:?} holds {expected} bytes of data, the file {got}")]
    Length {
        shape: Vec<usize>,
        expected: usize,
        got: usize,
    },
    #[error("a string is not valid unicode")]
    Unicode,
    #[error("not a zip archive of .npy arrays: {0}")]
    Zip(String),
    #[error("member '{name}': {source}")]
    Member { name: String, source: Box<NpyError> },
}

/// How one element is stored.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Dtype {
    /// A number of `size` bytes: `kind` `b` (bool), `i`, `u` or `f`, big-endian or not.
    Number { kind: u8, size: usize, big_endian: bool },
    /// Fixed-width unicode, `chars` UTF-32 code units, big-endian or not.
    Unicode { chars: usize, big_endian: bool },
}

impl Dtype {
    fn parse(descr: &str) -> Result<Self, NpyError> {
        let unknown = || NpyError::Dtype(descr.to_string());
        let mut chars = descr.chars();
        let big_endian = match chars.next() {
            Some('>') => true,
            Some('<' | '|' | '=') => false,
            _ => return Err(unknown()),
        };
        let kind = chars.next().ok_or_else(unknown)?;
        if kind == 'O' {
            return Err(NpyError::Objects(descr.to_string()));
        }
        let size: usize = chars.as_str().parse().map_err(|_| unknown())?;
        match (kind, size) {
            ('U', chars) => Ok(Self::Unicode { chars, big_endian }),
            ('b', 1) | ('i' | 'u', 1 | 2 | 4 | 8) | ('f', 4 | 8) => Ok(Self::Number {
                kind: kind as u8,
                size,
                big_endian,
            }),
            _ => Err(unknown()),
        }
    }

    fn size(self) -> usize {
        match self {
            Self::Number { size, .. } => size,
            Self::Unicode { chars, .. } => 4 * chars,
        }
    }

    /// One number from its `bytes` (`size` of them).
    fn number(kind: u8, big_endian: bool, bytes: &[u8]) -> f64 {
        let mut b = [0u8; 8];
        let n = bytes.len();
        if big_endian {
            b[..n].copy_from_slice(bytes);
            b[..n].reverse();
        } else {
            b[..n].copy_from_slice(bytes);
        }
        match (kind, n) {
            (b'f', 4) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            (b'f', _) => f64::from_le_bytes(b),
            (b'i', _) => {
                // Sign-extend the n-byte integer.
                let shift = 64 - 8 * n as u32;
                ((i64::from_le_bytes(b) << shift) >> shift) as f64
            }
            _ => u64::from_le_bytes(b) as f64,
        }
    }
}

/// Reads one `.npy` file's bytes.
pub fn parse_npy(bytes: &[u8]) -> Result<NpyArray, NpyError> {
    if bytes.len() < 8 || &bytes[..6] != MAGIC {
        return Err(NpyError::NotNpy);
    }
    let (major, minor) = (bytes[6], bytes[7]);
    let (length_bytes, utf8) = match major {
        1 => (2, false),
        2 => (4, false),
        3 => (4, true),
        _ => return Err(NpyError::Version(major, minor)),
    };
    let short = || NpyError::Header("the file ends inside it".into());
    let length_field = bytes.get(8..8 + length_bytes).ok_or_else(short)?;
    let header_len = length_field
        .iter()
        .rev()
        .fold(0usize, |n, &b| (n << 8) | usize::from(b));
    let start = 8 + length_bytes;
    let header = bytes.get(start..start + header_len).ok_or_else(short)?;
    let header = if utf8 {
        std::str::from_utf8(header).map_err(|_| NpyError::Header("not UTF-8".into()))?
    } else {
        std::str::from_utf8(header).map_err(|_| NpyError::Header("not ASCII".into()))?
    };
    let (descr, fortran_order, shape) = parse_header(header)?;
    let dtype = Dtype::parse(&descr)?;
    // A corrupt header can name a shape no memory holds: its size is checked, not wrapped.
    let expected = shape
        .iter()
        .try_fold(dtype.size(), |n, &d| n.checked_mul(d))
        .ok_or_else(|| NpyError::Header(format!("shape {shape:?} is larger than any memory")))?;
    let data = &bytes[start + header_len..];
    if data.len() != expected {
        return Err(NpyError::Length {
            shape,
            expected,
            got: data.len(),
        });
    }
    let order = c_order(&shape, fortran_order);
    let element = |i: usize| &data[i * dtype.size()..(i + 1) * dtype.size()];
    let values = match dtype {
        Dtype::Number { kind, big_endian, .. } => NpyValues::Numbers(
            order
                .map(|i| Dtype::number(kind, big_endian, element(i)))
                .collect(),
        ),
        Dtype::Unicode { big_endian, .. } => NpyValues::Texts(
            order
                .map(|i| unicode(element(i), big_endian))
                .collect::<Result<_, _>>()?,
        ),
    };
    Ok(NpyArray { shape, values })
}

/// The storage index of every element in C order: the identity, or Fortran order's transpose.
fn c_order(shape: &[usize], fortran_order: bool) -> Box<dyn Iterator<Item = usize> + '_> {
    let count: usize = shape.iter().product();
    if !fortran_order || shape.len() < 2 {
        return Box::new(0..count);
    }
    Box::new((0..count).map(move |c| {
        // Split the C-order index into coordinates (last fastest), then weigh them first fastest.
        let (mut rest, mut f, mut stride) = (c, 0, 1);
        let mut coordinates = vec![0; shape.len()];
        for (k, &d) in shape.iter().enumerate().rev() {
            coordinates[k] = rest % d.max(1);
            rest /= d.max(1);
        }
        for (&x, &d) in coordinates.iter().zip(shape) {
            f += x * stride;
            stride *= d;
        }
        f
    }))
}

/// One fixed-width UTF-32 string, its trailing NULs dropped.
fn unicode(bytes: &[u8], big_endian: bool) -> Result<String, NpyError> {
    bytes
        .chunks_exact(4)
        .map(|c| {
            let unit = [c[0], c[1], c[2], c[3]];
            if big_endian {
                u32::from_be_bytes(unit)
            } else {
                u32::from_le_bytes(unit)
            }
        })
        .take_while(|&u| u != 0)
        .map(|u| char::from_u32(u).ok_or(NpyError::Unicode))
        .collect()
}

/// The header dict `{'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }`: its dtype,
/// order and shape.
fn parse_header(header: &str) -> Result<(String, bool, Vec<usize>), NpyError> {
    let bad = |what: &str| NpyError::Header(format!("{what} in {}", header.trim()));
    let after = |key: &str| -> Result<&str, NpyError> {
        let at = header
            .find(&format!("'{key}'"))
            .ok_or_else(|| bad(&format!("no '{key}'")))?;
        let rest = &header[at + key.len() + 2..];
        let colon = rest
            .find(':')
            .ok_or_else(|| bad(&format!("no ':' after '{key}'")))?;
        Ok(rest[colon + 1..].trim_start())
    };
    let descr = after("descr")?;
    let quote = descr.chars().next().filter(|c| *c == '\'' || *c == '"');
    let descr = match quote {
        Some(q) => descr[1..]
            .split(q)
            .next()
            .ok_or_else(|| bad("an unclosed 'descr'"))?
            .to_string(),
        // A structured dtype is a list of fields.
        None => {
            return Err(NpyError::Dtype(
                descr.split('}').next().unwrap_or(descr).trim().to_string(),
            ));
        }
    };
    let fortran = after("fortran_order")?;
    let fortran_order = if fortran.starts_with("True") {
        true
    } else if fortran.starts_with("False") {
        false
    } else {
        return Err(bad("'fortran_order' neither True nor False"));
    };
    let shape = after("shape")?;
    let inside = shape
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| bad("'shape' not a tuple"))?;
    let shape = inside
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.trim_end_matches('L')
                .parse::<usize>()
                .map_err(|_| bad(&format!("shape entry '{s}'")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((descr, fortran_order, shape))
}

/// Reads every array of an `.npz`'s bytes, by name (the member's name less `.npy`), in the
/// archive's order.
pub fn parse_npz(bytes: &[u8]) -> Result<Vec<(String, NpyArray)>, NpyError> {
    let mut archive = ZipArchive::new(Cursor::new(bytes)).map_err(|e| NpyError::Zip(e.to_string()))?;
    let mut arrays = Vec::with_capacity(archive.len());
    for i in 0..archive.len() {
        let mut member = archive.by_index(i).map_err(|e| NpyError::Zip(e.to_string()))?;
        let name = member.name().to_string();
        let mut data = Vec::new();
        member
            .read_to_end(&mut data)
            .map_err(|e| NpyError::Zip(format!("member '{name}': {e}")))?;
        let array = parse_npy(&data).map_err(|source| NpyError::Member {
            name: name.clone(),
            source: Box::new(source),
        })?;
        let name = name.strip_suffix(".npy").unwrap_or(&name).to_string();
        arrays.push((name, array));
    }
    Ok(arrays)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header as numpy writes one, around `dict`, then `data`.
    fn npy(dict: &str, data: &[u8]) -> Vec<u8> {
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend((dict.len() as u16).to_le_bytes());
        bytes.extend(dict.as_bytes());
        bytes.extend(data);
        bytes
    }

    #[test]
    fn what_the_writer_writes_the_reader_reads() {
        let numbers = Npy::f4(vec![2, 3], [0.0, 1.5, -2.0, 3.25, 4.0, 1e-3]);
        let back = parse_npy(&numbers.to_bytes()).expect("reads");
        assert_eq!(back.shape, [2, 3]);
        assert_eq!(
            back.values,
            NpyValues::Numbers(vec![0.0, 1.5, -2.0, 3.25, 4.0, f64::from(1e-3f32)])
        );
        let texts = Npy::unicode(vec![3], &["A".into(), "bé".into(), "".into()]);
        let back = parse_npy(&texts.to_bytes()).expect("reads");
        assert_eq!(
            back.values,
            NpyValues::Texts(vec!["A".into(), "bé".into(), "".into()])
        );
        let wide = Npy::i8(vec![2], [-3, 1 << 40]);
        assert_eq!(
            parse_npy(&wide.to_bytes()).expect("reads").values,
            NpyValues::Numbers(vec![-3.0, (1u64 << 40) as f64])
        );
        let zip = npz_bytes([("frames", numbers), ("labels", texts)]).expect("zips");
        let arrays = parse_npz(&zip).expect("reads the archive");
        let names: Vec<&str> = arrays.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["frames", "labels"]);
    }

    #[test]
    fn byte_order_width_sign_and_fortran_order_are_read_as_numpy_means_them() {
        // uint16 big-endian 258 and 1; int16 little-endian -2; Fortran order of [[1, 2, 3], [4, 5, 6]].
        let be = npy(
            "{'descr': '>u2', 'fortran_order': False, 'shape': (2,), }",
            &[1, 2, 0, 1],
        );
        assert_eq!(
            parse_npy(&be).expect("reads").values,
            NpyValues::Numbers(vec![258.0, 1.0])
        );
        let signed = npy(
            "{'descr': '<i2', 'fortran_order': False, 'shape': (1,), }",
            &[0xfe, 0xff],
        );
        assert_eq!(
            parse_npy(&signed).expect("reads").values,
            NpyValues::Numbers(vec![-2.0])
        );
        let column_major: Vec<u8> = [1u8, 4, 2, 5, 3, 6].to_vec();
        let f = npy(
            "{'descr': '|u1', 'fortran_order': True, 'shape': (2, 3), }",
            &column_major,
        );
        assert_eq!(
            parse_npy(&f).expect("reads").values,
            NpyValues::Numbers(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
        );
    }

    #[test]
    fn a_bad_array_is_named_not_read() {
        assert_eq!(parse_npy(b"label,r0c0\n"), Err(NpyError::NotNpy));
        let pickled = npy(
            "{'descr': '|O', 'fortran_order': False, 'shape': (2,), }",
            &[0; 16],
        );
        assert!(matches!(parse_npy(&pickled), Err(NpyError::Objects(_))));
        let short = npy(
            "{'descr': '<f8', 'fortran_order': False, 'shape': (3,), }",
            &[0; 16],
        );
        assert_eq!(
            parse_npy(&short),
            Err(NpyError::Length {
                shape: vec![3],
                expected: 24,
                got: 16
            })
        );
        let huge = npy(
            "{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 4294967296), }",
            &[0; 8],
        );
        assert!(matches!(parse_npy(&huge), Err(NpyError::Header(_))));
        let half = npy(
            "{'descr': '<f2', 'fortran_order': False, 'shape': (1,), }",
            &[0; 2],
        );
        assert!(matches!(parse_npy(&half), Err(NpyError::Dtype(_))));
        assert!(matches!(
            parse_npy(&b"\x93NUMPY\x01\x00\xff"[..]),
            Err(NpyError::Header(_))
        ));
        assert!(matches!(parse_npz(b"not a zip"), Err(NpyError::Zip(_))));
    }
}
