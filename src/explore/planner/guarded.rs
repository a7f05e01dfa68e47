//! The guarded touch (beyond the paper): every touch action meets the surface or says why not.
//!
//! A planner iteration (Sec. III-A) expands toward a target in 2 cm steps from the nearest tree
//! vertex and reads only if the sensor happens to feel something on the way; most iterations of a
//! blind exploration meet nothing (docs/measurements.md, "Touches that land"). A real arm touches
//! differently: it moves slowly along a ray toward where it expects the object until the covering
//! meets a surface, a guarded move, which is also what the active-perception environments of the
//! field make a step (Tactile MNIST moves its sensor along its normal until contact). Here the ray
//! is chosen from the target alone and the workspace box, the only thing the planner knows of the
//! object (Sec. III-A): it passes through the target and descends toward the box's vertical axis
//! at 0.3 of the target's height above the table ([`ApproachRay::through`]), so a target high
//! above the axis touches a top, a low one a side, and a ray that passes the axis goes on down to
//! the table, which reads a flat object lying on it (a plate, a raised letter, a ring) anywhere
//! on its face. The pad enters the box on that ray facing along it (placed there, as the planner
//! returns to a tree vertex without retracing, `planner.rs`), moves along it with the planner's
//! checked expansion steps and guarded motions, and where the sensor feels the object the
//! controllers of Algorithm 1 settle it, exactly as a planner iteration's reading. The motion is
//! an Approach (Fig. 3c) along the pad's normal, so an edge or a slanted face that reaches the
//! pad's rigid back between the covering's samples before any taxel rises hands over to the
//! controllers too, as a rigid contact does in their own Approach; a planner expansion counts it
//! a collision (on the 12 shapes that was 59 of 240 touches, and converged touches rose from 0.66
//! to 0.78 when it handed over). The controllers' turns are limited by the table
//! ([`ArmPad::limited_by_the_table`](crate::control::ArmPad::limited_by_the_table)): on an
//! object's side near the table the wrist (a capsule 2.8 cm across behind a 1.2 cm pad) cannot
//! follow the surface normal to the horizontal, and the reading is taken at the steepest turn it
//! allows rather than lost as `arm_on_table` (68 of 960 touches on the 12 shapes were).
//!
//! An attempt that met the object and failed gets another ([`earns_a_retry`]), straight down from
//! above where it felt the object ([`ApproachRay::from_above`], [`where_felt_m`]), up to
//! [`MAX_ATTEMPTS`] in all. A touch therefore yields one reading attempt, or more when one failed
//! so, each with its status: `converged` (or how the controllers ended), `no_contact` (the ray
//! reached its end untouched), `collision` with who touched whom (the arm or the pad's back on
//! the object or the table), `unreachable` (no inverse-kinematics solution on the ray), or
//! `aborted` (a physics fault; the world put back).

use glam::DVec3;

use super::{Expansion, ExpansionEnd, Planner, Record};
use crate::control::orient::contact_points;
use crate::control::{ControlError, ReadTactile};
use crate::dataset::{AttemptCause, ContactStatus, Reading, Strategy};
use crate::explore::report::{ExplorationReport, unsettled_reading};
use crate::sim::mjcf::TABLE_TOP_Z_M;
use crate::sim::{Arm, PadTarget, Scene, SimError};
use crate::tactile::SensorConfig;

/// Where a guarded ray meets the workspace's vertical axis, as a fraction of the target's height
/// above the table. Steeper rays read flat objects (a ray must come down onto a raised letter
/// before it leaves the letter's face), shallower ones the sides of tall objects; converged
/// readings per guarded touch at random start poses (seed 9, random candidates; the 12 shapes,
/// 40 touches each / the 52 letters, 8 each; docs/measurements.md, "Touches that land"): 0.69 /
/// 0.74 at 0, 0.75 / 0.84 at 0.1, 0.78 / 0.87 at 0.25, **0.80 / 0.82 at 0.3**, 0.81 / 0.73 at
/// 0.35, 0.81 / 0.42 at 0.5, 0.69 at 0.7 (shapes).
pub const AXIS_HEIGHT_FRACTION: f64 = 0.3;

/// Whether a failed attempt of a guarded touch earns another (up to [`MAX_ATTEMPTS`]), straight
/// down from above where it felt the object ([`ApproachRay::from_above`]): when it met the object
/// and failed (a contact lost off an edge, the iterations run out, saturated, the arm or the pad's
/// back on something while moving or settling). An attempt that converged, met nothing on its
/// ray, could not be reached, faulted, or pressed the covering on the table gets none: nothing
/// says the object is there.
pub fn earns_a_retry(failed: &Reading) -> bool {
    !matches!(
        (failed.status, &failed.cause),
        (
            ContactStatus::Converged | ContactStatus::Unreachable | ContactStatus::Aborted,
            _
        ) | (ContactStatus::NoContact, None)
            | (
                _,
                Some(AttemptCause::CoveringOnTable | AttemptCause::PhysicsFault)
            )
    )
}

