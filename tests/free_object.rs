//! The object as a body MuJoCo moves (issue 74): the covering's push as a force, equal and
//! opposite on the object and the pad and as the stiffness model says at a known penetration;
//! a free object at rest stays at rest, a push changes its velocity by the impulse over its mass,
//! a toppled object is reported as tipped.

mod common;

use glam::{DQuat, DVec3};
use mujoco_rs::prelude::*;
use taction::pose::Pose;
use taction::sim::{
    FreeBody, MotionOutcome, MotionSummary, ObjectMount, ObjectSpec, PerturbationBounds, Scene, SceneBuilder,
};
use taction::tactile::{CoveringModulus, CoveringSensor, SensorConfig, sensor_xml, total_force_n};
use taction::valid::Valid;

/// A 10 cm cube of 0.4 kg on a free joint, its top face at z = 0.05, and a 0.1 kg pad on a free
/// joint looking down at it from `pad_height_m`, gravity off, nothing in contact: only the
/// covering of modulus `modulus` acts between them.
fn cube_under_a_free_pad(
    config: &Valid<SensorConfig>,
    modulus: CoveringModulus,
    pad_height_m: f64,
) -> (MjModel, CoveringSensor) {
    taction::tactile::ensure_registered();
    let xml = format!(
        "<mujoco><option gravity=\"0 0 0\" timestep=\"0.001\"/>\
         <extension><plugin plugin=\"taction.covering\"/></extension>\
         <worldbody>\
         <body name=\"object\"><freejoint/><geom type=\"box\" size=\"0.05 0.05 0.05\" mass=\"0.4\"/></body>\
         <body name=\"pad_body\" pos=\"0.01 -0.02 {pad_height_m}\"><freejoint/>\
         <geom type=\"box\" size=\"0.006 0.006 0.002\" pos=\"0 0 0.003\" mass=\"0.1\" contype=\"0\" conaffinity=\"0\"/>\
         <site name=\"pad\" zaxis=\"0 0 -1\"/></body>\
         </worldbody><sensor>{}</sensor></mujoco>",
        sensor_xml(config, "tactile", "pad", modulus)
    );
    let model = MjModel::from_xml_string(&xml).unwrap();
    let sensor = CoveringSensor::first(&model).unwrap();
    (model, sensor)
}

#[test]
fn the_covering_pushes_by_its_stiffness_and_the_pad_feels_the_opposite() {
    let config = Valid::new(SensorConfig::paper()).unwrap();
    let t = config.thickness_m;
    let depth_m = 0.4 * t;
    let modulus = CoveringModulus::new(20_000.0).unwrap();
    let (model, sensor) = cube_under_a_free_pad(&config, modulus, 0.05 + t - depth_m);
    let mut data = MjData::new(&model);
    data.forward();

    // The whole pad over the cube's top face, pressed `depth_m` in: E/t d A, straight down.
    let area_m2 = config.pad_width_m * config.pad_height_m;
    let expected_n = modulus.get() / t * depth_m * area_m2;
    let presses = sensor.last_press(&model, &data).unwrap();
    assert_eq!(presses.len(), 1, "{presses:?}");
    let force = total_force_n(&presses);
    assert!(
        (force.z + expected_n).abs() < 0.01 * expected_n,
        "{force} against {expected_n} N down"
    );
    assert!(force.truncate().length() < 1e-9 * expected_n);

    // MuJoCo's generalised forces: the object's free joint feels the force, the pad's its opposite.
    let qfrc = data.qfrc_passive();
    let (on_object, on_pad) = (DVec3::from_slice(&qfrc[0..3]), DVec3::from_slice(&qfrc[6..9]));
    assert!(
        (on_object - force).length() < 0.01 * expected_n,
        "{on_object} {force}"
    );
    assert!(
        (on_object + on_pad).length() < 0.01 * expected_n,
        "{on_object} {on_pad}"
    );

    // Stepped, the two bodies' momenta change by equal and opposite amounts.
    data.step();
    let v = data.qvel();
    let (object_momentum, pad_momentum) = (
        DVec3::from_slice(&v[0..3]) * 0.4,
        DVec3::from_slice(&v[6..9]) * 0.1,
    );
    assert!(object_momentum.z < 0.0 && pad_momentum.z > 0.0);
    assert!(
        (object_momentum + pad_momentum).length() < 0.01 * object_momentum.length(),
        "{object_momentum} {pad_momentum}"
    );
}

