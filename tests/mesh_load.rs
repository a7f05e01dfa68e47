//! Mesh loading and validation: the broken-mesh corpus (one defect per file), format round trips and
//! the geometry helpers.

use std::path::{Path, PathBuf};

use glam::DVec3;
use taction::mesh::{
    self, EdgeTopology, Location, MeshError, MeshFormat, TriMesh, ValidationReport, normalise_to_diagonal,
    orient_outward,
};

mod common;

fn corpus(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/broken_meshes")
        .join(name)
}

fn load_err(name: &str) -> MeshError {
    match mesh::load(corpus(name)) {
        Ok(loaded) => panic!(
            "{name} loaded ({} triangles) but should fail",
            loaded.mesh.triangles.len()
        ),
        Err(e) => {
            assert!(
                e.to_string().contains(name),
                "message of {name} does not name the file: {e}"
            );
            e
        }
    }
}

fn warnings(name: &str) -> ValidationReport {
    mesh::load(corpus(name))
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .warnings
}

#[test]
fn every_corpus_file_gives_a_result_not_a_panic() {
    let dir = corpus("");
    let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    assert!(names.len() >= 20);
    for path in names {
        if path.extension().is_some_and(|e| e == "md") {
            continue;
        }
        let _ = std::panic::catch_unwind(|| mesh::load(&path))
            .unwrap_or_else(|_| panic!("{} panicked", path.display()));
    }
}

#[test]
fn unusable_meshes_are_errors_naming_file_and_place() {
    assert!(matches!(load_err("empty.obj"), MeshError::NoVertices { .. }));
    assert!(matches!(load_err("no_faces.off"), MeshError::NoFaces { .. }));
    assert!(
        matches!(load_err("nan_vertex.obj"), MeshError::NonFinite { at: Location::Line(4), value, .. }
            if value.is_nan())
    );
    assert!(matches!(
        load_err("inf_vertex.off"),
        MeshError::NonFinite { at: Location::Line(6), value, .. } if value == f64::INFINITY
    ));
    assert!(matches!(
        load_err("index_out_of_range.obj"),
        MeshError::IndexOutOfRange {
            at: Location::Line(7),
            index: 9,
            count: 4,
            first: 1,
            ..
        }
    ));
    assert!(matches!(
        load_err("negative_index_out_of_range.obj"),
        MeshError::IndexOutOfRange {
            at: Location::Line(4),
            index: -4,
            count: 3,
            first: 1,
            ..
        }
    ));
    assert!(matches!(
        load_err("index_out_of_range.off"),
        MeshError::IndexOutOfRange {
            at: Location::Line(9),
            index: 4,
            count: 4,
            first: 0,
            ..
        }
    ));
    assert!(matches!(
        load_err("index_zero.obj"),
        MeshError::Parse {
            at: Location::Line(4),
            ..
        }
    ));
    assert!(
        matches!(load_err("bad_number.obj"), MeshError::Parse { at: Location::Line(2), ref what, .. }
            if what.contains("zero"))
    );
    assert!(
        matches!(load_err("truncated.off"), MeshError::Truncated { ref what, .. }
            if what.contains("2 of 4 vertices"))
    );
    assert!(matches!(
        load_err("bad_header.off"),
        MeshError::Parse {
            at: Location::Line(1),
            ..
        }
    ));
    assert!(matches!(
        load_err("short_face.off"),
        MeshError::Parse {
            at: Location::Line(6),
            ..
        }
    ));
    assert!(matches!(
        load_err("ascii_unclosed.stl"),
        MeshError::Parse {
            at: Location::Line(2),
            ..
        }
    ));
    assert!(matches!(
        load_err("ascii_nonfinite.stl"),
        MeshError::NonFinite {
            at: Location::Line(12),
            ..
        }
    ));
    assert!(matches!(
        load_err("nan_facet.stl"),
        MeshError::NonFinite {
            at: Location::Facet(2),
            ..
        }
    ));
    assert!(matches!(load_err("truncated.stl"), MeshError::Truncated { .. }));
    assert!(matches!(
        load_err("unknown_format.ply"),
        MeshError::UnknownFormat { .. }
    ));
    let message = load_err("index_out_of_range.obj").to_string();
    assert!(
        message.contains("line 7: vertex index 9 is out of range (the file has 4 vertices, numbered 1 to 4)"),
        "{message}"
    );
    assert!(load_err("nan_facet.stl").to_string().contains("facet 2"));
}

#[test]
fn defects_that_still_load_are_counted_warnings() {
    assert_eq!(
        warnings("zero_area_face.obj"),
        ValidationReport {
            zero_area_faces: 1,
            ..Default::default()
        }
    );
    assert_eq!(
        warnings("open_box.obj"),
        ValidationReport {
            boundary_edges: 4,
            boundary_loops: 1,
            ..Default::default()
        }
    );
    let fins = warnings("non_manifold.obj");
    assert_eq!(
        (fins.non_manifold_edges, fins.boundary_edges, fins.zero_area_faces),
        (1, 6, 0)
    );
    assert_eq!(
        warnings("flipped_face.obj"),
        ValidationReport {
            misoriented_edges: 3,
            ..Default::default()
        }
    );
    assert!(
        warnings("open_box.obj")
            .to_string()
            .contains("4 open boundary edge(s)")
    );
}

