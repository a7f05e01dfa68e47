//! The arm of Sec. V-A1: its joints, forward kinematics of the sensor pad, and guarded motion.
//!
//! Joint order is the chain order of `mjcf/arm.xml`: shoulder (z, y), elbow (z, y), forearm (z, y),
//! wrist (y, z). Configurations `q` are radians in that order.

use glam::{DMat3, DQuat, DVec3};
use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;

use crate::sim::scene::Scene;
use crate::sim::{Pose, SimError};

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
/// The arm's root body.
pub const ARM_BASE: &str = "base";

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
    joints: Vec<ArmJoint>,
    site: usize,
    root_body: usize,
}

/// A collision that stopped a motion: the two bodies MuJoCo found in contact.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Collision {
    pub body_a: String,
    pub body_b: String,
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

/// Speed and accuracy of [`Arm::move_to`].
#[derive(Debug, Clone, Copy)]
pub struct MoveOptions {
    /// Largest change of any joint's command per control interval, radians.
    pub max_step_rad: f64,
    /// Physics steps per control interval (the observer runs once per interval).
    pub steps_per_interval: usize,
    /// Joint error at which the motion counts as reached, radians.
    pub tolerance_rad: f64,
    /// Control intervals allowed after the last command for the servos to settle.
    pub settle_intervals: usize,
}

impl Default for MoveOptions {
    /// 0.01 rad per 5 steps of 2 ms: a slow 1 rad/s, as the planner's "slowly move" asks (Sec. III-A).
    fn default() -> Self {
        Self {
            max_step_rad: 0.01,
            steps_per_interval: 5,
            tolerance_rad: 2e-3,
            settle_intervals: 60,
        }
    }
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
        Ok(Some(Arm {
            joints,
            site,
            root_body: model.body_rootid()[base] as usize,
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

    /// The pad frame in the world from the current kinematics (`site_xpos`, `site_xmat`).
    pub fn pad_pose<M: ModelType>(&self, data: &MjData<M>) -> Pose {
        site_pose(data, self.site)
    }

    /// Puts the arm at `q` at rest with matching servo commands (a reset, not a motion).
    pub fn teleport(&self, scene: &mut Scene, q: &[f64]) {
        let data = scene.data_mut();
        self.set_q(data, q);
        for j in &self.joints {
            data.qvel_mut()[j.dof_adr] = 0.0;
        }
        self.command(data, q);
        scene.forward();
    }

    fn command<M: ModelType>(&self, data: &mut MjData<M>, q: &[f64]) {
        for (j, &v) in self.joints.iter().zip(q) {
            data.ctrl_mut()[j.actuator] = v;
        }
    }

    /// The first contact between an arm body and anything else, or between non-adjacent arm bodies.
    pub fn collision(&self, scene: &Scene) -> Option<Collision> {
        let model = scene.model();
        scene.contact_bodies().into_iter().find_map(|(a, b)| {
            let (arm_a, arm_b) = (self.owns_body(model, a), self.owns_body(model, b));
            let involved = arm_a || arm_b;
            let adjacent = model.body_parentid()[a] as usize == b || model.body_parentid()[b] as usize == a;
            (involved && !(arm_a && arm_b && adjacent)).then(|| Collision {
                body_a: scene.body_name(a),
                body_b: scene.body_name(b),
            })
        })
    }

    /// Drives the position servos toward `target` in small interpolated steps while MuJoCo steps,
    /// stopping at the first contact of the arm (or the pad's rigid back) with anything, or when
    /// `observer` returns `true` (it runs after every control interval with the scene, e.g. to read
    /// the sensor).
    pub fn move_to<F>(
        &self,
        scene: &mut Scene,
        target: &[f64],
        options: &MoveOptions,
        mut observer: F,
    ) -> Result<MoveOutcome, SimError>
    where
        F: FnMut(&mut Scene) -> bool,
    {
        if target.len() != self.dof() || target.iter().any(|v| !v.is_finite()) {
            return Err(SimError::BadConfiguration {
                message: format!("{target:?} is not an arm configuration"),
            });
        }
        let mut target = target.to_vec();
        self.clamp(&mut target);
        let start: Vec<f64> = self
            .joints
            .iter()
            .map(|j| scene.data().ctrl()[j.actuator])
            .collect();
        let span = start
            .iter()
            .zip(&target)
            .map(|(a, b)| (b - a).abs())
            .fold(0.0, f64::max);
        let intervals = (span / options.max_step_rad).ceil().max(1.0) as usize;
        let mut command = start.clone();
        for k in 1..=intervals + options.settle_intervals {
            if k <= intervals {
                let s = k as f64 / intervals as f64;
                for (c, (a, b)) in command.iter_mut().zip(start.iter().zip(&target)) {
                    *c = a + (b - a) * s;
                }
                self.command(scene.data_mut(), &command);
            }
            for _ in 0..options.steps_per_interval {
                scene.step()?;
                if let Some(c) = self.collision(scene) {
                    return Ok(MoveOutcome::Collided(c));
                }
            }
            if observer(scene) {
                return Ok(MoveOutcome::Stopped);
            }
            if k >= intervals {
                let q = self.q(scene.data());
                let error = q
                    .iter()
                    .zip(&target)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                if error <= options.tolerance_rad {
                    return Ok(MoveOutcome::Reached);
                }
            }
        }
        Err(SimError::Physics {
            message: format!(
                "the arm did not settle at {target:?} within {} control intervals",
                options.settle_intervals
            ),
        })
    }
}

/// The world pose of site `site`.
pub fn site_pose<M: ModelType>(data: &MjData<M>, site: usize) -> Pose {
    let m = data.site_xmat()[site];
    // MuJoCo's xmat is row-major; the site's axes are its columns.
    let rot = DMat3::from_cols(
        DVec3::new(m[0], m[3], m[6]),
        DVec3::new(m[1], m[4], m[7]),
        DVec3::new(m[2], m[5], m[8]),
    );
    Pose::new(DVec3::from_array(data.site_xpos()[site]), DQuat::from_mat3(&rot))
}
