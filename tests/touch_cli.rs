//! `taction touch`: the surface contact controllers from the command line, free-floating and on the
//! arm, and its errors.

mod common;

use std::process::{Command, Output};

use glam::DVec3;
use serde_json::Value;

fn touch(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_taction"))
        .arg("touch")
        .args(args)
        .output()
        .unwrap()
}

/// A 6 cm box standing on z = 0 (top face at z = 0.06), written as OBJ.
fn box_file(dir: &std::path::Path) -> String {
    let path = dir.join("box.obj");
    taction::mesh::write_obj(&common::box_mesh(DVec3::splat(0.06)), &path, "box").unwrap();
    path.display().to_string()
}

/// The JSON report of a successful run.
fn report(out: &Output) -> Value {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(stdout.lines().count(), 1, "one JSON object on one line: {stdout}");
    serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

fn vec3(v: &Value) -> DVec3 {
    let a: Vec<f64> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(a.len(), 3, "{v}");
    DVec3::new(a[0], a[1], a[2])
}

/// The checks every converged touch of a box face with normal `face` must pass.
fn assert_settled_on_face(r: &Value, face: DVec3, rows: usize, cols: usize) {
    assert_eq!(r["status"], "converged", "{r}");
    let iterations = r["iterations"].as_u64().unwrap();
    assert!((1..=40).contains(&iterations), "{r}");
    let normal = vec3(&r["pad_normal"]);
    assert!(
        (normal.length() - 1.0).abs() < 1e-9,
        "pad_normal not unit: {normal}"
    );
    let angle = normal.angle_between(-face).to_degrees();
    assert!(angle < 2.0, "pad normal {angle:.2} deg off the face normal: {r}");
    let image: Vec<Vec<f64>> = serde_json::from_value(r["image"].clone()).unwrap();
    assert_eq!(image.len(), rows);
    assert!(image.iter().all(|row| row.len() == cols));
    let values: Vec<f64> = image.into_iter().flatten().collect();
    assert!(values.iter().all(|v| (0.0..=1.0).contains(v)), "{r}");
    // A face is flat under the whole pad: every taxel presses, none is clipped.
    assert!(values.iter().all(|&v| v > 0.05 && v < 0.95), "{r}");
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let reported = r["mean_pressure"].as_f64().unwrap();
    assert!((reported - mean).abs() < 1e-12);
    let target = taction::control::ControlConfig::default().target_mean_pressure;
    assert!(
        (mean - target).abs() <= 0.05 * target,
        "mean pressure {mean} vs target {target}"
    );
    // The pad's back sits about (1 - target) t in front of the face: inside its covering, outside
    // the box.
    let center = vec3(&r["pad_center"]);
    let t = 0.0012;
    let depth = 0.03 - (center - DVec3::new(0.0, 0.0, 0.03)).dot(face);
    assert!(
        depth < -0.1 * t && depth > -t,
        "pad centre {center} at depth {depth}"
    );
}

#[test]
fn the_free_pad_settles_on_a_box_face() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path());
    // The top face, approached from 4 mm above, 15 degrees off.
    let normal = DVec3::new(15f64.to_radians().sin(), 0.0, -15f64.to_radians().cos());
    let normal_text = format!("{},{},{}", normal.x, normal.y, normal.z);
    let r = report(&touch(&[
        "--mesh",
        &mesh,
        "--pad-center",
        "0.004,0.002,0.064",
        "--pad-normal",
        &normal_text,
    ]));
    assert_settled_on_face(&r, DVec3::Z, 6, 6);

    // A side face (+x), a non-square image, the pad's up given.
    let r = report(&touch(&[
        "--mesh",
        &mesh,
        "--pad-center",
        "0.034,-0.003,0.03",
        "--pad-normal",
        "-1,0.2,-0.1",
        "--pad-up",
        "0,0,1",
        "--rows",
        "4",
        "--cols",
        "5",
    ]));
    assert_settled_on_face(&r, DVec3::X, 4, 5);
}

#[test]
fn the_arm_settles_on_the_box_top() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path());
    let r = report(&touch(&[
        "--mesh",
        &mesh,
        "--pad-center",
        "0.005,0,0.066",
        "--pad-normal",
        "0.3,0,-1",
        "--arm",
    ]));
    assert_settled_on_face(&r, DVec3::Z, 6, 6);
}

