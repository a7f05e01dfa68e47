//! Writes test spheres for the large-mesh measurements (issue 39): icospheres and geodesic spheres
//! 8 cm across, as a scanned object would be, as OBJ files.
//!
//! `cargo run --release --example icosphere -- OUT_DIR` writes `sphere_20k.obj` (20,480 triangles),
//! `sphere_200k.obj` (200,000) and `sphere_1300k.obj` (1,310,720) into `OUT_DIR`; without `OUT_DIR`
//! it writes the 20k sphere alone into the system's temporary folder.

#[path = "../tests/sensor_support/mod.rs"]
mod sensor_support;

use std::path::PathBuf;

use glam::DVec3;
use sensor_support::{geodesic_sphere, icosphere};
use taction::mesh::write_obj;

const RADIUS_M: f64 = 0.04;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out_dir = std::env::args().nth(1).map(PathBuf::from);
    let all = out_dir.is_some();
    let out = out_dir.unwrap_or_else(|| std::env::temp_dir().join("taction-spheres"));
    std::fs::create_dir_all(&out)?;
    let mut spheres = vec![("sphere_20k", icosphere(DVec3::ZERO, RADIUS_M, 5))];
    if all {
        spheres.push(("sphere_200k", geodesic_sphere(DVec3::ZERO, RADIUS_M, 100)));
        spheres.push(("sphere_1300k", icosphere(DVec3::ZERO, RADIUS_M, 8)));
    }
    for (name, mesh) in spheres {
        let path = out.join(format!("{name}.obj"));
        write_obj(&mesh, &path, &format!("{name}: a sphere 8 cm across"))?;
        println!("{}: {} triangles", path.display(), mesh.triangles.len());
    }
    Ok(())
}
