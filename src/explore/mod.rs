//! Exploration (Sec. III-A) and training-data collection (Sec. V-A3).

pub mod active;
pub mod collect;
pub mod grid;
pub mod planner;
pub mod reading;
pub mod sampler;
pub mod strategy;
pub mod surface_sampling;
pub mod tree;

pub use active::{ActiveGuidance, Probability, TouchScorer};
pub use planner::{Planner, PlannerConfig};
pub use reading::{AttemptCause, CauseKind, ExplorationReport, Reading};
pub use sampler::{SamplerConfig, sample_readings};
pub use strategy::Strategy;