#[test]
fn a_covering_without_modulus_pushes_nothing_and_a_bad_modulus_fails_the_model() {
    let config = Valid::new(SensorConfig::paper()).unwrap();
    let t = config.thickness_m;
    let (model, sensor) = cube_under_a_free_pad(&config, CoveringModulus::NONE, 0.05 + 0.5 * t);
    let mut data = MjData::new(&model);
    data.forward();
    assert_eq!(sensor.last_press(&model, &data), Some(vec![]));
    assert!(data.qfrc_passive().iter().all(|&f| f == 0.0));
    // The image is the same whatever the covering's modulus.
    let (pressing_model, pressing) =
        cube_under_a_free_pad(&config, CoveringModulus::SOFT_GEL, 0.05 + 0.5 * t);
    let mut pressing_data = MjData::new(&pressing_model);
    pressing_data.forward();
    assert_eq!(
        sensor.read(&data).unwrap().values(),
        pressing.read(&pressing_data).unwrap().values()
    );

    let xml = "<mujoco><extension><plugin plugin=\"taction.covering\"/></extension>\
         <worldbody><body mocap=\"true\"><site name=\"pad\"/></body></worldbody><sensor>\
         <plugin plugin=\"taction.covering\" objtype=\"site\" objname=\"pad\"><config key=\"modulus_pa\" value=\"-3\"/></plugin>\
         </sensor></mujoco>";
    let e = format!("{:?}", MjModel::from_xml_string(xml).err().unwrap());
    assert!(e.contains("modulus_pa") && e.contains("out of range"), "{e}");
}

/// The arm's world with `mesh` on a free joint of `body`, its start `pose`.
fn free_object_scene(mesh: taction::mesh::TriMesh, body: FreeBody, pose: Pose) -> Scene {
    let spec = ObjectSpec {
        mount: ObjectMount::Free,
        free_body: body,
        pose,
        ..ObjectSpec::new("free", mesh)
    };
    let config = Valid::new(SensorConfig::paper()).unwrap();
    taction::tactile::arm_with_sensor(spec, &config).build().unwrap()
}

#[test]
fn a_free_object_on_the_table_stays_at_rest_and_has_its_solid_mass() {
    let size = DVec3::new(0.08, 0.06, 0.1);
    let mut scene = free_object_scene(common::box_mesh(size), FreeBody::DEFAULT, Pose::IDENTITY);
    let mass = scene.object_mass_kg().unwrap();
    assert!((mass - 1000.0 * size.x * size.y * size.z).abs() < 1e-9, "{mass}");
    let settled = scene.settle_object().unwrap().unwrap();
    assert!(settled.shift_m < 1e-3, "{settled:?}");
    let start = scene.object_pose().unwrap();
    scene.step_holding_the_arm(10.0).unwrap();
    let motion = scene.object_motion_from(&start).unwrap();
    assert!(motion.shift_m < 1e-4 && motion.turn_rad < 1e-3, "{motion:?}");
    assert_eq!(motion.outcome(), MotionOutcome::Standing);
}

#[test]
fn a_push_changes_the_velocity_by_the_impulse_over_the_mass() {
    // A frictionless object on the table: the push alone changes its horizontal velocity.
    let slippery = FreeBody::new(800.0, 0.0).unwrap();
    let mut scene = free_object_scene(
        common::box_mesh(DVec3::new(0.06, 0.06, 0.04)),
        slippery,
        Pose::IDENTITY,
    );
    scene.settle_object().unwrap();
    let mass = scene.object_mass_kg().unwrap();
    let body = scene.object().unwrap().body;
    let dt = scene.model().opt().timestep;
    let (force_n, steps) = (2.0, 5);
    let impulse = force_n * dt * steps as f64;
    let before = scene.data().qvel()[..2].to_vec();
    scene.data_mut().xfrc_applied_mut()[body][0] = force_n;
    for _ in 0..steps {
        scene.step().unwrap();
    }
    scene.data_mut().xfrc_applied_mut()[body][0] = 0.0;
    let dv = scene.object_speed().unwrap().0 - DVec3::new(before[0], before[1], 0.0).length();
    assert!(
        (dv - impulse / mass).abs() < 0.02 * impulse / mass,
        "{dv} against {}",
        impulse / mass
    );
}

