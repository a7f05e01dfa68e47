//! Recorded readings of a real tactile sensor (Sec. V-E, V-F): the parser lives beside the dataset
//! format, in [`crate::dataset::recorded`] (format and calibration there); the experiments name it
//! here.

pub use crate::dataset::recorded::*;
