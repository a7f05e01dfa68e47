//! MuJoCo's own Python bindings load the plugin library and read the same images as the Rust side:
//! on a free-floating pad, on `mjcf/scene.xml` (the arm with the paper's sensor), and on a scene
//! `taction scene export` wrote; the README's Python block and `examples/python/read_tactile.py`
//! run exactly as written.
//!
//! Needs python3 with venv and pip. The venv (mujoco==3.17.0, matplotlib) is cached in
//! `target/sensor-python-venv`. When it cannot be made (PyPI unreachable) the tests say why and
//! pass without checking, except under CI (the `CI` variable set), where that is a failure.

mod sensor_support;

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::DVec3;
use sensor_support::{icosphere, pad_looking_down, shipped_scene_at_touch};
use taction::control::FreePad;
use taction::pose::PadPose;
use taction::sim::PAD_SITE;
use taction::sim::{IkOptions, InverseKinematics, ObjectSpec, PadTarget, SceneBuilder};
use taction::tactile::free_floating_builder;
use taction::tactile::{CoveringSensor, SensorConfig};
use taction::valid::Valid;

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"))
}

fn has_mujoco(python: &Path) -> bool {
    Command::new(python)
        .args([
            "-c",
            "import mujoco, matplotlib; assert mujoco.__version__ == '3.17.0'",
        ])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// A Python with mujoco 3.17.0, or why there is none.
fn python_with_mujoco() -> Result<PathBuf, String> {
    let venv = target_dir().join("sensor-python-venv");
    let python = venv.join("bin/python");
    if has_mujoco(&python) {
        return Ok(python);
    }
    // The tests of this file run in parallel threads (or processes, under nextest); one of them
    // makes the venv while the others wait on this lock, then find it made. Without it, concurrent
    // `pip install`s into one venv fail each other.
    std::fs::create_dir_all(target_dir()).map_err(|e| format!("{}: {e}", target_dir().display()))?;
    let lock_path = target_dir().join("sensor-python-venv.lock");
    let lock = std::fs::File::create(&lock_path).map_err(|e| format!("{}: {e}", lock_path.display()))?;
    lock.lock()
        .map_err(|e| format!("locking {}: {e}", lock_path.display()))?;
    if has_mujoco(&python) {
        return Ok(python);
    }
    let made = Command::new("python3")
        .arg("-m")
        .arg("venv")
        .arg(&venv)
        .output()
        .map_err(|e| format!("python3: {e}"))?;
    if !made.status.success() {
        return Err(format!(
            "python3 -m venv failed: {}",
            String::from_utf8_lossy(&made.stderr)
        ));
    }
    // The wheel `cargo xtask setup` downloaded, if present, saves fetching it again.
    let wheel = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(".runtime/download/mujoco-3.17.0-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl");
    let spec = if wheel.exists() && python_is_311(&python) {
        wheel.display().to_string()
    } else {
        "mujoco==3.17.0".into()
    };
    let pip = Command::new(&python)
        .args(["-m", "pip", "install", "-q", &spec, "matplotlib"])
        .output()
        .map_err(|e| format!("pip: {e}"))?;
    if !pip.status.success() || !has_mujoco(&python) {
        return Err(format!(
            "pip install mujoco==3.17.0 matplotlib failed ({}): {}{}",
            pip.status,
            String::from_utf8_lossy(&pip.stdout),
            String::from_utf8_lossy(&pip.stderr)
        ));
    }
    Ok(python)
}

fn python_is_311(python: &Path) -> bool {
    Command::new(python)
        .args(["-c", "import sys; assert sys.version_info[:2] == (3, 11)"])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// A Python with mujoco 3.17.0, or `None` after saying why there is none; under CI a missing
/// Python is a failure, so that these tests really run there.
fn python_or_skip() -> Option<PathBuf> {
    match python_with_mujoco() {
        Ok(python) => Some(python),
        Err(why) if std::env::var_os("CI").is_some() => {
            panic!("CI is set but no Python with mujoco 3.17.0 could be made: {why}")
        }
        Err(why) => {
            println!("skipped: no Python with mujoco 3.17.0 ({why})");
            None
        }
    }
}

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The plugin library as the README has users find it: built in release (as `cargo xtask setup`
/// does; nothing to do when it is up to date), its path printed by `taction plugin-path`.
fn plugin_library() -> PathBuf {
    let out = Command::new(env!("CARGO"))
        .args(["build", "--release", "--quiet", "-p", "taction-plugin"])
        .current_dir(repo())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "building the plugin library: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = Command::new(env!("CARGO_BIN_EXE_taction"))
        .arg("plugin-path")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "taction plugin-path: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lib = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    assert_eq!(
        lib,
        target_dir()
            .join("release/libtaction_covering.so")
            .canonicalize()
            .unwrap()
    );
    lib
}

/// Runs `python` on `script` (a file) with `args` in `cwd`; its stdout, or a panic with both streams.
fn run_python(python: &Path, cwd: &Path, script: &Path, args: &[&std::ffi::OsStr]) -> String {
    let out = Command::new(python)
        .arg(script)
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{}: {stdout}\n{}",
        script.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Comma-separated floats of one output line.
fn floats(line: &str) -> Vec<f64> {
    line.split(',').map(|v| v.trim().parse().unwrap()).collect()
}

const SCRIPT: &str = r#"
import sys, mujoco
lib, xml_path, pos, quat, bad_xml_path = sys.argv[1:6]
mujoco.mj_loadPluginLibrary(lib)
m = mujoco.MjModel.from_xml_path(xml_path)
d = mujoco.MjData(m)
d.mocap_pos[1] = [float(v) for v in pos.split(',')]
d.mocap_quat[1] = [float(v) for v in quat.split(',')]
mujoco.mj_forward(m, d)
print(','.join(repr(float(v)) for v in d.sensordata))
try:
    mujoco.MjModel.from_xml_path(bad_xml_path)
    print('compiled')
except ValueError as e:
    print(str(e).replace('\n', ' '))
"#;

#[test]
fn python_loads_the_plugin_and_reads_the_same_image() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let lib = plugin_library();
    let config = SensorConfig {
        rows: 14,
        cols: 14,
        noise_fraction: 0.1,
        noise_seed: 4,
        ..SensorConfig::default()
    };
    let object = ObjectSpec::new("ball", icosphere(DVec3::ZERO, 0.01, 3));
    let pose: PadPose = pad_looking_down(DVec3::new(0.001, 0.0, 0.0102));
    let config = Valid::new(config).unwrap();
    let mut sensor = FreePad::new(object.clone(), &config).unwrap();
    sensor.place(&pose);
    // Python's MjData runs mj_forward once, as the Rust scene did when it was built; read the second.
    let rust = sensor.read().unwrap();

    let dir = tempfile::tempdir().unwrap();
    let xml = free_floating_builder(object.clone(), &config).to_xml().unwrap();
    std::fs::write(dir.path().join("scene.xml"), &xml).unwrap();
    let bad = xml.replace(
        "key=\"rays_per_taxel\" value=\"4\"",
        "key=\"rays_per_taxel\" value=\"5\"",
    );
    assert_ne!(bad, xml);
    std::fs::write(dir.path().join("bad.xml"), bad).unwrap();
    std::fs::write(dir.path().join("check.py"), SCRIPT).unwrap();
    let q = pose.site_rotation();
    let pos = format!("{},{},{}", pose.center_m.x, pose.center_m.y, pose.center_m.z);
    let quat = format!("{},{},{},{}", q.w, q.x, q.y, q.z);
    let out = Command::new(&python)
        .arg(dir.path().join("check.py"))
        .arg(&lib)
        .arg(dir.path().join("scene.xml"))
        .arg(&pos)
        .arg(&quat)
        .arg(dir.path().join("bad.xml"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut lines = stdout.lines();
    let values: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(values.len(), 196);
    assert!(rust.max() > 0.2);
    // The first mj_forward of Python's MjData is reading 0 (noise stream 0); Rust's scene read
    // reading 1 above, so compare the noise-free structure and the exact noise of reading 0 apart.
    let mut first = FreePad::new(object, &config).unwrap();
    let handle = first.covering().clone();
    first.place(&pose);
    first.scene_mut().data_mut().reset();
    let data = first.scene_mut().data_mut();
    data.mocap_pos_mut()[1] = pose.center_m.to_array();
    data.mocap_quat_mut()[1] = [q.w, q.x, q.y, q.z];
    data.forward();
    let reading0 = handle.read(first.scene().data()).unwrap();
    assert_eq!(values, reading0.values(), "Python and Rust read different images");
    let error = lines.next().unwrap_or("");
    assert!(
        error.contains("rays_per_taxel=5") && error.contains("perfect square"),
        "{error}"
    );
}

/// Loads a model, sets `qpos`, runs mj_forward; prints `sensordata`, then how many taxel boxes the
/// plugin's visualize callback added to a fresh `MjvScene` for the sensor named "tactile".
const QPOS_SCRIPT: &str = r#"
import sys, mujoco
lib, xml_path, qpos = sys.argv[1:4]
mujoco.mj_loadPluginLibrary(lib)
m = mujoco.MjModel.from_xml_path(xml_path)
d = mujoco.MjData(m)
d.qpos[:] = [float(v) for v in qpos.split(',')]
mujoco.mj_forward(m, d)
print(','.join(repr(float(v)) for v in d.sensordata))
scn = mujoco.MjvScene(m, maxgeom=5000)
mujoco.mjv_updateScene(m, d, mujoco.MjvOption(), mujoco.MjvPerturb(), mujoco.MjvCamera(),
                       int(mujoco.mjtCatBit.mjCAT_ALL), scn)
sensor = m.sensor('tactile').id
print(sum(1 for i in range(scn.ngeom)
          if scn.geoms[i].objtype == int(mujoco.mjtObj.mjOBJ_UNKNOWN)
          and scn.geoms[i].objid == sensor
          and scn.geoms[i].category == int(mujoco.mjtCatBit.mjCAT_DECOR)))
"#;

/// Python's `sensordata` and taxel-box count for `xml` at `qpos`.
fn python_reading(python: &Path, lib: &Path, xml: &Path, qpos: &[f64]) -> (Vec<f64>, usize) {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("qpos.py");
    std::fs::write(&script, QPOS_SCRIPT).unwrap();
    let qpos = qpos
        .iter()
        .map(|v| format!("{v:?}"))
        .collect::<Vec<_>>()
        .join(",");
    let stdout = run_python(
        python,
        dir.path(),
        &script,
        &[lib.as_os_str(), xml.as_os_str(), std::ffi::OsStr::new(&qpos)],
    );
    let mut lines = stdout.lines();
    let values = floats(lines.next().unwrap_or(""));
    let tiles = lines.next().unwrap_or("").trim().parse().unwrap();
    (values, tiles)
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

#[test]
fn python_reads_the_shipped_scene_as_rust_does_for_the_same_qpos() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let lib = plugin_library();
    let (mut scene, sensor) = shipped_scene_at_touch();
    // The keyframe, and the forearm turned 2 mrad back up: the pad tilts, slides 0.4 mm off the
    // cylinder's centre and presses 0.08 mm deeper.
    let forearm_y = 5;
    let mut previous: Option<Vec<f64>> = None;
    for tilt_rad in [0.0, -0.002] {
        scene.data_mut().qpos_mut()[forearm_y] += tilt_rad;
        scene.forward();
        let qpos = scene.data().qpos().to_vec();
        let rust = scene.data().sensordata().to_vec();
        assert_ne!(
            previous.replace(rust.clone()),
            Some(rust.clone()),
            "the tilt changes the image"
        );
        let image = sensor.read(scene.data()).unwrap();
        assert!(image.max() > 0.3 && image.values().iter().all(|v| (0.0..=1.0).contains(v)));
        let (values, tiles) = python_reading(&python, &lib, &repo().join("mjcf/scene.xml"), &qpos);
        let difference = max_difference(&values, &rust);
        println!("tilt {tilt_rad} rad: Python vs Rust sensordata, largest difference {difference:e}");
        assert!(difference <= 1e-6, "Python {values:?}\nRust {rust:?}");
        assert_eq!(
            tiles, 36,
            "the plugin draws one box per taxel in Python's MjvScene"
        );
    }
}

#[test]
fn python_reads_an_exported_scene_as_the_rust_scene_builder_does() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let lib = plugin_library();
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args([
            "scene", "export", "--object", "pawn", "--rows", "8", "--cols", "8",
        ])
        .args(["--thickness-m", "0.002", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    // The same scene from the builder (mesh inline), the arm's pad pressed onto the pawn's top.
    let config = SensorConfig {
        rows: 8,
        cols: 8,
        thickness_m: 0.002,
        psf_sigma_m: taction::tactile::psf_sigma_for_thickness(0.002),
        ..SensorConfig::default()
    };
    let pawn = taction::mesh::ObjectSet::chess()
        .build_object("pawn", &taction::mesh::BuildOptions::default())
        .unwrap();
    let top_z_m = pawn.mesh.bounds().unwrap().1.z;
    let builder = SceneBuilder::with_arm_and_table().object(ObjectSpec::new("pawn", pawn.mesh));
    let mut scene = taction::tactile::add_sensor(builder, &Valid::new(config).unwrap(), PAD_SITE)
        .build()
        .unwrap();
    let arm = scene.arm().cloned().unwrap();
    let mut ik = InverseKinematics::new(scene.model_arc(), arm.clone(), IkOptions::default());
    let target = PadTarget {
        center_m: DVec3::new(0.0, 0.0, top_z_m + 0.001),
        normal: DVec3::NEG_Z,
    };
    let q = ik.solve(&target, &arm.q(scene.data())).unwrap();
    arm.teleport(&mut scene, &q);
    scene.forward();
    let sensor = CoveringSensor::first(scene.model()).unwrap();
    let image = sensor.read(scene.data()).unwrap();
    assert!(image.max() > 0.2, "{:?}", image.values());
    let rust = scene.data().sensordata().to_vec();
    let qpos = scene.data().qpos().to_vec();

    let (values, tiles) = python_reading(&python, &lib, &dir.path().join("scene.xml"), &qpos);
    let difference = max_difference(&values, &rust);
    println!("exported pawn: Python vs Rust sensordata, largest difference {difference:e}");
    assert!(difference <= 1e-6, "Python {values:?}\nRust {rust:?}");
    assert_eq!(tiles, 64);
}

/// The first ```python block of README.md's section `heading`.
fn readme_python_block(heading: &str) -> String {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let section = &readme[readme.find(heading).expect("README section")..];
    let start = section.find("```python\n").expect("a python block") + "```python\n".len();
    let end = section[start..].find("```").unwrap();
    section[start..start + end].to_string()
}

/// Rows of space-separated numbers, as the README block and the example print the image.
fn printed_image(stdout: &str) -> Vec<Vec<f64>> {
    stdout
        .lines()
        .filter(|l| l.split_whitespace().all(|w| w.parse::<f64>().is_ok()) && !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|w| w.parse().unwrap()).collect())
        .collect()
}

fn assert_is_the_touch_image(printed: &[Vec<f64>], decimals: i32) {
    let (scene, sensor) = shipped_scene_at_touch();
    let rust = sensor.read(scene.data()).unwrap();
    assert_eq!(printed.len(), 6, "{printed:?}");
    let flat: Vec<f64> = printed.iter().flatten().copied().collect();
    assert_eq!(flat.len(), 36, "{printed:?}");
    assert!(flat.iter().all(|v| (0.0..=1.0).contains(v)) && flat.iter().any(|&v| v > 0.0));
    let tolerance = 0.5 * 10f64.powi(-decimals) + 1e-12;
    assert!(
        max_difference(&flat, rust.values()) <= tolerance,
        "{flat:?}\n{:?}",
        rust.values()
    );
}

#[test]
fn the_readme_python_block_runs_as_written() {
    let Some(python) = python_or_skip() else {
        return;
    };
    plugin_library();
    let block = readme_python_block("### In MuJoCo");
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("readme_block.py");
    std::fs::write(&script, &block).unwrap();
    // The README runs it from the repository root.
    let stdout = run_python(&python, repo(), &script, &[]);
    assert_is_the_touch_image(&printed_image(&stdout), 3);
}

#[test]
fn the_python_example_saves_the_image_as_a_png() {
    let Some(python) = python_or_skip() else {
        return;
    };
    plugin_library();
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("tactile.png");
    let stdout = run_python(
        &python,
        dir.path(),
        &repo().join("examples/python/read_tactile.py"),
        &[std::ffi::OsStr::new("--out"), png.as_os_str()],
    );
    assert_is_the_touch_image(&printed_image(&stdout), 4);
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
}

/// Parses files with Python's strict `xml.etree` (what dm_control's `mjcf` reads MJCF with); loads
/// an exported scene, puts it at its keyframe `touch`, then at the joint angles `taction touch
/// --arm` reported; prints `sensordata` for each.
const KEYFRAME_SCRIPT: &str = r#"
import sys, mujoco, xml.etree.ElementTree as ET
lib, xml_path, arm_q = sys.argv[1], sys.argv[2], sys.argv[3]
for path in sys.argv[4:]:
    ET.parse(path)
mujoco.mj_loadPluginLibrary(lib)
m = mujoco.MjModel.from_xml_path(xml_path)
d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, m.key("touch").id)
mujoco.mj_forward(m, d)
print(','.join(repr(float(v)) for v in d.sensordata))
d.qpos[:] = [float(v) for v in arm_q.split(',')]
mujoco.mj_forward(m, d)
print(','.join(repr(float(v)) for v in d.sensordata))
"#;

#[test]
fn python_parses_the_mjcf_strictly_opens_an_export_at_its_touch_keyframe_and_replays_an_arm_touch() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let lib = plugin_library();
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("ball.obj");
    taction::mesh::write_obj(&icosphere(DVec3::new(0.0, 0.0, 0.03), 0.03, 3), &mesh, "ball").unwrap();
    let mesh_arg = mesh.to_str().unwrap();
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_taction"))
            .args(args)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let out = dir.path().join("scene");
    run(&[
        "scene",
        "export",
        "--object",
        mesh_arg,
        "--out",
        out.to_str().unwrap(),
    ]);
    let touch: serde_json::Value = serde_json::from_str(&run(&[
        "touch",
        "--mesh",
        mesh_arg,
        "--arm",
        "--pad-center",
        "0.004,0.002,0.066",
        "--pad-normal",
        "0.1,0,-1",
    ]))
    .unwrap();
    assert_eq!(touch["status"], "converged", "{touch}");
    let arm_q: Vec<f64> = serde_json::from_value(touch["arm_q_rad"].clone()).unwrap();
    let image: Vec<f64> = serde_json::from_value::<Vec<Vec<f64>>>(touch["image"].clone())
        .unwrap()
        .concat();

    // The same keyframe in the Rust scene builder's world.
    taction::tactile::ensure_registered();
    let model = mujoco_rs::prelude::MjModel::from_xml(out.join("scene.xml")).unwrap();
    let key = model
        .name_to_id(mujoco_rs::prelude::MjtObjBase::mjOBJ_KEY, "touch")
        .unwrap();
    let mut scene = taction::sim::Scene::new(model, None).unwrap();
    scene.data_mut().reset_keyframe(key).unwrap();
    scene.forward();
    let at_key = scene.data().sensordata().to_vec();
    assert!(at_key.iter().any(|&v| v > 0.2), "{at_key:?}");

    let script = dir.path().join("keyframe.py");
    std::fs::write(&script, KEYFRAME_SCRIPT).unwrap();
    let arm_q_text = arm_q
        .iter()
        .map(|v| format!("{v:?}"))
        .collect::<Vec<_>>()
        .join(",");
    let mut args: Vec<std::ffi::OsString> = vec![
        lib.into(),
        out.join("scene.xml").into(),
        arm_q_text.into(),
        out.join("scene.xml").into(),
    ];
    for entry in std::fs::read_dir(repo().join("mjcf")).unwrap() {
        args.push(entry.unwrap().path().into());
    }
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let stdout = run_python(&python, dir.path(), &script, &args);
    let mut lines = stdout.lines();
    let keyframe = floats(lines.next().unwrap_or(""));
    assert!(
        max_difference(&keyframe, &at_key) <= 1e-6,
        "Python {keyframe:?}\nRust {at_key:?}"
    );
    let replayed = floats(lines.next().unwrap_or(""));
    assert!(
        max_difference(&replayed, &image) <= 1e-6,
        "Python {replayed:?}\ntouch {image:?}"
    );
}
