//! Exploration (Sec. III-A) and training-data collection (Sec. V-A3).

pub mod grid;
pub mod strategy;
pub mod surface_sampling;
pub mod tree;

pub use strategy::Strategy;
