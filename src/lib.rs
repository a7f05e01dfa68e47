//! taction: tactile object recognition from appearance information.
//!
//! A reimplementation of *Tactile Object Recognition From Appearance Information* (Pezzementi,
//! Plaku, Reyda, Hager). Data flows one way through the modules, each using only those above it:
//!
//! ```text
//! mesh       objects as triangle meshes: loading, validation, object sets, raised letters
//! sim        the MuJoCo world: arm (FK/IK/move_to), table, perturbable object (Sec. V-A1)
//! tactile    the covering sensor: a MuJoCo sensor plugin that raycasts penetration (Sec. V-A2)
//! dataset    the hand-off from exploration to recognition: readings and their file, no MuJoCo
//! control    Approach / Press / Orient (Sec. III-B, Algorithm 1)
//! explore    the planner (Sec. III-A), the training sampler (Sec. V-A3), collection into datasets
//! describe   the six tactile image descriptors (Sec. IV-B)
//! recognize  bag-of-features: PCA, codebooks, cross-entropy decision (Sec. IV-A, V-B1)
//! active_touch  the planner steered by expected information gain (beyond the paper, Sec. VI)
//! experiment the run framework: resumable, shardable runs writing tidy CSV, plots and an index
//! paper      the paper's figures (Sec. V) as experiments on that framework
//! ```
//!
//! `describe` and `recognize` know nothing of MuJoCo: they work on [`tactile::TactileImage`]s and
//! datasets, so recorded data from a real sensor can be fed to them. `rng`, `units`, `valid` (configs
//! checked once, at the edge), `atomic` (the one writer of files), `pose` and `bodies` serve every
//! module; `tests/architecture.rs` checks the
//! flow.
//!
//! [`prelude`] gathers the names a user needs first; each module's root re-exports its own public
//! types, and the files behind it are private to the crate.
//!
//! `ARCHITECTURE.md` at the repository's root holds the module map, the decisions the code relies on
//! and the paper's errata.

pub mod atomic;
pub mod bodies;
pub mod pose;
pub mod rng;
pub mod units;
pub mod valid;

pub mod mesh;
pub mod sim;
pub mod tactile;

pub mod dataset;

pub mod control;
pub mod explore;

pub mod describe;
pub mod recognize;

pub mod active_touch;

pub mod prelude;

pub mod experiment;
pub mod paper;
