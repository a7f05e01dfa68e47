//! The arm of Sec. V-A1: its joints and the forward kinematics of the sensor pad.
//!
//! Joint order is the chain order of `mjcf/arm.xml`: shoulder (z, y), elbow (z, y), forearm (z, y),
//! wrist (y, z). Configurations `q` are radians in that order.
//!
//! The arm's motions in a scene are `motion.rs`'s: they need the
//! [`Scene`](crate::sim::Scene), which owns the arm's indices, so the arm sits below the scene and
//! its motions above it.

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;
use serde::{Deserialize, Serialize};

use crate::bodies::{ARM_BASE, OBJECT_BODY, PAD_BODY};
use crate::pose::{PadPose, Pose};
use crate::sim::SimError;
use crate::sim::mjcf::COLLISION_GROUP;

/// The arm's joints, in chain order; each has a position actuator of the same name.
pub const ARM_JOINTS: [&str; 8] = [
    "shoulder_z",
    "shoulder_y",
    "elbow_z",
    "elbow_y",
    "forearm_z",
    "forearm_y",
    "wrist_y",
    "wrist_z",
];
/// The site whose frame is the pad frame (+z the pad normal, +y image up).
pub const PAD_SITE: &str = "pad";
/// The pad's rigid back: a box whose front face is the pad plane (the covering lies in front of it).
pub const PAD_BACK_GEOM: &str = "sensor_back";

/// One joint of the arm.
#[derive(Debug, Clone)]
pub struct ArmJoint {
    pub name: &'static str,
    pub qpos_adr: usize,
    pub dof_adr: usize,
    pub actuator: usize,
    /// Joint limits, radians.
    pub range_rad: [f64; 2],
}

/// Indices of the arm in a compiled model: a cheap description, cloned freely.
#[derive(Debug, Clone)]
pub struct Arm {
    pub(super) joints: Vec<ArmJoint>,
    pub(super) site: usize,
    pub(super) root_body: usize,
    /// The pad's rigid back geom, when the model has one.
    pub(super) back_geom: Option<usize>,
    /// Geoms outside the arm's kinematic tree (what the pad can touch: table, object).
    pub(super) outside_geoms: Vec<usize>,
}

/// A collision that stopped a motion: the two bodies MuJoCo found in contact.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Collision {
    pub body_a: String,
    pub body_b: String,
}

impl Collision {
    /// The pad's rigid back on the object, as the covering sensor finds it (MuJoCo's contacts do
    /// not: the object's collision shell does not collide with the back, see `mjcf/arm.xml`).
    pub fn back_on_object() -> Self {
        Self {
            body_a: PAD_BODY.to_string(),
            body_b: OBJECT_BODY.to_string(),
        }
    }
}

impl std::fmt::Display for Collision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "'{}' touched '{}'", self.body_a, self.body_b)
    }
}

/// How a guarded motion ended.
#[derive(Debug, Clone, PartialEq)]
pub enum MoveOutcome {
    /// The arm reached the commanded configuration.
    Reached,
    /// An arm link or the pad's rigid back touched something; the arm stopped where the contact began.
    Collided(Collision),
    /// The observer asked to stop (e.g. the sensor felt the object).
    Stopped,
}

/// How [`Arm::move_to`] executes a motion (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Execution {
    /// Position servos and MuJoCo's dynamics, stepped until the arm settles.
    #[default]
    Servo,
    /// Kinematic checks of the segment at a resolution, then the arm placed at rest at the end.
    Kinematic,
}

/// Speed and accuracy of [`Arm::move_to`].
#[derive(Debug, Clone, Copy)]
pub struct MoveOptions {
    /// Largest change of any joint's command per control interval (servo) or between two checked
    /// samples (kinematic), radians.
    pub max_step_rad: f64,
    /// Physics steps per control interval (the observer runs once per interval).
    pub steps_per_interval: usize,
    /// Joint error at which the motion counts as reached, radians (servo).
    pub tolerance_rad: f64,
    /// Control intervals allowed after the last command for the servos to settle.
    pub settle_intervals: usize,
    /// Servo dynamics or kinematic checks.
    pub execution: Execution,
    /// Kinematic: largest travel of the pad between two checked samples, metres (centre travel plus
    /// the rotation times the rigid back's bounding radius).
    pub max_pad_step_m: f64,
}

impl Default for MoveOptions {
    /// 0.01 rad per 5 steps of 2 ms: a slow 1 rad/s, as the planner's "slowly move" asks (Sec. III-A).
    fn default() -> Self {
        Self {
            max_step_rad: 0.01,
            steps_per_interval: 5,
            tolerance_rad: 2e-3,
            settle_intervals: 60,
            execution: Execution::Servo,
            max_pad_step_m: 0.005,
        }
    }
}

impl MoveOptions {
    /// The same options with kinematic execution.
    pub fn kinematic(self) -> Self {
        Self {
            execution: Execution::Kinematic,
            ..self
        }
    }
}

/// What an observer of a kinematic motion asks for after a sample.
#[derive(Debug, Clone, PartialEq)]
pub enum Watch {
    /// Stop here.
    Stop,
    /// Go on, with the pad travelling at most this far (metres) before the next sample (the motion's
    /// own `max_pad_step_m` still applies).
    Continue { max_pad_step_m: f64 },
    /// The sample is in contact where MuJoCo's contacts do not see it (the covering sensor's exact
    /// check of the pad's rigid back): the motion ends as at a MuJoCo collision.
    Blocked(Collision),
}

