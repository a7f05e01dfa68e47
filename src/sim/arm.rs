//! The arm of Sec. V-A1: its joints, forward kinematics of the sensor pad, and guarded motion.
//!
//! Joint order is the chain order of `mjcf/arm.xml`: shoulder (z, y), elbow (z, y), forearm (z, y),
//! wrist (y, z). Configurations `q` are radians in that order.
//!
//! Motions are guarded: they stop at the first MuJoCo contact of an arm body (or of the pad's rigid
//! back) with anything, so the planner's tree keeps "collision-free configurations" joined by
//! "collision-free motions" (Sec. III-A). Two executions of the same straight joint-space motion:
//!
//! - [`Execution::Servo`]: the position servos track an interpolated command while MuJoCo steps the
//!   dynamics, the observer running once per control interval. The tactile plugin is not evaluated on
//!   the steps in between ([`Scene::step_without_sensors`]): nothing reads it there.
//! - [`Execution::Kinematic`]: the segment is sampled (at most `max_step_rad` per joint and
//!   `max_pad_step_m` of pad travel between samples, the observer may ask for finer samples near a
//!   surface) and each sample is checked with MuJoCo's own kinematics and collision detection, as
//!   sampling-based motion planners check edges (a sample whose every arm geom is clear of
//!   everything by more than 0.1 mm is cleared without the collision detection, with the same
//!   outcome: `contact_screen.rs`); the arm is then placed at rest at the end. This is
//!   what the servo execution converges to: the arm is gravity-compensated, position-controlled and
//!   the soft covering exerts no force in MuJoCo (the sensor plugin measures it), so at rest the
//!   servos hold exactly the commanded configuration and, short of a rigid contact, which stops both
//!   executions, the transient between two commands changes no reading. It costs a few kinematics and
//!   collision evaluations per motion instead of hundreds of physics steps.

use glam::DVec3;
use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;
use serde::{Deserialize, Serialize};

