//! Surfaces of revolution and the chess pieces: watertight, outward, and with the volume of their
//! profile (disc integration / Pappus) within 1%.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::DVec2;
use taction::mesh::ChessPiece;
use taction::mesh::Profile;
use taction::mesh::{EdgeTopology, MeshError, TriMesh, ValidationReport};

fn assert_closed_outward(mesh: &TriMesh, what: &str) {
    let report = ValidationReport::of(mesh);
    assert!(report.is_clean(), "{what}: {report}");
    let topology = EdgeTopology::new(mesh);
    assert!(
        topology.is_closed() && topology.is_consistently_oriented(),
        "{what}"
    );
    assert_eq!(topology.euler_characteristic(mesh), 2, "{what}");
    assert!(mesh.signed_volume() > 0.0, "{what} faces inward");
}

/// Pappus' centroid theorem on the region between the flattened profile and the axis:
/// V = 2 pi * (centroid r) * area = 2 pi * integral of r dA, by the polygon (shoelace) formulas.
fn pappus_volume(points: &[DVec2]) -> f64 {
    let mut first_moment = 0.0;
    for i in 0..points.len() {
        let (a, b) = (points[i], points[(i + 1) % points.len()]);
        first_moment += (a.x + b.x) * a.perp_dot(b) / 6.0;
    }
    // Out along the bottom, up the outside, back in along the top, down the axis: counter-clockwise
    // in the (r, z) plane, so the shoelace sums are positive.
    TAU * first_moment
}

#[test]
fn sphere_cylinder_and_cone_have_their_textbook_volumes() {
    let r = 0.03;
    let sphere = Profile::builder(-r).arc_to(0.0, 0.0, FRAC_PI_2).finish().unwrap();
    assert!((sphere.analytic_volume_m3() - 4.0 / 3.0 * PI * r.powi(3)).abs() < 1e-15);
    let mesh = sphere.revolve(128, TAU / 128.0).unwrap();
    assert_closed_outward(&mesh, "sphere");
    assert!((mesh.signed_volume() / sphere.analytic_volume_m3() - 1.0).abs() < 0.01);

    let (radius, height) = (0.02, 0.05);
    let cylinder = Profile::builder(0.0)
        .line_to(radius, 0.0)
        .line_to(radius, height)
        .line_to(0.0, height);
    let cylinder = cylinder.finish().unwrap();
    assert!((cylinder.analytic_volume_m3() - PI * radius * radius * height).abs() < 1e-15);
    // Inscribed regular n-gon prism: area (n/2) r^2 sin(2 pi / n).
    for n in [3, 7, 64] {
        let mesh = cylinder.revolve(n, 0.1).unwrap();
        assert_closed_outward(&mesh, "cylinder");
        let prism = 0.5 * n as f64 * radius * radius * (TAU / n as f64).sin() * height;
        assert!((mesh.signed_volume() - prism).abs() < 1e-15, "n = {n}");
    }

    let cone = Profile::builder(0.0)
        .line_to(radius, 0.0)
        .line_to(0.0, height)
        .finish()
        .unwrap();
    assert!((cone.analytic_volume_m3() - PI * radius * radius * height / 3.0).abs() < 1e-15);
}

#[test]
fn chess_pieces_are_watertight_with_their_profile_volume() {
    for piece in ChessPiece::ALL {
        let profile = piece.profile().unwrap();
        let mesh = piece.mesh().unwrap();
        assert_closed_outward(&mesh, piece.name());
        let analytic = profile.analytic_volume_m3();
        assert!(
            (mesh.signed_volume() / analytic - 1.0).abs() < 0.01,
            "{}",
            piece.name()
        );
        // The closed-form arcs agree with Pappus on a finely flattened profile.
        let fine = pappus_volume(&profile.points(TAU / 20000.0));
        assert!(
            (fine / analytic - 1.0).abs() < 1e-6,
            "{}: {fine} vs {analytic}",
            piece.name()
        );
        let (lo, hi) = mesh.bounds().unwrap();
        assert_eq!(lo.z, 0.0);
        assert!((lo.x + hi.x).abs() < 1e-12 && (lo.y + hi.y).abs() < 1e-12);
        assert!(hi.z > 0.035 && hi.z < 0.06, "{} is {} m tall", piece.name(), hi.z);
    }
    assert_ne!(ChessPiece::Pawn.mesh().unwrap(), ChessPiece::Rook.mesh().unwrap());
    assert_eq!(ChessPiece::Rook.mesh().unwrap(), ChessPiece::Rook.mesh().unwrap());
}

#[test]
fn invalid_profiles_are_errors() {
    let open = Profile::builder(0.0)
        .line_to(0.01, 0.0)
        .line_to(0.01, 0.02)
        .finish();
    assert!(matches!(open, Err(MeshError::Profile { .. })));
    let crossing = Profile::builder(0.0)
        .line_to(0.01, 0.0)
        .line_to(-0.01, 0.01)
        .line_to(0.0, 0.02)
        .finish();
    assert!(matches!(crossing, Err(MeshError::Profile { .. })));
    let on_axis_only = Profile::builder(0.0).line_to(0.0, 0.02).finish();
    assert!(matches!(on_axis_only, Err(MeshError::Profile { .. })));
    let nan = Profile::builder(0.0)
        .line_to(f64::NAN, 0.0)
        .line_to(0.0, 1.0)
        .finish();
    assert!(matches!(nan, Err(MeshError::Profile { .. })));
    let ok = Profile::builder(0.0)
        .line_to(0.01, 0.0)
        .line_to(0.0, 0.02)
        .finish()
        .unwrap();
    assert!(matches!(
        ok.revolve(2, 0.1),
        Err(MeshError::InvalidParameter {
            field: "segments",
            ..
        })
    ));
    assert!(matches!(
        ok.revolve(8, 0.0),
        Err(MeshError::InvalidParameter { .. })
    ));
}
