//! Surface contact control on the free-floating pad, with the real covering sensor in MuJoCo.

mod common;

use glam::{DQuat, DVec3};
use rand::RngExt;
use taction::control::{ControlConfig, FreePad, settle};
use taction::dataset::ContactStatus;
use taction::mesh::TriMesh;
use taction::pose::PadPose;
use taction::pose::Pose;
use taction::rng;
use taction::sim::ObjectSpec;
use taction::tactile::SensorConfig;
use taction::valid::Valid;

fn sensor() -> SensorConfig {
    SensorConfig::square(6, 6, 0.012, 0.0012)
}

fn free_sensor(object: ObjectSpec) -> FreePad {
    FreePad::new(object, &Valid::new(sensor()).unwrap()).unwrap()
}

/// Runs the controllers from `start` and returns the outcome.
fn settle_from(
    pad: &mut FreePad,
    start: &PadPose,
    config: &ControlConfig,
) -> taction::control::ContactOutcome {
    pad.place(start);
    settle(pad, &Valid::new(*config).unwrap()).unwrap()
}

/// A 20 cm slab whose top face passes through the origin with normal `n`.
fn tilted_plane(tilt: DQuat) -> ObjectSpec {
    let slab = common::box_mesh(DVec3::new(0.2, 0.2, 0.02));
    let mut spec = ObjectSpec::new("plane", slab);
    // The slab's top is at z = 0.02 in its frame; put it at the origin, then tilt.
    spec.pose = Pose::new(tilt * DVec3::new(0.0, 0.0, -0.02), tilt);
    spec
}

#[test]
fn tilted_planes_converge_normal_and_pressure() {
    tilted_planes_converge(&ControlConfig::default());
}

#[test]
fn tilted_planes_converge_with_the_edge_guard_too() {
    tilted_planes_converge(&ControlConfig {
        orient_edge_guard: true,
        ..ControlConfig::default()
    });
}

/// A 2 mm plate with an 8 mm wide bar along y raised 3 mm on it, centred at x = 0 (a letter's
/// stroke, Sec. V-D).
fn raised_bar() -> ObjectSpec {
    let mut mesh = TriMesh::cuboid(DVec3::new(0.03, 0.03, 0.001)).translated(DVec3::new(0.0, 0.0, 0.001));
    mesh.append(&TriMesh::cuboid(DVec3::new(0.004, 0.03, 0.0015)).translated(DVec3::new(0.0, 0.0, 0.0035)));
    ObjectSpec::new("bar", mesh)
}

/// Tilt of the settled pad from level, degrees, started level 7 mm above the plate, centred at `x`.
fn settled_tilt_deg(x_m: f64, config: &ControlConfig) -> f64 {
    let mut free = free_sensor(raised_bar());
    let start = PadPose::new(DVec3::new(x_m, 0.0, 0.012), DVec3::NEG_Z, DVec3::Y).unwrap();
    let outcome = settle_from(&mut free, &start, config);
    assert_eq!(outcome.status, ContactStatus::Converged, "x = {x_m}");
    outcome.pose.normal.angle_between(DVec3::NEG_Z).to_degrees()
}

#[test]
fn the_edge_guard_keeps_a_level_pad_level_beside_a_stroke_edge() {
    let guarded = ControlConfig {
        orient_edge_guard: true,
        ..ControlConfig::default()
    };
    // The bar's edge is at x = 4 mm. On the bar 1-4 mm in from its edge, and off it 1-2.5 mm (the
    // bar under one side of the pad) or 4.5-5.5 mm (under its border column).
    for offset_mm in [-4.0, -3.0, -2.0, -1.0, 1.0, 1.5, 2.0, 2.5, 4.5, 5.0, 5.5] {
        let x = 0.004 + offset_mm * 1e-3;
        let tilt = settled_tilt_deg(x, &guarded);
        assert!(
            tilt < 5.0,
            "{offset_mm} mm off the edge: settled {tilt:.1} deg from level"
        );
    }
    // Without the guard a partly covered column reads as a slope and the pad tips onto the plate.
    let unguarded = settled_tilt_deg(0.0055, &ControlConfig::default());
    assert!(unguarded > 10.0, "{unguarded}");
}

/// Runs the controllers on eight seeded tilted planes from 30 degrees off their normal.
fn tilted_planes_converge(config: &ControlConfig) {
    let mut r = rng::rng(404);
    for trial in 0..8 {
        let tilt_axis = DVec3::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0), 0.0).normalize();
        let tilt = DQuat::from_axis_angle(tilt_axis, r.random_range(0.0..=40f64).to_radians());
        let surface_n = tilt * DVec3::Z;
        let mut free = free_sensor(tilted_plane(tilt));
        // Start 3 mm above the surface, the pad normal 30 degrees off the inward normal.
        let off_axis = surface_n.any_orthonormal_vector();
        let normal = DQuat::from_axis_angle(off_axis, 30f64.to_radians()) * -surface_n;
        let start = PadPose::new(surface_n * 0.003, normal, normal.any_orthonormal_vector()).unwrap();
        let outcome = settle_from(&mut free, &start, config);
        assert_eq!(
            outcome.status,
            ContactStatus::Converged,
            "trial {trial}: {:?}",
            outcome.status
        );
        let angle = outcome.pose.normal.angle_between(-surface_n).to_degrees();
        assert!(
            angle <= 2.0,
            "trial {trial}: pad normal {angle:.2} deg off the surface normal"
        );
        let mean = outcome.image.mean();
        assert!(
            (mean - config.target_mean_pressure).abs() <= 0.05 * config.target_mean_pressure,
            "trial {trial}: mean pressure {mean}"
        );
    }
}

