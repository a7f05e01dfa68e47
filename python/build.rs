//! The extension module finds MuJoCo where the `mujoco` Python package keeps it: the wheel
//! `mujoco==3.17.0` (a dependency of this package) ships `libmujoco.so.3.17.0` in
//! `site-packages/mujoco/`, a sibling of `site-packages/taction/`. So one MuJoCo is loaded whether
//! the user imports `mujoco`, `taction` or both, and the covering plugin this module registers is
//! registered with the MuJoCo that stock `mujoco` uses.
fn main() {
    println!("cargo::rustc-link-arg-cdylib=-Wl,-rpath,$ORIGIN/../mujoco");
}
