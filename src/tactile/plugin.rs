//! Registration of the `taction.covering` sensor plugin with MuJoCo.

/// Registers the plugin with MuJoCo, once per process.
pub fn register() {}