#[test]
fn sphere_converges_and_box_edge_reading_shows_the_edge() {
    let config = ControlConfig::default();
    let mut free = free_sensor(ObjectSpec::new(
        "sphere",
        common::sphere_mesh(0.03, DVec3::new(0.0, 0.0, 0.03), 24),
    ));
    let start = PadPose::new(
        DVec3::new(0.01, 0.0, 0.066),
        DVec3::new(-0.2, 0.0, -1.0),
        DVec3::Y,
    )
    .unwrap();
    let outcome = settle_from(&mut free, &start, &config);
    assert_eq!(outcome.status, ContactStatus::Converged);
    // On a sphere the settled pad faces the centre from where it touches: the line along the pad normal
    // through the contact's centroid passes through the centre.
    let image = &outcome.image;
    let (mut wx, mut wy, mut w) = (0.0, 0.0, 0.0);
    for r in 0..6 {
        for c in 0..6 {
            let v = image.get(r, c);
            let (x, y) = sensor().taxel_centre_m(r, c);
            wx += v * x;
            wy += v * y;
            w += v;
        }
    }
    let pose = outcome.pose;
    let contact = pose.center_m + pose.right() * (wx / w) + pose.up * (wy / w);
    let to_center = (DVec3::new(0.0, 0.0, 0.03) - contact).normalize();
    let angle = pose.normal.angle_between(to_center).to_degrees();
    assert!(
        angle < 2.0,
        "settled {angle} deg off the sphere's normal after {} iterations\n{image}",
        outcome.iterations
    );

    // A box edge along y at x = 0.04, z = 0.08; approach from the diagonal.
    let mut free = free_sensor(ObjectSpec::new(
        "box",
        common::box_mesh(DVec3::new(0.08, 0.08, 0.08)),
    ));
    let normal = DVec3::new(-1.0, 0.0, -1.0).normalize();
    let start = PadPose::new(DVec3::new(0.045, 0.0, 0.085), normal, DVec3::Y).unwrap();
    let outcome = settle_from(&mut free, &start, &config);
    assert_eq!(outcome.status, ContactStatus::Converged);
    let image = &outcome.image;
    // The edge runs along the pad's up axis (world y): a ridge in the middle columns, a step to the sides.
    let column_mean = |c: usize| (0..6).map(|r| image.get(r, c)).sum::<f64>() / 6.0;
    let (middle, side) = (
        (column_mean(2) + column_mean(3)) / 2.0,
        (column_mean(0) + column_mean(5)) / 2.0,
    );
    assert!(middle > side + 0.2, "no edge in the reading:\n{image}");
}

#[test]
fn approach_into_empty_space_reports_no_contact() {
    let config = ControlConfig {
        approach_max_distance_m: 0.02,
        ..ControlConfig::default()
    };
    let mut free = free_sensor(ObjectSpec::new("box", common::box_mesh(DVec3::splat(0.05))));
    let start = PadPose::new(DVec3::new(0.0, 0.0, 0.1), DVec3::Z, DVec3::Y).unwrap();
    let outcome = settle_from(&mut free, &start, &config);
    assert_eq!(outcome.status, ContactStatus::NoContact);
    let travelled = (outcome.pose.center_m - start.center_m).length();
    assert!(
        travelled <= config.approach_max_distance_m + 1e-9 && travelled >= 0.019,
        "{travelled}"
    );
    assert!(outcome.image.max() == 0.0);
}

#[test]
fn same_seed_same_commands_and_readings() {
    let config = ControlConfig {
        expected_noise_fraction: 0.2,
        ..ControlConfig::default()
    };
    let run = |seed: u64| {
        let sensor = SensorConfig {
            noise_fraction: 0.2,
            noise_seed: seed,
            ..sensor()
        };
        let mut pad = FreePad::new(
            tilted_plane(DQuat::from_rotation_x(0.3)),
            &Valid::new(sensor).unwrap(),
        )
        .unwrap();
        let start = PadPose::new(DVec3::new(0.0, 0.0, 0.004), -DVec3::Z, DVec3::Y).unwrap();
        pad.place(&start);
        let o = settle(&mut pad, &Valid::new(config).unwrap()).unwrap();
        (o.trace, o.image, o.status)
    };
    let a = run(7);
    assert_eq!(a, run(7));
    assert_ne!(a.1, run(8).1);
}