#[test]
fn a_toppled_object_is_reported_as_tipped() {
    // A tall thin post put on the table leaning 40 degrees falls over.
    let post = common::box_mesh(DVec3::new(0.02, 0.02, 0.12));
    let lean = Pose::new(
        DVec3::new(0.0, 0.0, 0.02),
        DQuat::from_rotation_x(40f64.to_radians()),
    );
    let mut scene = free_object_scene(post, FreeBody::DEFAULT, lean);
    let upright = Pose::IDENTITY;
    scene.settle_object().unwrap();
    let motion = scene.object_motion_from(&upright).unwrap();
    assert_eq!(motion.outcome(), MotionOutcome::Tipped, "{motion:?}");
    assert!(
        motion.tilt_rad > 80f64.to_radians(),
        "it lies on its side: {motion:?}"
    );
}

#[test]
fn a_free_object_must_enclose_a_volume() {
    let mut sheet = common::box_mesh(DVec3::splat(0.05));
    sheet.triangles.truncate(2);
    let spec = ObjectSpec {
        mount: ObjectMount::Free,
        ..ObjectSpec::new("sheet", sheet)
    };
    let e = SceneBuilder::with_arm_and_table()
        .object(spec)
        .build()
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("object 'sheet'") && e.contains("encloses no volume"),
        "{e}"
    );
}

/// `taction collect --mode planner --free-object --contact-sheet 0` of `meshes` into `out`, with
/// `flags` besides.
fn collect_planner_free(
    meshes: &[std::path::PathBuf],
    out: &std::path::Path,
    flags: &[&str],
) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_taction"))
        .args([
            "collect",
            "--mode",
            "planner",
            "--free-object",
            "--contact-sheet",
            "0",
        ])
        .args(flags)
        .arg("--objects")
        .args(meshes)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

