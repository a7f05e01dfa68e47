//! `mjcf/scene.xml` (the world with the paper's sensor on the pad), the plugin's taxel drawing in
//! MuJoCo's visual scene, `taction scene export` and `taction plugin-path`, on the Rust side.
//! tests/sensor_python.rs checks the same files through MuJoCo's official Python bindings.

mod common;
mod sensor_support;

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::{DMat3, DVec3};
use mujoco_rs::mujoco_c::{mjtCatBit, mjtGeom, mjtObj};
use mujoco_rs::prelude::*;
use sensor_support::shipped_scene_at_touch;
use taction::tactile::{CoveringSensor, SensorConfig, ensure_registered};
use taction::tactile::{taxel_rgba, taxel_tiles};

#[test]
fn scene_xml_carries_the_paper_sensor_and_its_touch_keyframe_reads_the_cylinder_rim() {
    let (scene, sensor) = shipped_scene_at_touch();
    let config = sensor.config();
    let paper = SensorConfig::default();
    assert_eq!(
        (config.rows, config.cols, config.rays_per_taxel),
        (6, 6, paper.rays_per_taxel)
    );
    for (got, want) in [
        (config.pad_width_m, paper.pad_width_m),
        (config.pad_height_m, paper.pad_height_m),
        (config.thickness_m, paper.thickness_m),
        (config.psf_sigma_m, paper.psf_sigma_m),
        (config.noise_fraction, paper.noise_fraction),
    ] {
        assert!((got - want).abs() <= 1e-12, "{config:?}");
    }

    let image = sensor.read(scene.data()).unwrap();
    let pose = image.pose().expect("the image carries the pad pose");
    assert!(
        (pose.center_m - DVec3::new(0.045, 0.0, 0.0906)).length() < 1e-5,
        "{pose:?}"
    );
    assert!(pose.normal.dot(DVec3::NEG_Z) > 1.0 - 1e-9, "{pose:?}");
    let values = image.values();
    assert!(values.iter().all(|v| (0.0..=1.0).contains(v)), "{values:?}");
    // Half the pad lies over the cylinder top pressed 0.6 of 1.2 mm, the other half over nothing:
    // the rim runs along the columns, blurred by the point-spread.
    for row in values.chunks(6) {
        assert!(row[..2].iter().all(|v| (v - 0.5).abs() < 0.01), "{values:?}");
        assert!(row[4..].iter().all(|&v| v < 1e-6), "{values:?}");
        assert!(row.windows(2).all(|w| w[0] >= w[1]), "{values:?}");
    }
}

/// The decor boxes the covering plugin added to `scene` for sensor `sensor_id`.
fn tiles_in(scene: &MjvScene, sensor_id: usize) -> Vec<mujoco_rs::mujoco_c::mjvGeom> {
    let raw = scene.ffi();
    // SAFETY: geoms has maxgeom slots, the first ngeom filled by mjv_updateScene.
    let geoms = unsafe { std::slice::from_raw_parts(raw.geoms, raw.ngeom as usize) };
    geoms
        .iter()
        .filter(|g| {
            g.objtype == mjtObj::mjOBJ_UNKNOWN as i32
                && g.objid == sensor_id as i32
                && g.category == mjtCatBit::mjCAT_DECOR as i32
                && g.type_ == mjtGeom::mjGEOM_BOX as i32
        })
        .cloned()
        .collect()
}

fn update(scene: &mut MjvScene, data: &mut MjData<std::sync::Arc<MjModel>>) {
    let option = MjvOption::default();
    let perturb = MjvPerturb::default();
    let mut camera = MjvCamera::default();
    scene.update(data, &option, &perturb, &mut camera);
}

