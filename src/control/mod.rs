//! Surface contact control (Sec. III-B, Fig. 3, Algorithm 1): Approach, Press and Orient settle the
//! sensor on the surface so that a patch of surface gives a consistent tactile image.

pub(crate) mod approach;
pub mod arm_pad;
pub mod carrier;
pub(crate) mod config;
pub mod free_pad;
pub mod orient;
pub(crate) mod press;
pub(crate) mod surface_contact;
pub(crate) mod trace;

pub use arm_pad::ArmPad;
pub use carrier::{ControlError, PadCarrier, PadMotion, ReadTactile, sensor_reader};
pub use config::ControlConfig;
pub use free_pad::FreePad;
pub use surface_contact::{ContactOutcome, ContactReport, settle};
pub use trace::{Command, Trace};
