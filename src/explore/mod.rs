//! Exploration (Sec. III-A) and training-data collection (Sec. V-A3).

pub mod strategy;

pub use strategy::Strategy;
