//! The `taction.covering` sensor plugin as a library that MuJoCo loads itself
//! (`mujoco.mj_loadPluginLibrary(path)` in Python, or a plugin folder of MuJoCo's own viewer).
//! Loading runs the constructor below, which registers the plugin with the MuJoCo it resolves to.

/// Runs when the dynamic loader maps this library (ELF `.init_array`), as MuJoCo's own plugin
/// libraries do with `mjPLUGIN_LIB_INIT`.
#[used]
#[unsafe(link_section = ".init_array")]
static REGISTER_ON_LOAD: extern "C" fn() = register_on_load;

extern "C" fn register_on_load() {
    taction::tactile::register();
}