#[test]
fn visualize_draws_each_taxel_in_front_of_the_pad_coloured_by_its_value() {
    let (mut scene, sensor) = shipped_scene_at_touch();
    let model = scene.model_arc();
    let image = sensor.read(scene.data()).unwrap();
    let config = *sensor.config();
    let mut visual = MjvScene::new(&model, 2000);
    update(&mut visual, scene.data_mut());
    let tiles = tiles_in(&visual, sensor.sensor_id());
    assert_eq!(tiles.len(), 36);

    let site = sensor.site_id();
    let p = DVec3::from_array(scene.data().site_xpos()[site]);
    let m = scene.data().site_xmat()[site];
    let frame = DMat3::from_cols(
        DVec3::new(m[0], m[3], m[6]),
        DVec3::new(m[1], m[4], m[7]),
        DVec3::new(m[2], m[5], m[8]),
    );
    let expected = taxel_tiles(&config, p, frame, image.values());
    let pose = image.pose().unwrap();
    for (k, (tile, want)) in tiles.iter().zip(&expected).enumerate() {
        assert_eq!(tile.rgba, taxel_rgba(image.values()[k]), "taxel {k}");
        let center = DVec3::new(tile.pos[0] as f64, tile.pos[1] as f64, tile.pos[2] as f64);
        assert!((center - want.center_m).length() < 1e-6, "taxel {k}");
        // In front of the pad: inside the covering, half its thickness along the normal.
        let depth = (center - pose.center_m).dot(pose.normal);
        assert!(
            (depth - 0.5 * config.thickness_m).abs() < 1e-6,
            "taxel {k}: {depth}"
        );
    }
    // Row 0 is the pad's up edge, column 0 its left edge seen from behind (right = normal x up).
    let right = pose.normal.cross(pose.up);
    let c = |k: usize| {
        DVec3::new(
            tiles[k].pos[0] as f64,
            tiles[k].pos[1] as f64,
            tiles[k].pos[2] as f64,
        )
    };
    assert!((c(0) - c(6)).dot(pose.up) > 1.9e-3);
    assert!((c(1) - c(0)).dot(right) > 1.9e-3);
    // A zero taxel and a pressed one get different colours.
    let zero = image.values().iter().position(|&v| v == 0.0).unwrap();
    let pressed = image.values().iter().position(|&v| v > 0.3).unwrap();
    assert_ne!(tiles[zero].rgba, tiles[pressed].rgba);

    // A full geom buffer: the plugin draws what fits and never writes past it (MuJoCo adds some
    // of its own geoms after the plugins', so fewer of those fit too).
    let others = visual.ffi().ngeom as usize - 36;
    let mut small = MjvScene::new(&model, others + 5);
    update(&mut small, scene.data_mut());
    assert_eq!(small.ffi().ngeom as usize, others + 5);
    let drawn = tiles_in(&small, sensor.sensor_id()).len();
    assert!((5..36).contains(&drawn), "{drawn} taxels drawn");
}

fn taction(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(args)
        .output()
        .expect("the taction binary runs")
}

