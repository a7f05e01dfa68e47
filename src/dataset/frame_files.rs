//! Recorded frames as users keep them (issue 73): besides the frames CSV (`recorded.rs`), a folder
//! of class folders of images (torchvision's `ImageFolder` convention) and numpy's `.npz`, read
//! into the same [`RealData`] with the same checks, calibration and normalisation, so that
//! `dataset import` files any of them as a dataset.
//!
//! # A folder of class folders
//!
//! ```text
//! frames/
//!   mug/0001.png  mug/0002.png ...
//!   pawn/0001.png ...
//! ```
//!
//! Each folder directly inside is one label (its name), each image in it one frame; labels and
//! files are taken in name order, so the frames' order is the files'. A folder inside a class
//! folder is one contact (a press recorded as a sequence of frames, `mug/press-07/0001.png ...`):
//! its images are that contact's frames, in name order, kept together by every split; an image
//! directly in the class folder is a contact of its own. Images are PNG (8 or 16 bit
//! grayscale; a palette or fewer bits are expanded) or JPEG (8 bit grayscale), every one of the
//! same size, `rows` its height and `cols` its width; a pixel's value is its raw reading. Files
//! at the top level and hidden files (`.DS_Store`) are skipped; any other file in a class folder
//! that is not such an image, a colour image, an empty class or contact folder, a folder inside a
//! contact folder or an image of another size is an error naming the file.
//!
//! # An `.npz`
//!
//! Two arrays (`numpy.savez("frames.npz", frames=frames, labels=labels)`): `frames`, numbers of
//! shape `(N, rows, cols)`, and `labels`, `N` strings or integers (an integer label is named by
//! its decimal digits). A third array, `contacts` (optional), groups frames taken across one press:
//! `N` integers or strings, the frames of one label with the same value one contact's frames,
//! consecutive (as the CSV's `contact` column, `recorded.rs`); a negative integer or an empty
//! string is a frame that is a contact of its own. A `.npz` that `taction dataset export` wrote
//! reads too: its `images`, `object` and `contact` arrays stand for `frames`, `labels` and
//! `contacts`.

use std::fs;
use std::io::{BufReader, Cursor};
use std::path::Path;

use crate::dataset::npy::{NpyArray, NpyValues, parse_npz};
use crate::dataset::recorded::{
    FramePlace, RawFrame, RealData, RealDataError, RealImport, check_calibration_grid, check_grid,
    checked_frame,
};

/// The image files a class folder may hold, by extension (any case).
const IMAGE_EXTENSIONS: [&str; 3] = ["png", "jpg", "jpeg"];

/// Whether `path` holds a frames CSV (`recorded.rs`) rather than frames kept as [`import_real`]
/// otherwise reads them: a folder, or a file named `.npz` (or `.npy`, refused with the way round).
pub fn is_frames_csv(path: &Path) -> bool {
    !path.is_dir() && numpy_extension(path).is_none()
}

/// `npz` or `npy` when `path` is named so (any case).
fn numpy_extension(path: &Path) -> Option<&'static str> {
    let extension = path.extension()?.to_string_lossy().to_ascii_lowercase();
    ["npz", "npy"].into_iter().find(|e| *e == extension)
}

/// Reads recorded frames from `path`: a folder of class folders of images, an `.npz`, or else a
/// frames CSV (`recorded.rs`).
pub fn import_real(path: &Path, options: &RealImport) -> Result<RealData, RealDataError> {
    if path.is_dir() {
        return import_real_images(path, options);
    }
    match numpy_extension(path) {
        Some("npz") => import_real_npz(path, options),
        Some(_) => Err(invalid(
            path,
            "an .npy holds one array, the frames without their labels: save both in an .npz, \
             numpy.savez(\"frames.npz\", frames=frames, labels=labels)",
        )),
        None => crate::dataset::recorded::import_real_csv(path, options),
    }
}

/// The error of a whole source (no line, frame or file below it).
fn invalid(path: &Path, what: impl Into<String>) -> RealDataError {
    RealDataError::Source {
        origin: path.display().to_string(),
        what: what.into(),
    }
}

