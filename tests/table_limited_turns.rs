//! The arm's pad with its turns limited by the table (what a guarded touch settles with): on a
//! box's side just above the table Orient turns the pad toward the horizontal wall, the wrist
//! behind the pad (a capsule 2.8 cm across) would meet the table, and the plain carrier ends the
//! attempt as a collision; the limited one stops the turn where the arm still clears the table
//! and settles there, pressed to the target like any reading.

use glam::DVec3;
use taction::control::{ArmPad, ContactOutcome, ControlConfig, sensor_reader, settle};
use taction::dataset::ContactStatus;
use taction::explore::precise_kinematic_motion;
use taction::mesh::TriMesh;
use taction::sim::{InverseKinematics, ObjectSpec, PAD_SITE, PadTarget, Scene, SceneBuilder};
use taction::tactile::{CoveringSensor, SensorConfig, add_sensor};
use taction::valid::Valid;

/// The box's half extent, metres: 8 cm across, taller than the wrist is wide.
const HALF_M: f64 = 0.04;

/// Settles from `start` with the plain carrier and with the table-limited one.
fn both(scene: &mut Scene, ik: &mut InverseKinematics, start: &[f64]) -> [ContactOutcome; 2] {
    let sensor = SensorConfig::paper();
    let (_, motion) = precise_kinematic_motion(0.125 * sensor.thickness_m);
    let control = Valid::new(ControlConfig::default()).expect("defaults are valid");
    [false, true].map(|limited| {
        let arm = scene.arm().cloned().expect("arm");
        arm.teleport(scene, start);
        let reader = sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE).expect("covering"));
        let mut pad = ArmPad::new(scene, ik, sensor, reader, motion).expect("arm pad");
        if limited {
            pad = pad.limited_by_the_table();
        }
        settle(&mut pad, &control).expect("settles")
    })
}

/// Whether the attempt ended with an arm link (not the pad, whose back the carrier backs off) on
/// the table.
fn link_on_table(outcome: &ContactOutcome) -> bool {
    outcome.collision.as_ref().is_some_and(|c| {
        let bodies = [c.body_a.as_str(), c.body_b.as_str()];
        bodies.contains(&"world") && bodies.iter().any(|b| b.starts_with("link"))
    })
}

#[test]
fn a_turn_the_table_blocks_is_stopped_short_and_the_reading_settles() {
    let sensor = SensorConfig::paper();
    let object = ObjectSpec::new("box", TriMesh::cuboid(DVec3::splat(HALF_M)));
    let builder = SceneBuilder::with_arm_and_table().object(object);
    let mut scene: Scene = add_sensor(builder, &Valid::new(sensor).expect("sensor"), PAD_SITE)
        .build()
        .expect("scene");
    let arm = scene.arm().cloned().expect("arm");
    let (ik_options, _) = precise_kinematic_motion(0.125 * sensor.thickness_m);
    let mut ik = InverseKinematics::new(scene.model_arc(), arm.clone(), ik_options);
    let home = arm.q(scene.data());
    let centre = scene.object_pose().expect("object").transform_point(DVec3::ZERO);
    // The table top is the world's z = 0 (`mjcf/`).
    let bottom_z = 0.0;
    let (mut blocked, mut tried) = (0, 0);
    // Starts 1.5 cm off the four sides, 1.2-2 cm above the table, facing the wall and tilted down
    // 35 degrees: the first contact is the pad's lower edge, and Orient turns it up to level.
    for side in 0..4 {
        let outward = DVec3::new([1.0, 0.0, -1.0, 0.0][side], [0.0, 1.0, 0.0, -1.0][side], 0.0);
        let along = outward.cross(DVec3::Z);
        for (offset_m, height_m) in [(-0.015, 0.012), (0.0, 0.016), (0.015, 0.02)] {
            let tilt = 35f64.to_radians();
            let normal = (-outward * tilt.cos() - DVec3::Z * tilt.sin()).normalize();
            let surface = centre + outward * HALF_M + along * offset_m;
            let target = PadTarget {
                center_m: DVec3::new(surface.x, surface.y, bottom_z + height_m) - normal * 0.015,
                normal,
            };
            let Ok(q) = ik.solve(&target, &home) else {
                continue;
            };
            arm.teleport(&mut scene, &q);
            if arm.collision(&scene).is_some() {
                continue;
            }
            tried += 1;
            let [plain, limited] = both(&mut scene, &mut ik, &q);
            assert!(
                !link_on_table(&limited),
                "the limited carrier touched the table: {limited:?}"
            );
            if link_on_table(&plain) {
                blocked += 1;
                assert_eq!(plain.status, ContactStatus::Collision);
                assert_eq!(limited.status, ContactStatus::Converged, "{:?}", limited.trace);
                // Pressed to the target, short of level: the turn stopped where the arm clears.
                let control = ControlConfig::default();
                assert!(
                    (limited.image.mean() - control.target_mean_pressure).abs() <= control.pressure_tolerance
                );
                assert!(limited.pose.normal.z < -1e-3, "{:?}", limited.pose);
            } else {
                assert_eq!(
                    plain.status, limited.status,
                    "unchanged where the table is not in the way"
                );
                assert_eq!(plain.image, limited.image);
            }
        }
    }
    assert!(tried >= 4, "only {tried} starts reachable");
    assert!(
        blocked >= 2,
        "the table blocked {blocked} of {tried} turns: the case is not exercised"
    );
}
