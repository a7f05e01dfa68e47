//! Gives every binary, test and bench an rpath to the MuJoCo runtime that `cargo xtask setup`
//! extracted (`.cargo/config.toml` sets `MUJOCO_DYNAMIC_LINK_DIR`), so nothing needs LD_LIBRARY_PATH.
fn main() {
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    if let Ok(dir) = std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
