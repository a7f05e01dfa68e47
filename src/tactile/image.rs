//! The tactile image: what one reading of the covering sensor is (Sec. IV: "viewing tactile sensor
//! readings as images").
//!
//! Layout: row-major, `rows x cols`; row 0 is the pad's `+up` edge, column 0 its left edge seen from
//! behind the pad (looking along the pad normal, into the covering). Values are fractions of the
//! sensing range, in [0, 1]: 0 is no penetration, 1 is the covering pushed through completely.

use std::fmt;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::atomic::{FileError, write_atomic};
use crate::pose::PadPose;

/// Errors from building or reading a tactile image; each names the offending place.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("a tactile image needs at least one row and one column, got {rows}x{cols}")]
    Empty { rows: usize, cols: usize },
    #[error("a {rows}x{cols} tactile image needs {} values, got {got}", rows * cols)]
    WrongLength { rows: usize, cols: usize, got: usize },
    #[error("taxel (row {row}, col {col}) is {value}: values must be finite and within [0, 1]")]
    OutOfRange { row: usize, col: usize, value: f64 },
    #[error("{path}: line {line}: {what}")]
    Parse { path: String, line: usize, what: String },
    #[error("{path}: no rows of values (want rows of comma-separated values in [0, 1])")]
    NoRows { path: String },
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: cannot encode PNG: {what}")]
    Png { path: String, what: String },
}

impl From<FileError> for ImageError {
    fn from(e: FileError) -> Self {
        Self::Io {
            path: e.path.display().to_string(),
            source: e.source,
        }
    }
}

/// One tactile reading, `rows x cols` fractions of the sensing range (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TactileImage {
    rows: usize,
    cols: usize,
    values: Vec<f64>,
    /// The pad pose the reading was taken at, when known (simulation knows it; recorded data may not).
    pose: Option<PadPose>,
}

