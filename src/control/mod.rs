//! Surface contact control (Sec. III-B, Fig. 3, Algorithm 1): Approach, Press and Orient settle the
//! sensor on the surface so that a patch of surface gives a consistent tactile image.

pub mod status;

pub use status::ContactStatus;
