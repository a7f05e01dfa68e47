//! `taction plugin-path`: where the `taction.covering` plugin library is, for MuJoCo users.
//!
//! The library is the `plugin/` crate (`libtaction_covering.so`), which `cargo xtask setup` builds in
//! release next to the `taction` binary. Python loads it with
//! `mujoco.mj_loadPluginLibrary(path)`; copied into the `plugin/` folder of the installed `mujoco`
//! package (`mujoco.PLUGINS_DIR`), every `import mujoco` loads it, `python -m mujoco.viewer`
//! included.

use std::path::{Path, PathBuf};

use clap::Args;

/// The plugin library's file name on this platform.
pub const PLUGIN_LIBRARY: &str = "libtaction_covering.so";

#[derive(Debug, Args)]
pub struct PluginPathArgs {}

/// No plugin library where the binary looked; names the places and the command that builds it.
#[derive(Debug, thiserror::Error)]
#[error(
    "no {PLUGIN_LIBRARY} in {}; build it with `cargo xtask setup` (or `cargo build --release -p taction-plugin`)",
    .searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(" or ")
)]
pub struct PluginNotBuilt {
    pub searched: Vec<PathBuf>,
}

/// The folders searched for the library, in order: the release folder of the binary's target
/// directory (`target/release/`, where the set-up builds it and the README points), then the
/// binary's own folder (an installed `taction` with the library beside it). A debug build of the
/// plugin (e.g. left by `cargo build --workspace`) reads the same but is slower and ten times
/// larger, so it is found only when there is no release one.
pub fn search_dirs(exe: &Path) -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(dir) = exe.parent() {
        if let Some(profiles) = dir.parent() {
            let release = profiles.join("release");
            if release != dir {
                dirs.push(release);
            }
        }
        dirs.push(dir.to_path_buf());
    }
    dirs
}

/// The absolute path of the plugin library.
pub fn plugin_library() -> Result<PathBuf, Box<dyn std::error::Error>> {
    let exe = std::env::current_exe()?;
    let exe = exe.canonicalize().unwrap_or(exe);
    let dirs = search_dirs(&exe);
    dirs.iter()
        .map(|d| d.join(PLUGIN_LIBRARY))
        .find(|p| p.is_file())
        .ok_or_else(|| PluginNotBuilt { searched: dirs }.into())
}

pub fn run(_args: &PluginPathArgs) -> Result<(), Box<dyn std::error::Error>> {
    println!("{}", plugin_library()?.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_release_build_is_searched_first() {
        assert_eq!(
            search_dirs(Path::new("/w/target/debug/taction")),
            [
                PathBuf::from("/w/target/release"),
                PathBuf::from("/w/target/debug")
            ]
        );
        assert_eq!(
            search_dirs(Path::new("/w/target/release/taction")),
            [PathBuf::from("/w/target/release")]
        );
    }
}