#[test]
fn scene_export_writes_the_builders_scene_with_its_mesh_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pawn scene");
    let run = taction(&[
        "scene",
        "export",
        "--object",
        "pawn",
        "--rows",
        "8",
        "--cols",
        "8",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let xml = std::fs::read_to_string(out.join("scene.xml")).unwrap();
    assert!(xml.contains("file=\"pawn.obj\""), "the mesh is an asset file");
    assert!(out.join("pawn.obj").is_file());

    ensure_registered();
    let exported = MjModel::from_xml(out.join("scene.xml")).expect("the exported scene compiles");
    let sensor = CoveringSensor::first(&exported).unwrap();
    assert_eq!((sensor.config().rows, sensor.config().cols), (8, 8));
    // The same model as the Rust scene builder's, mesh, collision shell and all.
    let set = taction::mesh::ObjectSet::chess();
    let pawn = set
        .build_object("pawn", &taction::mesh::BuildOptions::default())
        .unwrap();
    let builder = taction::sim::SceneBuilder::with_arm_and_table()
        .object(taction::sim::ObjectSpec::new("pawn", pawn.mesh));
    let built = taction::tactile::add_sensor(builder, sensor.config(), "pad")
        .build()
        .unwrap();
    let model = built.model();
    assert_eq!(exported.ngeom(), model.ngeom());
    assert_eq!(exported.nmesh(), model.nmesh());
    assert_eq!(exported.nmeshvert(), model.nmeshvert());
    assert_eq!(exported.nmeshface(), model.nmeshface());
    assert_eq!(exported.nsensordata(), 64);
}

#[test]
fn scene_export_names_the_flag_of_an_unknown_object_or_bad_sensor() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let run = taction(&["scene", "export", "--object", "no_such_thing", "--out", out]);
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("--object") && stderr.contains("no_such_thing"),
        "{stderr}"
    );
    let run = taction(&["scene", "export", "--object", "pawn", "--rows", "0", "--out", out]);
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("--rows"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn plugin_path_prints_the_library_the_set_up_built() {
    // `cargo xtask setup` (run by `cargo xtask test`) builds the library in release; this debug
    // binary finds it in the release folder beside its own.
    let run = taction(&["plugin-path"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let path = PathBuf::from(stdout.trim());
    assert!(path.is_absolute() && path.is_file(), "{stdout}");
    assert!(path.ends_with("libtaction_covering.so"), "{stdout}");
}

/// `xml` read by a strict XML parser (as Python's `xml.etree` and dm_control's `mjcf` read MJCF),
/// or a panic naming `origin` and the parser's complaint.
fn strictly_parsed<'a>(xml: &'a str, origin: &str) -> roxmltree::Document<'a> {
    roxmltree::Document::parse(xml).unwrap_or_else(|e| panic!("{origin} is not well-formed XML: {e}"))
}

/// Runs `taction scene export --object OBJECT` into `out`; the written scene.xml.
fn export_scene(object: &str, out: &Path) -> String {
    let run = taction(&[
        "scene",
        "export",
        "--object",
        object,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    std::fs::read_to_string(out.join("scene.xml")).unwrap()
}

/// A 5 cm box resting on the table at the origin, written as `name`.obj in `dir`.
fn box_file(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(format!("{name}.obj"));
    taction::mesh::write_obj(&common::box_mesh(DVec3::splat(0.05)), &path, "box").unwrap();
    path
}

#[test]
fn every_shipped_generated_and_exported_mjcf_is_well_formed_xml() {
    let mjcf = Path::new(env!("CARGO_MANIFEST_DIR")).join("mjcf");
    let mut shipped = 0;
    for entry in std::fs::read_dir(&mjcf).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "xml") {
            strictly_parsed(
                &std::fs::read_to_string(&path).unwrap(),
                &path.display().to_string(),
            );
            shipped += 1;
        }
    }
    assert!(shipped >= 5, "{shipped} files in mjcf/");

    // What the builders write: the arm's world with a fixed and a free object and the sensor, and
    // the free-floating pad's. The object's name lands in a comment: `--` must not end it early.
    let config = taction::valid::Valid::new(SensorConfig::default()).unwrap();
    let named = |mount| taction::sim::ObjectSpec {
        mount,
        ..taction::sim::ObjectSpec::new("a--b -", common::box_mesh(DVec3::splat(0.05)))
    };
    for mount in [taction::sim::ObjectMount::Mocap, taction::sim::ObjectMount::Free] {
        let builder = taction::sim::SceneBuilder::with_arm_and_table().object(named(mount));
        let xml = taction::tactile::add_sensor(builder, &config, "pad")
            .to_xml()
            .unwrap();
        strictly_parsed(&xml, &format!("the arm's scene ({mount:?} object)"));
    }
    let free = taction::tactile::free_floating_builder(named(taction::sim::ObjectMount::Mocap), &config)
        .to_xml()
        .unwrap();
    strictly_parsed(&free, "the free-floating pad's scene");

    // `taction scene export` for a mesh file (its name with `--` in it) and a built-in object.
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path(), "my--box");
    for (object, out) in [(mesh.to_str().unwrap(), "file"), ("pawn", "pawn")] {
        let xml = export_scene(object, &dir.path().join(out));
        let document = strictly_parsed(&xml, &format!("the scene exported for {object}"));
        let key = document
            .descendants()
            .find(|n| n.has_tag_name("key"))
            .unwrap_or_else(|| panic!("the scene exported for {object} has no keyframe"));
        assert_eq!(key.attribute("name"), Some("touch"));
    }
}