impl Arm {
    /// Finds the arm in `model`; `Ok(None)` when the model has no arm (e.g. a free-floating sensor).
    pub fn find(model: &MjModel) -> Result<Option<Arm>, SimError> {
        let Some(site) = model.name_to_id(MjtObjBase::mjOBJ_SITE, PAD_SITE) else {
            return Ok(None);
        };
        let Some(base) = model.name_to_id(MjtObjBase::mjOBJ_BODY, ARM_BASE) else {
            return Ok(None);
        };
        let mut joints = Vec::with_capacity(ARM_JOINTS.len());
        for name in ARM_JOINTS {
            let missing = || SimError::Mjcf {
                origin: "arm".into(),
                message: format!("no joint or actuator '{name}'"),
            };
            let j = model
                .name_to_id(MjtObjBase::mjOBJ_JOINT, name)
                .ok_or_else(missing)?;
            let actuator = model
                .name_to_id(MjtObjBase::mjOBJ_ACTUATOR, name)
                .ok_or_else(missing)?;
            joints.push(ArmJoint {
                name,
                qpos_adr: model.jnt_qposadr()[j] as usize,
                dof_adr: model.jnt_dofadr()[j] as usize,
                actuator,
                range_rad: model.jnt_range()[j],
            });
        }
        let root_body = model.body_rootid()[base] as usize;
        let back_geom = model
            .name_to_id(MjtObjBase::mjOBJ_GEOM, PAD_BACK_GEOM)
            .filter(|&g| model.body_rootid()[model.geom_bodyid()[g] as usize] as usize == root_body);
        let outside = |g: usize| {
            let b = model.geom_bodyid()[g] as usize;
            !(b != 0 && model.body_rootid()[b] as usize == root_body)
        };
        // A contact-free geom whose body carries a collision shell is represented by the shell's
        // pieces: they enclose its surface, so their distance is a lower bound of its own, and a far
        // tighter one than that of its convex hull, which is what MuJoCo would measure.
        let shelled = |g: usize| {
            let b = model.geom_bodyid()[g];
            model.geom_contype()[g] == 0
                && model.geom_conaffinity()[g] == 0
                && (0..model.ffi().ngeom as usize)
                    .any(|h| model.geom_bodyid()[h] == b && model.geom_group()[h] == COLLISION_GROUP)
        };
        let outside_geoms = (0..model.ffi().ngeom as usize)
            .filter(|&g| outside(g) && !shelled(g))
            .collect();
        Ok(Some(Arm {
            joints,
            site,
            root_body,
            back_geom,
            outside_geoms,
        }))
    }

    pub fn joints(&self) -> &[ArmJoint] {
        &self.joints
    }

    /// Number of arm joints.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    pub fn site(&self) -> usize {
        self.site
    }

    /// Whether body `b` belongs to the arm (its kinematic tree).
    pub fn owns_body(&self, model: &MjModel, b: usize) -> bool {
        b != 0 && model.body_rootid()[b] as usize == self.root_body
    }

    /// The current configuration, radians.
    pub fn q<M: ModelType>(&self, data: &MjData<M>) -> Vec<f64> {
        self.joints.iter().map(|j| data.qpos()[j.qpos_adr]).collect()
    }

    /// Writes a configuration into qpos (no physics; call `forward` after).
    pub fn set_q<M: ModelType>(&self, data: &mut MjData<M>, q: &[f64]) {
        for (j, &v) in self.joints.iter().zip(q) {
            data.qpos_mut()[j.qpos_adr] = v;
        }
    }

    /// `q` clamped into the joint limits.
    pub fn clamp(&self, q: &mut [f64]) {
        for (j, v) in self.joints.iter().zip(q.iter_mut()) {
            *v = v.clamp(j.range_rad[0], j.range_rad[1]);
        }
    }

    /// Whether `q` is within the joint limits.
    pub fn within_limits(&self, q: &[f64]) -> bool {
        self.joints
            .iter()
            .zip(q)
            .all(|(j, &v)| v >= j.range_rad[0] - 1e-12 && v <= j.range_rad[1] + 1e-12)
    }

    /// Where the pad is, from the current kinematics (`site_xpos`, `site_xmat`).
    pub fn pad_pose<M: ModelType>(&self, data: &MjData<M>) -> PadPose {
        PadPose::of_site(&self.site_pose(data))
    }

    /// The pad site's rigid pose in the world (what inverse kinematics and the motion's travel
    /// measure); [`Arm::pad_pose`] is the same frame as a [`PadPose`].
    pub fn site_pose<M: ModelType>(&self, data: &MjData<M>) -> Pose {
        site_pose(data, self.site)
    }

    /// The pad's rigid back geom, if the model has one named [`PAD_BACK_GEOM`] on the arm.
    pub fn back_geom(&self) -> Option<usize> {
        self.back_geom
    }

    pub(super) fn command<M: ModelType>(&self, data: &mut MjData<M>, q: &[f64]) {
        for (j, &v) in self.joints.iter().zip(q) {
            data.ctrl_mut()[j.actuator] = v;
        }
    }
}

/// The world pose of site `site`.
pub fn site_pose<M: ModelType>(data: &MjData<M>, site: usize) -> Pose {
    Pose::from_xmat(data.site_xpos()[site], &data.site_xmat()[site])
}
