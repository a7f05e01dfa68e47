//! Wavefront OBJ: reading `v` and `f` records, and writing meshes (metres).

use std::fmt::Write as _;
use std::path::Path;

use glam::DVec3;

use super::TriMesh;
use super::error::{Location, MeshError};
use super::load::{MeshBuilder, content_lines};

/// Parses OBJ text. Face corners may be `i`, `i/t`, `i//n` or `i/t/n`, 1-based or negative
/// (relative to the vertices read so far); records other than `v` and `f` are ignored.
pub(crate) fn parse(text: &str, path: &Path) -> Result<TriMesh, MeshError> {
    let mut builder = MeshBuilder::one_based(path);
    // One buffer for every face's corners: a scanned mesh has millions of faces.
    let mut corners: Vec<(i64, i64)> = Vec::with_capacity(8);
    for (line_no, line) in content_lines(text) {
        let at = Location::Line(line_no);
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let mut coords = [""; 3];
                let mut given = 0;
                for token in tokens {
                    if let Some(slot) = coords.get_mut(given) {
                        *slot = token;
                    }
                    given += 1;
                }
                if given < 3 {
                    return Err(builder.parse_error(at, format!("a vertex needs 3 coordinates, got {given}")));
                }
                let x = builder.coordinate(at, coords[0])?;
                let y = builder.coordinate(at, coords[1])?;
                let z = builder.coordinate(at, coords[2])?;
                builder.push_vertex(DVec3::new(x, y, z));
            }
            Some("f") => {
                let count = builder.vertex_count() as i64;
                corners.clear();
                for corner in tokens {
                    let index = corner.split('/').next().unwrap_or("");
                    let i: i64 = index.parse().map_err(|_| {
                        builder.parse_error(at, format!("'{corner}' is not a vertex reference"))
                    })?;
                    corners.push(match i {
                        0 => return Err(builder.parse_error(at, "vertex index 0 (OBJ indices start at 1)")),
                        i if i > 0 => (i - 1, i),
                        i => (count.saturating_add(i), i),
                    });
                }
                builder.push_polygon_as_written(at, &corners)?;
            }
            _ => {}
        }
    }
    builder.finish()
}

/// The mesh as OBJ text: a comment header, `v` lines in metres (shortest round-trip decimal, so
/// reading the file back gives the same coordinates bit for bit), then `f` lines (1-based).
pub fn to_obj_string(mesh: &TriMesh, comment: &str) -> String {
    let mut out = String::with_capacity(mesh.vertices.len() * 40 + mesh.triangles.len() * 24);
    for line in comment.lines() {
        let _ = writeln!(out, "# {line}");
    }
    let _ = writeln!(
        out,
        "# units: metres; {} vertices, {} triangles",
        mesh.vertices.len(),
        mesh.triangles.len()
    );
    for v in &mesh.vertices {
        let _ = writeln!(out, "v {} {} {}", v.x, v.y, v.z);
    }
    for [a, b, c] in &mesh.triangles {
        let _ = writeln!(out, "f {} {} {}", a + 1, b + 1, c + 1);
    }
    out
}

/// Writes the mesh as an OBJ file (see [`to_obj_string`]).
pub fn write_obj(mesh: &TriMesh, path: &Path, comment: &str) -> Result<(), MeshError> {
    Ok(crate::atomic::write_atomic(
        path,
        to_obj_string(mesh, comment).as_bytes(),
    )?)
}
