//! Loading a mesh file: the format from the extension, then the format's parser, then validation.

use std::path::Path;

use super::error::MeshError;
use super::validate::ValidationReport;
use super::{TriMesh, obj, off, stl};

/// The mesh file formats `load` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (`v` and `f` records; other records ignored).
    Obj,
    /// Object File Format (`OFF`/`COFF` header, counts, vertices, polygon faces).
    Off,
    /// STL, ASCII or binary (told apart by content).
    Stl,
}

impl MeshFormat {
    /// The format named by `path`'s extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Self, MeshError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("obj") => Ok(Self::Obj),
            Some("off") => Ok(Self::Off),
            Some("stl") => Ok(Self::Stl),
            _ => Err(MeshError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// A mesh as loaded, with the validation warnings it raised.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedMesh {
    pub mesh: TriMesh,
    pub warnings: ValidationReport,
}

/// Loads an OBJ, OFF or STL file (coordinates taken as they are, no unit conversion) and validates
/// it. Polygons with more than three vertices are fan-triangulated.
pub fn load(path: impl AsRef<Path>) -> Result<LoadedMesh, MeshError> {
    let path = path.as_ref();
    let format = MeshFormat::from_path(path)?;
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse(&bytes, format, path)
}

/// Parses the bytes of a mesh file of `format`; `path` only names the file in messages.
pub fn parse(bytes: &[u8], format: MeshFormat, path: &Path) -> Result<LoadedMesh, MeshError> {
    // UTF-8 checked first the fast way; only a file that is not gets its bad bytes replaced.
    let text = || match std::str::from_utf8(bytes) {
        Ok(text) => std::borrow::Cow::Borrowed(text),
        Err(_) => String::from_utf8_lossy(bytes),
    };
    let mesh = match format {
        MeshFormat::Obj => obj::parse(&text(), path)?,
        MeshFormat::Off => off::parse(&text(), path)?,
        MeshFormat::Stl => stl::parse(bytes, path)?,
    };
    let warnings = ValidationReport::of(&mesh);
    Ok(LoadedMesh { mesh, warnings })
}
