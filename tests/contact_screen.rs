//! The contact screen of the arm's kinematic motions (`src/sim/contact_screen.rs`): a sample it
//! clears is one where MuJoCo's collision detection finds no contact of the arm, also after the
//! object moved under a remembered distance, and an exploration makes the same readings with the
//! screen as with `mj_collision` at every sample.

use glam::{DQuat, DVec3};
use rand::RngExt;
use taction::control::sensor_reader;
use taction::explore::{Planner, TouchSetup};
use taction::mesh::ObjectSet;
use taction::pose::Pose;
use taction::sim::{
    IkOptions, InverseKinematics, ObjectSpec, PAD_SITE, PadTarget, PerturbationBounds, Scene, SceneBuilder,
    Screened, Section,
};
use taction::tactile::{CoveringSensor, SensorConfig, add_sensor};
use taction::valid::Valid;

/// A concave object (legs, neck: many small shell pieces) and a convex one (few large pieces).
fn objects() -> Vec<ObjectSpec> {
    let set = ObjectSet::shapes();
    let all = ObjectSpec::all_of(&set).expect("the shapes (fetched by `cargo xtask setup`)");
    all.into_iter()
        .filter(|o| o.name == "camel" || o.name == "pawn")
        .collect()
}

fn sensor() -> SensorConfig {
    SensorConfig::square(6, 6, 0.012, 0.0012)
}

/// The scene of `object` with the arm, the table and the covering sensor, as the planner has it.
fn scene_of(object: &ObjectSpec) -> Scene {
    let builder = SceneBuilder::with_arm_and_table().object(object.clone());
    add_sensor(builder, &Valid::new(sensor()).unwrap(), PAD_SITE)
        .build()
        .unwrap()
}

/// Approaches of each object's surface the way Press makes them, in small joint-space steps
/// (the pad sent by inverse kinematics from 1.5-3 cm outside a random face, tilted up to 0.4 rad,
/// to 0.5-1.5 cm inside it, in 120 steps), the object moved by up to 1.5 cm now and then: at every
/// step the screen either leaves the sample to MuJoCo or clears it, and MuJoCo finds no contact of
/// the arm in any cleared one. The approaches meet contacts after runs of cleared samples, whose
/// remembered distances a rotating link or a move of the object outlives, so a screen that cleared
/// a touching arm would be caught.
#[test]
fn a_cleared_sample_has_no_contact_of_the_arm() {
    let mut rng = taction::rng::stream(5, 0);
    let (mut cleared, mut undecided, mut contacts, mut moves) = (0, 0, 0, 0);
    for object in objects() {
        let mut scene = scene_of(&object);
        let arm = scene.arm().cloned().unwrap();
        let mut ik = InverseKinematics::for_scene(&scene, IkOptions::default()).unwrap();
        let home = arm.q(scene.data());
        let mesh = &object.mesh;
        for _ in 0..30 {
            let pose = scene.object_pose().unwrap();
            let [i, j, k] = mesh.triangles[rng.random_range(0..mesh.triangles.len())].map(|v| v as usize);
            let (a, b, c) = (mesh.vertices[i], mesh.vertices[j], mesh.vertices[k]);
            let Some(outward) = pose.transform_vector((b - a).cross(c - a)).try_normalize() else {
                continue;
            };
            let point = pose.transform_point((a + b + c) / 3.0);
            let tilt = DQuat::from_axis_angle(outward.any_orthonormal_vector(), rng.random_range(-0.4..0.4));
            let mut pad_at = |offset_m: f64| {
                let target = PadTarget {
                    center_m: point + outward * offset_m,
                    normal: tilt * -outward,
                };
                ik.solve(&target, &home).ok()
            };
            let (Some(from), Some(to)) = (
                pad_at(rng.random_range(0.015..0.03)),
                pad_at(-rng.random_range(0.005..0.015)),
            ) else {
                continue;
            };
            for step in 0..=120 {
                if rng.random_range(0.0..1.0) < 0.02 {
                    let shift = DVec3::new(
                        rng.random_range(-0.015..0.015),
                        rng.random_range(-0.015..0.015),
                        rng.random_range(0.0..0.005),
                    );
                    let pose = scene.object_pose().unwrap();
                    let turned = DQuat::from_rotation_z(rng.random_range(-0.2..0.2)) * pose.rotation;
                    scene
                        .set_object_pose(Pose {
                            position_m: pose.position_m + shift,
                            rotation: turned,
                        })
                        .unwrap();
                    moves += 1;
                }
                let s = step as f64 / 120.0;
                let mut q: Vec<f64> = from.iter().zip(&to).map(|(a, b)| a + (b - a) * s).collect();
                arm.clamp(&mut q);
                arm.place(&mut scene, &q);
                let contact = arm.collision(&scene);
                contacts += usize::from(contact.is_some());
                match scene.screen_contacts() {
                    Screened::Clear => {
                        cleared += 1;
                        assert_eq!(
                            contact, None,
                            "{}: a cleared sample at {q:?} touches",
                            object.name
                        );
                    }
                    Screened::Undecided => undecided += 1,
                }
            }
        }
    }
    eprintln!(
        "{cleared} cleared, {undecided} undecided, {contacts} with a contact, {moves} moves of the object"
    );
    assert!(cleared > 1000 && undecided > 200 && contacts > 100 && moves > 50);
}