impl TactileImage {
    /// An image from row-major values; every value must be finite and in [0, 1].
    pub fn new(rows: usize, cols: usize, values: Vec<f64>) -> Result<Self, ImageError> {
        if rows == 0 || cols == 0 {
            return Err(ImageError::Empty { rows, cols });
        }
        if values.len() != rows * cols {
            return Err(ImageError::WrongLength {
                rows,
                cols,
                got: values.len(),
            });
        }
        if let Some((i, &value)) = values
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && (0.0..=1.0).contains(*v)))
        {
            return Err(ImageError::OutOfRange {
                row: i / cols,
                col: i % cols,
                value,
            });
        }
        Ok(Self {
            rows,
            cols,
            values,
            pose: None,
        })
    }

    /// An all-zero image (no contact).
    pub fn zeros(rows: usize, cols: usize) -> Result<Self, ImageError> {
        Self::new(rows, cols, vec![0.0; rows * cols])
    }

    /// The same image tagged with the pad pose it was taken at.
    pub fn with_pose(mut self, pose: PadPose) -> Self {
        self.pose = Some(pose);
        self
    }

    pub fn rows(&self) -> usize {
        self.rows
    }

    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Row-major values, row 0 first.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    pub fn pose(&self) -> Option<&PadPose> {
        self.pose.as_ref()
    }

    /// The value at (`row`, `col`); panics only on an index outside the image, a programming error.
    pub fn get(&self, row: usize, col: usize) -> f64 {
        assert!(
            row < self.rows && col < self.cols,
            "taxel ({row}, {col}) outside {}x{}",
            self.rows,
            self.cols
        );
        self.values[row * self.cols + col]
    }

    /// Mean taxel value: the "average pressure of all sensor elements" of Sec. III-B.
    pub fn mean(&self) -> f64 {
        self.values.iter().sum::<f64>() / self.values.len() as f64
    }

    /// Largest taxel value.
    pub fn max(&self) -> f64 {
        self.values.iter().copied().fold(0.0, f64::max)
    }

    /// Writes `rows` lines of `cols` comma-separated values (the format `taction sense` writes and
    /// `taction describe` reads).
    pub fn write_csv(&self, path: &Path) -> Result<(), ImageError> {
        Ok(write_atomic(path, self.to_csv_string().as_bytes())?)
    }

    /// The CSV text of [`write_csv`](Self::write_csv); values in shortest round-trip form.
    pub fn to_csv_string(&self) -> String {
        let mut s = String::new();
        for row in self.values.chunks(self.cols) {
            let line: Vec<String> = row.iter().map(|v| v.to_string()).collect();
            s.push_str(&line.join(","));
            s.push('\n');
        }
        s
    }

    /// Reads an image written by [`write_csv`](Self::write_csv); errors name the file and line.
    pub fn read_csv(path: &Path) -> Result<Self, ImageError> {
        let text = std::fs::read_to_string(path).map_err(|source| ImageError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse_csv(&text, &path.display().to_string())
    }

    /// Parses CSV text; `origin` names the source in errors.
    pub fn parse_csv(text: &str, origin: &str) -> Result<Self, ImageError> {
        let parse = |line: usize, what: String| ImageError::Parse {
            path: origin.to_string(),
            line,
            what,
        };
        let mut values = Vec::new();
        let mut cols = None;
        let mut rows = 0;
        for (i, line) in text.lines().enumerate() {
            let line_no = i + 1;
            if line.trim().is_empty() {
                continue;
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            match cols {
                None => cols = Some(fields.len()),
                Some(c) if c != fields.len() => {
                    return Err(parse(
                        line_no,
                        format!("{} values, but earlier rows have {c}", fields.len()),
                    ));
                }
                Some(_) => {}
            }
            for (j, field) in fields.iter().enumerate() {
                let v: f64 = field
                    .parse()
                    .map_err(|_| parse(line_no, format!("column {}: '{field}' is not a number", j + 1)))?;
                if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                    return Err(parse(
                        line_no,
                        format!("column {}: {v} is not a finite value in [0, 1]", j + 1),
                    ));
                }
                values.push(v);
            }
            rows += 1;
        }
        let cols = cols.ok_or_else(|| ImageError::NoRows {
            path: origin.to_string(),
        })?;
        Self::new(rows, cols, values)
    }

    /// Writes an 8-bit grayscale PNG, each taxel a `scale x scale` block (nearest neighbour), so a
    /// 6x6 image is visible; white is full penetration. `scale` 0 picks one making the long side >= 192 px.
    pub fn write_png(&self, path: &Path, scale: usize) -> Result<(), ImageError> {
        let scale = if scale == 0 {
            192usize.div_ceil(self.rows.max(self.cols))
        } else {
            scale
        };
        let (w, h) = (self.cols * scale, self.rows * scale);
        let mut pixels = vec![0u8; w * h];
        for (y, row) in pixels.chunks_mut(w).enumerate() {
            for (x, p) in row.iter_mut().enumerate() {
                *p = to_gray(self.get(y / scale, x / scale));
            }
        }
        write_gray_png(path, w, h, &pixels)
    }
}

/// An 8-bit grayscale picture, row-major.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GrayPicture {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<u8>,
}

/// Gutter between the images of a contact sheet, pixels.
pub const CONTACT_SHEET_GUTTER_PX: usize = 2;

/// `images` (all of one shape) as a grid `columns` wide, each taxel `scale x scale` pixels with a
/// [`CONTACT_SHEET_GUTTER_PX`] dark gutter between images: a contact sheet like the strips of the
/// paper's Fig. 1 and Fig. 5.
pub fn contact_sheet(
    images: &[TactileImage],
    columns: usize,
    scale: usize,
) -> Result<GrayPicture, ImageError> {
    let Some(first) = images.first() else {
        return Err(ImageError::Empty { rows: 0, cols: 0 });
    };
    let (rows, cols) = (first.rows(), first.cols());
    if let Some(other) = images.iter().find(|i| i.rows() != rows || i.cols() != cols) {
        return Err(ImageError::WrongLength {
            rows,
            cols,
            got: other.values().len(),
        });
    }
    let (columns, scale, gutter) = (columns.max(1), scale.max(1), CONTACT_SHEET_GUTTER_PX);
    let grid_rows = images.len().div_ceil(columns);
    let (cell_w, cell_h) = (cols * scale + gutter, rows * scale + gutter);
    let (w, h) = (columns * cell_w + gutter, grid_rows * cell_h + gutter);
    let mut pixels = vec![40u8; w * h];
    for (k, image) in images.iter().enumerate() {
        let (x0, y0) = (gutter + (k % columns) * cell_w, gutter + (k / columns) * cell_h);
        for y in 0..rows * scale {
            for x in 0..cols * scale {
                pixels[(y0 + y) * w + x0 + x] = to_gray(image.get(y / scale, x / scale));
            }
        }
    }
    Ok(GrayPicture {
        width: w,
        height: h,
        pixels,
    })
}

