//! A touch with the arm (Sec. V-A1): the pad is put 5 mm above a chess pawn, looking down, and the
//! surface contact controllers of Algorithm 1 (Approach, Press, Orient; Sec. III-B) settle it on
//! the pawn's head. Prints how the touch ended and the tactile image it settled on.
//!
//! `cargo run --release --example arm_touch`

use glam::DVec3;

use taction::control::{ArmPad, ControlConfig, sensor_reader, settle};
use taction::dataset::ContactStatus;
use taction::explore::precise_motion;
use taction::mesh::{BuildOptions, ObjectSet};

use taction::sim::{InverseKinematics, ObjectSpec, PAD_SITE, PadTarget, SimError};
use taction::tactile::{CoveringSensor, SensorConfig, arm_with_sensor};
use taction::valid::Valid;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let pawn = ObjectSet::chess().build_object("pawn", &BuildOptions::default())?;
    let top_m = pawn.mesh.vertices.iter().map(|v| v.z).fold(f64::MIN, f64::max);

    // The world: the arm, the table, the pawn at the origin, the sensor on the arm's pad site.
    let sensor = Valid::new(SensorConfig::paper())?;
    let mut scene = arm_with_sensor(ObjectSpec::from(pawn), &sensor).build()?;
    let arm = scene.arm().cloned().ok_or(SimError::NoArm)?;
    let reader = sensor_reader(CoveringSensor::on_site(scene.model(), PAD_SITE)?);

    // The arm's configuration that puts the pad 5 mm above the pawn's head, looking down.
    let (ik_options, motion) = precise_motion();
    let mut ik = InverseKinematics::new(scene.model_arc(), arm.clone(), ik_options);
    let start = PadTarget {
        center_m: DVec3::new(0.0, 0.0, top_m + 0.005),
        normal: -DVec3::Z,
    };
    let q = ik.solve(&start, &arm.q(scene.data()))?;
    arm.teleport(&mut scene, &q);

    // Algorithm 1 on the arm.
    let control = Valid::new(ControlConfig::default())?;
    let mut pad = ArmPad::new(&mut scene, &mut ik, *sensor, reader, motion)?;
    let outcome = settle(&mut pad, &control)?;
    println!(
        "{:?} after {} Press/Orient iterations; pad centre {:.4} m, normal {:.3}\n{}",
        outcome.status, outcome.iterations, outcome.pose.center_m, outcome.pose.normal, outcome.image
    );

    if outcome.status != ContactStatus::Converged {
        return Err(format!("the touch ended {:?}, not converged", outcome.status).into());
    }
    Ok(())
}