#[test]
fn clean_files_in_every_format_give_the_same_tetrahedron() {
    let obj = mesh::load(corpus("quad_cube.obj")).unwrap();
    assert!(obj.warnings.is_clean(), "{}", obj.warnings);
    assert_eq!((obj.mesh.vertices.len(), obj.mesh.triangles.len()), (8, 12));
    assert!((obj.mesh.signed_volume() - 1.0).abs() < 1e-12);
    assert!((obj.mesh.total_area() - 6.0).abs() < 1e-12);

    let binary = mesh::load(corpus("tetra_binary.stl")).unwrap();
    let header_solid = mesh::load(corpus("solid_header_binary.stl")).unwrap();
    let ascii = mesh::load(corpus("tetra_ascii.stl")).unwrap();
    for loaded in [&binary, &header_solid, &ascii] {
        assert!(loaded.warnings.is_clean(), "{}", loaded.warnings);
        assert_eq!((loaded.mesh.vertices.len(), loaded.mesh.triangles.len()), (4, 4));
        assert!((loaded.mesh.signed_volume() - 1.0 / 6.0).abs() < 1e-12);
    }
    assert_eq!(binary.mesh, ascii.mesh);
    assert_eq!(binary.mesh, header_solid.mesh);
}

#[test]
fn obj_writer_round_trips_bit_for_bit() {
    let mut m = common::box_mesh(DVec3::new(0.1, 0.2, 0.3));
    m.vertices[3] += DVec3::new(1e-17, -0.1 / 3.0, std::f64::consts::PI * 1e-3);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("box.obj");
    mesh::write_obj(&m, &path, "a box\nsecond line").unwrap();
    let back = mesh::load(&path).unwrap();
    assert_eq!(back.mesh, m);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("# a box\n# second line\n"));
    let reparsed = mesh::parse(text.as_bytes(), MeshFormat::Obj, Path::new("mem.obj")).unwrap();
    assert_eq!(reparsed.mesh, m);
}

#[test]
fn off_with_counts_on_header_line_comments_and_colours_parses() {
    let text = "OFF 4 4 0 # counts on the header line\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n\
                3 0 2 1 255 0 0\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
    let loaded = mesh::parse(text.as_bytes(), MeshFormat::Off, Path::new("inline.off")).unwrap();
    assert!(loaded.warnings.is_clean());
    assert!((loaded.mesh.signed_volume() - 1.0 / 6.0).abs() < 1e-12);
}

#[test]
fn normalise_scales_centres_and_rests_on_table() {
    let m = common::box_mesh(DVec3::new(2.0, 3.0, 6.0)).translated(DVec3::new(5.0, -7.0, 11.0));
    let n = normalise_to_diagonal(&m, 0.12).unwrap();
    let (lo, hi) = n.bounds().unwrap();
    assert!((n.bounding_diagonal_m().unwrap() - 0.12).abs() < 1e-15);
    assert!((lo.x + hi.x).abs() < 1e-15 && (lo.y + hi.y).abs() < 1e-15);
    assert_eq!(lo.z, 0.0);
    // Uniform scaling by s multiplies volume by s^3: 36 * (0.12 / 7)^3.
    assert!((n.signed_volume() - 36.0 * (0.12f64 / 7.0).powi(3)).abs() < 1e-15);
    assert!(normalise_to_diagonal(&m, 0.0).is_err());
    assert!(normalise_to_diagonal(&m, f64::NAN).is_err());
    let point = TriMesh {
        vertices: vec![DVec3::ONE; 3],
        triangles: vec![[0, 1, 2]],
    };
    assert!(matches!(
        normalise_to_diagonal(&point, 0.1),
        Err(MeshError::Degenerate { .. })
    ));
}

#[test]
fn orientation_and_topology_of_a_closed_box() {
    let m = common::box_mesh(DVec3::new(1.0, 2.0, 3.0));
    let topo = EdgeTopology::new(&m);
    assert!(topo.is_closed() && topo.is_consistently_oriented());
    assert_eq!(topo.euler_characteristic(&m), 2);
    assert_eq!(topo.edge_count(), 18);
    let inside_out = m.flipped();
    assert!((inside_out.signed_volume() + 6.0).abs() < 1e-12);
    let (fixed, flipped) = orient_outward(inside_out);
    assert!(flipped);
    assert_eq!(fixed, m);
    let (same, flipped) = orient_outward(m.clone());
    assert!(!flipped && same == m);
    let mut two = m.clone();
    two.append(&m.translated(DVec3::X * 5.0));
    assert_eq!(mesh::connected_components(&two), 2);
    assert_eq!(EdgeTopology::new(&two).euler_characteristic(&two), 4);
}

#[test]
fn up_axis_rotations_are_proper_and_bring_up_to_z() {
    use taction::mesh::{UpAxis, rotate_up_to_z};
    let m = common::box_mesh(DVec3::new(1.0, 2.0, 3.0)).translated(DVec3::new(0.0, 0.0, -1.5));
    for (up, extent) in [
        (UpAxis::Z, 3.0),
        (UpAxis::Y, 2.0),
        (UpAxis::NegY, 2.0),
        (UpAxis::X, 1.0),
        (UpAxis::NegZ, 3.0),
    ] {
        let r = rotate_up_to_z(&m, up);
        let (lo, hi) = r.bounds().unwrap();
        assert!((hi.z - lo.z - extent).abs() < 1e-12, "{up:?}");
        assert!(
            (r.signed_volume() - 6.0).abs() < 1e-12,
            "{up:?} changed the orientation"
        );
    }
    let tip = TriMesh {
        vertices: vec![DVec3::Y, DVec3::X, DVec3::Z],
        triangles: vec![[0, 1, 2]],
    };
    assert_eq!(rotate_up_to_z(&tip, UpAxis::Y).vertices[0], DVec3::Z);
    assert_eq!(rotate_up_to_z(&tip, UpAxis::X).vertices[1], DVec3::Z);
    assert_eq!(rotate_up_to_z(&tip, UpAxis::NegY).vertices[0], -DVec3::Z);
}
