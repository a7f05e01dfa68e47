//! A free object under the arm (issue 74): the world stepped by MuJoCo's dynamics while the arm
//! holds still, and what that did to the object.
//!
//! The arm is a stiff position-controlled robot, as its kinematic execution assumes
//! (`motion.rs`): between its motions it holds its configuration exactly, and the object answers
//! the covering's push (`tactile::press_back`), gravity and its contacts with the table and the
//! arm's links. A motion of the pad is followed by [`Scene::let_object_answer`]: a short dwell of
//! dynamics, after which the reading is taken, so a touch is quasi-static, as the paper's
//! controllers are (Sec. III-B).

use glam::DVec3;

use crate::pose::Pose;
use crate::sim::SimError;
use crate::sim::object::ObjectMount;
use crate::sim::scene::Scene;

/// How long the object answers each motion of the pad, seconds: 25 steps of 2 ms. On the soft
/// gel's 36 N/m the shapes (28-125 g) ring at 3-6 Hz, damped at a quarter to a half of critical, and
/// the press they ring under is at most a sixteenth of the friction holding them, so they barely stir;
/// what has not settled is felt at the next command, whose reading sees where the object is.
pub const DWELL_S: f64 = 0.05;

/// Faster than this, metres per second, a free object's motion is a physics fault: a 12 cm
/// object dropped from a metre lands at 4.4 m/s.
pub const MAX_OBJECT_SPEED_M_PER_S: f64 = 10.0;

/// How long a free object may take to come to rest on the table before the first touch, seconds.
pub const SETTLE_MAX_S: f64 = 2.0;

/// An object at rest moves slower than this, metres per second (and [`REST_TURN_RAD_PER_S`]).
pub const REST_SPEED_M_PER_S: f64 = 1e-3;
/// An object at rest turns slower than this, radians per second.
pub const REST_TURN_RAD_PER_S: f64 = 0.02;

/// An object whose up axis turned more than this from where it stood is tipped over: a named
/// outcome of a touch ([`ObjectMotion::outcome`]).
pub const TIPPED_RAD: f64 = std::f64::consts::FRAC_PI_6;

/// Half the table's side (`mjcf/table.xml`), metres: an object whose centre leaves it fell off.
pub const TABLE_HALF_SIDE_M: f64 = 0.6;

/// How an object was moved, from one pose to another.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectMotion {
    /// How far its frame's origin moved, metres.
    pub shift_m: f64,
    /// How far its centre (its bounding box's) moved along the table, metres: what a
    /// perturbation's translation draws (Sec. V-B4), whatever the turn about the centre.
    pub centre_shift_m: f64,
    /// The angle of the rotation between the two poses, radians.
    pub turn_rad: f64,
    /// How far its up axis (the world's z at `before`) turned from upright, radians.
    pub tilt_rad: f64,
    /// Where its centre is at the end, world metres.
    pub centre_m: DVec3,
}

/// What became of a free object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionOutcome {
    /// Still standing on the table, moved or not.
    Standing,
    /// Its up axis turned more than [`TIPPED_RAD`].
    Tipped,
    /// Its centre left the table, or fell below it.
    OffTable,
}

impl MotionOutcome {
    /// The outcome as files name it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Standing => "standing",
            Self::Tipped => "tipped",
            Self::OffTable => "off_table",
        }
    }
}

impl ObjectMotion {
    /// The motion from `before` to `after` of an object whose centre is `centre_local` in its
    /// own frame.
    pub fn between(before: &Pose, after: &Pose, centre_local: DVec3) -> Self {
        let turn = after.rotation * before.rotation.inverse();
        let up_before = DVec3::Z;
        let up_after = turn * up_before;
        let centre_m = after.transform_point(centre_local);
        let centre_shift = centre_m - before.transform_point(centre_local);
        Self {
            shift_m: (after.position_m - before.position_m).length(),
            centre_shift_m: centre_shift.truncate().length(),
            turn_rad: turn.normalize().angle_between(glam::DQuat::IDENTITY),
            tilt_rad: up_before.angle_between(up_after),
            centre_m,
        }
    }

