//! Exploration (Sec. III-A) and training-data collection (Sec. V-A3).

pub mod active;
pub mod collect;
pub(crate) mod grid;
pub mod planner;
pub(crate) mod reach;
pub(crate) mod report;
pub(crate) mod sampler;
pub(crate) mod setup;
pub(crate) mod surface_sampling;
pub(crate) mod tree;

pub use active::{ActiveGuidance, Probability, TouchScorer};
pub use collect::{Collect, CollectError, CollectMode, CollectPlan, sensor_reader};
pub use grid::ReadingGrid;
pub use planner::{Planner, PlannerConfig};
pub use reach::{ArmReach, carried};
pub use report::ExplorationReport;
pub use sampler::{SamplerConfig, TrainingSampler};
pub use setup::TouchSetup;
pub use surface_sampling::{SurfacePoint, SurfaceSampler};
pub use tree::{ExplorationTree, Vertex};
