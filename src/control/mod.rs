//! Surface contact control (Sec. III-B, Fig. 3, Algorithm 1): Approach, Press and Orient settle the
//! sensor on the surface so that a patch of surface gives a consistent tactile image.

pub(crate) mod approach;
pub(crate) mod arm_pad;
pub(crate) mod carrier;
pub(crate) mod config;
pub(crate) mod free_pad;
pub(crate) mod orient;
pub(crate) mod press;
pub(crate) mod surface_contact;
pub(crate) mod trace;

// Settling the pad on the surface (Algorithm 1), configured once, and how it ended.
pub use config::ControlConfig;
pub use surface_contact::{ContactOutcome, ContactReport, settle};
pub use trace::{Command, Trace};

// What carries the pad and reads it: the free pad, the arm, and the reader of the sensor.
pub use arm_pad::ArmPad;
pub use carrier::{ControlError, PadCarrier, PadMotion, ReadTactile, sensor_reader};
pub use free_pad::FreePad;

// Orient's geometry: where a taxel sits on the pad.
