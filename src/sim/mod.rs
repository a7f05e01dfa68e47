//! The MuJoCo world (Sec. V-A1): the articulated arm with the sensor pad on its end, a table, and
//! the object under exploration, free to be perturbed between readings (Sec. V-B4).

pub mod pose;

pub use pose::Pose;