/// The planner's exploration of each object, fixed and perturbed after every reading (Sec. V-B4):
/// the same report, readings and images to the bit, whether kinematic motions clear samples with
/// the screen or ask `mj_collision` at every one.
#[test]
fn an_exploration_is_the_same_with_the_screen_as_without_it() {
    for object in objects() {
        for perturbation in [
            PerturbationBounds::NONE,
            PerturbationBounds::new(10.0, 0.1).unwrap(),
        ] {
            let explore = |scene: Scene| {
                let mut scene = scene;
                let reader = sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE).unwrap());
                let mut planner = Planner::new(
                    &scene,
                    Valid::default(),
                    TouchSetup {
                        sensor: sensor(),
                        control: Valid::default(),
                        perturbation,
                    },
                    taction::rng::stream(23, 0),
                    reader,
                )
                .unwrap();
                planner.explore(&mut scene, &object.name, 4).unwrap()
            };
            let screened = explore(scene_of(&object));
            let unscreened = explore(scene_of(&object).without_contact_screen());
            assert_eq!(screened.converged(), 4, "{}", object.name);
            assert!(
                screened == unscreened,
                "{}: the screen changed the exploration",
                object.name
            );
        }
    }
}

/// A world whose contacts the screen does not model (a predefined `<pair>`, which MuJoCo collides
/// whatever the contact bits say; a plane the arm may touch, which has no bounds) gets no screen:
/// every sample goes to `mj_collision`, where the same world without them clears the arm at home,
/// far from everything.
#[test]
fn a_world_with_contacts_the_screen_does_not_model_is_not_screened() {
    let object = objects().remove(0);
    let mut plain = scene_of(&object);
    assert_eq!(plain.screen_contacts(), Screened::Clear);
    let builder = SceneBuilder::with_arm_and_table()
        .object(object.clone())
        .add(Section::Contact, r#"<pair geom1="link4" geom2="table"/>"#);
    let mut paired = add_sensor(builder, &Valid::new(sensor()).unwrap(), PAD_SITE)
        .build()
        .unwrap();
    assert_eq!(paired.screen_contacts(), Screened::Undecided);
    // A floor plane under the table: a shape without a bounding sphere, which the arm's links may
    // touch.
    let builder = SceneBuilder::with_arm_and_table().object(object.clone()).add(
        Section::Worldbody,
        r#"<geom name="floor" type="plane" size="2 2 0.1" pos="0 0 -0.5"/>"#,
    );
    let mut floored = add_sensor(builder, &Valid::new(sensor()).unwrap(), PAD_SITE)
        .build()
        .unwrap();
    assert_eq!(floored.screen_contacts(), Screened::Undecided);
}
