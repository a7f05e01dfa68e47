//! The names a user of the library reaches for first, in the order of the data flow: the sensor,
//! the controllers, exploration into a dataset, descriptors, and recognition.
//!
//! ```
//! use taction::prelude::*;
//!
//! // The paper's letters sensor, and controllers whose every field is checked once, here.
//! let sensor = SensorConfig::default();
//! assert_eq!(sensor.check(), Ok(()));
//! let control = Valid::new(ControlConfig::default())?;
//! let too_far = ControlConfig { orient_step: 1.5, ..*control };
//! assert_eq!(Valid::new(too_far).unwrap_err().field, "orient_step");
//! # Ok::<(), taction::valid::RangeError>(())
//! ```
//!
//! Everything else stays at its module's root (`taction::recognize::OnlinePosterior`, `taction::recognize::pipeline::GaussianMixture`, ...); the
//! modules' own files are not part of the interface.

pub use crate::control::{ContactOutcome, ControlConfig, FreePad, PadCarrier, settle};
pub use crate::dataset::{ContactStatus, Dataset, DatasetHeader, Reading};
pub use crate::describe::{Descriptor, DescriptorKind};
pub use crate::explore::{Collect, CollectMode, CollectPlan};
pub use crate::explore::{PlannerConfig, SamplerConfig};
pub use crate::mesh::{ObjectSet, TriMesh};
pub use crate::pose::PadPose;
pub use crate::recognize::{
    DescriptorChoice, OnlinePosterior, ReadingRange, Recognizer, TrainConfig, TrainedModel, evaluate, train,
};
pub use crate::sim::{ObjectSpec, PerturbationBounds};
pub use crate::tactile::{CoveringSensor, SensorConfig, TactileImage};
pub use crate::valid::{Check, Valid};
