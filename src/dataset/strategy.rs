//! Which procedure produced a reading.

use serde::{Deserialize, Serialize};

/// The procedure behind a reading: the planner's two growth strategies (Sec. III-A), its active
/// choice among them (beyond the paper, `explore::active`), the training sampler (Sec.
/// V-A3), or a recording from a real sensor (Sec. V-E, V-F).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Strategy {
    /// The planner's global strategy: a uniform target in the workspace, RRT-style expansion.
    Global,
    /// The planner's local strategy: a target near an earlier reading in a sparsely read grid cell.
    Local,
    /// The planner's active strategy (beyond the paper): several global and local proposals drawn
    /// as above, the one with the largest expected information gain about the object's identity
    /// expanded (the paper's future work, Sec. VI).
    Active,
    /// The training sampler: an area-weighted random surface point, object pose known.
    Sampler,
    /// A reading recorded with a physical sensor and imported.
    Recorded,
}

impl Strategy {
    pub const ALL: [Strategy; 5] = [
        Self::Global,
        Self::Local,
        Self::Active,
        Self::Sampler,
        Self::Recorded,
    ];

    /// The snake_case name used in CSV files and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Self::Global => "global",
            Self::Local => "local",
            Self::Active => "active",
            Self::Sampler => "sampler",
            Self::Recorded => "recorded",
        }
    }

    /// Parses [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}
