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
    /// The object's pose when the attempt began (it may have been perturbed since the last one).
    pub object_pose: Pose,
    /// A free object's pose when the reading was taken: the touch may have moved it from
    /// `object_pose` (issue 74). `None` where the object is fixed (the paper's mocap mount), which
    /// no touch moves. Left out of the JSON when `None`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object_pose_after: Option<Pose>,
    pub status: ContactStatus,
    /// Press/Orient alternations the controllers ran.
    pub iterations: u32,
    pub strategy: Strategy,
    /// Why the attempt ended, where its status alone does not say: who touched whom (a
    /// `Collision` reading), the covering on the table, contact lost, a physics fault.
    pub cause: Option<AttemptCause>,
    /// The press this reading is one frame of, when a recording took several frames across one
    /// press (issue 73: a sequence imported as one contact's frames, numbered from 0 in the order
    /// of their first frame). `None`: the reading is a contact of its own, as every simulated
    /// reading and every single recorded frame is. Readings of one contact are never split
    /// between training and validation or test. Left out of the JSON when `None`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<u32>,
}

/// The names of what ends an attempt short of convergence: one vocabulary for the dataset's
/// `cause` column, the causes table `collect` and `dataset show` print, and the planner's count of
/// stopped expansion steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CauseKind {
    /// `pad_on_object`: the pad's body on the object: its rigid back (the covering fully
    /// compressed somewhere while the controllers were still pressing or turning) or, during a
    /// motion, its holder.
    PadOnObject,
    /// `arm_on_object`: an arm link (not the pad) on the object.
    ArmOnObject,
    /// `arm_on_table`: any arm body, the pad included, on the table.
    ArmOnTable,
    /// `arm_on_arm`: two arm links on each other.
    ArmOnArm,
    /// `covering_on_table`: the controllers converged, but the covering's volume reaches the table
    /// top: a reading of the environment, not of the object (see `covering_meets_table`).
    CoveringOnTable,
    /// `lost_contact`: `no_contact` after the controllers had pressed (Orient or Press lifted the
    /// pad off a narrow feature), as opposed to an Approach that met nothing.
    LostContact,
    /// `physics_fault`: MuJoCo's state went bad (a `mjWARN_BADQACC`-type warning, or non-finite
    /// positions or velocities); the world was put back as it was when the attempt began.
    PhysicsFault,
}

impl CauseKind {
    pub const ALL: [CauseKind; 7] = [
        Self::PadOnObject,
        Self::ArmOnObject,
        Self::ArmOnTable,
        Self::ArmOnArm,
        Self::CoveringOnTable,
        Self::LostContact,
        Self::PhysicsFault,
    ];

    /// The snake_case name, in files and tables alike.
    pub fn name(self) -> &'static str {
        match self {
            Self::PadOnObject => "pad_on_object",
            Self::ArmOnObject => "arm_on_object",
            Self::ArmOnTable => "arm_on_table",
            Self::ArmOnArm => "arm_on_arm",
            Self::CoveringOnTable => "covering_on_table",
            Self::LostContact => "lost_contact",
            Self::PhysicsFault => "physics_fault",
        }
    }

    /// Parses [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Whether the cause is two rigid bodies touching, which an [`AttemptCause`] names.
    pub fn is_touch(self) -> bool {
        matches!(
            self,
            Self::PadOnObject | Self::ArmOnObject | Self::ArmOnTable | Self::ArmOnArm
        )
    }
}

/// What ended a reading attempt short of convergence, beyond its [`ContactStatus`]: a
/// [`CauseKind`], with the two bodies when bodies touched.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AttemptCause {
    /// Two rigid bodies touched: an arm link or the pad's rigid back (`body_a`), and the object,
    /// the table (`world`) or another arm link. Collision-free motions are the planner's premise
    /// (Sec. III-A).
    Touched { body_a: String, body_b: String },
    /// See [`CauseKind::CoveringOnTable`].
    CoveringOnTable,
    /// See [`CauseKind::LostContact`].
    LostContact,
    /// See [`CauseKind::PhysicsFault`].
    PhysicsFault,
}

