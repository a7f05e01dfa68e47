//! Times the phases from a mesh file to the free pad's first reading (issue 39, large meshes), with
//! the process's peak memory after each: the object's build (parse, validate, face outward, size),
//! the pad's scene (the MJCF text with the collision shell, MuJoCo's compile of it with the mesh
//! handed over as numbers, the data, in which the sensor builds its BVH), the first reading; then,
//! apart, the sensor's BVH of the mesh alone (already inside the scene's time).
//!
//! `cargo run --release --example mesh_phases -- MESH.obj` (without a mesh: a 20,480-triangle sphere
//! 8 cm across, written to the temporary folder first).

#[path = "../tests/sensor_support/mod.rs"]
mod sensor_support;

use std::path::PathBuf;
use std::time::Instant;

use glam::DVec3;
use taction::control::FreePad;
use taction::mesh::{BuildOptions, ObjectSet};
use taction::pose::PadPose;
use taction::sim::ObjectSpec;
use taction::tactile::SensorConfig;
use taction::tactile::pipeline::MeshBvh;
use taction::valid::Valid;

/// The process's peak resident memory so far, MB (Linux's `VmHWM`; 0 elsewhere).
fn peak_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| {
            let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
            line.split_whitespace().nth(1)?.parse::<f64>().ok()
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = match std::env::args().nth(1) {
        Some(path) => PathBuf::from(path),
        None => {
            let path = std::env::temp_dir().join("taction-mesh-phases-sphere_20k.obj");
            let sphere = sensor_support::icosphere(DVec3::ZERO, 0.04, 5);
            taction::mesh::write_obj(&sphere, &path, "a sphere 8 cm across")?;
            path
        }
    };
    let start = Instant::now();
    let lap = |what: &str, since: &mut Instant| {
        eprintln!(
            "{what:<36} {:8.3} s   peak {:7.0} MB",
            since.elapsed().as_secs_f64(),
            peak_mb()
        );
        *since = Instant::now();
    };
    let mut t = Instant::now();
    let set = ObjectSet::resolve(&[path], None, None)?;
    let object = set.build(&BuildOptions::default())?.remove(0);
    eprintln!("{} triangles", object.mesh.triangles.len());
    lap("object build (parse..size)", &mut t);
    let config = Valid::new(SensorConfig::default())?;
    let spec = ObjectSpec::from(object);
    let (lo, hi) = spec.mesh.bounds().ok_or("empty mesh")?;
    let vertex_xyz: Vec<f32> = spec
        .mesh
        .vertices
        .iter()
        .flat_map(|v| v.as_vec3().to_array())
        .collect();
    let face: Vec<i32> = spec.mesh.triangles.iter().flatten().map(|&i| i as i32).collect();
    let mut t = Instant::now();
    let mut pad = FreePad::new(spec, &config)?;
    lap("pad scene (text, compile, BVH)", &mut t);
    let top = DVec3::new((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, hi.z - 0.001);
    let image = pad.read_at(&PadPose::new(top, DVec3::NEG_Z, DVec3::Y).ok_or("pad pose")?)?;
    lap("first reading", &mut t);
    eprintln!("file to first reading {:.3} s", start.elapsed().as_secs_f64());
    eprintln!("image sum {}", image.values().iter().sum::<f64>());
    drop(pad);
    let mut t = Instant::now();
    let bvh = MeshBvh::new(&vertex_xyz, &face)?;
    lap("of the scene: the sensor's BVH alone", &mut t);
    eprintln!("sensor BVH {:.0} MB on the heap", bvh.heap_bytes() as f64 / 1e6);
    Ok(())
}
