//! What the mesh parsers share, below them and below the loader that dispatches to them: the
//! builder that collects and checks a file's vertices and polygons, and the content lines of a
//! text format.

use std::path::{Path, PathBuf};

use glam::DVec3;

use super::TriMesh;
use super::error::{Location, MeshError};

/// Collects vertices and polygons while a file is parsed, checking what makes a mesh unusable:
/// non-finite coordinates and vertex indices out of range (errors at the offending place), and an
/// empty result.
pub(crate) struct MeshBuilder {
    path: PathBuf,
    vertices: Vec<DVec3>,
    /// Every polygon's corners, one after another, as (resolved 0-based index, index as written)
    /// pairs; checked in `finish`, since an OBJ face may name a vertex defined further down. One
    /// list for all, not one per polygon: a scanned mesh has millions (issue 39).
    corners: Vec<(i64, i64)>,
    /// Each polygon: where it was read, and the end of its corners in `corners`.
    polygons: Vec<(Location, usize)>,
    /// The index the file's format gives its first vertex (1 in OBJ, 0 in OFF), for messages.
    first_index: i64,
}

impl MeshBuilder {
    pub(crate) fn new(path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            vertices: Vec::new(),
            corners: Vec::new(),
            polygons: Vec::new(),
            first_index: 0,
        }
    }

    /// A builder for a format that numbers its vertices from 1 (OBJ), so that messages quote
    /// indices as the file writes them.
    pub(crate) fn one_based(path: &Path) -> Self {
        Self {
            first_index: 1,
            ..Self::new(path)
        }
    }

    pub(crate) fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    pub(crate) fn parse_error(&self, at: Location, what: impl Into<String>) -> MeshError {
        MeshError::Parse {
            path: self.path.clone(),
            at,
            what: what.into(),
        }
    }

    /// Parses a coordinate token; a token that is not a number is a parse error, a non-finite
    /// number (`nan`, `inf`) a [`MeshError::NonFinite`].
    pub(crate) fn coordinate(&self, at: Location, token: &str) -> Result<f64, MeshError> {
        let value: f64 = token
            .parse()
            .map_err(|_| self.parse_error(at, format!("'{token}' is not a number")))?;
        if value.is_finite() {
            Ok(value)
        } else {
            Err(MeshError::NonFinite {
                path: self.path.clone(),
                at,
                value,
            })
        }
    }

    pub(crate) fn push_vertex(&mut self, v: DVec3) -> u32 {
        self.vertices.push(v);
        (self.vertices.len() - 1) as u32
    }

    /// Adds a polygon of 0-based indices (possibly out of range: checked in `finish`), written
    /// 0-based in the file.
    pub(crate) fn push_polygon(&mut self, at: Location, indices: Vec<i64>) -> Result<(), MeshError> {
        let corners: Vec<(i64, i64)> = indices.into_iter().map(|i| (i, i)).collect();
        self.push_polygon_as_written(at, &corners)
    }

    /// Adds a polygon of (0-based index, index as the file writes it) pairs.
    pub(crate) fn push_polygon_as_written(
        &mut self,
        at: Location,
        indices: &[(i64, i64)],
    ) -> Result<(), MeshError> {
        if indices.len() < 3 {
            return Err(self.parse_error(
                at,
                format!("a face needs at least 3 vertices, got {}", indices.len()),
            ));
        }
        self.corners.extend_from_slice(indices);
        self.polygons.push((at, self.corners.len()));
        Ok(())
    }

    /// Appends the OBJ records parsed from the text after this builder's (on their own: `later`'s
    /// negative corners, OBJ's indices relative to the vertices read so far, count only `later`'s
    /// vertices, and shift by this builder's). The result is the builder of the two texts read in
    /// one pass.
    pub(crate) fn append_obj_records(&mut self, later: MeshBuilder) {
        let vertices_before = self.vertices.len() as i64;
        let corners_before = self.corners.len();
        self.vertices.extend(later.vertices);
        self.corners
            .extend(later.corners.into_iter().map(|(index, written)| {
                if written < 0 {
                    (index + vertices_before, written)
                } else {
                    (index, written)
                }
            }));
        self.polygons.extend(
            later
                .polygons
                .into_iter()
                .map(|(at, end)| (at, end + corners_before)),
        );
    }

    /// Checks indices, fan-triangulates polygons (v0, v_i, v_i+1) and returns the mesh.
    pub(crate) fn finish(self) -> Result<TriMesh, MeshError> {
        if self.vertices.is_empty() {
            return Err(MeshError::NoVertices { path: self.path });
        }
        if self.polygons.is_empty() {
            return Err(MeshError::NoFaces { path: self.path });
        }
        let count = self.vertices.len();
        let mut triangles = Vec::with_capacity(self.polygons.len());
        let mut start = 0;
        for &(at, end) in &self.polygons {
            let polygon = &self.corners[start..end];
            start = end;
            if let Some(&(_, index)) = polygon.iter().find(|&&(i, _)| i < 0 || i >= count as i64) {
                return Err(MeshError::IndexOutOfRange {
                    path: self.path,
                    at,
                    index,
                    count,
                    first: self.first_index,
                });
            }
            let p = |k: usize| polygon[k].0 as u32;
            triangles.extend((1..polygon.len() - 1).map(|k| [p(0), p(k), p(k + 1)]));
        }
        Ok(TriMesh {
            vertices: self.vertices,
            triangles,
        })
    }
}

/// The non-empty lines of a text file with their 1-based numbers, comments (from `#`) removed.
pub(crate) fn content_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    content_lines_from(text, 1)
}

/// [`content_lines`] of a part of a file whose first line is line `first_line`.
pub(crate) fn content_lines_from(text: &str, first_line: usize) -> impl Iterator<Item = (usize, &str)> {
    text.lines().enumerate().filter_map(move |(i, line)| {
        let line = line.split('#').next().unwrap_or("").trim();
        (!line.is_empty()).then_some((first_line + i, line))
    })
}
