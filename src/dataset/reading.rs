//! One reading per settling attempt: what exploration hands to recognition.

use serde::{Deserialize, Serialize};

use crate::bodies::{ARM_BODIES, OBJECT_BODY, PAD_BODY};
use crate::dataset::{ContactStatus, Strategy};
use crate::pose::Pose;
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
    /// Why the attempt ended, where its status alone does not say: the bodies that touched (a
    /// `Collision` reading), or the covering on the table.
    pub cause: Option<AttemptCause>,
}

/// What ended a reading attempt short of convergence, beyond its [`ContactStatus`].
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AttemptCause {
    /// Two rigid bodies touched: an arm link or the pad's rigid back, and the object, the table
    /// (`world`) or another arm link. Collision-free motions are the planner's premise (Sec. III-A).
    Touched { body_a: String, body_b: String },
    /// The controllers converged, but the covering's volume reaches the table top: a reading of the
    /// environment, not of the object (see `covering_meets_table`).
    CoveringMeetsTable,
}

/// The kinds of [`AttemptCause`] a user tells apart: who touched whom.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CauseKind {
    /// The pad's body on the object: its rigid back (the covering fully compressed somewhere while
    /// the controllers were still pressing or turning) or, during a motion, its holder.
    PadOnObject,
    /// An arm link (not the pad) on the object.
    ArmOnObject,
    /// Any arm body, the pad included, on the table.
    ArmOnTable,
    /// Two arm links on each other.
    ArmOnArm,
    /// The covering-meets-table rule.
    CoveringOnTable,
}

impl CauseKind {
    pub const ALL: [CauseKind; 5] = [
        Self::PadOnObject,
        Self::ArmOnObject,
        Self::ArmOnTable,
        Self::ArmOnArm,
        Self::CoveringOnTable,
    ];

    /// The snake_case name used in tables.
    pub fn name(self) -> &'static str {
        match self {
            Self::PadOnObject => "pad_on_object",
            Self::ArmOnObject => "arm_on_object",
            Self::ArmOnTable => "arm_on_table",
            Self::ArmOnArm => "arm_on_arm",
            Self::CoveringOnTable => "covering_on_table",
        }
    }
}

impl AttemptCause {
    /// The text of the dataset's `cause` column: `covering_meets_table`, or the two bodies as
    /// `arm_body/other_body` (e.g. `sensor/object`, `link4/world`).
    pub fn name(&self) -> String {
        match self {
            Self::Touched { body_a, body_b } => format!("{body_a}/{body_b}"),
            Self::CoveringMeetsTable => "covering_meets_table".into(),
        }
    }

    /// Parses [`name`](Self::name).
    pub fn from_name(text: &str) -> Option<Self> {
        if text == "covering_meets_table" {
            return Some(Self::CoveringMeetsTable);
        }
        let (a, b) = text.split_once('/')?;
        (!a.is_empty() && !b.is_empty()).then(|| Self::Touched {
            body_a: a.to_string(),
            body_b: b.to_string(),
        })
    }

    /// Who touched whom. The pad's body is the arm's last (`sensor`); the table is the world body.
    pub fn kind(&self) -> CauseKind {
        match self {
            Self::CoveringMeetsTable => CauseKind::CoveringOnTable,
            Self::Touched { body_a, body_b } => {
                let other = body_b.as_str();
                if ARM_BODIES.contains(&other) {
                    CauseKind::ArmOnArm
                } else if other == OBJECT_BODY {
                    if body_a == PAD_BODY {
                        CauseKind::PadOnObject
                    } else {
                        CauseKind::ArmOnObject
                    }
                } else {
                    CauseKind::ArmOnTable
                }
            }
        }
    }
}