/// Reads an `.npz` of `frames` and `labels` (module docs).
pub fn import_real_npz(path: &Path, options: &RealImport) -> Result<RealData, RealDataError> {
    let origin = path.display().to_string();
    let bytes = fs::read(path).map_err(|source| RealDataError::Io {
        origin: origin.clone(),
        source,
    })?;
    let arrays = parse_npz(&bytes).map_err(|e| invalid(path, e.to_string()))?;
    let array = |names: [&str; 2]| {
        names
            .iter()
            .find_map(|name| arrays.iter().find(|(n, _)| n == name).map(|(_, a)| a))
    };
    let find = |names: [&str; 2]| {
        array(names).ok_or_else(|| {
            let held: Vec<&str> = arrays.iter().map(|(n, _)| n.as_str()).collect();
            invalid(
                path,
                format!(
                    "no array '{}' (or '{}'); it holds: {}",
                    names[0],
                    names[1],
                    held.join(", ")
                ),
            )
        })
    };
    let frames = find(["frames", "images"])?;
    let labels = find(["labels", "object"])?;
    let contacts = array(["contacts", "contact"]);
    let (n, rows, cols) = match (frames.shape.as_slice(), &frames.values) {
        (&[n, rows, cols], NpyValues::Numbers(_)) => (n, rows, cols),
        _ => {
            return Err(invalid(
                path,
                format!(
                    "the frames array is {} of shape {:?}; expected numbers of shape (N, rows, cols)",
                    frames.kind(),
                    frames.shape
                ),
            ));
        }
    };
    check_grid(rows, cols).map_err(|what| invalid(path, what))?;
    check_calibration_grid((rows, cols), options).map_err(|what| invalid(path, what))?;
    let labels = label_texts(labels, n).map_err(|what| invalid(path, what))?;
    let contacts = match contacts {
        Some(contacts) => contact_names(contacts, n).map_err(|what| invalid(path, what))?,
        None => vec![None; n],
    };
    let NpyValues::Numbers(values) = &frames.values else {
        return Err(invalid(path, "the frames array holds no numbers"));
    };
    let taxels = rows * cols;
    let raw = labels
        .into_iter()
        .zip(contacts)
        .enumerate()
        .map(|(i, (label, contact))| {
            let frame = values[i * taxels..(i + 1) * taxels].to_vec();
            checked_frame(label, FramePlace::Frame(i), frame, cols, options, &origin)
                .map(|frame| frame.of_contact(contact))
        })
        .collect::<Result<Vec<RawFrame>, _>>()?;
    RealData::recorded(raw, (rows, cols), options, &origin)
}

/// The `n` labels of a labels array: strings, or integers named by their digits.
fn label_texts(labels: &NpyArray, n: usize) -> Result<Vec<String>, String> {
    per_frame(labels, n, ("labels", "label"), str::to_string, |x| {
        format!("{x:.0}")
    })
}

/// The `n` names of a contacts array (module docs): strings, or integers named by their digits; a
/// negative integer or an empty string is a frame that is a contact of its own.
fn contact_names(contacts: &NpyArray, n: usize) -> Result<Vec<Option<String>>, String> {
    per_frame(
        contacts,
        n,
        ("contacts", "contact"),
        |t| Some(t.to_string()),
        |x| (x >= 0.0).then(|| format!("{x:.0}")),
    )
}

/// One value a frame from an array of `n` strings or integers (`names`: the array's and one
/// value's, for messages), each string through `text` and each integer through `integer`.
fn per_frame<T>(
    array: &NpyArray,
    n: usize,
    (array_name, value_name): (&str, &str),
    text: impl Fn(&str) -> T,
    integer: impl Fn(f64) -> T,
) -> Result<Vec<T>, String> {
    if array.shape != [n] {
        return Err(format!(
            "the {array_name} array has shape {:?}, the frames {n} frames: expected shape ({n},)",
            array.shape
        ));
    }
    match &array.values {
        NpyValues::Texts(texts) => Ok(texts.iter().map(|t| text(t)).collect()),
        NpyValues::Numbers(numbers) => numbers
            .iter()
            .map(|&x| match x.fract() == 0.0 && x.is_finite() {
                true => Ok(integer(x)),
                false => Err(format!("{value_name} {x} is neither a string nor an integer")),
            })
            .collect(),
    }
}

/// Reads a folder of class folders of images (module docs).
pub fn import_real_images(root: &Path, options: &RealImport) -> Result<RealData, RealDataError> {
    let origin = root.display().to_string();
    let io = |source| RealDataError::Io {
        origin: origin.clone(),
        source,
    };
    let classes = sorted_entries(root).map_err(io)?;
    let classes: Vec<_> = classes.into_iter().filter(|p| p.is_dir()).collect();
    if classes.is_empty() {
        return Err(invalid(
            root,
            "no class folders: one folder per label, each holding that label's images",
        ));
    }
    let mut frames = ImageFrames {
        origin: origin.clone(),
        options,
        size: None,
        raw: Vec::new(),
    };
    for class in &classes {
        let label = file_name(class);
        let entries = visible_entries(class).map_err(io)?;
        if entries.is_empty() {
            return Err(invalid(root, format!("class folder '{label}' holds no image")));
        }
        for entry in entries {
            let name = file_name(&entry);
            if !entry.is_dir() {
                frames.read(&label, &entry, format!("{label}/{name}"), None)?;
                continue;
            }
            let images = visible_entries(&entry).map_err(io)?;
            if images.is_empty() {
                return Err(invalid(
                    root,
                    format!("contact folder '{label}/{name}' holds no image"),
                ));
            }
            for image in images {
                let place = format!("{label}/{name}/{}", file_name(&image));
                frames.read(&label, &image, place, Some(&name))?;
            }
        }
    }
    let Some(((rows, cols), _)) = frames.size else {
        return Err(invalid(root, "no images"));
    };
    RealData::recorded(frames.raw, (rows, cols), options, &origin)
}

