//! STL, ASCII and binary. STL stores each facet's corners by value; corners with identical
//! coordinates are merged into one vertex (in order of first appearance), which restores the
//! connectivity that watertightness checks need.
//!
//! Binary or ASCII is decided by content: a file whose size is exactly 84 + 50 n bytes, n being the
//! facet count at offset 80, is binary (some binary files also begin with `solid`); otherwise a file
//! beginning with `solid` is ASCII.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;

use super::TriMesh;
use super::builder::{MeshBuilder, content_lines};
use super::error::{Location, MeshError};

const HEADER_BYTES: usize = 80;
const FACET_BYTES: usize = 50;

pub(crate) fn parse(bytes: &[u8], path: &Path) -> Result<TriMesh, MeshError> {
    let binary_size = (bytes.len() >= HEADER_BYTES + 4).then(|| {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        (n, HEADER_BYTES + 4 + FACET_BYTES * n)
    });
    match binary_size {
        Some((n, size)) if size == bytes.len() => parse_binary(bytes, n, path),
        _ if bytes.trim_ascii_start().starts_with(b"solid") => {
            parse_ascii(&String::from_utf8_lossy(bytes), path)
        }
        Some((n, size)) => Err(MeshError::Truncated {
            path: path.to_path_buf(),
            what: format!(
                "binary STL with {n} facets needs {size} bytes, the file has {}",
                bytes.len()
            ),
        }),
        None => Err(MeshError::Truncated {
            path: path.to_path_buf(),
            what: format!(
                "{} bytes is shorter than a binary STL header (84 bytes)",
                bytes.len()
            ),
        }),
    }
}

/// Merges corners with bit-identical coordinates (-0.0 taken as 0.0).
struct Welder {
    index: HashMap<[u64; 3], u32>,
}

impl Welder {
    fn new() -> Self {
        Self {
            index: HashMap::new(),
        }
    }

    fn vertex(&mut self, builder: &mut MeshBuilder, v: DVec3) -> i64 {
        let key = [v.x, v.y, v.z].map(|c| (c + 0.0).to_bits());
        *self.index.entry(key).or_insert_with(|| builder.push_vertex(v)) as i64
    }
}

fn parse_binary(bytes: &[u8], facets: usize, path: &Path) -> Result<TriMesh, MeshError> {
    let mut builder = MeshBuilder::new(path);
    let mut welder = Welder::new();
    for f in 0..facets {
        let at = Location::Facet(f + 1);
        let record = &bytes[HEADER_BYTES + 4 + f * FACET_BYTES..][..FACET_BYTES];
        let float = |k: usize| {
            f32::from_le_bytes([
                record[4 * k],
                record[4 * k + 1],
                record[4 * k + 2],
                record[4 * k + 3],
            ])
        };
        let mut corners = Vec::with_capacity(3);
        for c in 0..3 {
            let v = DVec3::new(
                float(3 + 3 * c) as f64,
                float(4 + 3 * c) as f64,
                float(5 + 3 * c) as f64,
            );
            if let Some(value) = v.to_array().into_iter().find(|x| !x.is_finite()) {
                return Err(MeshError::NonFinite {
                    path: path.to_path_buf(),
                    at,
                    value,
                });
            }
            corners.push(welder.vertex(&mut builder, v));
        }
        builder.push_polygon(at, corners)?;
    }
    builder.finish()
}

fn parse_ascii(text: &str, path: &Path) -> Result<TriMesh, MeshError> {
    let mut builder = MeshBuilder::new(path);
    let mut welder = Welder::new();
    let mut facet: Option<(Location, Vec<i64>)> = None;
    for (line_no, line) in content_lines(text) {
        let at = Location::Line(line_no);
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("solid" | "endsolid" | "outer" | "endloop") => {}
            Some("facet") => {
                if facet.is_some() {
                    return Err(builder.parse_error(at, "'facet' inside a facet (missing 'endfacet')"));
                }
                facet = Some((at, Vec::with_capacity(3)));
            }
            Some("vertex") => {
                let coords: Vec<&str> = tokens.collect();
                if coords.len() != 3 {
                    return Err(builder
                        .parse_error(at, format!("a vertex needs 3 coordinates, got {}", coords.len())));
                }
                let v = DVec3::new(
                    builder.coordinate(at, coords[0])?,
                    builder.coordinate(at, coords[1])?,
                    builder.coordinate(at, coords[2])?,
                );
                let index = welder.vertex(&mut builder, v);
                match facet.as_mut() {
                    Some((_, corners)) => corners.push(index),
                    None => return Err(builder.parse_error(at, "'vertex' outside a facet")),
                }
            }
            Some("endfacet") => match facet.take() {
                Some((start, corners)) => builder.push_polygon(start, corners)?,
                None => return Err(builder.parse_error(at, "'endfacet' without 'facet'")),
            },
            Some(other) => return Err(builder.parse_error(at, format!("unexpected '{other}' in ASCII STL"))),
            None => {}
        }
    }
    if let Some((start, _)) = facet {
        return Err(builder.parse_error(start, "facet not closed by 'endfacet'"));
    }
    builder.finish()
}
