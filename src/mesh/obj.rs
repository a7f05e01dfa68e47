//! Wavefront OBJ: reading `v` and `f` records, and writing meshes (metres).

use std::fmt::Write as _;
use std::path::Path;

use glam::DVec3;

use super::TriMesh;
use super::builder::{MeshBuilder, content_lines_from};
use super::error::{Location, MeshError};

/// Texts longer than this are parsed as two halves at once: a 1.3M-triangle scan is 72 MB of OBJ
/// text, a fifth of the time from its file to its first reading on one core (issue 39).
const SPLIT_PARSE_BYTES: usize = 4 << 20;

/// Parses OBJ text. Face corners may be `i`, `i/t`, `i//n` or `i/t/n`, 1-based or negative
/// (relative to the vertices read so far); records other than `v` and `f` are ignored. A long text
/// is parsed as two halves split at a line break, on two threads; the mesh, and the first error
/// in the file's order, are the same as the whole text's parsed in one pass.
pub(crate) fn parse(text: &str, path: &Path) -> Result<TriMesh, MeshError> {
    match line_break_near_middle(text) {
        Some(split) => parse_in_two(text, split, path),
        None => parse_records(text, 1, path)?.finish(),
    }
}

/// [`parse`] of `text` as the halves before and after byte `split`, just after a line break, on
/// two threads.
fn parse_in_two(text: &str, split: usize, path: &Path) -> Result<TriMesh, MeshError> {
    let (head, tail) = text.split_at(split);
    let tail_first_line = head.bytes().filter(|&b| b == b'\n').count() + 1;
    let (head_records, tail_records) = std::thread::scope(|scope| {
        let tail_records = scope.spawn(|| parse_records(tail, tail_first_line, path));
        let head_records = parse_records(head, 1, path);
        // A parse returns its errors; were its thread lost, the half is parsed here.
        let tail_records = tail_records
            .join()
            .unwrap_or_else(|_| parse_records(tail, tail_first_line, path));
        (head_records, tail_records)
    });
    let mut builder = head_records?;
    builder.append_obj_records(tail_records?);
    builder.finish()
}

/// Where a text longer than [`SPLIT_PARSE_BYTES`] splits in two: just after the first line break
/// from its middle (none for a shorter text, or one without a break there).
fn line_break_near_middle(text: &str) -> Option<usize> {
    if text.len() <= SPLIT_PARSE_BYTES {
        return None;
    }
    let middle = text.len() / 2;
    let after = text.as_bytes()[middle..].iter().position(|&b| b == b'\n')?;
    Some(middle + after + 1)
}

/// The `v` and `f` records of `text`, whose first line is line `first_line` of the file; a
/// negative corner is resolved against the vertices of `text` alone
/// ([`MeshBuilder::append_obj_records`] shifts it by those before).
fn parse_records(text: &str, first_line: usize, path: &Path) -> Result<MeshBuilder, MeshError> {
    let mut builder = MeshBuilder::one_based(path);
    // One buffer for every face's corners: a scanned mesh has millions of faces.
    let mut corners: Vec<(i64, i64)> = Vec::with_capacity(8);
    for (line_no, line) in content_lines_from(text, first_line) {
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
    Ok(builder)
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

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "# a square and a triangle\n\
        v 0 0 0\nv 1 0 0\n\nv 1 1 0 # a corner\nv 0 1 0\n\
        f 1 2 3 4\n\
        v 2 0 0\nv 2 1 0\n\
        f -1 -2 2\n\
        f 2/1 6//2 3/3/3\n\
        o rest\nv 3 3 0\nf -1 -2 -3\n";

    fn breaks(text: &str) -> impl Iterator<Item = usize> + '_ {
        text.match_indices('\n')
            .map(|(at, _)| at + 1)
            .filter(move |&at| at < text.len())
    }

    #[test]
    fn two_halves_at_any_line_break_give_the_one_pass_mesh() {
        let path = Path::new("t.obj");
        let whole = parse_records(TEXT, 1, path).unwrap().finish().unwrap();
        assert_eq!(whole.triangles.len(), 5);
        for split in breaks(TEXT) {
            assert_eq!(
                parse_in_two(TEXT, split, path).unwrap(),
                whole,
                "split at byte {split}"
            );
        }
    }

    #[test]
    fn two_halves_report_the_first_error_of_the_file_at_its_line() {
        let path = Path::new("t.obj");
        // An error in the tail only, and one in each half: the file's first, at its own line.
        let text = format!("{TEXT}v 1 x 0\n");
        let last_line = text.lines().count();
        let text_two = format!("v 0 0\n{text}");
        for (text, line) in [(text.as_str(), last_line), (text_two.as_str(), 1)] {
            let one_pass = parse_records(text, 1, path).err().map(|e| e.to_string());
            assert!(
                one_pass
                    .as_deref()
                    .is_some_and(|e| e.contains(&format!("line {line}"))),
                "{one_pass:?}"
            );
            for split in breaks(text) {
                let halves = parse_in_two(text, split, path).err().map(|e| e.to_string());
                assert_eq!(halves, one_pass, "split at byte {split}");
            }
        }
        // A relative corner before any vertex of the file is out of range in either half.
        let text = "f -1 -2 -3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let one_pass = parse_records(text, 1, path)
            .unwrap()
            .finish()
            .err()
            .map(|e| e.to_string());
        assert!(one_pass.is_some());
        for split in breaks(text) {
            assert_eq!(
                parse_in_two(text, split, path).err().map(|e| e.to_string()),
                one_pass
            );
        }
    }

    #[test]
    fn only_a_long_text_is_split_and_just_after_a_line_break() {
        assert_eq!(line_break_near_middle(TEXT), None);
        let long = "v 0 0 0\n".repeat(SPLIT_PARSE_BYTES / 8 + 2);
        let split = line_break_near_middle(&long).unwrap();
        assert_eq!(&long[split - 1..split + 1], "\nv");
        assert!(split.abs_diff(long.len() / 2) <= 8);
    }
}
