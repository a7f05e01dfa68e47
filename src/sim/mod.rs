//! The MuJoCo world (Sec. V-A1): the articulated arm with the sensor pad on its end, a table, and
//! the object under exploration, free to be perturbed between readings (Sec. V-B4).

pub mod arm;
pub(crate) mod collision_shell;
pub(crate) mod ik;
pub mod mjcf;
pub(crate) mod object;
pub(crate) mod perturb;
pub(crate) mod scene;

pub use arm::{Arm, Collision, MoveOptions, MoveOutcome};
pub use ik::{IkError, IkOptions, InverseKinematics, PadTarget};
pub use object::{ObjectMount, ObjectSpec};
pub use perturb::{Perturbation, PerturbationBounds};
pub use scene::{Scene, SceneBuilder, SceneObject};

/// Errors of the simulated world; each says which part and what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    #[error("MJCF ({origin}): {message}")]
    Mjcf { origin: String, message: String },
    #[error("object '{name}': {message}")]
    Object { name: String, message: String },
    #[error("the scene has no object")]
    NoObject,
    #[error("the scene has no arm")]
    NoArm,
    #[error("physics: {message}")]
    Physics { message: String },
    #[error("{message}")]
    BadConfiguration { message: String },
}
