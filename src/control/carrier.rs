//! What the controllers command: anything that carries the pad and takes pose commands.
//!
//! One controller implementation drives both the free-floating pad (a mocap body, Sec. V-A3) and the
//! arm-mounted pad (pose commands through inverse kinematics, executed by MuJoCo stepping).

use crate::sim::{Collision, SimError};
use crate::tactile::{PadPose, SensorConfig, TactileImage};

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
    #[error(transparent)]
    Config(#[from] crate::control::config::ControlConfigError),
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