/// The frames of a folder of class folders as they are read: each image one frame, every one of
/// the first one's size.
struct ImageFrames<'a> {
    origin: String,
    options: &'a RealImport,
    /// The first frame's grid and where it came from.
    size: Option<((usize, usize), String)>,
    raw: Vec<RawFrame>,
}

impl ImageFrames<'_> {
    /// The image at `path` (`place` below the root) as a frame of `label`, one of the contact
    /// folder `contact` when it lies in one.
    fn read(
        &mut self,
        label: &str,
        path: &Path,
        place: String,
        contact: Option<&str>,
    ) -> Result<(), RealDataError> {
        let at = FramePlace::Image(place.clone());
        let frame_error = |what: String| RealDataError::Frame {
            origin: self.origin.clone(),
            at: at.clone(),
            what,
        };
        if path.is_dir() {
            return Err(frame_error(
                "a folder inside a contact folder: a contact folder holds that press's images".to_string(),
            ));
        }
        let ((rows, cols), values) = read_gray_image(path).map_err(frame_error)?;
        match &self.size {
            None => {
                check_grid(rows, cols).map_err(frame_error)?;
                check_calibration_grid((rows, cols), self.options).map_err(frame_error)?;
                self.size = Some(((rows, cols), place));
            }
            Some((grid, first)) if *grid != (rows, cols) => {
                return Err(frame_error(format!(
                    "{rows}x{cols} pixels (rows x cols), but {first} is {}x{}: every frame is one size",
                    grid.0, grid.1
                )));
            }
            Some(_) => {}
        }
        let frame = checked_frame(label.to_string(), at, values, cols, self.options, &self.origin)?;
        self.raw.push(frame.of_contact(contact.map(str::to_string)));
        Ok(())
    }
}

/// The entries of `dir` in name order, without hidden files (`.DS_Store`).
fn visible_entries(dir: &Path) -> std::io::Result<Vec<std::path::PathBuf>> {
    let mut entries = sorted_entries(dir)?;
    entries.retain(|p| !file_name(p).starts_with('.'));
    Ok(entries)
}

/// The entries of `dir`, in name order.
fn sorted_entries(dir: &Path) -> std::io::Result<Vec<std::path::PathBuf>> {
    let mut entries = fs::read_dir(dir)?
        .map(|e| e.map(|e| e.path()))
        .collect::<std::io::Result<Vec<_>>>()?;
    entries.sort();
    Ok(entries)
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// A grayscale image's `(rows, cols)` and its pixels, row-major, as raw readings.
fn read_gray_image(path: &Path) -> Result<((usize, usize), Vec<f64>), String> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if !IMAGE_EXTENSIONS.contains(&extension.as_str()) {
        return Err(format!(
            "not an image ({}); a class folder holds .png, .jpg or .jpeg frames",
            IMAGE_EXTENSIONS.map(|e| format!(".{e}")).join(", ")
        ));
    }
    let bytes = fs::read(path).map_err(|e| e.to_string())?;
    if extension == "png" {
        read_png(&bytes)
    } else {
        read_jpeg(&bytes)
    }
}

fn read_png(bytes: &[u8]) -> Result<((usize, usize), Vec<f64>), String> {
    let not_png = |e: png::DecodingError| format!("not a readable PNG: {e}");
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    // A palette or gray of fewer than 8 bits becomes 8-bit; 16-bit stays 16-bit.
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(not_png)?;
    let (color, depth) = reader.output_color_type();
    if color != png::ColorType::Grayscale {
        return Err(format!(
            "a {color:?} PNG; a tactile frame is one channel: save it as grayscale (8 or 16 bit)"
        ));
    }
    let size = reader
        .output_buffer_size()
        .ok_or("the PNG's size overflows memory")?;
    let mut buffer = vec![0; size];
    let info = reader.next_frame(&mut buffer).map_err(not_png)?;
    let (rows, cols) = (info.height as usize, info.width as usize);
    let data = &buffer[..info.buffer_size()];
    let values = match depth {
        png::BitDepth::Sixteen => data
            .chunks_exact(2)
            .map(|b| f64::from(u16::from_be_bytes([b[0], b[1]])))
            .collect(),
        _ => data.iter().map(|&b| f64::from(b)).collect(),
    };
    Ok(((rows, cols), values))
}

fn read_jpeg(bytes: &[u8]) -> Result<((usize, usize), Vec<f64>), String> {
    let mut decoder = jpeg_decoder::Decoder::new(BufReader::new(bytes));
    let pixels = decoder
        .decode()
        .map_err(|e| format!("not a readable JPEG: {e}"))?;
    let info = decoder.info().ok_or("a JPEG without a frame header")?;
    if info.pixel_format != jpeg_decoder::PixelFormat::L8 {
        return Err(format!(
            "a {:?} JPEG; a tactile frame is one 8-bit channel: save it as grayscale (16-bit frames as PNG)",
            info.pixel_format
        ));
    }
    let (rows, cols) = (usize::from(info.height), usize::from(info.width));
    Ok(((rows, cols), pixels.iter().map(|&b| f64::from(b)).collect()))
}
