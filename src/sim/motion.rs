//! The arm's motions in a scene (Sec. V-A1), guarded: they stop at the first MuJoCo contact of an
//! arm body (or of the pad's rigid back) with anything, so the planner's tree keeps
//! "collision-free configurations" joined by "collision-free motions" (Sec. III-A). Two executions
//! of the same straight joint-space motion:
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

use crate::pose::Pose;
use crate::sim::SimError;
use crate::sim::arm::{Arm, Collision, Execution, MoveOptions, MoveOutcome, Watch};
use crate::sim::contact_screen::Screened;
use crate::sim::scene::Scene;

impl Arm {
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

    /// The arm at `q` with zero velocity and servo commands equal to `q`: at rest, held there.
    pub(super) fn rest_at(&self, scene: &mut Scene, q: &[f64]) {
        let data = scene.data_mut();
        self.set_q(data, q);
        for j in &self.joints {
            data.qvel_mut()[j.dof_adr] = 0.0;
        }
        self.command(data, q);
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