impl AttemptCause {
    /// Which of the vocabulary's causes this is. The pad's body is the arm's last (`sensor`); the
    /// table is the world body.
    pub fn kind(&self) -> CauseKind {
        match self {
            Self::CoveringOnTable => CauseKind::CoveringOnTable,
            Self::LostContact => CauseKind::LostContact,
            Self::PhysicsFault => CauseKind::PhysicsFault,
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

    /// The text of the dataset's `cause` column: the kind's name (`pad_on_object`, ...).
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// The text of the dataset's `touched_bodies` column: the two bodies as `arm_body/other_body`
    /// (e.g. `sensor/object`, `link4/world`) when bodies touched.
    pub fn touched_bodies(&self) -> Option<String> {
        match self {
            Self::Touched { body_a, body_b } => Some(format!("{body_a}/{body_b}")),
            _ => None,
        }
    }

    /// Parses the `cause` and `touched_bodies` columns of a dataset file (format 3); the error
    /// says what is wrong. A touch needs its two bodies, and they must be that kind of touch; any
    /// other cause has none.
    pub fn from_columns(cause: &str, touched_bodies: &str) -> Result<Option<Self>, String> {
        if cause.is_empty() {
            return match touched_bodies.is_empty() {
                true => Ok(None),
                false => Err(format!("bodies '{touched_bodies}' without a cause")),
            };
        }
        let names: Vec<&str> = CauseKind::ALL.iter().map(|k| k.name()).collect();
        let kind = CauseKind::from_name(cause)
            .ok_or_else(|| format!("unknown cause '{cause}' (expected one of {})", names.join(", ")))?;
        let parsed = match kind {
            CauseKind::CoveringOnTable => Self::CoveringOnTable,
            CauseKind::LostContact => Self::LostContact,
            CauseKind::PhysicsFault => Self::PhysicsFault,
            _ => Self::touched(touched_bodies).ok_or_else(|| {
                format!("cause '{cause}' needs the two bodies as 'a/b', found '{touched_bodies}'")
            })?,
        };
        if parsed.kind() != kind {
            return Err(format!(
                "bodies '{touched_bodies}' are {}, not {cause}",
                parsed.name()
            ));
        }
        if !kind.is_touch() && !touched_bodies.is_empty() {
            return Err(format!(
                "cause '{cause}' names no bodies, found '{touched_bodies}'"
            ));
        }
        Ok(Some(parsed))
    }

    /// Parses the `cause` column of format 2, which held the bodies themselves (`sensor/object`)
    /// or `covering_meets_table`; a lost contact was left to be inferred, as
    /// [`Reading::inferred_cause`] does.
    pub fn from_format_2(text: &str) -> Option<Self> {
        if text == "covering_meets_table" {
            return Some(Self::CoveringOnTable);
        }
        Self::touched(text)
    }

    /// `a/b` as a touch of body `a` on body `b`.
    fn touched(text: &str) -> Option<Self> {
        let (a, b) = text.split_once('/')?;
        (!a.is_empty() && !b.is_empty() && !b.contains('/')).then(|| Self::Touched {
            body_a: a.to_string(),
            body_b: b.to_string(),
        })
    }
}

impl Reading {
    /// Whether the contact controllers converged (Sec. III-B): the readings recognition uses.
    pub fn is_converged(&self) -> bool {
        self.status == ContactStatus::Converged
    }

    /// The contact as every export writes it (the dataset's `contact` column): its number, or -1
    /// for a reading that is a contact of its own.
    pub fn contact_number(&self) -> i64 {
        self.contact.map_or(-1, i64::from)
    }

    /// The cause a reading with no recorded one has by its status alone: `lost_contact` for a
    /// `no_contact` after the controllers had pressed. What formats 1 and 2, which did not write
    /// it, are read with.
    pub fn inferred_cause(status: ContactStatus, iterations: u32) -> Option<AttemptCause> {
        (status == ContactStatus::NoContact && iterations > 0).then_some(AttemptCause::LostContact)
    }
}