/// Reading attempts a guarded touch makes at most: the first along its ray, then one from above
/// after each that met the object and failed ([`earns_a_retry`]). Converged readings per touch on
/// the 12 shapes at random start poses (seeds 9, 21, 33, 40 random touches per object, retries
/// through where the pad felt the object, docs/measurements.md "Touches that land"): 0.957 with
/// two attempts, **0.962 with three**, 1.13 -> 1.17 attempts a touch; the rotor (a slotted ring
/// whose top loses a pad off its slots' edges) 0.77 -> 0.80, and 0.80 over seven seeds.
pub const MAX_ATTEMPTS: usize = 3;

/// Where a failed attempt felt the object, in the world: the pad-plane point under the mean of its
/// image's contact taxels (above `threshold`), or the pad's centre when its last image felt nothing
/// (a contact lost). `None` for an attempt without a pad pose. A pad that ended half over an edge
/// or a slot felt the surface on one side; coming down on its centre again would meet the same
/// edge, on what it felt meets the face: converged readings per touch on the rotor 0.72 -> 0.77,
/// on the 12 shapes 0.944 -> 0.957 (two attempts, seeds 9, 21, 33).
fn where_felt_m(failed: &Reading, sensor: &SensorConfig, threshold: f64) -> Option<DVec3> {
    let pose = failed.image.pose()?;
    let felt = contact_points(&failed.image, sensor, threshold);
    if felt.is_empty() {
        return Some(pose.center_m);
    }
    // In the pad's plane: only the point's place across the pad matters to a ray from above.
    let mean = felt.iter().sum::<DVec3>() / felt.len() as f64;
    Some(pose.transform_point(mean.with_z(0.0)))
}

/// A target within this horizontal distance of the workspace's axis is approached straight down,
/// metres (the direction toward the axis is not defined there).
const ON_AXIS_M: f64 = 1e-3;

/// The straight line a guarded touch carries the pad along, facing along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApproachRay {
    /// Where the pad starts: where the ray enters the workspace box (the target itself when it
    /// lies outside the box), metres.
    pub start_m: DVec3,
    /// The direction of travel, unit, always descending: the pad's normal along the way.
    pub direction: DVec3,
    /// Where the pad stops if it has felt nothing: `end_height_m` above the table top, metres.
    pub end_m: DVec3,
}

impl ApproachRay {
    /// The ray through `target` toward the vertical axis of the box `[workspace_min_m,
    /// workspace_max_m]` at [`AXIS_HEIGHT_FRACTION`] of the target's height above the table
    /// (straight down on the axis), from where it enters the box to where it is `end_height_m` above the
    /// table. `None` when the target is not above that height (no descending ray passes through it).
    ///
    /// ```
    /// use glam::DVec3;
    /// use taction::explore::ApproachRay;
    ///
    /// let (min, max) = (DVec3::new(-0.1, -0.1, 0.02), DVec3::new(0.1, 0.1, 0.2));
    /// let ray = ApproachRay::through(DVec3::new(0.05, 0.0, 0.1), min, max, 0.001).unwrap();
    /// // Toward the axis, where it is 0.07 m lower.
    /// assert!((ray.direction - DVec3::new(-0.05, 0.0, -0.07).normalize()).length() < 1e-12);
    /// assert!((ray.start_m.x - 0.1).abs() < 1e-12); // enters through the box's side
    /// assert!((ray.end_m.z - 0.001).abs() < 1e-12);
    /// ```
    pub fn through(
        target: DVec3,
        workspace_min_m: DVec3,
        workspace_max_m: DVec3,
        end_height_m: f64,
    ) -> Option<Self> {
        let height_m = target.z - TABLE_TOP_Z_M;
        if !(target.is_finite() && height_m > end_height_m) {
            return None;
        }
        let axis = 0.5 * (workspace_min_m + workspace_max_m);
        let to_axis = DVec3::new(axis.x - target.x, axis.y - target.y, 0.0);
        let direction = if to_axis.length() < ON_AXIS_M {
            DVec3::NEG_Z
        } else {
            (to_axis - DVec3::Z * ((1.0 - AXIS_HEIGHT_FRACTION) * height_m)).normalize()
        };
        let back_m = distance_to_exit(target, -direction, workspace_min_m, workspace_max_m);
        let ahead_m = (height_m - end_height_m) / -direction.z;
        Some(Self {
            start_m: target - direction * back_m,
            direction,
            end_m: target + direction * ahead_m,
        })
    }