    /// Off the table, tipped over, or standing.
    pub fn outcome(&self) -> MotionOutcome {
        let c = self.centre_m;
        if c.x.abs() > TABLE_HALF_SIDE_M || c.y.abs() > TABLE_HALF_SIDE_M || c.z < 0.0 {
            MotionOutcome::OffTable
        } else if self.tilt_rad > TIPPED_RAD {
            MotionOutcome::Tipped
        } else {
            MotionOutcome::Standing
        }
    }
}

/// What a run of motions did to an object: each measure's mean, 95th percentile and largest,
/// and the outcomes counted. How `collect` reports touches and perturbations alike, so a push is
/// measured as a teleport is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionSummary {
    pub motions: usize,
    /// The origin's shift, metres.
    pub shift_m: Spread,
    /// The centre's shift along the table, metres.
    pub centre_shift_m: Spread,
    pub turn_rad: Spread,
    pub tipped: usize,
    pub off_table: usize,
}

/// One measure over a run of motions.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Spread {
    pub mean: f64,
    pub p95: f64,
    pub max: f64,
}

impl Spread {
    fn of(values: impl Iterator<Item = f64>) -> Self {
        let mut sorted: Vec<f64> = values.collect();
        sorted.sort_by(f64::total_cmp);
        match sorted.last() {
            None => Self::default(),
            Some(&max) => Self {
                mean: crate::stats::mean(&sorted),
                p95: crate::stats::percentile(&sorted, 0.95),
                max,
            },
        }
    }
}

impl MotionSummary {
    pub fn of(motions: &[ObjectMotion]) -> Self {
        let count = |outcome| motions.iter().filter(|m| m.outcome() == outcome).count();
        Self {
            motions: motions.len(),
            shift_m: Spread::of(motions.iter().map(|m| m.shift_m)),
            centre_shift_m: Spread::of(motions.iter().map(|m| m.centre_shift_m)),
            turn_rad: Spread::of(motions.iter().map(|m| m.turn_rad)),
            tipped: count(MotionOutcome::Tipped),
            off_table: count(MotionOutcome::OffTable),
        }
    }
}

impl Scene {
    /// Whether the scene's object is on a free joint: touches then run through the dynamics.
    pub fn object_is_free(&self) -> bool {
        self.object().is_some_and(|o| o.mount == ObjectMount::Free)
    }

    /// Steps the dynamics for `duration_s` with the arm, if there is one, held at its
    /// configuration (its joints put back and stopped after every step: a stiff position-controlled
    /// arm), so that only the object moves; kinematics and contacts are current at the end. A
    /// state gone bad is the step's [`SimError::PhysicsFault`].
    pub fn step_holding_the_arm(&mut self, duration_s: f64) -> Result<(), SimError> {
        let held = self.arm().cloned().map(|arm| {
            let q = arm.q(self.data());
            (arm, q)
        });
        let steps = (duration_s / self.model().opt().timestep).round().max(1.0) as usize;
        for _ in 0..steps {
            self.step_without_sensors()?;
            if let Some((arm, q)) = &held {
                arm.rest_at(self, q);
            }
            self.check_object_speed()?;
        }
        self.kinematics_and_collision();
        Ok(())
    }

    /// A [`SimError::PhysicsFault`] when the object moves faster than [`MAX_OBJECT_SPEED_M_PER_S`]:
    /// nothing under a pad's press or on a table does, and a contact solver that diverged (a
    /// degenerate friction cone, a crushed collision shell) leaves finite but absurd velocities
    /// that MuJoCo's own checks (beyond 1e10) would let through.
    fn check_object_speed(&self) -> Result<(), SimError> {
        match self.object_speed() {
            Some((speed, _)) if speed > MAX_OBJECT_SPEED_M_PER_S => Err(SimError::PhysicsFault {
                time_s: self.data().time(),
                what: format!(
                    "the free object moves at {speed:.3e} m/s (more than {MAX_OBJECT_SPEED_M_PER_S} m/s): the contact solver diverged"
                ),
            }),
            _ => Ok(()),
        }
    }

    /// A free object's answer to the pad's last motion: [`DWELL_S`] of dynamics, the arm held.
    /// Nothing for a mocap object.
    pub fn let_object_answer(&mut self) -> Result<(), SimError> {
        if !self.object_is_free() {
            return Ok(());
        }
        self.step_holding_the_arm(DWELL_S)
    }

