//! What exploration yields: one reading per settling attempt, and a summary of a run.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::control::ContactStatus;
use crate::explore::strategy::Strategy;
use crate::sim::Pose;
use crate::tactile::TactileImage;

/// One reading: the tactile image (tagged with the pad pose it was taken at) and how it was obtained.
/// Only `Converged` readings are used for recognition; the others are kept for statistics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reading {
    pub image: TactileImage,
    /// Name of the object touched.
    pub object: String,
    /// The object's pose when the reading was taken (it may have been perturbed since the last one).
    pub object_pose: Pose,
    pub status: ContactStatus,
    /// Press/Orient alternations the controllers ran.
    pub iterations: u32,
    pub strategy: Strategy,
}

/// The readings of one exploration or sampling run, and what happened on the way.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExplorationReport {
    /// Every settling attempt, in order.
    pub readings: Vec<Reading>,
    /// Planner iterations (or sampler draws) used.
    pub iterations: usize,
    /// Expansion steps stopped by a collision of the arm.
    pub collisions: usize,
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

    /// Reading attempts by status.
    pub fn by_status(&self) -> BTreeMap<ContactStatus, usize> {
        let mut counts = BTreeMap::new();
        for r in &self.readings {
            *counts.entry(r.status).or_insert(0) += 1;
        }
        counts
    }
}
