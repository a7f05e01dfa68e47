//! The pad on the arm as a [`PadCarrier`]: pose commands go through inverse kinematics and are
//! executed by the position servos while MuJoCo steps (Sec. III-B on the arm of Sec. V-A1).

use glam::DVec3;

use crate::control::carrier::{ControlError, PadCarrier, PadMotion};
use crate::sim::{Arm, IkError, InverseKinematics, MoveOptions, MoveOutcome, PadTarget, Pose, Scene};
use crate::tactile::{PadPose, SensorConfig, TactileImage};

/// The pad frame of a pad site pose: centre at the site, normal its +z, up its +y.
pub fn pad_pose_of_site(site: &Pose) -> PadPose {
    PadPose {
        center_m: site.position_m,
        normal: site.transform_vector(DVec3::Z).normalize(),
        up: site.transform_vector(DVec3::Y).normalize(),
    }
}

/// The arm-mounted pad: a scene with an arm, an IK solver, and a way to read the sensor.
pub struct ArmPad<'s, R> {
    scene: &'s mut Scene,
    arm: Arm,
    ik: &'s mut InverseKinematics,
    sensor: SensorConfig,
    reader: R,
    motion: MoveOptions,
}

impl<'s, R> ArmPad<'s, R>
where
    R: FnMut(&mut Scene) -> Result<TactileImage, ControlError>,
{
    /// `reader` returns the current tactile image of the scene's pad.
    pub fn new(
        scene: &'s mut Scene,
        ik: &'s mut InverseKinematics,
        sensor: SensorConfig,
        reader: R,
        motion: MoveOptions,
    ) -> Result<Self, ControlError> {
        let arm = scene.arm().cloned().ok_or(crate::sim::SimError::NoArm)?;
        Ok(Self {
            scene,
            arm,
            ik,
            sensor,
            reader,
            motion,
        })
    }

    pub fn scene(&mut self) -> &mut Scene {
        self.scene
    }

    pub fn arm(&self) -> &Arm {
        &self.arm
    }
}

impl<R> ArmPad<'_, R> {
    /// Whether a collision is the pad's own body (the rigid back) against something outside the arm.
    fn is_pad_contact(&self, c: &crate::sim::Collision) -> bool {
        let model = self.scene.model();
        let pad_body = model.site_bodyid()[self.arm.site()] as usize;
        let pad_name = self.scene.body_name(pad_body);
        let other = if c.body_a == pad_name {
            &c.body_b
        } else if c.body_b == pad_name {
            &c.body_a
        } else {
            return false;
        };
        (0..model.ffi().nbody as usize)
            .find(|&b| &self.scene.body_name(b) == other)
            .is_some_and(|b| !self.arm.owns_body(model, b))
    }
}

impl<R> PadCarrier for ArmPad<'_, R>
where
    R: FnMut(&mut Scene) -> Result<TactileImage, ControlError>,
{
    fn sensor(&self) -> &SensorConfig {
        &self.sensor
    }

    fn pad_pose(&self) -> PadPose {
        pad_pose_of_site(&self.arm.pad_pose(self.scene.data()))
    }

    fn read(&mut self) -> Result<TactileImage, ControlError> {
        let pose = self.pad_pose();
        Ok((self.reader)(self.scene)?.with_pose(pose))
    }

    fn move_pad(&mut self, target: &PadPose) -> Result<PadMotion, ControlError> {
        let start = self.arm.q(self.scene.data());
        let q = match self.ik.solve(
            &PadTarget {
                center_m: target.center_m,
                normal: target.normal,
            },
            &start,
        ) {
            Ok(q) => q,
            Err(IkError::Unreachable { .. } | IkError::BadTarget) => return Ok(PadMotion::Unreachable),
        };
        match self.arm.move_to(self.scene, &q, &self.motion, |_| false)? {
            MoveOutcome::Reached | MoveOutcome::Stopped => Ok(PadMotion::Moved),
            MoveOutcome::Collided(c) if self.is_pad_contact(&c) => {
                // A controller command pressed the pad's rigid back onto the surface: back off to the
                // last pose, which was free of contact (the servo's retreat, not simulated step by step).
                self.arm.teleport(self.scene, &start);
                Ok(PadMotion::RigidContact)
            }
            MoveOutcome::Collided(c) => Ok(PadMotion::Collided(c)),
        }
    }
}