/// Arm bodies in contact with each other in `scene`'s current contacts, by name.
fn arm_on_arm(scene: &taction::sim::Scene) -> Vec<(String, String)> {
    let arm = scene.arm().expect("the scene has the arm");
    scene
        .contact_bodies()
        .into_iter()
        .filter(|&(a, b)| arm.owns_body(scene.model(), a) && arm.owns_body(scene.model(), b))
        .map(|(a, b)| (scene.body_name(a), scene.body_name(b)))
        .collect()
}

#[test]
fn no_two_arm_bodies_touch_in_the_shipped_or_a_built_scene() {
    let (mut shipped, _) = shipped_scene_at_touch();
    let mut built = taction::sim::SceneBuilder::with_arm_and_table()
        .object(taction::sim::ObjectSpec::new(
            "box",
            common::box_mesh(DVec3::splat(0.05)),
        ))
        .build()
        .unwrap();
    assert_eq!(arm_on_arm(&shipped), [], "at the keyframe 'touch'");
    // Home, and the arm turned, bent and folded, clear of itself, the table and the object.
    let configurations_deg: [[f64; 8]; 5] = [
        [0.0; 8],
        [90.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, -45.0, 0.0, 60.0, 0.0, 45.0, 0.0, 0.0],
        [-60.0, -30.0, 45.0, 60.0, -30.0, 30.0, 20.0, -20.0],
        [150.0, 20.0, -90.0, -40.0, 60.0, -70.0, -45.0, 80.0],
    ];
    for scene in [&mut shipped, &mut built] {
        let arm = scene.arm().cloned().unwrap();
        for q_deg in configurations_deg {
            let q: Vec<f64> = q_deg.iter().map(|d| d.to_radians()).collect();
            arm.teleport(scene, &q);
            assert_eq!(arm_on_arm(scene), [], "at {q_deg:?} deg");
        }
    }
}

#[test]
fn an_exported_scene_opens_at_its_touch_keyframe_with_the_pad_pressed_on_the_object() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path(), "box");
    let target = taction::control::ControlConfig::default().target_mean_pressure;
    for object in [mesh.to_str().unwrap(), "pawn"] {
        let out = dir.path().join(Path::new(object).file_stem().unwrap());
        export_scene(object, &out);
        ensure_registered();
        let model = MjModel::from_xml(out.join("scene.xml")).expect("the exported scene compiles");
        let key = model
            .name_to_id(MjtObjBase::mjOBJ_KEY, "touch")
            .unwrap_or_else(|| panic!("{object}: no keyframe 'touch'"));
        let mut scene = taction::sim::Scene::new(model, None).unwrap();
        scene.data_mut().reset_keyframe(key).unwrap();
        scene.forward();
        let sensor = CoveringSensor::first(scene.model()).unwrap();
        let image = sensor.read(scene.data()).unwrap();
        let pose = image.pose().unwrap();
        assert!(
            pose.normal.dot(DVec3::NEG_Z) > 0.9,
            "{object}: the pad looks down: {pose:?}"
        );
        assert!(
            (image.mean() - target).abs() <= 0.05 * target,
            "{object}: mean pressure {} at the keyframe, the controllers' target {target}",
            image.mean()
        );
        let arm = scene.arm().cloned().unwrap();
        assert_eq!(
            arm.collision(&scene),
            None,
            "{object}: the arm touches nothing rigid"
        );
        // The servos hold the pose: ctrl is the keyframe's joint angles.
        let q = arm.q(scene.data());
        let ctrl: Vec<f64> = arm
            .joints()
            .iter()
            .map(|j| scene.data().ctrl()[j.actuator])
            .collect();
        assert_eq!(q, ctrl, "{object}");
    }
}

