//! Contact geometry (beyond the paper): where each touch landed, matched against every known
//! object's surface at a pose the recogniser is not told.
//!
//! The paper recognises from the appearance of tactile images alone (Sec. IV), and discards where
//! the arm was when it took them. Every converged reading carries its pad pose, and the arm knows
//! it; systems that recognise in a handful of touches use it (Petrovskaya and Khatib, T-RO 2011:
//! contacts against known meshes with a pose filter; iCLAP: tactile words with their contact
//! positions). This module reads a [`Contact`] from a reading, and the [`GeometryModel`] turns the
//! contacts of the touches so far into `ln p(contacts | O_j)` for every object, with a few pose
//! hypotheses per object fitted to them; `recognize` fuses that with the bag of features. It knows
//! meshes and readings, nothing of MuJoCo, and never reads a reading's `object_pose`.

pub(crate) mod contact;
pub(crate) mod model;
pub(crate) mod pose_fit;
pub(crate) mod predict;
pub(crate) mod surface;
pub(crate) mod track;

pub use contact::{Contact, ContactNoise, Touch};
pub use model::{GeometryError, GeometryModel, GeometryParams, GeometryPosterior};
pub use predict::GainOf;
pub use surface::{ObjectSurface, SURFACE_SPACING_M};
