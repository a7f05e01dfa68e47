//! What the controllers command: anything that carries the pad and takes pose commands.
//!
//! One controller implementation drives both the free-floating pad (a mocap body, Sec. V-A3) and the
//! arm-mounted pad (pose commands through inverse kinematics, executed by MuJoCo stepping).

use mujoco_rs::prelude::MjModel;

use crate::sim::arm::PAD_SITE;
use crate::sim::{Collision, Scene, SimError};
use crate::tactile::{CoveringSensor, PadPose, SensorConfig, TactileImage};

/// How a pose command went.
#[derive(Debug, Clone, PartialEq)]
pub enum PadMotion {
    /// The pad is at the commanded pose.
    Moved,
    /// The pad's own rigid back touched the surface it is pressing (the covering is fully compressed
    /// somewhere under the pad); the carrier backed off to its previous pose.
    RigidContact,
    /// The carrier touched something with a rigid part on the way and stopped.
    Collided(Collision),
    /// The pose cannot be reached (inverse kinematics failed within the joint limits).
    Unreachable,
}

/// Errors that end a controller run abnormally (not a controller outcome such as `NoContact`).
#[derive(Debug, thiserror::Error)]
pub enum ControlError {
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error(transparent)]
    Tactile(#[from] crate::tactile::sensor::TactileError),
    #[error("cannot start the worker threads: {0}")]
    ThreadPool(String),
}

/// A pad that can be read and moved.
pub trait PadCarrier {
    /// The sensor's configuration (pad geometry, covering thickness).
    fn sensor(&self) -> &SensorConfig;
    /// Where the pad is now.
    fn pad_pose(&self) -> PadPose;
    /// The tactile image at the current pose.
    fn read(&mut self) -> Result<TactileImage, ControlError>;
    /// Moves the pad to `target`.
    fn move_pad(&mut self, target: &PadPose) -> Result<PadMotion, ControlError>;
}

/// Whether the object reaches the pad's rigid back in the scene's current configuration.
pub type BackCheck<'s> = Box<dyn FnMut(&mut Scene) -> Result<bool, ControlError> + 's>;

/// The rigid back of the pad in `model`, when a covering sensor sits on the pad site: computes the
/// scene's sensors at the current configuration and asks the covering whether the object reached
/// the back ([`CoveringSensor::back_reached`], exact on the object's triangles). Both carriers take
/// it from the scene, so that the free-floating pad of the training sampler and the arm's pad stop
/// Press at the same depth: a pad whose back passed through the object (the free pad did, until
/// the covering read its target) pressed a sharp feature twice as deep as the arm could, and the
/// model learned images the arm never feels (Sec. III-B's saturation termination).
pub fn pad_back_check<'s>(model: &MjModel) -> Option<BackCheck<'s>> {
    let covering = CoveringSensor::on_site(model, PAD_SITE).ok()?;
    Some(Box::new(move |scene: &mut Scene| {
        scene.compute_sensors();
        Ok(covering.back_reached(scene.model(), scene.data()))
    }))
}

/// Where a turned pad retries when its rigid back would meet the surface: backed off along the new
/// normal by t/4, t/2, then t, as a compliant wrist would (Press then closes the gap); both
/// carriers retry Orient commands so.
pub fn backed_off(target: &PadPose, thickness_m: f64) -> [PadPose; 3] {
    [0.25, 0.5, 1.0].map(|k| PadPose {
        center_m: target.center_m - target.normal * (k * thickness_m),
        ..*target
    })
}