    /// Straight down through `point` from the workspace's top `top_z_m` to `end_height_m` above
    /// the table: a guarded touch's retry ([`earns_a_retry`]). The objects rest on the
    /// table, so what lies under a failed attempt faces up somewhere below it, and a pad coming
    /// down meets it level, which is how the controllers converge best (Sec. V-B1: "the sensor
    /// must approach from an angle reasonably close to the object's surface normal"; the paper's
    /// letters are read from above, Sec. V-B8). Along the normal Orient had turned to instead,
    /// 0.89 of touches converged on the 12 shapes (seeds 9, 21, 33), from above 0.94.
    pub fn from_above(point: DVec3, top_z_m: f64, end_height_m: f64) -> Self {
        Self {
            start_m: DVec3::new(point.x, point.y, top_z_m.max(point.z)),
            direction: DVec3::NEG_Z,
            end_m: DVec3::new(point.x, point.y, TABLE_TOP_Z_M + end_height_m),
        }
    }

    /// The ray's length from start to end, metres.
    pub fn length_m(&self) -> f64 {
        (self.end_m - self.start_m).length()
    }
}

/// How far `from` travels along `direction` (unit) before it leaves the box `[min, max]`; zero
/// when it is outside already.
fn distance_to_exit(from: DVec3, direction: DVec3, min: DVec3, max: DVec3) -> f64 {
    let inside = from.cmpge(min).all() && from.cmple(max).all();
    if !inside {
        return 0.0;
    }
    (0..3)
        .filter(|&i| direction[i] != 0.0)
        .map(|i| {
            let bound = if direction[i] > 0.0 { max[i] } else { min[i] };
            (bound - from[i]) / direction[i]
        })
        .fold(f64::INFINITY, f64::min)
        .max(0.0)
}

