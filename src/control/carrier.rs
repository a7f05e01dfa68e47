//! What the controllers command: anything that carries the pad and takes pose commands.
//!
//! One controller implementation drives both the free-floating pad (a mocap body, Sec. V-A3) and the
//! arm-mounted pad (pose commands through inverse kinematics, executed by MuJoCo stepping).

use crate::pose::PadPose;
use crate::sim::{Collision, Scene, SimError};
use crate::tactile::{CoveringSensor, SensorConfig, TactileImage};

/// How a pose command went.
#[derive(Debug, Clone, PartialEq)]
pub enum PadMotion {
    /// The pad is at the commanded pose.
    Moved,
    /// The pad's own rigid back touched a rigid surface (the table: the object's contact with the
    /// pad is what the covering measures, and Press ends on its image, Sec. III-B); the carrier
    /// backed off to its previous pose.
    RigidContact,
    /// The carrier touched something with a rigid part on the way and stopped.
    Collided(Collision),
    /// The pose cannot be reached (inverse kinematics failed within the joint limits).
    Unreachable,
    /// An Orient turn the arm cannot make without touching the table; the pad stayed where it
    /// was (a carrier limited by the table, `ArmPad::limited_by_the_table`).
    TurnOutOfReach,
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

impl ControlError {
    /// Whether the simulation's state went bad ([`SimError::PhysicsFault`]): the attempt is lost,
    /// but the world can be restored from a checkpoint and the run go on.
    pub fn is_physics_fault(&self) -> bool {
        matches!(self, Self::Sim(e) if e.is_physics_fault())
    }
}

/// How a carrier reads its pad: the tactile image of the scene as it is now. Any closure
/// `FnMut(&mut Scene) -> Result<TactileImage, ControlError>` is one (a blanket impl); the plain
/// one is [`sensor_reader`], and wrapping it is how a caller counts reads or injects a fault.
pub trait ReadTactile: FnMut(&mut Scene) -> Result<TactileImage, ControlError> {}

impl<F> ReadTactile for F where F: FnMut(&mut Scene) -> Result<TactileImage, ControlError> {}

/// The reader of a scene's covering sensor: computes kinematics and the position-stage sensors
/// ([`Scene::compute_sensors`]; the plugin computes there, from the site and geom frames) and
/// returns the image. The dynamics stages of a full `mj_forward` would change nothing the plugin
/// reads.
pub fn sensor_reader(sensor: CoveringSensor) -> impl ReadTactile + Send + use<> {
    move |scene: &mut Scene| {
        scene.compute_sensors()?;
        Ok(sensor.read(scene.data())?)
    }
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

/// Where a turned pad retries when its rigid back would meet the table: backed off along the new
/// normal by t/4, t/2, then t, as a compliant wrist would (Press then closes the gap); the arm's
/// carrier retries Orient commands so.
pub fn backed_off(target: &PadPose, thickness_m: f64) -> [PadPose; 3] {
    [0.25, 0.5, 1.0].map(|k| PadPose {
        center_m: target.center_m - target.normal * (k * thickness_m),
        ..*target
    })
}
