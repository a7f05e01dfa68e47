//! taction: tactile object recognition from appearance information.
//!
//! A reimplementation of *Tactile Object Recognition From Appearance Information* (Pezzementi,
//! Plaku, Reyda, Hager). Data flows one way through the modules, each using only those above it:
//!
//! ```text
//! mesh       objects as triangle meshes: loading, validation, object sets, raised letters
//! sim        the MuJoCo world: arm (FK/IK/move_to), table, perturbable object (Sec. V-A1)
//! tactile    the covering sensor: a MuJoCo sensor plugin that raycasts penetration (Sec. V-A2)
//! control    Approach / Press / Orient (Sec. III-B, Algorithm 1)
//! explore    the planner (Sec. III-A) and the training sampler (Sec. V-A3)
//! dataset    readings on disk: the hand-off from exploration to recognition
//! describe   the six tactile image descriptors (Sec. IV-B)
//! recognize  bag-of-features: PCA, codebooks, cross-entropy decision (Sec. IV-A, V-B1)
//! experiment the paper's figures as runs writing tidy CSV and plots (Sec. V)
//! ```
//!
//! `describe` and `recognize` know nothing of MuJoCo: they work on [`tactile::TactileImage`]s and
//! datasets, so recorded data from a real sensor can be fed to them. `rng`, `units` and `atomic`
//! (the one writer of files) serve every module.
//!
//! `ARCHITECTURE.md` at the repository's root holds the module map, the decisions the code relies on
//! and the paper's errata.

pub mod atomic;
pub mod rng;
pub mod units;

pub mod mesh;
pub mod sim;
pub mod tactile;

pub mod control;
pub mod explore;

pub mod dataset;

pub mod describe;
pub mod recognize;

pub mod experiment;
