//! `taction._taction`: the library as Python classes that speak numpy. The package `taction`
//! (`python/taction/__init__.py`) re-exports it and adds the Gymnasium environment.
//!
//! Every class is a thin owner of a library type: `Object` of [`taction::mesh::Object`], `Sensor`
//! of [`taction::control::FreePad`]s, `Dataset` of [`taction::dataset::Dataset`], `Model` of
//! [`taction::recognize::Recognizer`], `Posterior` of its [`taction::recognize::ModelPosterior`],
//! `TouchEpisode` of [`taction::active_touch::TouchEpisode`]. Arguments are checked by the
//! library's own checks (`valid::Check`), so an error says what the CLI says, as a
//! `taction.TactionError`. Collection and training release the GIL.

mod args;
mod array;
mod dataset;
mod episode;
mod error;
mod model;
mod object;
mod sensor;

use pyo3::prelude::*;

/// Registers the `taction.covering` sensor plugin with the MuJoCo this module is linked to when the
/// dynamic loader maps it (ELF `.init_array`), as the plugin library does: after `import taction`,
/// stock `mujoco` compiles models that use the sensor, and `mujoco.mj_loadPluginLibrary` on
/// `taction.plugin_path()` (this module's file) is a no-op.
#[used]
#[unsafe(link_section = ".init_array")]
static REGISTER_ON_LOAD: extern "C" fn() = register_on_load;

extern "C" fn register_on_load() {
    taction::tactile::register();
}

#[pymodule]
fn _taction(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("TactionError", m.py().get_type::<error::TactionError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<object::Object>()?;
    m.add_function(wrap_pyfunction!(object::objects, m)?)?;
    m.add_function(wrap_pyfunction!(sensor::scene, m)?)?;
    m.add_class::<sensor::Sensor>()?;
    m.add_class::<dataset::Dataset>()?;
    m.add_function(wrap_pyfunction!(dataset::collect, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::collect_arm_calibration, m)?)?;
    m.add_class::<model::Model>()?;
    m.add_class::<model::Posterior>()?;
    m.add_function(wrap_pyfunction!(model::train, m)?)?;
    m.add_function(wrap_pyfunction!(model::train_for_arm, m)?)?;
    m.add_function(wrap_pyfunction!(model::arm_model, m)?)?;
    m.add_class::<episode::TouchEpisode>()?;
    Ok(())
}