impl<R> Planner<R>
where
    R: ReadTactile,
{
    /// The ray of a guarded touch's next attempt after `failed`, if it earns one
    /// ([`earns_a_retry`]): down from the workspace's top through where it felt the object
    /// ([`where_felt_m`]).
    fn retry_ray(&self, failed: &Reading) -> Option<ApproachRay> {
        if !earns_a_retry(failed) {
            return None;
        }
        let felt_m = where_felt_m(failed, &self.setup.sensor, self.setup.control.contact_threshold)?;
        Some(ApproachRay::from_above(
            felt_m,
            self.config.workspace_max_m.z,
            self.setup.sensor.thickness_m,
        ))
    }

    /// One guarded touch through `candidate`'s target (a proposal of
    /// [`propose_candidates`](Self::propose_candidates), or any point above the table; its kind
    /// tags the reading): the pad placed where the [`ApproachRay`] enters the workspace, moved
    /// along it until the sensor feels a surface, and settled there by the controllers
    /// (Algorithm 1). The report holds one reading attempt whatever happened, and another after
    /// each that met the object and failed, [`MAX_ATTEMPTS`] at most ([`earns_a_retry`]; the module
    /// docs list the statuses); a converged one enters the grid and the touch odds, as a planner
    /// iteration's does, and the object is perturbed after every settled attempt.
    pub fn guarded_touch(
        &mut self,
        scene: &mut Scene,
        object: &str,
        candidate: (Strategy, DVec3),
    ) -> Result<ExplorationReport, ControlError> {
        let arm = scene.arm().cloned().ok_or(SimError::NoArm)?;
        let mut record = Record {
            report: ExplorationReport {
                iterations: 1,
                ..ExplorationReport::default()
            },
            on_converged: &mut || {},
        };
        let (min, max) = (self.config.workspace_min_m, self.config.workspace_max_m);
        let ray = ApproachRay::through(candidate.1, min, max, self.setup.sensor.thickness_m);
        // The first attempt's ray (none: the target admits no descending ray), then the retries'.
        let mut next = Some(ray);
        while let Some(ray) = next.take() {
            if let Some(end) = self.approach_along_ray(scene, &arm, object, candidate.0, ray, &mut record)? {
                let at = arm.pad_pose(scene.data());
                let object_pose = scene.object_pose().unwrap_or_default();
                let reading =
                    unsettled_reading(&self.setup.sensor, at, (object, object_pose), candidate.0, end);
                record.push(reading?, scene);
            }
            let attempts = &record.report.readings;
            if let Some(last) = attempts.last().filter(|_| attempts.len() < MAX_ATTEMPTS) {
                next = self.retry_ray(last).map(Some);
            }
        }
        self.odds
            .record(candidate.0, candidate.1, record.report.converged() > 0);
        Ok(record.report)
    }

    /// The guarded approach of [`guarded_touch`](Self::guarded_touch): `None` when the sensor felt
    /// the surface and the controllers' reading is in `record`; else how the touch ended short of
    /// them (status and cause).
    fn approach_along_ray(
        &mut self,
        scene: &mut Scene,
        arm: &Arm,
        object: &str,
        label: Strategy,
        ray: Option<ApproachRay>,
        record: &mut Record<'_>,
    ) -> Result<Option<(ContactStatus, Option<AttemptCause>)>, ControlError> {
        let unreachable = Some((ContactStatus::Unreachable, None));
        let Some(ray) = ray else {
            return Ok(unreachable);
        };
        let start = PadTarget {
            center_m: ray.start_m,
            normal: ray.direction,
        };
        let root = self.tree.vertices()[0].q.clone();
        let Ok(q) = self.expansion_ik.solve(&start, &root) else {
            return Ok(unreachable);
        };
        arm.place(scene, &q);
        if let Some(collision) = arm.collision(scene) {
            return Ok(Some((
                ContactStatus::Collision,
                Some(AttemptCause::from(&collision)),
            )));
        }
        let pad = arm.pad_pose(scene.data());
        let vertex = self.tree.add(0, q, pad.center_m, pad.normal);
        let checkpoint = scene.checkpoint()?;
        let expansion = Expansion {
            vertex,
            // Carried as a local expansion is: facing the vertex's normal, the ray's direction.
            strategy: Strategy::Local,
            label,
            target: ray.end_m,
            object,
            checkpoint: &checkpoint,
            max_steps: (ray.length_m() / self.config.step_m).ceil() as usize + 1,
            guarded: true,
        };
        Ok(match self.expand(scene, arm, &expansion, record) {
            Ok(ExpansionEnd::Read) => None,
            Ok(ExpansionEnd::Collided(c)) => Some((ContactStatus::Collision, Some(AttemptCause::from(&c)))),
            Ok(ExpansionEnd::Unreachable) => unreachable,
            Ok(ExpansionEnd::Nothing) => Some((ContactStatus::NoContact, None)),
            Err(e) if e.is_physics_fault() => {
                scene.restore(&checkpoint)?;
                Some((ContactStatus::Aborted, Some(AttemptCause::PhysicsFault)))
            }
            Err(e) => return Err(e),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MIN: DVec3 = DVec3::new(-0.1, -0.1, 0.02);
    const MAX: DVec3 = DVec3::new(0.1, 0.1, 0.2);

    #[test]
    fn a_ray_passes_through_its_target_descending_from_the_box_to_the_table() {
        for target in [
            DVec3::new(0.09, 0.05, 0.03),
            DVec3::new(-0.02, 0.07, 0.19),
            DVec3::new(0.0, 0.0, 0.1),
            DVec3::new(0.3, 0.0, 0.1),
        ] {
            let ray = ApproachRay::through(target, MIN, MAX, 0.002).unwrap();
            assert!((ray.direction.length() - 1.0).abs() < 1e-12);
            assert!(ray.direction.z < 0.0, "{target}");
            // The target lies on the segment from start to end.
            let along = (target - ray.start_m).dot(ray.direction);
            assert!(((ray.start_m + ray.direction * along) - target).length() < 1e-12);
            assert!(along >= 0.0 && along <= ray.length_m());
            assert!((ray.end_m.z - (TABLE_TOP_Z_M + 0.002)).abs() < 1e-12);
            // The start is on the box's boundary, or the target itself outside it.
            let inside = target.cmpge(MIN).all() && target.cmple(MAX).all();
            if inside {
                let on_face = (0..3).any(|i| {
                    (ray.start_m[i] - MIN[i]).abs() < 1e-12 || (ray.start_m[i] - MAX[i]).abs() < 1e-12
                });
                assert!(on_face, "{target}: {}", ray.start_m);
            } else {
                assert_eq!(ray.start_m, target);
            }
        }
        // On the axis: straight down from the box's top.
        let down = ApproachRay::through(DVec3::new(0.0, 0.0, 0.1), MIN, MAX, 0.002).unwrap();
        assert_eq!(down.direction, DVec3::NEG_Z);
        assert!((down.start_m.z - 0.2).abs() < 1e-12);
    }

    /// A first attempt as the dataset records it: how it ended, `status` and `cause`.
    fn attempt(status: ContactStatus, cause: Option<AttemptCause>) -> Reading {
        Reading {
            image: crate::tactile::TactileImage::zeros(6, 6).unwrap(),
            object: "box".into(),
            object_pose: crate::pose::Pose::default(),
            object_pose_after: None,
            status,
            iterations: 0,
            strategy: Strategy::Global,
            cause,
            contact: None,
        }
    }

    #[test]
    fn a_second_attempt_follows_only_a_failure_that_met_the_object() {
        let touched = |a: &str, b: &str| {
            Some(AttemptCause::Touched {
                body_a: a.into(),
                body_b: b.into(),
            })
        };
        let none = [
            attempt(ContactStatus::Converged, None),
            attempt(ContactStatus::NoContact, None),
            attempt(ContactStatus::Unreachable, None),
            attempt(ContactStatus::Aborted, Some(AttemptCause::PhysicsFault)),
            attempt(ContactStatus::Collision, Some(AttemptCause::CoveringOnTable)),
        ];
        let one = [
            attempt(ContactStatus::NoContact, Some(AttemptCause::LostContact)),
            attempt(ContactStatus::MaxIterations, None),
            attempt(ContactStatus::Saturated, None),
            attempt(ContactStatus::Collision, touched("link4", "world")),
            attempt(ContactStatus::Collision, touched("link4", "object")),
            attempt(ContactStatus::Collision, touched("sensor", "object")),
        ];
        for reading in none {
            assert!(!earns_a_retry(&reading), "{reading:?}");
        }
        for reading in one {
            assert!(earns_a_retry(&reading), "{reading:?}");
        }
    }

    #[test]
    fn a_retry_comes_down_from_the_top_through_where_the_pad_ended() {
        let down = ApproachRay::from_above(DVec3::new(0.03, -0.01, 0.02), MAX.z, 0.002);
        assert_eq!(down.direction, DVec3::NEG_Z);
        assert_eq!(down.start_m, DVec3::new(0.03, -0.01, MAX.z));
        assert!((down.end_m.z - (TABLE_TOP_Z_M + 0.002)).abs() < 1e-12);
        assert_eq!((down.end_m.x, down.end_m.y), (0.03, -0.01));
        // A pad that ended above the box's top starts where it is.
        let high = ApproachRay::from_above(DVec3::new(0.0, 0.0, 0.3), MAX.z, 0.002);
        assert_eq!(high.start_m.z, 0.3);
    }

    #[test]
    fn a_retry_aims_at_the_taxels_that_felt_the_object_or_the_pad_centre() {
        let sensor = SensorConfig::paper();
        // Facing down, row 0 toward +y: the pad's right is +x.
        let pad = crate::pose::PadPose {
            center_m: DVec3::new(0.1, 0.2, 0.05),
            normal: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        let (rows, cols) = (sensor.rows, sensor.cols);
        // Contact in the right half of every row only: a pad half over an edge.
        let values = (0..rows * cols)
            .map(|i| if i % cols >= cols / 2 { 0.4 } else { 0.0 })
            .collect();
        let mut half = attempt(ContactStatus::MaxIterations, None);
        half.image = crate::tactile::TactileImage::new(rows, cols, values)
            .unwrap()
            .with_pose(pad);
        let felt = where_felt_m(&half, &sensor, 0.05).unwrap();
        assert!(
            (felt.x - (0.1 + 0.25 * sensor.pad_width_m)).abs() < 1e-12,
            "{felt}"
        );
        assert!(
            (felt.y - 0.2).abs() < 1e-12 && (felt.z - 0.05).abs() < 1e-12,
            "{felt}"
        );
        // Nothing above the threshold, or nothing felt: the pad's centre.
        assert_eq!(where_felt_m(&half, &sensor, 0.5), Some(pad.center_m));
        let mut lost = attempt(ContactStatus::NoContact, Some(AttemptCause::LostContact));
        lost.image = lost.image.with_pose(pad);
        assert_eq!(where_felt_m(&lost, &sensor, 0.05), Some(pad.center_m));
        // No pose, no point.
        assert_eq!(
            where_felt_m(&attempt(ContactStatus::Saturated, None), &sensor, 0.05),
            None
        );
    }

    #[test]
    fn no_ray_descends_through_a_target_at_the_table_or_not_finite() {
        assert_eq!(
            ApproachRay::through(DVec3::new(0.05, 0.0, 0.001), MIN, MAX, 0.002),
            None
        );
        assert_eq!(
            ApproachRay::through(DVec3::new(f64::NAN, 0.0, 0.1), MIN, MAX, 0.002),
            None
        );
    }
}
