//! What can go wrong with a mesh file, an object set or a glyph; every error names its place.

use std::fmt;
use std::path::PathBuf;

/// Where in a mesh file something was found: a text line, or a facet of a binary STL.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// 1-based line number of a text format (OBJ, OFF, ASCII STL).
    Line(usize),
    /// 1-based facet number of a binary STL.
    Facet(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Facet(n) => write!(f, "facet {n}"),
        }
    }
}

/// Errors of the `mesh` module.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{}: unknown mesh format (expected .obj, .off or .stl)", path.display())]
    UnknownFormat { path: PathBuf },
    #[error("{}: {at}: {what}", path.display())]
    Parse {
        path: PathBuf,
        at: Location,
        what: String,
    },
    #[error("{}: the file ends early: {what}", path.display())]
    Truncated { path: PathBuf, what: String },
    #[error("{}: {at}: coordinate {value} is not finite", path.display())]
    NonFinite { path: PathBuf, at: Location, value: f64 },
    #[error(
        "{}: {at}: vertex index {index} is out of range (the file has {count} vertices, numbered {first} to {})",
        path.display(),
        *first + *count as i64 - 1
    )]
    IndexOutOfRange {
        path: PathBuf,
        at: Location,
        /// The index as the file writes it (1-based or negative in OBJ, 0-based in OFF).
        index: i64,
        count: usize,
        /// The index of the file's first vertex in its format.
        first: i64,
    },
    #[error("{}: the mesh has no vertices", path.display())]
    NoVertices { path: PathBuf },
    #[error("{}: the mesh has no faces", path.display())]
    NoFaces { path: PathBuf },
    #[error("{}: cannot write: {source}", path.display())]
    Write { path: PathBuf, source: std::io::Error },
    #[error("the mesh is degenerate: {what}")]
    Degenerate { what: String },
    #[error("invalid {field}: {what}")]
    InvalidParameter { field: &'static str, what: String },
    #[error("invalid profile: {what}")]
    Profile { what: String },
    #[error("{}: cannot read the font: {what}", path.display())]
    Font { path: PathBuf, what: String },
    #[error("{}: glyph '{glyph}': {what}", font.display())]
    Glyph {
        font: PathBuf,
        glyph: char,
        what: String,
    },
    #[error("cannot triangulate {what}")]
    Triangulation { what: String },
    #[error("the {set} meshes are not in the cache {}: {hint}", dir.display())]
    NotFetched { set: String, dir: PathBuf, hint: String },
    #[error("{}: checksum mismatch (expected sha256 {expected}, got {actual}): {hint}", path.display())]
    Checksum {
        path: PathBuf,
        expected: String,
        actual: String,
        hint: String,
    },
    #[error("fetching {what} failed: {why}")]
    Fetch { what: String, why: String },
    #[error("object '{object}': {problem}")]
    Implausible {
        object: String,
        problem: super::Implausible,
    },
    #[error("object set: {what}")]
    ObjectSet { what: String },
}

impl From<crate::atomic::FileError> for MeshError {
    fn from(e: crate::atomic::FileError) -> Self {
        Self::Write {
            path: e.path,
            source: e.source,
        }
    }
}
