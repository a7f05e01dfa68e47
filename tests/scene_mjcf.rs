//! `mjcf/scene.xml` (the world with the paper's sensor on the pad), the plugin's taxel drawing in
//! MuJoCo's visual scene, `taction scene export` and `taction plugin-path`, on the Rust side.
//! tests/sensor_python.rs checks the same files through MuJoCo's official Python bindings.

mod sensor_support;

use std::path::PathBuf;
use std::process::Command;

use glam::{DMat3, DVec3};
use mujoco_rs::mujoco_c::{mjtCatBit, mjtGeom, mjtObj};
use mujoco_rs::prelude::*;
use sensor_support::shipped_scene_at_touch;
use taction::tactile::plugin::{taxel_rgba, taxel_tiles};
use taction::tactile::{CoveringSensor, SensorConfig, ensure_registered};

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
    let built = taction::tactile::add_sensor(builder, sensor.config(), "tactile", "pad")
        .unwrap()
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
