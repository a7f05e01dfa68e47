//! What an exploration or sampling run yields: its readings, and what happened on the way.

use std::collections::BTreeMap;

use crate::bodies::ARM_BODIES;
use crate::dataset::{AttemptCause, CauseKind, ContactStatus, Reading};
use crate::sim::Collision;

/// The collision that stopped a motion, as a reading's cause: the arm's body first.
impl From<&Collision> for AttemptCause {
    fn from(collision: &Collision) -> Self {
        let (a, b) = (&collision.body_a, &collision.body_b);
        let (body_a, body_b) = if ARM_BODIES.contains(&b.as_str()) && !ARM_BODIES.contains(&a.as_str()) {
            (b.clone(), a.clone())
        } else {
            (a.clone(), b.clone())
        };
        Self::Touched { body_a, body_b }
    }
}

/// The readings of one exploration or sampling run, and what happened on the way.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExplorationReport {
    /// Every settling attempt, in order.
    pub readings: Vec<Reading>,
    /// Planner iterations (or sampler draws) used.
    pub iterations: usize,
    /// Expansion steps stopped by a collision of the arm, by who touched whom.
    pub expansion_collisions: BTreeMap<CauseKind, usize>,
    /// Expansion steps with no inverse-kinematics solution.
    pub unreachable_steps: usize,
}

impl ExplorationReport {
    /// Number of converged readings.
    pub fn converged(&self) -> usize {
        self.readings
            .iter()
            .filter(|r| r.status == ContactStatus::Converged)
            .count()
    }

    /// Expansion steps stopped by a collision of the arm.
    pub fn collisions(&self) -> usize {
        self.expansion_collisions.values().sum()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn causes_put_the_arm_first_round_trip_and_classify() {
        let touched = |a: &str, b: &str| {
            AttemptCause::from(&Collision {
                body_a: a.into(),
                body_b: b.into(),
            })
        };
        let pad = touched("object", "sensor");
        assert_eq!(pad.name(), "sensor/object");
        assert_eq!(pad.kind(), CauseKind::PadOnObject);
        assert_eq!(touched("link3", "object").kind(), CauseKind::ArmOnObject);
        assert_eq!(touched("world", "link4").kind(), CauseKind::ArmOnTable);
        assert_eq!(touched("base", "link3").kind(), CauseKind::ArmOnArm);
        for cause in [pad, touched("world", "link4"), AttemptCause::CoveringMeetsTable] {
            assert_eq!(AttemptCause::from_name(&cause.name()), Some(cause));
        }
        assert_eq!(AttemptCause::from_name("sensor"), None);
        assert_eq!(AttemptCause::from_name("/object"), None);
    }
}
