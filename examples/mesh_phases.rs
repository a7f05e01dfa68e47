//! Times the phases from a mesh file to the free pad's first reading (issue 39, large meshes): the
//! object's build (parse, validate, face outward, size), the scene's MJCF text (with the collision
//! shell), MuJoCo's compile, the data (the sensor's BVH is built there), the first reading.
//!
//! `cargo run --release --example mesh_phases -- MESH.obj` (without a mesh: a 20,480-triangle sphere
//! 8 cm across, written to the temporary folder first); run it under `/usr/bin/time -v` for the
//! peak memory.

#[path = "../tests/sensor_support/mod.rs"]
mod sensor_support;

use std::path::PathBuf;
use std::time::Instant;

use glam::DVec3;
use mujoco_rs::prelude::{MjData, MjModel};
use taction::control::FreePad;
use taction::mesh::TriMesh;
use taction::mesh::{BuildOptions, ObjectSet};
use taction::pose::PadPose;
use taction::sim::{ObjectSpec, numbers};
use taction::tactile::{SensorConfig, free_floating_builder};
use taction::valid::Valid;

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
    let lap = |what: &str, since: &mut Instant| {
        eprintln!("{what:<28} {:8.3} s", since.elapsed().as_secs_f64());
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
    let builder = free_floating_builder(spec.clone(), &config);
    let xml = builder.to_xml()?;
    eprintln!("MJCF {} MB", xml.len() / 1_000_000);
    lap("MJCF text (with shell)", &mut t);
    let model = MjModel::from_xml_string(&xml)?;
    lap("MuJoCo compile", &mut t);
    let data = MjData::new(&model);
    lap("MjData (sensor BVH)", &mut t);
    drop(data);
    drop(model);
    drop(xml);
    let alone = mesh_alone_xml(&spec.mesh);
    let mut t = Instant::now();
    let model = MjModel::from_xml_string(&alone)?;
    lap("MuJoCo compile, mesh alone", &mut t);
    drop(model);
    drop(alone);
    let mut t = Instant::now();
    let mut pad = FreePad::new(spec, &config)?;
    lap("FreePad::new (all again)", &mut t);
    let top = DVec3::new((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, hi.z - 0.001);
    let image = pad.read_at(&PadPose::new(top, DVec3::NEG_Z, DVec3::Y).ok_or("pad pose")?)?;
    lap("first reading", &mut t);
    eprintln!("image sum {}", image.values().iter().sum::<f64>());
    Ok(())
}

/// A model of the object's mesh alone (no collision shell, no sensor), as the scene writes it.
fn mesh_alone_xml(mesh: &TriMesh) -> String {
    let vertex = numbers(mesh.vertices.iter().flat_map(|v| v.to_array()));
    let face = numbers(mesh.triangles.iter().flatten().map(|&i| f64::from(i)));
    format!(
        "<mujoco><asset><mesh name=\"object\" inertia=\"shell\" vertex=\"{vertex}\" face=\"{face}\"/></asset>\
         <worldbody><body mocap=\"true\"><geom type=\"mesh\" mesh=\"object\" contype=\"0\" conaffinity=\"0\"/>\
         </body></worldbody></mujoco>"
    )
}
