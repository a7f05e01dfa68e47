//! `taction sense`: one raw reading from the command line.

mod sensor_support;

use std::process::Command;

use glam::DVec3;
use sensor_support::box_between;
use taction::tactile::TactileImage;

fn sense(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_taction"))
        .arg("sense")
        .args(args)
        .output()
        .unwrap()
}

/// A box mesh file whose top face is the plane z = 0.
fn box_file(dir: &std::path::Path) -> String {
    let path = dir.join("slab.obj");
    let mesh = box_between(DVec3::new(-0.03, -0.03, -0.02), DVec3::new(0.03, 0.03, 0.0));
    taction::mesh::write_obj(&mesh, &path, "slab").unwrap();
    path.display().to_string()
}

#[test]
fn sense_writes_the_reading_as_csv_and_png() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path());
    let csv = dir.path().join("r.csv");
    // Pad 0.4 mm above the top face, looking down; 1 mm covering: every taxel reads 0.6.
    let out = sense(&[
        "--mesh",
        &mesh,
        "--pad-center",
        "0.001,-0.002,0.0004",
        "--pad-normal",
        "0,0,-1",
        "--rows",
        "4",
        "--cols",
        "5",
        "--thickness-m",
        "0.001",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let image = TactileImage::read_csv(&csv).unwrap();
    assert_eq!((image.rows(), image.cols()), (4, 5));
    assert!(image.values().iter().all(|v| (v - 0.6).abs() < 1e-6), "{image}");

    let png = dir.path().join("r.png");
    let out = sense(&[
        "--mesh",
        &mesh,
        "--pad-center",
        "0,0,-0.0003",
        "--pad-normal",
        "0,0,-2",
        "--pad-up",
        "1,0,0",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
}

/// A rectangular pad 16 mm wide and 4 mm high, its centre over the slab's edge at x = 0.03: the
/// half of its 8 columns (2 mm apart) over the slab read the covering's 0.6, the other half 0,
/// and both of its rows alike. A square pad of either side would read another image.
#[test]
fn a_rectangular_pad_reads_its_width_along_a_row_and_its_height_along_a_column() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path());
    let csv = dir.path().join("r.csv");
    let out = sense(&[
        "--mesh",
        &mesh,
        "--pad-center",
        "0.03,0,0.0004",
        "--pad-normal",
        "0,0,-1",
        "--pad-up",
        "0,1,0",
        "--rows",
        "2",
        "--cols",
        "8",
        "--pad-width-m",
        "0.016",
        "--pad-height-m",
        "0.004",
        "--thickness-m",
        "0.001",
        "--psf-sigma-m",
        "0",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let image = TactileImage::read_csv(&csv).unwrap();
    assert_eq!((image.rows(), image.cols()), (2, 8));
    for row in 0..2 {
        let values: Vec<f64> = (0..8).map(|col| image.get(row, col)).collect();
        let on_slab = values.iter().filter(|v| (**v - 0.6).abs() < 1e-6).count();
        let off_slab = values.iter().filter(|v| v.abs() < 1e-12).count();
        assert_eq!((on_slab, off_slab), (4, 4), "row {row}: {values:?}");
        assert_eq!(
            values[0] == 0.0,
            values[7] != 0.0,
            "row {row}: one side each: {values:?}"
        );
    }
}

#[test]
fn bad_flags_give_one_line_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = box_file(dir.path());
    let out_csv = dir.path().join("r.csv");
    let out_csv = out_csv.to_str().unwrap();
    let base = [
        "--mesh",
        mesh.as_str(),
        "--pad-center",
        "0,0,0.001",
        "--pad-normal",
        "0,0,-1",
    ];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--rows", "0", "--out", out_csv], "--rows"),
        (
            vec!["--rays-per-taxel", "3", "--out", out_csv],
            "--rays-per-taxel",
        ),
        (vec!["--thickness-m", "-0.001", "--out", out_csv], "--thickness-m"),
        (vec!["--noise", "5", "--out", out_csv], "--noise"),
        (vec!["--pad-m", "0", "--out", out_csv], "--pad-m"),
        (vec!["--pad-width-m", "0", "--out", out_csv], "--pad-width-m"),
        (vec!["--pad-height-m", "-1", "--out", out_csv], "--pad-height-m"),
        (
            vec![
                "--pad-height-m",
                "0.002",
                "--thickness-m",
                "0.0015",
                "--out",
                out_csv,
            ],
            "--thickness-m",
        ),
        (vec!["--pad-up", "0,0,3", "--out", out_csv], "--pad-up"),
        (vec!["--out", "reading.txt"], "--out"),
        (vec!["--pad-center", "1,2", "--out", out_csv], "--pad-center"),
    ];
    for (extra, flag) in cases {
        let mut args: Vec<&str> = base.to_vec();
        // A later --pad-center overrides the base one only if clap allows; give it alone instead.
        if extra.contains(&"--pad-center") {
            args.truncate(2);
            args.extend_from_slice(&["--pad-normal", "0,0,-1"]);
        }
        args.extend(extra);
        let out = sense(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{flag} accepted");
        let first = stderr.lines().next().unwrap_or("");
        assert!(first.contains(flag), "{flag}: {stderr}");
    }
    let out = sense(&[
        "--mesh",
        "/nonexistent/m.obj",
        "--pad-center",
        "0,0,0",
        "--pad-normal",
        "0,0,1",
        "--out",
        out_csv,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("/nonexistent/m.obj") && stderr.lines().count() == 1,
        "{stderr}"
    );
}

#[test]
fn an_inward_wound_mesh_is_reversed_so_inside_still_reads_full() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("inverted.obj");
    let mesh = box_between(DVec3::new(-0.03, -0.03, -0.02), DVec3::new(0.03, 0.03, 0.0)).flipped();
    taction::mesh::write_obj(&mesh, &path, "inverted slab").unwrap();
    let csv = dir.path().join("r.csv");
    // The pad 0.5 mm inside the box: every pad point is inside the solid.
    let out = sense(&[
        "--mesh",
        path.to_str().unwrap(),
        "--pad-center",
        "0,0,-0.0005",
        "--pad-normal",
        "0,0,-1",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("reversed"));
    let image = TactileImage::read_csv(&csv).unwrap();
    assert!(image.values().iter().all(|&v| v == 1.0), "{image}");
}
