//! How one run of the surface contact controllers ended.

use serde::{Deserialize, Serialize};

/// The outcome of Approach -> Press <-> Orient (Fig. 3a). Only a [`Converged`](Self::Converged)
/// reading is used for recognition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactStatus {
    /// Press and Orient both issued no command in a row, or the normals agreed within the threshold.
    Converged,
    /// Approach travelled its whole distance without any taxel rising above the contact threshold.
    NoContact,
    /// A taxel reached saturation and pressing could not bring the image back into range.
    Saturated,
    /// The iteration budget ran out before convergence.
    MaxIterations,
    /// The arm or the sensor's rigid back touched the object or the table.
    Collision,
    /// The commanded pad pose has no inverse-kinematics solution within the joint limits.
    Unreachable,
    /// The simulation's state went bad during the attempt (cause `physics_fault`): the world was
    /// put back as it was when the attempt began, and exploration went on.
    Aborted,
}

impl ContactStatus {
    pub const ALL: [ContactStatus; 7] = [
        Self::Converged,
        Self::NoContact,
        Self::Saturated,
        Self::MaxIterations,
        Self::Collision,
        Self::Unreachable,
        Self::Aborted,
    ];

    /// The snake_case name used in CSV files and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::NoContact => "no_contact",
            Self::Saturated => "saturated",
            Self::MaxIterations => "max_iterations",
            Self::Collision => "collision",
            Self::Unreachable => "unreachable",
            Self::Aborted => "aborted",
        }
    }

    /// Parses [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}