/// Writes the `contact_sheet` of `images` as PNG.
pub fn write_contact_sheet(
    images: &[TactileImage],
    columns: usize,
    scale: usize,
    path: &Path,
) -> Result<(), ImageError> {
    let sheet = contact_sheet(images, columns, scale)?;
    write_gray_png(path, sheet.width, sheet.height, &sheet.pixels)
}

/// A value in [0, 1] as an 8-bit gray level.
pub fn to_gray(value: f64) -> u8 {
    (value.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Writes an 8-bit grayscale PNG of `width x height` row-major pixels.
pub fn write_gray_png(path: &Path, width: usize, height: usize, pixels: &[u8]) -> Result<(), ImageError> {
    write_png(path, width, height, png::ColorType::Grayscale, pixels)
}

/// Writes an 8-bit RGB PNG of `width x height` row-major pixels, three bytes each.
pub fn write_rgb_png(path: &Path, width: usize, height: usize, pixels: &[u8]) -> Result<(), ImageError> {
    write_png(path, width, height, png::ColorType::Rgb, pixels)
}

fn write_png(
    path: &Path,
    width: usize,
    height: usize,
    color: png::ColorType,
    pixels: &[u8],
) -> Result<(), ImageError> {
    let name = || path.display().to_string();
    let dims = |v: usize| {
        u32::try_from(v).map_err(|_| ImageError::Png {
            path: name(),
            what: "too large".into(),
        })
    };
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, dims(width)?, dims(height)?);
    encoder.set_color(color);
    encoder.set_depth(png::BitDepth::Eight);
    let png_err = |e: png::EncodingError| ImageError::Png {
        path: name(),
        what: e.to_string(),
    };
    let mut writer = encoder.write_header().map_err(png_err)?;
    writer.write_image_data(pixels).map_err(png_err)?;
    writer.finish().map_err(png_err)?;
    Ok(write_atomic(path, &bytes)?)
}

impl fmt::Display for TactileImage {
    /// A compact text rendering, one line per row, for terminals.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const SHADES: &[u8] = b" .:-=+*#%@";
        for row in self.values.chunks(self.cols) {
            let line: String = row
                .iter()
                .map(|v| {
                    SHADES[((v * (SHADES.len() - 1) as f64).round() as usize).min(SHADES.len() - 1)] as char
                })
                .collect();
            writeln!(f, "{line}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_shapes_and_values() {
        assert!(matches!(
            TactileImage::new(0, 3, vec![]),
            Err(ImageError::Empty { .. })
        ));
        assert!(matches!(
            TactileImage::new(2, 2, vec![0.0; 3]),
            Err(ImageError::WrongLength { got: 3, .. })
        ));
        let e = TactileImage::new(2, 2, vec![0.0, 0.5, f64::NAN, 1.0]).unwrap_err();
        assert!(matches!(e, ImageError::OutOfRange { row: 1, col: 0, .. }), "{e}");
        assert!(TactileImage::new(1, 2, vec![0.0, 1.5]).is_err());
    }

    #[test]
    fn csv_round_trip_is_exact() {
        let values: Vec<f64> = (0..12).map(|i| (i as f64 / 11.0).powf(1.3)).collect();
        let image = TactileImage::new(3, 4, values).unwrap();
        let back = TactileImage::parse_csv(&image.to_csv_string(), "mem").unwrap();
        assert_eq!(image, back);
    }

    #[test]
    fn csv_errors_name_the_line() {
        let e = TactileImage::parse_csv("0,0.5\n0.1,x\n", "f.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("f.csv: line 2") && e.contains("'x'"), "{e}");
        let e = TactileImage::parse_csv("0,0.5\n0.1\n", "f.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2"), "{e}");
        let e = TactileImage::parse_csv("0,NaN\n", "f.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 1"), "{e}");
        for empty in ["", "\n  \n"] {
            let e = TactileImage::parse_csv(empty, "f.csv").unwrap_err().to_string();
            assert!(e.contains("f.csv: no rows of values"), "{e}");
        }
    }
}
