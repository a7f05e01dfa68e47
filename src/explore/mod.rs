//! Exploration (Sec. III-A) and training-data collection (Sec. V-A3).

pub mod active;
pub mod collect;
pub mod grid;
pub mod planner;
pub mod report;
pub mod sampler;
pub mod surface_sampling;
pub mod tree;

pub use active::{ActiveGuidance, Probability, TouchScorer};
pub use planner::{Planner, PlannerConfig};
pub use report::ExplorationReport;
pub use sampler::{SamplerConfig, sample_readings};
