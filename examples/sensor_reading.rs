//! One reading of the covering sensor (Sec. V-A2) on a chess pawn, with the free-floating pad:
//! the pad looks straight down onto the top of the pawn, pressed half the covering's thickness
//! into it, and the tactile image is printed.
//!
//! `cargo run --release --example sensor_reading`

use glam::DVec3;
use taction::control::FreePad;
use taction::mesh::{BuildOptions, ObjectSet};
use taction::pose::PadPose;
use taction::sim::ObjectSpec;
use taction::tactile::SensorConfig;
use taction::valid::Valid;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // A built-in object: generated, checked and plausible (`Object::from_file` loads your own).
    let pawn = ObjectSet::chess().build_object("pawn", &BuildOptions::default())?;
    let top_m = pawn.mesh.vertices.iter().map(|v| v.z).fold(f64::MIN, f64::max);

    // The paper's letters sensor: 6x6 taxels on a 12 mm pad, a 1.2 mm covering.
    let config = Valid::new(SensorConfig::paper())?;
    let mut pad = FreePad::new(ObjectSpec::from(pawn), &config)?;
    let pressed = PadPose {
        center_m: DVec3::new(0.0, 0.0, top_m - 0.5 * config.thickness_m),
        normal: -DVec3::Z,
        up: DVec3::Y,
    };
    let image = pad.read_at(&pressed)?;
    println!(
        "the pawn's top, pressed {:.1} mm deep:\n{image}",
        0.5e3 * config.thickness_m
    );

    let peak = image.values().iter().copied().fold(0.0, f64::max);
    if peak <= 0.0 {
        return Err("the pad pressed into the pawn read nothing".into());
    }
    Ok(())
}
