//! What an exploration or sampling run yields: its readings, and what happened on the way.

use std::collections::BTreeMap;

use crate::control::ContactOutcome;
use crate::dataset::{AttemptCause, CauseKind, ContactStatus, Reading, Strategy};
use crate::pose::PadPose;
use crate::pose::Pose;
use crate::sim::ObjectMotion;
use crate::tactile::{SensorConfig, TactileError, TactileImage};

/// The reading of one settling attempt on `object` (at `object_pose`): the controllers' image and
/// status, and what ended the attempt (the collision, or a contact lost after pressing). The one
/// place both carriers' readings are made, so that the planner's and the sampler's causes agree.
pub(crate) fn attempt_reading(
    outcome: ContactOutcome,
    object: &str,
    object_pose: Pose,
    strategy: Strategy,
) -> Reading {
    let cause = match &outcome.collision {
        Some(collision) => Some(AttemptCause::from(collision)),
        None => Reading::inferred_cause(outcome.status, outcome.iterations),
    };
    Reading {
        image: outcome.image,
        object: object.to_string(),
        object_pose,
        object_pose_after: None,
        status: outcome.status,
        iterations: outcome.iterations,
        strategy,
        cause,
        contact: None,
    }
}

/// The reading of an attempt a physics fault aborted: no image (all zeros, at the pad's start
/// pose), status `aborted`, cause `physics_fault`.
pub(crate) fn aborted_reading(
    sensor: &SensorConfig,
    start: PadPose,
    object: &str,
    object_pose: Pose,
    strategy: Strategy,
) -> Result<Reading, TactileError> {
    unsettled_reading(
        sensor,
        start,
        (object, object_pose),
        strategy,
        (ContactStatus::Aborted, Some(AttemptCause::PhysicsFault)),
    )
}

/// The reading of an attempt that never reached the controllers (a guarded touch that met
/// nothing, or was stopped on the way): no image (all zeros, tagged with the pad's pose `at`),
/// `status` and its cause, no controller iterations.
pub(crate) fn unsettled_reading(
    sensor: &SensorConfig,
    at: PadPose,
    (object, object_pose): (&str, Pose),
    strategy: Strategy,
    (status, cause): (ContactStatus, Option<AttemptCause>),
) -> Result<Reading, TactileError> {
    let image = TactileImage::zeros(sensor.rows, sensor.cols)
        .map_err(|source| TactileError::Image {
            sensor: crate::tactile::SENSOR_NAME.into(),
            source,
        })?
        .with_pose(at);
    Ok(Reading {
        image,
        object: object.to_string(),
        object_pose,
        object_pose_after: None,
        status,
        iterations: 0,
        strategy,
        cause,
        contact: None,
    })
}

/// The readings of one exploration or sampling run, and what happened on the way.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExplorationReport {
    /// Every settling attempt, in order.
    pub readings: Vec<Reading>,
    /// Planner iterations (or sampler draws) used.
    pub iterations: usize,
    /// Expansion steps stopped short, by cause: a collision of the arm (who touched whom), or a
    /// physics fault (the world restored to the iteration's start).
    pub expansion_stops: BTreeMap<CauseKind, usize>,
    /// Expansion steps with no inverse-kinematics solution.
    pub unreachable_steps: usize,
    /// Where the object is free ([`ObjectMount::Free`](crate::sim::ObjectMount)): how each
    /// reading's touch moved it, from where it lay when the controllers took over to where the
    /// reading was taken, one per settled reading in order. Empty for a mocap object.
    pub object_motions: Vec<ObjectMotion>,
    /// How each perturbation between readings (Sec. V-B4) moved the object, teleported or
    /// pushed, in order. Empty when the object is not perturbed.
    pub perturbation_motions: Vec<ObjectMotion>,
}

impl ExplorationReport {
    /// Number of converged readings.
    pub fn converged(&self) -> usize {
        self.readings.iter().filter(|r| r.is_converged()).count()
    }

    /// Expansion steps stopped by a collision of the arm.
    pub fn collisions(&self) -> usize {
        self.expansion_stops
            .iter()
            .filter(|(kind, _)| kind.is_touch())
            .map(|(_, n)| n)
            .sum()
    }

    /// Physics faults met, in reading attempts and in expansion steps alike.
    pub fn physics_faults(&self) -> usize {
        let in_readings = self
            .readings
            .iter()
            .filter(|r| r.cause == Some(AttemptCause::PhysicsFault))
            .count();
        in_readings
            + self
                .expansion_stops
                .get(&CauseKind::PhysicsFault)
                .copied()
                .unwrap_or(0)
    }

    /// Reading attempts by status.
    pub fn by_status(&self) -> BTreeMap<ContactStatus, usize> {
        let mut counts = BTreeMap::new();
        for r in &self.readings {
            *counts.entry(r.status).or_insert(0) += 1;
        }
        counts
    }
}
