//! `taction demo`: the product in one run.

use clap::Args;
use glam::DVec3;

use taction::sim::{IkOptions, InverseKinematics, MoveOptions, MoveOutcome, ObjectSpec, PadTarget, SceneBuilder};

#[derive(Debug, Args)]
pub struct DemoArgs {}

/// Loads the world, brings the pad above the object with inverse kinematics, lowers it until it
/// touches, and prints what happened.
pub fn run(_args: &DemoArgs) -> Result<(), Box<dyn std::error::Error>> {
    let mesh = taction::mesh::TriMesh {
        vertices: (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { -0.04 } else { 0.04 },
                    if i & 2 == 0 { -0.03 } else { 0.03 },
                    if i & 4 == 0 { 0.0 } else { 0.1 },
                )
            })
            .collect(),
        triangles: vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ],
    };
    let mut scene = SceneBuilder::with_arm_and_table().object(ObjectSpec::new("box", mesh)).build()?;
    let arm = scene.arm().cloned().ok_or("the world has no arm")?;
    let mut ik = InverseKinematics::new(scene.model_arc(), arm.clone(), IkOptions::default());
    println!("world loaded: arm with {} joints, a 8 x 6 x 10 cm box on the table", arm.dof());
    let mut z = 0.16;
    loop {
        let target = PadTarget { center_m: DVec3::new(0.0, 0.0, z), normal: -DVec3::Z };
        let q = ik.solve(&target, &arm.q(scene.data()))?;
        match arm.move_to(&mut scene, &q, &MoveOptions::default(), |_| false)? {
            MoveOutcome::Reached => {
                println!("pad at z = {:.3} m, looking down", arm.pad_pose(scene.data()).position_m.z);
            }
            MoveOutcome::Collided(c) => {
                println!("touched: {c} at pad height z = {:.4} m", arm.pad_pose(scene.data()).position_m.z);
                return Ok(());
            }
            MoveOutcome::Stopped => {}
        }
        z -= 0.01;
        if z < 0.0 {
            return Err("the pad reached the table without touching the object".into());
        }
    }
}
