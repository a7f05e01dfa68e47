//! The pad on the arm as a [`PadCarrier`]: pose commands go through inverse kinematics (warm-started
//! at the current configuration) and are executed by [`Arm::move_to`] with the carrier's
//! [`MoveOptions`]: position servos while MuJoCo steps, or MuJoCo-checked kinematic motion (see
//! `sim::arm`), Sec. III-B on the arm of Sec. V-A1. The sensor is read only when a command is done.
//!
//! On the object the pad is stopped by Press's own terminations alone (Sec. III-B: the mean
//! pressure reached, or a taxel close to saturation), as the free-floating pad of the training
//! sampler is: the pad's rigid back collides with the table but not with the object
//! (`mjcf/arm.xml`), whose contact with the pad is what the covering measures. The two carriers
//! therefore settle to the same image from the same start (`tests/carrier_parity.rs`). An exact
//! stop at the object's triangles, which this carrier had and the free pad had not, ended Press
//! at a sharp feature's tip: the arm's readings of the dragon pressed to a mean of 0.13 where the
//! free pad's reached 0.27, 44% of the arm's readings were cut short so, and the model learned
//! images the arm never felt; given to both carriers it cut Fig. 14's convergence on the dragon
//! from 100% to 63%. The price: where a feature narrower than a taxel (an ear, a horn) pokes into
//! the covering, no taxel saturates and the pad plane can pass the surface there (by up to 2.2 mm
//! on the shapes, `tests/explore_shapes.rs` counts it), as the paper's simulated sensor, a depth
//! camera through the covering, allows.
//!
//! A Press command that would press the back onto the table is refused (the carrier stays at its
//! previous pose and reports [`PadMotion::RigidContact`]). An Orient command that would do so is
//! executed backed off along the new pad normal by the least of t/4, t/2 or t that keeps the back
//! clear, as a compliant wrist would; Press then closes the gap. The IK holds the pad's roll
//! through both (`InverseKinematics::solve_with_up`).

use glam::DQuat;

use crate::bodies::PAD_BODY;
use crate::control::carrier::{ControlError, PadCarrier, PadMotion, ReadTactile, backed_off};
use crate::dataset::{AttemptCause, CauseKind};
use crate::pose::PadPose;
use crate::sim::arm::Execution;
use crate::sim::{Arm, Collision, IkError, InverseKinematics, MoveOptions, MoveOutcome, PadTarget, Scene};
use crate::tactile::{SensorConfig, TactileImage};

/// The arm-mounted pad: a scene with an arm, an IK solver, and a way to read the sensor.
pub struct ArmPad<'s, R> {
    scene: &'s mut Scene,
    arm: Arm,
    ik: &'s mut InverseKinematics,
    sensor: SensorConfig,
    reader: R,
    motion: MoveOptions,
    /// The configuration at which a Press command was last refused outright by a rigid contact.
    refused_at: Option<Vec<f64>>,
    /// Whether an Orient turn that would bring an arm link onto the table is shortened to what
    /// the arm can reach ([`limited_by_the_table`](Self::limited_by_the_table)).
    table_limits_turns: bool,
}