use crate::bodies::{ARM_BASE, OBJECT_BODY, PAD_BODY};
use crate::pose::{PadPose, Pose};
use crate::sim::SimError;
use crate::sim::contact_screen::Screened;
use crate::sim::mjcf::COLLISION_GROUP;
use crate::sim::scene::Scene;

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
    joints: Vec<ArmJoint>,
    site: usize,
    root_body: usize,
    /// The pad's rigid back geom, when the model has one.
    back_geom: Option<usize>,
    /// Geoms outside the arm's kinematic tree (what the pad can touch: table, object).
    outside_geoms: Vec<usize>,
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

    /// Like [`teleport`](Self::teleport), computing only kinematics and contacts (what motions and
    /// [`collision`](Self::collision) need): `sensordata` and the velocity and acceleration stages are
    /// stale until the next `mj_forward` or `mj_step` (sensor readers compute what they read).
    pub fn place(&self, scene: &mut Scene, q: &[f64]) {
        self.rest_at(scene, q);
        scene.kinematics_and_collision();
    }

    /// Zero velocity and servo commands equal to `q`, which must be the configuration in `qpos`.
    fn rest_at(&self, scene: &mut Scene, q: &[f64]) {
        let data = scene.data_mut();
        self.set_q(data, q);
        for j in &self.joints {
            data.qvel_mut()[j.dof_adr] = 0.0;
        }
        self.command(data, q);
    }

    /// The pad's rigid back geom, if the model has one named [`PAD_BACK_GEOM`] on the arm.
    pub fn back_geom(&self) -> Option<usize> {
        self.back_geom
    }

    /// Smallest distance (MuJoCo's `mj_geomDistance`; convex hulls for meshes, so never more than the
    /// true distance) between the pad's rigid back and any geom outside the arm (an object's collision
    /// shell standing in for its exact mesh), capped at
    /// `dist_max_m`; `None` when the model has no rigid back. Needs current kinematics.
    pub fn pad_clearance_m(&self, scene: &mut Scene, dist_max_m: f64) -> Result<Option<f64>, SimError> {
        let Some(back) = self.back_geom else {
            return Ok(None);
        };
        let mut clearance = dist_max_m;
        let back_center = DVec3::from_array(scene.data().geom_xpos()[back]);
        let back_radius_m = scene.model().geom_rbound()[back];
        for &g in &self.outside_geoms {
            // Bounding spheres farther apart than the clearance found so far cannot lower it; the
            // exact (GJK) distance is asked only of the geoms near the back. A zero radius is a
            // plane, which has no bounding sphere.
            let radius_m = scene.model().geom_rbound()[g];
            let center = DVec3::from_array(scene.data().geom_xpos()[g]);
            if radius_m > 0.0 && (center - back_center).length() - radius_m - back_radius_m >= clearance {
                continue;
            }
            clearance = clearance.min(scene.geom_distance_m(back, g, clearance)?);
        }
        Ok(Some(clearance))
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

    /// Moves the arm to `target`, stopping at the first contact of the arm (or the pad's rigid back)
    /// with anything, or when `observer` returns `true`. Servo execution drives the position servos
    /// in small interpolated steps while MuJoCo steps, the observer running after every control
    /// interval; kinematic execution runs it after every checked sample (see
    /// [`move_kinematic`](Self::move_kinematic)). Either way the observer sees current kinematics but
    /// stale `sensordata` (and, in a kinematic motion, contacts that may be stale): to read a sensor
    /// it runs `mj_forward` (or [`Scene::compute_sensors`]) first. When the motion ends, kinematics
    /// and contacts are those of where the arm stopped.
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
        if options.execution == Execution::Kinematic {
            return self.move_kinematic(scene, target, options, |s| {
                if observer(s) {
                    Ok(Watch::Stop)
                } else {
                    Ok(Watch::Continue {
                        max_pad_step_m: f64::INFINITY,
                    })
                }
            });
        }
        self.move_servo(scene, target, options, observer)
    }

    /// The servo execution of [`move_to`](Self::move_to): the position servos driven in
    /// `max_step_rad` interpolated steps while MuJoCo steps, then up to `settle_intervals` more
    /// control intervals for the joints to settle within `tolerance_rad`.
    fn move_servo<F>(
        &self,
        scene: &mut Scene,
        target: &[f64],
        options: &MoveOptions,
        mut observer: F,
    ) -> Result<MoveOutcome, SimError>
    where
        F: FnMut(&mut Scene) -> bool,
    {
        let target = self.checked_target(target)?;
        let start: Vec<f64> = self
            .joints
            .iter()
            .map(|j| scene.data().ctrl()[j.actuator])
            .collect();
        let intervals = (largest_difference(&start, &target) / options.max_step_rad)
            .ceil()
            .max(1.0) as usize;
        let mut command = start.clone();
        for k in 1..=intervals + options.settle_intervals {
            if k <= intervals {
                let s = k as f64 / intervals as f64;
                for (c, (a, b)) in command.iter_mut().zip(start.iter().zip(&target)) {
                    *c = a + (b - a) * s;
                }
                self.command(scene.data_mut(), &command);
            }
            if let Some(c) = self.step_interval(scene, options)? {
                return Ok(MoveOutcome::Collided(c));
            }
            if observer(scene) {
                return Ok(MoveOutcome::Stopped);
            }
            if k >= intervals && largest_difference(&self.q(scene.data()), &target) <= options.tolerance_rad {
                return Ok(MoveOutcome::Reached);
            }
        }
        Err(SimError::Physics {
            message: format!(
                "the arm did not settle at {target:?} within {} control intervals",
                options.settle_intervals
            ),
        })
    }

    /// One control interval of `steps_per_interval` MuJoCo steps; the first contact of the arm
    /// with anything ends it.
    fn step_interval(&self, scene: &mut Scene, options: &MoveOptions) -> Result<Option<Collision>, SimError> {
        for _ in 0..options.steps_per_interval {
            scene.step_without_sensors()?;
            if let Some(c) = self.collision(scene) {
                return Ok(Some(c));
            }
        }
        Ok(None)
    }

    /// `target` validated and clamped into the joint limits.
    fn checked_target(&self, target: &[f64]) -> Result<Vec<f64>, SimError> {
        if target.len() != self.dof() || target.iter().any(|v| !v.is_finite()) {
            return Err(SimError::BadConfiguration {
                message: format!("{target:?} is not an arm configuration"),
            });
        }
        let mut target = target.to_vec();
        self.clamp(&mut target);
        Ok(target)
    }

    /// The kinematic execution of a straight joint-space motion from the current configuration to
    /// `target`: samples no farther apart than `max_step_rad` on any joint and `max_pad_step_m` (or
    /// the observer's last, smaller request) of pad travel, each checked by MuJoCo's kinematics and
    /// collision detection (a sample far from any contact cleared first, `sim/contact_screen.rs`).
    /// At a collision the arm is placed at rest at the last collision-free sample and the collision
    /// returned, as when the observer says [`Watch::Blocked`]; when it says
    /// [`Watch::Stop`] (it sees the sample's kinematics) the arm is placed at rest at
    /// that sample; otherwise at `target`.
    pub fn move_kinematic<F>(
        &self,
        scene: &mut Scene,
        target: &[f64],
        options: &MoveOptions,
        mut observer: F,
    ) -> Result<MoveOutcome, SimError>
    where
        F: FnMut(&mut Scene) -> Result<Watch, SimError>,
    {
        let target = self.checked_target(target)?;
        let start = self.q(scene.data());
        let path = JointPath {
            span: largest_difference(&start, &target),
            reach_m: self.back_geom.map_or(0.0, |g| scene.model().geom_rbound()[g]),
            max_step_rad: options.max_step_rad.max(1e-6),
            start: &start,
            target: &target,
        };
        let mut limit_m = options.max_pad_step_m;
        let mut last_free = start.clone();
        scene.data_mut().kinematics();
        let mut sample = PathSample {
            s: 0.0,
            q: start.clone(),
            pad: self.site_pose(scene.data()),
        };
        // Whether the last sample was cleared by the contact screen, its MuJoCo contacts not computed.
        let mut cleared = false;
        while sample.s < 1.0 {
            self.next_sample(scene, &path, &mut sample, limit_m);
            let contact;
            (contact, cleared) = self.sample_contact(scene);
            scene.check_state()?;
            if let Some(c) = contact {
                self.place(scene, &last_free);
                return Ok(MoveOutcome::Collided(c));
            }
            // The observer may have computed sensors; the kinematics stay those of `q`.
            match observer(scene)? {
                Watch::Stop => {
                    self.rest_at(scene, &sample.q);
                    if cleared {
                        scene.data_mut().collision();
                    }
                    return Ok(MoveOutcome::Stopped);
                }
                Watch::Blocked(c) => {
                    self.place(scene, &last_free);
                    return Ok(MoveOutcome::Collided(c));
                }
                Watch::Continue { max_pad_step_m } => {
                    limit_m = max_pad_step_m.min(options.max_pad_step_m).max(1e-6);
                }
            }
            last_free.copy_from_slice(&sample.q);
        }
        // The last sample was `target` itself: its kinematics are current, and so are its contacts
        // once computed where the screen cleared it.
        self.rest_at(scene, &target);
        if cleared {
            scene.data_mut().collision();
        }
        Ok(MoveOutcome::Reached)
    }

    /// The first contact of the arm at the current kinematics, as [`collision`](Self::collision)
    /// finds it after `mj_collision`, and whether the scene's contact screen
    /// ([`Scene::screen_contacts`]) cleared the sample: it then has none, and MuJoCo's contacts are
    /// left as they were (stale, until the motion computes them at the sample it ends on).
    fn sample_contact(&self, scene: &mut Scene) -> (Option<Collision>, bool) {
        if scene.screen_contacts() == Screened::Clear {
            return (None, true);
        }
        scene.data_mut().collision();
        (self.collision(scene), false)
    }

    /// Advances `sample` along `path` by at most `max_step_rad` on any joint and at most
    /// `limit_m` of pad travel (the increment shrinks until it does: the pad's pose at a trial
    /// increment comes from the arm's twin, without placing the object's shell, and the rigid
    /// back's bounding radius turns the pad's rotation into travel); the scene's kinematics are
    /// left at the new sample.
    fn next_sample(&self, scene: &mut Scene, path: &JointPath<'_>, sample: &mut PathSample, limit_m: f64) {
        let mut ds = (1.0 - sample.s).min(path.max_step_rad / path.span.max(1e-12));
        loop {
            let next = (sample.s + ds).min(1.0);
            path.at(next, &mut sample.q);
            let pad = scene.pad_pose_at(self, &sample.q);
            let travel = (pad.position_m - sample.pad.position_m).length()
                + pad.rotation.angle_between(sample.pad.rotation) * path.reach_m;
            if travel <= limit_m || ds * path.span <= 1e-7 {
                scene.arm_moved_to(self, &sample.q);
                sample.pad = pad;
                sample.s = next;
                return;
            }
            ds *= (0.9 * limit_m / travel).clamp(0.1, 0.5);
        }
    }
}

