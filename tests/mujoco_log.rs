//! MuJoCo's log stays off the user's disk (`sim::keep_mujoco_log_off_disk`, which the `taction`
//! command calls first): a physics fault is still detected and reported, and no `MUJOCO_LOG.TXT`
//! appears in the working directory. One test in a binary of its own, since it changes the
//! process's working directory and MuJoCo's global log configuration (which `common` switched
//! off before `main`, as for every test binary: the test switches it back on first).

mod common;

use glam::DVec3;
use mujoco_rs::wrappers::mj_logging;
use taction::sim::{ObjectSpec, SceneBuilder, keep_mujoco_log_off_disk};

/// A scene of a box whose velocities are made NaN before a step: MuJoCo warns of a bad velocity,
/// resets the state, and the scene reports the fault.
fn faulted_step() -> Option<String> {
    let object = ObjectSpec::new("box", common::box_mesh(DVec3::new(0.10, 0.08, 0.10)));
    let mut scene = SceneBuilder::with_arm_and_table().object(object).build().unwrap();
    scene.data_mut().qvel_mut().fill(f64::NAN);
    assert!(scene.step().is_err(), "a NaN velocity should fail the step");
    scene.fault()
}

#[test]
fn a_physics_fault_is_reported_without_a_log_file_in_the_working_directory() {
    let dir = tempfile::tempdir().unwrap();
    std::env::set_current_dir(dir.path()).unwrap();
    let log = dir.path().join("MUJOCO_LOG.TXT");

    // MuJoCo's default writes the file (which `common` switched off): on again, so the check
    // below can tell.
    let file_on = mj_logging::log_config().with_logto_file(true);
    // SAFETY: this test is the only one of its binary: no other thread uses MuJoCo.
    unsafe { mj_logging::set_log_config(file_on) };
    let fault = faulted_step().expect("the fault should be reported");
    assert!(fault.contains("bad velocity"), "{fault}");
    assert!(
        log.exists(),
        "MuJoCo's default handler should write {}",
        log.display()
    );
    std::fs::remove_file(&log).unwrap();

    // SAFETY: this test is the only one of its binary: no other thread uses MuJoCo.
    unsafe { keep_mujoco_log_off_disk() };
    let fault = faulted_step().expect("the fault should still be reported");
    assert!(fault.contains("bad velocity"), "{fault}");
    assert!(!log.exists(), "{} was written", log.display());
}