impl<'s, R> ArmPad<'s, R>
where
    R: ReadTactile,
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
            refused_at: None,
            table_limits_turns: false,
        })
    }

    /// The carrier with Orient turns limited by the table: a turn that would bring an arm link
    /// (not the pad, whose rigid back backs off instead) onto the table is tried at half and a
    /// quarter of its angle, and when none of them is free the pad stays, as Orient issuing no
    /// command (the turn is out of the arm's reach: [`PadMotion::TurnOutOfReach`]). Near the
    /// table's edge of an object the wrist cannot follow the surface normal to the horizontal,
    /// and the reading is taken pressed at the steepest turn the arm allows.
    pub fn limited_by_the_table(mut self) -> Self {
        self.table_limits_turns = true;
        self
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

impl<R> ArmPad<'_, R>
where
    R: ReadTactile,
{
    /// Whether a collision is an arm link (the pad's body excepted) on the table, as a reading's
    /// cause names it (`arm_on_table`).
    fn is_arm_on_table(&self, c: &Collision) -> bool {
        let cause = AttemptCause::from(c);
        let pad = matches!(&cause, AttemptCause::Touched { body_a, .. } if body_a == PAD_BODY);
        cause.kind() == CauseKind::ArmOnTable && !pad
    }

    /// The turn from `current` to `target` at half, then a quarter of its angle (the normal and up
    /// turned by that part of the rotation, the centre that part of the way along the chord), the
    /// first the arm makes without a collision; else the pad put back at `start` and the turn
    /// reported out of reach.
    fn shortened_turn(
        &mut self,
        current: &PadPose,
        target: &PadPose,
        start: &[f64],
    ) -> Result<PadMotion, ControlError> {
        let turn = DQuat::from_rotation_arc(current.normal, target.normal);
        for fraction in [0.5, 0.25] {
            let partial = DQuat::IDENTITY.slerp(turn, fraction);
            let shorter = PadPose {
                center_m: current.center_m.lerp(target.center_m, fraction),
                normal: (partial * current.normal).normalize(),
                up: (partial * current.up).normalize(),
            };
            self.arm.place(self.scene, start);
            if let (PadMotion::Moved, None) = self.try_move(&shorter, start)? {
                return Ok(PadMotion::Moved);
            }
        }
        self.arm.place(self.scene, start);
        Ok(PadMotion::TurnOutOfReach)
    }
}

impl<R> PadCarrier for ArmPad<'_, R>
where
    R: ReadTactile,
{
    fn sensor(&self) -> &SensorConfig {
        &self.sensor
    }

    fn pad_pose(&self) -> PadPose {
        self.arm.pad_pose(self.scene.data())
    }

    fn read(&mut self) -> Result<TactileImage, ControlError> {
        let pose = self.pad_pose();
        Ok((self.reader)(self.scene)?.with_pose(pose))
    }

    /// The command, then a free object's answer to it ([`Scene::let_object_answer`]): the reading
    /// after a motion sees where the covering's push left the object.
    fn move_pad(&mut self, target: &PadPose) -> Result<PadMotion, ControlError> {
        let motion = self.command_pad(target)?;
        self.scene.let_object_answer()?;
        Ok(motion)
    }
}

impl<R> ArmPad<'_, R>
where
    R: ReadTactile,
{
    /// One pose command, the object held as it is: IK and the guarded motion, an Orient turn
    /// backed off or shortened where the table is in the way, a Press refused twice reported.
    fn command_pad(&mut self, target: &PadPose) -> Result<PadMotion, ControlError> {
        let start = self.arm.q(self.scene.data());
        let current = self.pad_pose();
        let (motion, contact) = self.try_move(target, &start)?;
        if let PadMotion::Collided(c) = &motion
            && self.table_limits_turns
            && self.is_arm_on_table(c)
            && current.normal.angle_between(target.normal) > 1e-6
        {
            return self.shortened_turn(&current, target, &start);
        }
        let Some(contact) = contact else {
            return Ok(motion);
        };
        // An Orient command (the normal turns): back off along the new normal until the back is clear.
        if current.normal.angle_between(target.normal) > 1e-6 {
            for retreated in backed_off(target, self.sensor.thickness_m) {
                self.arm.place(self.scene, &start);
                match self.try_move(&retreated, &start)? {
                    (_, Some(_)) => {}
                    (other, None) => return Ok(other),
                }
            }
            self.arm.place(self.scene, &start);
            return Ok(PadMotion::RigidContact);
        }
        // A Press command refused at once, twice from the same configuration (nothing moved the pad
        // in between): the back rests on the surface while the covering is not saturated under the
        // pad (a sliver of the pad over an edge, say) and Orient has nothing to turn. Pressing cannot
        // proceed; the rigid contact is reported as the collision it is rather than refused again
        // until the iteration budget runs out.
        if self.motion.execution == Execution::Kinematic && self.arm.q(self.scene.data()) == start {
            if self.refused_at.as_deref() == Some(start.as_slice()) {
                return Ok(PadMotion::Collided(contact));
            }
            self.refused_at = Some(start);
        }
        Ok(motion)
    }
}

impl<R> ArmPad<'_, R>
where
    R: ReadTactile,
{
    /// One command from configuration `start` (where the arm is): IK, then the guarded motion; with
    /// [`PadMotion::RigidContact`] the contact. At a rigid contact of the pad the kinematic execution
    /// stays at the last contact-free sample of the motion (the back within `max_pad_step_m` of the
    /// surface: Press has pushed as far as the back allows); the servo execution, which stops in
    /// contact, goes back to `start`, which was free of contact (the servo's retreat, not simulated
    /// step by step).
    fn try_move(
        &mut self,
        target: &PadPose,
        start: &[f64],
    ) -> Result<(PadMotion, Option<Collision>), ControlError> {
        let q = match self.ik.solve_with_up(
            &PadTarget {
                center_m: target.center_m,
                normal: target.normal,
            },
            target.up,
            start,
        ) {
            Ok(q) => q,
            Err(IkError::Unreachable { .. } | IkError::BadTarget) => {
                return Ok((PadMotion::Unreachable, None));
            }
        };
        Ok(match self.arm.move_to(self.scene, &q, &self.motion, |_| false)? {
            MoveOutcome::Reached | MoveOutcome::Stopped => (PadMotion::Moved, None),
            MoveOutcome::Collided(c) if self.is_pad_contact(&c) => {
                if self.motion.execution == Execution::Servo {
                    self.arm.place(self.scene, start);
                }
                (PadMotion::RigidContact, Some(c))
            }
            MoveOutcome::Collided(c) => (PadMotion::Collided(c), None),
        })
    }
}
