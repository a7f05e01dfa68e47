//! The covering sensor's images pinned on three meshes (a smooth icosphere, a box with sharp edges
//! pushed through the pad, and the CGAL fandisk), several resolutions, ray counts, point-spreads and
//! noise: any change to the reading path must reproduce them within 1e-6.
//!
//! The fixtures in `tests/sensor_golden/` were captured from the sensor before its reading was
//! optimised. `TACTION_WRITE_GOLDEN=1 cargo test --test sensor_golden` rewrites them from the code
//! as it is (only for a deliberate change of the sensor model).

mod sensor_support;

use std::fmt::Write as _;
use std::path::PathBuf;

use glam::DVec3;
use sensor_support::{box_between, icosphere};
use taction::control::FreePad;
use taction::mesh::TriMesh;
use taction::mesh::{cgal_mesh, ensure_fetched};
use taction::pose::PadPose;
use taction::sim::ObjectSpec;
use taction::tactile::{SensorConfig, psf_sigma_for_thickness};
use taction::valid::Valid;

const TOLERANCE: f64 = 1e-6;

fn fixture_path(mesh: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/sensor_golden")
        .join(format!("{mesh}.csv"))
}

/// The configurations read on every mesh: the paper's three resolutions, 1, 4 and 16 rays per
/// taxel, with and without the point-spread, one with noise (which must keep its stream).
fn configs() -> Vec<(&'static str, SensorConfig)> {
    let base = SensorConfig::default();
    vec![
        ("6x6x4", base),
        (
            "6x6x1_sharp",
            SensorConfig {
                rays_per_taxel: 1,
                psf_sigma_m: 0.0,
                ..base
            },
        ),
        (
            "14x14x16",
            SensorConfig {
                rows: 14,
                cols: 14,
                rays_per_taxel: 16,
                ..base
            },
        ),
        (
            "26x26x4_thick",
            SensorConfig {
                rows: 26,
                cols: 26,
                thickness_m: 0.003,
                psf_sigma_m: psf_sigma_for_thickness(0.003),
                ..base
            },
        ),
        (
            "14x8x9_noise",
            SensorConfig {
                rows: 14,
                cols: 8,
                pad_height_m: 0.02,
                rays_per_taxel: 9,
                noise_fraction: 0.1,
                noise_seed: 5,
                ..base
            },
        ),
    ]
}

/// Pads pressed `depth` covering thicknesses into the mesh at its extreme point along each
/// direction (outward), offset sideways, turned about the normal.
fn poses(mesh: &TriMesh, config: &SensorConfig) -> Vec<(String, PadPose)> {
    let presses = [
        (DVec3::new(0.0, 0.0, 1.0), DVec3::Y, 0.5, DVec3::ZERO),
        (
            DVec3::new(0.3, -0.2, 1.0),
            DVec3::new(1.0, 1.0, 0.0),
            0.8,
            DVec3::new(0.002, 0.001, 0.0),
        ),
        (
            DVec3::new(1.0, 0.4, -0.2),
            DVec3::Z,
            1.6,
            DVec3::new(0.0, -0.003, 0.001),
        ),
        (DVec3::new(-0.5, -1.0, 0.3), DVec3::X, 0.3, DVec3::ZERO),
    ];
    presses
        .iter()
        .enumerate()
        .map(|(k, &(outward, up, depth, shift))| {
            let d = outward.normalize();
            let reach = mesh
                .vertices
                .iter()
                .map(|v| v.dot(d))
                .fold(f64::NEG_INFINITY, f64::max);
            let extreme = mesh
                .vertices
                .iter()
                .copied()
                .find(|v| v.dot(d) == reach)
                .unwrap_or(DVec3::ZERO);
            // The pad plane sits `depth * t` inside the extreme point, centred over it.
            let on_plane = extreme - d * (extreme.dot(d) - reach) + shift;
            let center = on_plane - d * (depth * config.thickness_m);
            (format!("press{k}"), PadPose::new(center, -d, up).unwrap())
        })
        .collect()
}

fn meshes() -> Vec<(&'static str, TriMesh)> {
    let cache = ensure_fetched().unwrap();
    let fandisk = cache.load(cgal_mesh("fandisk").unwrap()).unwrap().mesh;
    let (lo, hi) = fandisk.bounds().unwrap();
    let fandisk = fandisk
        .translated(-(lo + hi) * 0.5)
        .scaled(0.08 / (hi - lo).length());
    vec![
        ("icosphere", icosphere(DVec3::ZERO, 0.03, 4)),
        (
            "box",
            box_between(DVec3::new(-0.02, -0.015, -0.01), DVec3::new(0.02, 0.015, 0.01)),
        ),
        ("fandisk", fandisk),
    ]
}

/// `case,value,value,...` lines, one per (config, pose), in the order read.
fn read_all(name: &str, mesh: &TriMesh) -> String {
    let mut out = String::new();
    for (config_name, config) in configs() {
        let mut sensor =
            FreePad::new(ObjectSpec::new(name, mesh.clone()), &Valid::new(config).unwrap()).unwrap();
        for (pose_name, pose) in poses(mesh, &config) {
            // Two readings at each pose: the second continues the noise stream.
            for reading in 0..2 {
                let image = sensor.read_at(&pose).unwrap();
                write!(out, "{config_name}/{pose_name}/{reading}").unwrap();
                for v in image.values() {
                    write!(out, ",{v:?}").unwrap();
                }
                out.push('\n');
            }
        }
    }
    out
}

fn parse(text: &str) -> Vec<(String, Vec<f64>)> {
    text.lines()
        .map(|line| {
            let mut fields = line.split(',');
            let case = fields.next().unwrap_or_default().to_string();
            let values = fields
                .map(|f| {
                    f.parse()
                        .unwrap_or_else(|e| panic!("{case}: bad value {f:?}: {e}"))
                })
                .collect();
            (case, values)
        })
        .collect()
}

#[test]
fn images_match_the_pinned_fixtures() {
    let write = std::env::var_os("TACTION_WRITE_GOLDEN").is_some();
    let mut touched = 0usize;
    for (name, mesh) in meshes() {
        let got = read_all(name, &mesh);
        let path = fixture_path(name);
        if write {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, &got).unwrap();
            continue;
        }
        let want = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let (got, want) = (parse(&got), parse(&want));
        assert_eq!(got.len(), want.len(), "{name}: number of cases");
        for ((case, g), (want_case, w)) in got.iter().zip(&want) {
            assert_eq!(case, want_case, "{name}");
            assert_eq!(g.len(), w.len(), "{name} {case}");
            let worst = g.iter().zip(w).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(worst <= TOLERANCE, "{name} {case}: differs by {worst:e}");
            touched += w.iter().any(|&v| v > 0.0) as usize;
        }
    }
    // The fixtures must exercise contact, not empty images.
    assert!(write || touched >= 100, "only {touched} images with contact");
}