    /// Lets a free object come to rest (gravity, the table, the arm held) for at most
    /// [`SETTLE_MAX_S`]: at rest once it moves slower than [`REST_SPEED_M_PER_S`] and turns
    /// slower than [`REST_TURN_RAD_PER_S`] for 0.1 s. Returns how it moved from where it was put;
    /// `None` for a mocap object, which stays where it is put.
    pub fn settle_object(&mut self) -> Result<Option<ObjectMotion>, SimError> {
        if !self.object_is_free() {
            return Ok(None);
        }
        let start = self.object_pose().ok_or(SimError::NoObject)?;
        let interval_s = 0.1;
        let mut elapsed_s = 0.0;
        while elapsed_s < SETTLE_MAX_S {
            self.step_holding_the_arm(interval_s)?;
            elapsed_s += interval_s;
            let (speed, turn) = self.object_speed().ok_or(SimError::NoObject)?;
            if speed < REST_SPEED_M_PER_S && turn < REST_TURN_RAD_PER_S {
                break;
            }
        }
        self.forward();
        self.object_motion_from(&start).map(Some)
    }

    /// How the object moved from `before` to where it is now.
    pub fn object_motion_from(&self, before: &Pose) -> Result<ObjectMotion, SimError> {
        let after = self.object_pose().ok_or(SimError::NoObject)?;
        let centre = self.object_center_local().ok_or(SimError::NoObject)?;
        Ok(ObjectMotion::between(before, &after, centre))
    }

    /// The free object's linear speed (metres per second) and turning rate (radians per second).
    pub fn object_speed(&self) -> Option<(f64, f64)> {
        let object = self.object()?;
        let joint = self.model().body_jntadr()[object.body];
        if joint < 0 {
            return Some((0.0, 0.0));
        }
        let dof = self.model().jnt_dofadr()[joint as usize] as usize;
        let v = &self.data().qvel()[dof..dof + 6];
        Some((
            DVec3::new(v[0], v[1], v[2]).length(),
            DVec3::new(v[3], v[4], v[5]).length(),
        ))
    }

    /// The free object's mass, kilograms; `None` for a mocap object (it has no dynamics).
    pub fn object_mass_kg(&self) -> Option<f64> {
        let object = self.object().filter(|o| o.mount == ObjectMount::Free)?;
        Some(self.model().body_mass()[object.body])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    #[test]
    fn a_motion_names_its_outcome() {
        let before = Pose::IDENTITY;
        let centre = DVec3::new(0.0, 0.0, 0.05);
        let slid = Pose {
            position_m: DVec3::new(0.01, 0.0, 0.0),
            rotation: DQuat::from_rotation_z(0.3),
        };
        let motion = ObjectMotion::between(&before, &slid, centre);
        assert!((motion.shift_m - 0.01).abs() < 1e-15 && (motion.turn_rad - 0.3).abs() < 1e-12);
        assert!(
            (motion.centre_shift_m - 0.01).abs() < 1e-15,
            "the centre on the axis of the turn"
        );
        let off_axis = ObjectMotion::between(&before, &slid, DVec3::new(0.02, 0.0, 0.05));
        let swept = 2.0 * 0.02 * (0.3f64 / 2.0).sin();
        assert!(off_axis.centre_shift_m > 0.01 && off_axis.centre_shift_m < 0.01 + swept + 1e-12);
        assert!(motion.tilt_rad < 1e-12, "a turn about the vertical tips nothing");
        assert_eq!(motion.outcome(), MotionOutcome::Standing);
        let tipped = Pose {
            rotation: DQuat::from_rotation_x(0.6),
            ..slid
        };
        assert_eq!(
            ObjectMotion::between(&before, &tipped, centre).outcome(),
            MotionOutcome::Tipped
        );
        let leaning = Pose {
            rotation: DQuat::from_rotation_x(0.5),
            ..slid
        };
        assert_eq!(
            ObjectMotion::between(&before, &leaning, centre).outcome(),
            MotionOutcome::Standing
        );
        let fallen = Pose {
            position_m: DVec3::new(0.7, 0.0, 0.0),
            ..slid
        };
        assert_eq!(
            ObjectMotion::between(&before, &fallen, centre).outcome(),
            MotionOutcome::OffTable
        );
    }
}