/// A straight joint-space motion of [`Arm::move_kinematic`], from `start` (s = 0) to `target`
/// (s = 1).
struct JointPath<'a> {
    start: &'a [f64],
    target: &'a [f64],
    /// The largest joint change along the path, radians.
    span: f64,
    /// The rigid back's bounding radius: how far its rim moves per radian the pad turns.
    reach_m: f64,
    max_step_rad: f64,
}

impl JointPath<'_> {
    /// The configuration at `s` into `q`; `target` itself from s = 1 on.
    fn at(&self, s: f64, q: &mut [f64]) {
        if s >= 1.0 {
            q.copy_from_slice(self.target);
        } else {
            for (v, (a, b)) in q.iter_mut().zip(self.start.iter().zip(self.target)) {
                *v = a + (b - a) * s;
            }
        }
    }
}

/// Where a kinematic motion is: its path parameter, the configuration and the pad site's pose.
struct PathSample {
    s: f64,
    q: Vec<f64>,
    pad: Pose,
}

/// The largest change of any joint from `from` to `to`, radians.
fn largest_difference(from: &[f64], to: &[f64]) -> f64 {
    from.iter()
        .zip(to)
        .map(|(a, b)| (b - a).abs())
        .fold(0.0, f64::max)
}

/// The world pose of site `site`.
pub fn site_pose<M: ModelType>(data: &MjData<M>, site: usize) -> Pose {
    Pose::from_xmat(data.site_xpos()[site], &data.site_xmat()[site])
}
