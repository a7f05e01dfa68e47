//! Which pad poses the arm can take (Sec. V-A1): the training sampler's draws restricted to the
//! starts the exploring arm could reach, so that training sees the object from the directions
//! testing will.
//!
//! The arm stands on the table beside the object and cannot reach the underside resting on the
//! table, nor, in general, a patch facing down or away behind the object, which the free sampler
//! reads (how often, on the 12 shapes: `docs/measurements.md`, "Training that matches the arm").
//! A draw passes when the
//! arm's inverse kinematics places the pad at the start pose with no part of the arm touching
//! anything; the start is then the pose the arm actually takes, its roll about the normal
//! included, which the arm's controllers then hold (`InverseKinematics::solve_with_up`).

use crate::explore::planner::precise_motion;
use crate::pose::PadPose;
use crate::pose::Pose;
use crate::sim::{Arm, InverseKinematics, ObjectSpec, PadTarget, Scene, SceneBuilder, SimError};

/// The arm, the table and the object at rest on it: the scene the planner explores.
pub struct ArmReach {
    scene: Scene,
    arm: Arm,
    ik: InverseKinematics,
    home: Vec<f64>,
}

impl ArmReach {
    /// The arm's scene with `object` (its own pose, on the table).
    pub fn new(object: ObjectSpec) -> Result<Self, SimError> {
        let scene = SceneBuilder::with_arm_and_table().object(object).build()?;
        let arm = scene.arm().cloned().ok_or(SimError::NoArm)?;
        let (ik_options, _) = precise_motion();
        let ik = InverseKinematics::for_scene(&scene, ik_options)?;
        let home = arm.q(scene.data());
        Ok(Self { scene, arm, ik, home })
    }

    /// Where the object stands in the arm's scene.
    pub fn object_pose(&self) -> Pose {
        self.scene.object_pose().unwrap_or_default()
    }

    /// The pad pose the arm takes when asked for `start` (world frame of the arm's scene): the
    /// same centre and normal, the arm's own roll; `None` when no configuration within the joint
    /// limits reaches it or the arm would touch the object, the table or itself there.
    pub fn start_pose(&mut self, start: &PadPose) -> Option<PadPose> {
        let target = PadTarget {
            center_m: start.center_m,
            normal: start.normal,
        };
        let q = self.ik.solve(&target, &self.home).ok()?;
        self.arm.teleport(&mut self.scene, &q);
        if self.arm.collision(&self.scene).is_some() {
            return None;
        }
        Some(self.arm.pad_pose(self.scene.data()))
    }
}

/// `pose` carried by the rigid motion `motion` (a pad pose of one scene's object frame into
/// another's).
pub fn carried(pose: &PadPose, motion: &Pose) -> PadPose {
    PadPose {
        center_m: motion.transform_point(pose.center_m),
        normal: motion.transform_vector(pose.normal),
        up: motion.transform_vector(pose.up),
    }
}