#[test]
fn an_arm_touch_reports_its_joint_angles_and_replays_in_the_exported_scene() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path());
    let r = report(&touch(&[
        "--mesh",
        &mesh,
        "--pad-center",
        "0.008,0.004,0.066",
        "--pad-normal",
        "0.2,0.1,-1",
        "--arm",
    ]));
    assert_eq!(r["status"], "converged", "{r}");
    let joints: Vec<String> = serde_json::from_value(r["arm_joints"].clone()).unwrap();
    assert_eq!(joints, taction::sim::ARM_JOINTS);
    let q: Vec<f64> = serde_json::from_value(r["arm_q_rad"].clone()).unwrap();
    let image: Vec<f64> = serde_json::from_value::<Vec<Vec<f64>>>(r["image"].clone())
        .unwrap()
        .concat();

    // The scene MuJoCo's tools get for the same mesh, its qpos set to the reported angles.
    let out = dir.path().join("scene");
    let export = Command::new(env!("CARGO_BIN_EXE_taction"))
        .args(["scene", "export", "--object", &mesh, "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        export.status.success(),
        "{}",
        String::from_utf8_lossy(&export.stderr)
    );
    taction::tactile::ensure_registered();
    let model = mujoco_rs::prelude::MjModel::from_xml(out.join("scene.xml")).unwrap();
    let mut scene = taction::sim::Scene::new(model, None).unwrap();
    assert_eq!(
        scene.data().qpos().len(),
        q.len(),
        "the arm's joints are the whole qpos"
    );
    scene.data_mut().qpos_mut().copy_from_slice(&q);
    scene.forward();
    let sensor = taction::tactile::CoveringSensor::first(scene.model()).unwrap();
    let replayed = sensor.read(scene.data()).unwrap();
    let difference = replayed
        .values()
        .iter()
        .zip(&image)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        difference <= 1e-9,
        "replayed {:?}\nreported {image:?}",
        replayed.values()
    );
    let center = vec3(&r["pad_center"]);
    assert!((replayed.pose().unwrap().center_m - center).length() < 1e-9);

    // The free pad has no arm: no joint angles.
    let r = report(&touch(&[
        "--mesh",
        &mesh,
        "--pad-center",
        "0,0,0.064",
        "--pad-normal",
        "0,0,-1",
    ]));
    assert!(
        r.get("arm_q_rad").is_none() && r.get("arm_joints").is_none(),
        "{r}"
    );
}

#[test]
fn pointing_away_reports_no_contact_and_noise_is_seeded() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path());
    let r = report(&touch(&[
        "--mesh",
        &mesh,
        "--pad-center",
        "0,0,0.07",
        "--pad-normal",
        "0,0,1",
    ]));
    assert_eq!(r["status"], "no_contact", "{r}");
    assert_eq!(r["iterations"], 0);

    let noisy = |seed: &str| {
        touch(&[
            "--mesh",
            &mesh,
            "--pad-center",
            "0,0,0.064",
            "--pad-normal",
            "0,0,-1",
            "--noise",
            "0.2",
            "--seed",
            seed,
        ])
        .stdout
    };
    let a = noisy("3");
    assert!(!a.is_empty());
    assert_eq!(a, noisy("3"), "same seed, same output");
    assert_ne!(a, noisy("4"), "the seed drives the noise");
}

#[test]
fn bad_flags_give_one_line_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path());
    let control = dir.path().join("control.json");
    std::fs::write(&control, "{\"orient_stp\": 0.3}").unwrap();
    let control = control.display().to_string();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["--pad-center", "nan,0,0.07", "--pad-normal", "0,0,-1"],
            "--pad-center",
        ),
        (
            vec!["--pad-center", "0,0,inf", "--pad-normal", "0,0,-1"],
            "--pad-center",
        ),
        (
            vec!["--pad-center", "0,0,0.07", "--pad-normal", "0,0,0"],
            "--pad-normal",
        ),
        (
            vec![
                "--pad-center",
                "0,0,0.07",
                "--pad-normal",
                "0,0,-1",
                "--target-pressure",
                "1.5",
            ],
            "--target-pressure",
        ),
        (
            vec![
                "--pad-center",
                "0,0,0.07",
                "--pad-normal",
                "0,0,-1",
                "--target-pressure",
                "NaN",
            ],
            "--target-pressure",
        ),
        (
            vec![
                "--pad-center",
                "0,0,0.07",
                "--pad-normal",
                "0,0,-1",
                "--noise",
                "3",
            ],
            "--noise",
        ),
        (
            vec![
                "--pad-center",
                "0,0,0.07",
                "--pad-normal",
                "0,0,-1",
                "--rows",
                "0",
            ],
            "--rows",
        ),
        (
            vec![
                "--pad-center",
                "0,0,0.07",
                "--pad-normal",
                "0,0,-1",
                "--control",
                &control,
            ],
            "orient_stp",
        ),
        (
            vec!["--pad-center", "0.9,0,0.07", "--pad-normal", "0,0,-1", "--arm"],
            "--pad-center",
        ),
    ];
    for (extra, flag) in cases {
        let mut args = vec!["--mesh", mesh.as_str()];
        args.extend(extra);
        let out = touch(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} accepted");
        assert!(!stderr.contains("panicked"), "{stderr}");
        let first = stderr.lines().next().unwrap_or("");
        assert!(first.contains(flag), "{flag}: {stderr}");
        assert!(out.stdout.is_empty());
    }
    let out = touch(&[
        "--mesh",
        "/nonexistent/m.obj",
        "--pad-center",
        "0,0,0",
        "--pad-normal",
        "0,0,1",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("/nonexistent/m.obj") && stderr.lines().count() == 1,
        "{stderr}"
    );
}
