//! The MuJoCo world (Sec. V-A1): the articulated arm with the sensor pad on its end, a table, and
//! the object under exploration, free to be perturbed between readings (Sec. V-B4).

pub(crate) mod arm;
pub(crate) mod collision_shell;
pub(crate) mod contact_screen;
pub(crate) mod free_object;
pub(crate) mod ik;
pub(crate) mod mjcf;
mod motion;
pub(crate) mod object;
pub(crate) mod perturb;
pub(crate) mod push;
pub(crate) mod scene;
pub(crate) mod start_pose;
pub(crate) mod twin;

// The world: built from objects and the arm, stepped, saved and restored.
pub use object::{
    DRAWN_MESH_TRIANGLES, LARGE_MESH_TRIANGLES, ObjectMount, ObjectSpec, ObjectSurfaces, ROLLING_FRICTION_M,
    TORSIONAL_FRICTION_M,
};
pub use scene::{
    Scene, SceneBuilder, SceneObject, SceneState, give_back_freed_memory, keep_mujoco_log_off_disk,
};

pub use crate::bodies::{FreeBody, FreeBodyError};

// A free object under the arm: the dynamics stepped while the arm holds, and what they did to it.
pub use free_object::{
    DWELL_S, MotionOutcome, MotionSummary, ObjectMotion, REST_SPEED_M_PER_S, REST_TURN_RAD_PER_S,
    SETTLE_MAX_S, Spread, TABLE_HALF_SIDE_M, TIPPED_RAD,
};

// The arm carrying the pad (its joints, the pad's site), moved by inverse kinematics.
pub use arm::{
    ARM_JOINTS, Arm, Collision, Execution, MoveOptions, MoveOutcome, PAD_BACK_GEOM, PAD_SITE, Watch,
};
pub use ik::{IkError, IkOptions, InverseKinematics, PadTarget};
pub use twin::ArmTwin;

// Kinematic motions' samples cleared of contacts without MuJoCo's collision detection.
pub use contact_screen::{CLEARANCE_M, Screened};

// The object perturbed between readings (Sec. V-B4), and placed at its start
// (`Scene::place_at_start`; the start itself is plain data of the `pose` leaf).
pub use crate::pose::{MaxHeading, StartPose};
pub use perturb::{Perturbation, PerturbationAct, PerturbationBounds};
pub use push::{PUSH_MAX_S, SHOVE_M_PER_S, TWIST_RAD_PER_S};

// MJCF text for code that adds bodies to the world: its sections, the collision group, numbers.
pub use mjcf::{COLLISION_GROUP, Section, comment, numbers, sensed_surface_names};

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
    /// MuJoCo's state went bad (see [`Scene::fault`]): what a caller resets the world from, with
    /// [`Scene::restore`], rather than giving up.
    #[error("physics fault at t = {time_s} s: {what}")]
    PhysicsFault { time_s: f64, what: String },
    #[error("{message}")]
    BadConfiguration { message: String },
}

impl SimError {
    /// Whether this is a [`PhysicsFault`](Self::PhysicsFault), which leaves the world to be restored.
    pub fn is_physics_fault(&self) -> bool {
        matches!(self, Self::PhysicsFault { .. })
    }
}