/// `SceneBuilder::build` hands MuJoCo the object's mesh as numbers, not text (issue 39, large
/// meshes); the model must be the one the builder's MJCF text compiles to, to the last bit, even
/// where a coordinate lies exactly halfway between two single-precision values (the text rounds
/// to its own side there, a cast to even).
#[test]
fn a_built_scene_is_the_model_its_mjcf_text_compiles_to_bit_for_bit() {
    ensure_registered();
    let mut mesh = sensor_support::icosphere(DVec3::new(0.0, 0.0, 0.04), 0.04, 2);
    // Away from 0, where the tie would be a subnormal `strtof` refuses.
    let halfway = |x: f64| {
        let f = x as f32;
        if x.abs() < 1e-3 {
            x
        } else {
            (f64::from(f) + f64::from(f.next_up())) * 0.5
        }
    };
    for v in mesh.vertices.iter_mut().step_by(3) {
        *v = DVec3::new(halfway(v.x), halfway(v.y), v.z);
    }
    let ties_cast_to_even = mesh
        .vertices
        .iter()
        .filter(|v| {
            let text = taction::sim::numbers([v.x]);
            text.parse::<f32>().unwrap() != v.x as f32
        })
        .count();
    assert!(
        ties_cast_to_even > 0,
        "the mesh must hold ties the cast rounds otherwise"
    );
    let config = taction::valid::Valid::new(SensorConfig::default()).unwrap();
    let tied = taction::sim::ObjectSpec::new("tied", mesh.clone());
    for (builder, object) in [
        (taction::sim::SceneBuilder::with_arm_and_table(), &tied),
        (
            taction::tactile::free_floating_builder(tied.clone(), &config),
            &tied,
        ),
    ] {
        let builder = builder.object(object.clone());
        let built = builder.build().unwrap();
        let from_text = MjModel::from_xml_string(&builder.to_xml().unwrap()).unwrap();
        let bytes = |model: &MjModel| {
            let mut buffer = vec![0u8; model.size()];
            model.save_to_buffer(&mut buffer).unwrap();
            buffer
        };
        let differing = (built.model().mesh_vert().iter().flatten())
            .zip(from_text.mesh_vert().iter().flatten())
            .filter(|(a, b)| a.to_bits() != b.to_bits())
            .count();
        assert_eq!(differing, 0, "mesh coordinates differ");
        assert!(bytes(built.model()) == bytes(&from_text), "the MJB files differ");
    }
}

/// A large mesh: `build` gives MuJoCo a coarse copy and carries the exact surface as two numeric
/// fields; `to_xml`, whose text cannot carry them (MuJoCo refuses a `<numeric>` of more than a few
/// hundred values), writes the whole mesh, and its text compiles.
#[test]
fn a_large_mesh_is_a_copy_with_its_surface_when_built_and_whole_in_the_text() {
    ensure_registered();
    let sphere = sensor_support::icosphere(DVec3::new(0.0, 0.0, 0.04), 0.04, 5);
    let triangles = sphere.triangles.len();
    let config = taction::valid::Valid::new(SensorConfig::default()).unwrap();
    let large = taction::sim::ObjectSpec {
        large_mesh_triangles: 1_000,
        ..taction::sim::ObjectSpec::new("large", sphere)
    };
    let builder = taction::tactile::free_floating_builder(large, &config);
    let built = builder.build().unwrap();
    let from_text = MjModel::from_xml_string(&builder.to_xml().unwrap()).unwrap();
    let object_faces = |model: &MjModel| {
        let mesh = model.name_to_id(MjtObjBase::mjOBJ_MESH, "object").unwrap();
        model.mesh_facenum()[mesh] as usize
    };
    let (vertex_name, face_name) = taction::sim::sensed_surface_names("object");
    let numeric_size = |model: &MjModel, name: &str| {
        model
            .name_to_id(MjtObjBase::mjOBJ_NUMERIC, name)
            .map(|id| model.numeric_size()[id] as usize)
    };
    assert!(object_faces(built.model()) <= taction::sim::DRAWN_MESH_TRIANGLES);
    assert_eq!(numeric_size(built.model(), &face_name), Some(3 * triangles));
    assert!(numeric_size(built.model(), &vertex_name).is_some());
    assert_eq!(object_faces(&from_text), triangles);
    assert_eq!(numeric_size(&from_text, &face_name), None);
}
