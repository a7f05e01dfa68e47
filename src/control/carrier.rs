//! What the controllers command: anything that carries the pad and takes pose commands.
//!
//! One controller implementation drives both the free-floating pad (a mocap body, Sec. V-A3) and the
//! arm-mounted pad (pose commands through inverse kinematics, executed by MuJoCo stepping).

use crate::bodies::ARM_BODIES;
use crate::dataset::AttemptCause;
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

/// The collision that stopped a motion, as a reading's cause: the arm's body first.
impl From<&Collision> for AttemptCause {
    fn from(collision: &Collision) -> Self {
        let (a, b) = (&collision.body_a, &collision.body_b);
        let (body_a, body_b) = if ARM_BODIES.contains(&b.as_str()) && !ARM_BODIES.contains(&a.as_str()) {
            (b.clone(), a.clone())
        } else {
            (a.clone(), b.clone())
        };
        Self::Touched { body_a, body_b }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::CauseKind;

    #[test]
    fn causes_put_the_arm_first_round_trip_and_classify() {
        let touched = |a: &str, b: &str| {
            AttemptCause::from(&Collision {
                body_a: a.into(),
                body_b: b.into(),
            })
        };
        let pad = touched("object", "sensor");
        assert_eq!(pad.touched_bodies().as_deref(), Some("sensor/object"));
        assert_eq!(pad.name(), "pad_on_object");
        assert_eq!(touched("link3", "object").kind(), CauseKind::ArmOnObject);
        assert_eq!(touched("world", "link4").kind(), CauseKind::ArmOnTable);
        assert_eq!(touched("base", "link3").kind(), CauseKind::ArmOnArm);
        for cause in [
            pad,
            touched("world", "link4"),
            AttemptCause::CoveringOnTable,
            AttemptCause::LostContact,
            AttemptCause::PhysicsFault,
        ] {
            let bodies = cause.touched_bodies().unwrap_or_default();
            assert_eq!(AttemptCause::from_columns(cause.name(), &bodies), Ok(Some(cause)));
        }
        assert_eq!(AttemptCause::from_columns("", ""), Ok(None));
        for (cause, bodies, wrong) in [
            ("pad_on_object", "", "needs the two bodies"),
            ("pad_on_object", "sensor", "needs the two bodies"),
            (
                "pad_on_object",
                "link4/world",
                "are arm_on_table, not pad_on_object",
            ),
            ("lost_contact", "sensor/object", "names no bodies"),
            ("", "sensor/object", "without a cause"),
            ("sensor/object", "", "unknown cause 'sensor/object'"),
        ] {
            let e = AttemptCause::from_columns(cause, bodies).unwrap_err();
            assert!(e.contains(wrong), "{cause} {bodies}: {e}");
        }
    }
}
