//! Object File Format (OFF): a header line `OFF` (or `COFF`, `NOFF`, `CNOFF`: colours and normals
//! are ignored), the counts `V F E`, then one vertex per line and one polygon per line
//! (`k i_1 ... i_k`, 0-based, trailing colour values ignored).

use std::path::Path;

use glam::DVec3;

use super::TriMesh;
use super::builder::{MeshBuilder, content_lines};
use super::error::{Location, MeshError};

pub(crate) fn parse(text: &str, path: &Path) -> Result<TriMesh, MeshError> {
    let mut builder = MeshBuilder::new(path);
    let mut lines = content_lines(text);
    let (vertex_count, face_count) = read_header(&mut lines, &builder, path)?;
    for k in 0..vertex_count {
        let (line_no, line) = lines
            .next()
            .ok_or_else(|| truncated(path, format!("{k} of {vertex_count} vertices read")))?;
        read_vertex(&mut builder, Location::Line(line_no), line)?;
    }
    for k in 0..face_count {
        let (line_no, line) = lines
            .next()
            .ok_or_else(|| truncated(path, format!("{k} of {face_count} faces read")))?;
        read_face(&mut builder, Location::Line(line_no), line)?;
    }
    builder.finish()
}

fn truncated(path: &Path, what: String) -> MeshError {
    MeshError::Truncated {
        path: path.to_path_buf(),
        what,
    }
}

/// The header keyword and the vertex and face counts (on the header's line or the next).
fn read_header<'t>(
    lines: &mut impl Iterator<Item = (usize, &'t str)>,
    builder: &MeshBuilder,
    path: &Path,
) -> Result<(usize, usize), MeshError> {
    let (header_line, header) = lines
        .next()
        .ok_or_else(|| truncated(path, "no OFF header".into()))?;
    let mut header_tokens = header.split_whitespace();
    let keyword = header_tokens.next().unwrap_or("");
    if !matches!(keyword, "OFF" | "COFF" | "NOFF" | "CNOFF") {
        return Err(builder.parse_error(
            Location::Line(header_line),
            format!("expected the header 'OFF', got '{keyword}'"),
        ));
    }
    let rest: Vec<&str> = header_tokens.collect();
    if rest.first() == Some(&"BINARY") {
        return Err(builder.parse_error(Location::Line(header_line), "binary OFF is not supported"));
    }
    let (counts_line, counts): (usize, Vec<&str>) = if rest.is_empty() {
        let (n, line) = lines
            .next()
            .ok_or_else(|| truncated(path, "no vertex and face counts".into()))?;
        (n, line.split_whitespace().collect())
    } else {
        (header_line, rest)
    };
    let at = Location::Line(counts_line);
    let count = |i: usize, what: &str| -> Result<usize, MeshError> {
        let token = counts
            .get(i)
            .ok_or_else(|| builder.parse_error(at, format!("missing the {what} count")))?;
        token
            .parse()
            .map_err(|_| builder.parse_error(at, format!("{what} count '{token}' is not a whole number")))
    };
    Ok((count(0, "vertex")?, count(1, "face")?))
}

/// One vertex line: three coordinates (anything after them ignored).
fn read_vertex(builder: &mut MeshBuilder, at: Location, line: &str) -> Result<(), MeshError> {
    let tokens: Vec<&str> = line.split_whitespace().collect();
    if tokens.len() < 3 {
        return Err(builder.parse_error(at, format!("a vertex needs 3 coordinates, got {}", tokens.len())));
    }
    let x = builder.coordinate(at, tokens[0])?;
    let y = builder.coordinate(at, tokens[1])?;
    let z = builder.coordinate(at, tokens[2])?;
    builder.push_vertex(DVec3::new(x, y, z));
    Ok(())
}

/// One face line: its size k, then k vertex indices (trailing colour values ignored).
fn read_face(builder: &mut MeshBuilder, at: Location, line: &str) -> Result<(), MeshError> {
    let mut tokens = line.split_whitespace();
    let n_token = tokens.next().unwrap_or("");
    let n: usize = n_token
        .parse()
        .map_err(|_| builder.parse_error(at, format!("face size '{n_token}' is not a whole number")))?;
    let indices = tokens
        .take(n)
        .map(|t| {
            t.parse::<i64>()
                .map_err(|_| builder.parse_error(at, format!("'{t}' is not a vertex index")))
        })
        .collect::<Result<Vec<i64>, MeshError>>()?;
    if indices.len() < n {
        return Err(builder.parse_error(at, format!("face of {n} vertices lists only {}", indices.len())));
    }
    builder.push_polygon(at, indices)
}
