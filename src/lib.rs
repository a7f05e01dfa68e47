//! taction: tactile object recognition from appearance information.
//!
//! A reimplementation of *Tactile Object Recognition From Appearance Information* (Pezzementi,
//! Plaku, Reyda, Hager). Data flows one way, each module using only those above it: `mesh` (the
//! objects), `sim` (the MuJoCo world and the arm), `tactile` (the covering sensor), `dataset` (the
//! readings, MuJoCo-free), `control` (Algorithm 1), `explore` (the planner and the sampler),
//! `describe` (the six descriptors), `recognize` (bag of features), `active_touch`, `experiment`
//! (the run framework) and `paper` (the paper's experiments on it); `rng`, `units`, `valid`,
//! `atomic`, `pose`, `bodies` and `simd` serve them all. `describe` and `recognize` know nothing of
//! MuJoCo, so recorded frames of a real sensor feed them the same way.
//!
//! The module map, with the paper's section and the files to start from for each module, is
//! section 2 of `ARCHITECTURE.md` at the repository's root (the one map; `tests/architecture.rs`
//! checks the flow), beside the decisions the code relies on and the paper's errata.
//!
//! [`prelude`] gathers the names a user needs first; each module's root re-exports its own public
//! types, and the files behind it are private to the crate. `examples/` holds three short programs
//! (`cargo run --release --example NAME`): `sensor_reading`, `arm_touch`, `recognize_chess`.

pub mod atomic;
pub mod bodies;
pub mod pose;
pub mod queue;
pub mod rng;
pub(crate) mod simd;
pub mod stats;
pub mod units;
pub mod valid;

pub mod mesh;
pub mod sim;
pub mod tactile;

pub mod dataset;

pub mod control;
pub mod explore;

pub mod describe;
pub mod locate;
pub mod recognize;

pub mod active_touch;

pub mod prelude;

pub mod experiment;
pub mod paper;