#[test]
fn collect_touches_a_free_object_records_it_and_says_how_far_each_touch_moved_it() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("block.obj");
    taction::mesh::write_obj(&common::box_mesh(DVec3::new(0.06, 0.05, 0.07)), &mesh, "a block").unwrap();
    let out = dir.path().join("d.csv");
    let run = collect_planner_free(&[mesh], &out, &["--readings", "3"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let line = stdout
        .lines()
        .find(|l| l.starts_with("free object block: "))
        .unwrap();
    // "free object block: N touches moved it X mm and Y deg each on average ..."
    let words: Vec<&str> = line.split_whitespace().collect();
    let (touches, shift_mm): (usize, f64) = (words[3].parse().unwrap(), words[7].parse().unwrap());
    assert!(touches >= 3 && shift_mm < 1.0, "{line}");
    assert!(
        line.contains("0 tipped it over, 0 pushed it off the table; it came to rest 0.0 deg from upright"),
        "a block stands as it was built: {line}"
    );

    let dataset = taction::dataset::Dataset::read(&out).unwrap();
    assert_eq!(dataset.header().free_object, Some(FreeBody::DEFAULT));
    // Every touch's pose before and after is in the file; the printed average is theirs.
    let shifts_mm: Vec<f64> = dataset
        .readings()
        .iter()
        .filter(|r| r.is_converged())
        .map(|r| {
            let after = r
                .object_pose_after
                .expect("a free object's reading records its pose after");
            (after.position_m - r.object_pose.position_m).length() * 1e3
        })
        .collect();
    assert!(dataset.readings().iter().all(|r| r.object_pose_after.is_some()));
    let mean_mm = shifts_mm.iter().sum::<f64>() / shifts_mm.len() as f64;
    assert!((mean_mm - shift_mm).abs() < 0.0015, "{mean_mm} mm against {line}");
    assert!(
        dataset
            .summary()
            .to_string()
            .contains("free object (1000 kg/m3, friction 0.8)")
    );
}

#[test]
fn an_exported_free_object_scene_opens_pressed_and_the_object_stays_under_the_servos() {
    let dir = tempfile::tempdir().unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_taction"))
        .args([
            "scene",
            "export",
            "--object",
            "pawn",
            "--free-object",
            "--object-density",
            "1200",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let xml = std::fs::read_to_string(dir.path().join("scene.xml")).unwrap();
    assert!(
        xml.contains("<freejoint") && xml.contains("key=\"modulus_pa\" value=\"300\""),
        "{xml}"
    );
    assert!(
        xml.contains("a solid of 1200 kg/m3, friction 0.8"),
        "the header says the material"
    );

    taction::tactile::ensure_registered();
    let model = MjModel::from_xml(dir.path().join("scene.xml")).expect("the exported scene compiles");
    let key = model
        .name_to_id(MjtObjBase::mjOBJ_KEY, "touch")
        .expect("a keyframe 'touch'");
    let mut scene = Scene::new(model, None).unwrap();
    scene.data_mut().reset_keyframe(key).unwrap();
    scene.forward();
    let body = scene
        .model()
        .name_to_id(MjtObjBase::mjOBJ_BODY, "object")
        .unwrap();
    let sensor = CoveringSensor::first(scene.model()).unwrap();
    let presses = sensor.last_press(scene.model(), scene.data()).unwrap();
    let press = presses
        .iter()
        .find(|p| p.body == body)
        .expect("the pad presses the object");
    assert!(press.force_n.z < 0.0, "the pad presses down: {press:?}");
    // The mass is the pawn's as a solid of 1200 kg/m3.
    let pawn = taction::mesh::ObjectSet::builtin("chess", None)
        .unwrap()
        .build_object("pawn", &taction::mesh::BuildOptions::default())
        .unwrap();
    let volume = taction::mesh::SolidMoments::of(&pawn.mesh).unwrap().volume_m3;
    assert!((scene.model().body_mass()[body] - 1200.0 * volume).abs() < 1e-9);
    // MuJoCo's own stepping, the servos holding the arm: the object stays where it stood.
    let start = DVec3::from_array(scene.data().xpos()[body]);
    for _ in 0..500 {
        scene.step().unwrap();
    }
    let moved = (DVec3::from_array(scene.data().xpos()[body]) - start).length();
    assert!(
        moved < 2e-4,
        "the object moved {moved} m in 1 s under the pressing pad"
    );
}

#[test]
fn a_sliding_free_objects_dataset_is_the_same_on_one_thread_and_on_two() {
    let dir = tempfile::tempdir().unwrap();
    let mut meshes = Vec::new();
    for (name, size) in [
        ("block", DVec3::new(0.06, 0.05, 0.07)),
        ("post", DVec3::new(0.03, 0.03, 0.1)),
    ] {
        let path = dir.path().join(format!("{name}.obj"));
        taction::mesh::write_obj(&common::box_mesh(size), &path, name).unwrap();
        meshes.push(path);
    }
    let collect = |threads: &str| {
        let out = dir.path().join(format!("d{threads}.csv"));
        let flags = [
            "--object-density",
            "500",
            "--object-friction",
            "0",
            "--readings",
            "3",
            "--seed",
            "5",
            "--start-pose",
            "random",
            "--allow-short",
            "--threads",
            threads,
        ];
        let run = collect_planner_free(&meshes, &out, &flags);
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        out
    };
    let (one, two) = (collect("1"), collect("2"));
    assert_eq!(std::fs::read(&one).unwrap(), std::fs::read(two).unwrap());
    // A light, slippery object slides under the press, and the file says how far.
    let dataset = taction::dataset::Dataset::read(&one).unwrap();
    let largest_mm = dataset
        .readings()
        .iter()
        .filter_map(|r| Some((r.object_pose_after?.position_m - r.object_pose.position_m).length() * 1e3))
        .fold(0.0, f64::max);
    assert!(largest_mm > 0.5, "the largest slide is {largest_mm} mm");
}

/// The same `draws` draws of Sec. V-B4's bounds (10 deg, 10% of the width), teleporting `object`
/// fixed and pushing it free (each from where it stands): how each moved it.
fn pushed_and_teleported(object: &ObjectSpec, draws: usize) -> (MotionSummary, MotionSummary) {
    let config = Valid::new(SensorConfig::paper()).unwrap();
    let build = |spec: ObjectSpec| taction::tactile::arm_with_sensor(spec, &config).build().unwrap();
    let mut pushed = build(object.mounted(Some(FreeBody::DEFAULT)));
    pushed.settle_object().unwrap();
    let mut teleported = build(object.clone());
    let width = teleported.object_width_m().unwrap();
    let mut rng = taction::rng::stream(17, 0);
    let (mut by_push, mut by_teleport) = (Vec::new(), Vec::new());
    for _ in 0..draws {
        let draw = PerturbationBounds::PAPER.draw(width, &mut rng);
        by_push.push(pushed.push_object(&draw).unwrap());
        let before = teleported.object_pose().unwrap();
        teleported.perturb_object(&draw).unwrap();
        by_teleport.push(teleported.object_motion_from(&before).unwrap());
        teleported.set_object_pose(before).unwrap();
    }
    (MotionSummary::of(&by_push), MotionSummary::of(&by_teleport))
}

/// Issue 74's bar for a push: its mean shift of the centre along the table and its mean turn are
/// the teleport's within 10%, and nothing tips or leaves the table.
fn assert_pushed_as_far_as_teleported(object: &ObjectSpec, draws: usize) {
    let (push, teleport) = pushed_and_teleported(object, draws);
    let close = |a: f64, b: f64| (a - b).abs() <= 0.1 * b;
    assert!(
        close(push.centre_shift_m.mean, teleport.centre_shift_m.mean)
            && close(push.turn_rad.mean, teleport.turn_rad.mean),
        "{}: pushed {push:?}, teleported {teleport:?}",
        object.name
    );
    assert_eq!((push.tipped, push.off_table), (0, 0), "{}: {push:?}", object.name);
}

#[test]
fn a_push_moves_a_free_object_as_far_as_the_teleport_of_the_same_draw() {
    for size in [DVec3::new(0.08, 0.06, 0.05), DVec3::new(0.03, 0.03, 0.1)] {
        assert_pushed_as_far_as_teleported(&ObjectSpec::new("box", common::box_mesh(size)), 12);
    }
}

/// The shapes a hand pushing at the base alone rocked and tipped (the bunny, standing with its
/// centre of mass 2 mm inside its supports, 20 of 40 times): held upright as they slide, each is
/// pushed as far as the teleport and none tips.
#[test]
fn a_push_holds_the_rounded_and_top_heavy_shapes_upright() {
    let shapes = taction::mesh::ObjectSet::shapes();
    let options = taction::mesh::BuildOptions {
        fetch: true,
        ..Default::default()
    };
    for name in ["bunny", "elephant", "pawn"] {
        let built = shapes
            .build_object(name, &options)
            .expect("the shapes (fetched by `cargo xtask setup`)");
        assert_pushed_as_far_as_teleported(&ObjectSpec::new(name, built.mesh), 12);
    }
}

/// A push is a free object's: a mocap object has no dynamics to push.
#[test]
fn a_mocap_object_cannot_be_pushed() {
    let config = Valid::new(SensorConfig::paper()).unwrap();
    let mut scene = taction::tactile::arm_with_sensor(
        ObjectSpec::new("fixed", common::box_mesh(DVec3::splat(0.05))),
        &config,
    )
    .build()
    .unwrap();
    let draw = taction::sim::PerturbationBounds::PAPER.draw(0.05, &mut taction::rng::stream(1, 0));
    let e = scene.push_object(&draw).unwrap_err().to_string();
    assert!(e.contains("a push needs a free object"), "{e}");
}
