//! The covering sensor (Sec. V-A2, DESIGN.md §4): an orthographic depth camera looking through a
//! soft covering of thickness t, blurred by a point-spread, averaged to taxels, with optional noise.
//! It is a MuJoCo sensor plugin (`taction.covering`), so any MuJoCo user reads it from `sensordata`.

pub mod config;
pub mod image;
pub mod plugin;

pub use config::SensorConfig;
pub use image::{ImageError, PadPose, TactileImage};
