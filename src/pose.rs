//! Rigid poses in the world frame (metres, unit quaternions).

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// A rigid transform: a point `p` of the body frame is at `rotation * p + position_m` in the world.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub position_m: DVec3,
    pub rotation: DQuat,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    pub const IDENTITY: Self = Self {
        position_m: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
    };

    pub fn new(position_m: DVec3, rotation: DQuat) -> Self {
        Self {
            position_m,
            rotation: rotation.normalize(),
        }
    }

    /// A body point in world coordinates.
    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.position_m
    }

    /// A body direction in world coordinates.
    pub fn transform_vector(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    /// The inverse transform (world to body).
    pub fn inverse(&self) -> Self {
        let r = self.rotation.inverse();
        Self {
            position_m: -(r * self.position_m),
            rotation: r,
        }
    }

    /// `self` after `other`: first `other`, then `self` (`(self * other)(p) = self(other(p))`).
    pub fn compose(&self, other: &Pose) -> Self {
        Self::new(
            self.transform_point(other.position_m),
            self.rotation * other.rotation,
        )
    }

    /// MuJoCo's quaternion order (w, x, y, z).
    pub fn mujoco_quat(&self) -> [f64; 4] {
        [self.rotation.w, self.rotation.x, self.rotation.y, self.rotation.z]
    }

    /// From MuJoCo's position and (w, x, y, z) quaternion.
    pub fn from_mujoco(pos: [f64; 3], quat: [f64; 4]) -> Self {
        Self::new(
            DVec3::from_array(pos),
            DQuat::from_xyzw(quat[1], quat[2], quat[3], quat[0]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_and_compose_round_trip() {
        let a = Pose::new(
            DVec3::new(0.1, -0.2, 0.3),
            DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1),
        );
        let b = Pose::new(DVec3::new(-0.5, 0.05, 0.2), DQuat::from_rotation_z(0.4));
        let p = DVec3::new(0.7, 0.1, -0.9);
        assert!((a.inverse().transform_point(a.transform_point(p)) - p).length() < 1e-12);
        assert!(
            (a.compose(&b).transform_point(p) - a.transform_point(b.transform_point(p))).length() < 1e-12
        );
        let m = Pose::from_mujoco(a.position_m.to_array(), a.mujoco_quat());
        assert!((m.transform_point(p) - a.transform_point(p)).length() < 1e-12);
    }
}
