//! Numerical inverse kinematics of the pad: damped least squares on MuJoCo's site Jacobian.
//!
//! The task is 5-D: the pad centre `p` (3) and the pad normal `n` (2; rotation about the normal is
//! free, since the descriptors are invariant to it, Sec. IV). With `J_p`, `J_r` the translational and
//! rotational site Jacobians (3 x nv, restricted to the arm's columns) and `P = I - n nᵀ` the projector
//! that removes rotation about the current normal, one iteration solves
//!
//! ```text
//!   J = [ J_p ; w P J_r ],   e = [ p* - p ; w θ a ],   a θ = rotation taking n to n*,
//!   Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e            (damped least squares, Wampler 1986)
//! ```
//!
//! with `w` (metres per radian) weighing orientation against position, then clamps `q + Δq` into the
//! joint limits. Several seeded restarts cover configurations a single descent cannot reach; a target
//! no restart reaches within tolerance is reported [`IkError::Unreachable`], never a wrong pose.

use std::sync::Arc;

use glam::{DMat3, DQuat, DVec3};
use mujoco_rs::prelude::*;
use nalgebra::{DMatrix, DVector, Matrix6, Vector6};
use rand::RngExt;

use crate::rng;
use crate::sim::arm::Arm;
use crate::sim::{Scene, SimError};

/// A pad placement to reach: the pad centre and the direction its normal should point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PadTarget {
    pub center_m: DVec3,
    /// Unit direction for the pad normal (into the covering, toward the object).
    pub normal: DVec3,
}

/// Tolerances and effort of the solver.
#[derive(Debug, Clone, Copy)]
pub struct IkOptions {
    /// Largest accepted position error, metres.
    pub position_tolerance_m: f64,
    /// Largest accepted angle between the pad normal and the target normal, radians.
    pub angle_tolerance_rad: f64,
    /// Iterations per attempt.
    pub max_iterations: usize,
    /// Attempts: the first starts at the given configuration, the rest at seeded random ones.
    pub attempts: usize,
    /// Damping λ of the least-squares step.
    pub damping: f64,
    /// Weight of orientation error, metres per radian.
    pub orientation_weight_m: f64,
    /// Seed of the restart configurations.
    pub seed: u64,
}

impl Default for IkOptions {
    fn default() -> Self {
        Self {
            position_tolerance_m: 2e-4,
            angle_tolerance_rad: 0.2_f64.to_radians(),
            max_iterations: 120,
            attempts: 12,
            damping: 0.02,
            orientation_weight_m: 0.1,
            seed: 0x1b,
        }
    }
}

/// Why no configuration was returned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkError {
    #[error(
        "pad target unreachable within the joint limits (best: {best_position_error_m:.4} m, {best_angle_deg:.2} deg off)"
    )]
    Unreachable {
        best_position_error_m: f64,
        best_angle_deg: f64,
    },
    #[error("pad target is not finite or its normal is zero")]
    BadTarget,
}

/// An IK solver with its own scratch `MjData`, so solving never disturbs the simulation.
pub struct InverseKinematics {
    arm: Arm,
    data: MjData<Arc<MjModel>>,
    options: IkOptions,
    calls: u64,
}

impl InverseKinematics {
    pub fn new(model: Arc<MjModel>, arm: Arm, options: IkOptions) -> Self {
        Self {
            arm,
            data: MjData::new(model),
            options,
            calls: 0,
        }
    }

    /// The solver for the arm of `scene`, on the arm's twin where the scene has one (the same
    /// frames and Jacobian bit for bit, without placing the rest of the world at every iteration:
    /// [`ArmTwin`](crate::sim::ArmTwin)).
    pub fn for_scene(scene: &Scene, options: IkOptions) -> Result<Self, SimError> {
        match scene.arm_twin() {
            Some(twin) => Ok(Self::new(twin.model_arc(), twin.arm().clone(), options)),
            None => {
                let arm = scene.arm().cloned().ok_or(SimError::NoArm)?;
                Ok(Self::new(scene.model_arc(), arm, options))
            }
        }
    }

    pub fn options(&self) -> &IkOptions {
        &self.options
    }

    /// The pad pose at configuration `q` (forward kinematics on the scratch data).
    pub fn forward(&mut self, q: &[f64]) -> crate::pose::Pose {
        self.arm.set_q(&mut self.data, q);
        self.data.kinematics();
        self.arm.site_pose(&self.data)
    }

    /// A configuration within the joint limits placing the pad at `target`, starting the search at
    /// `start`. Deterministic: the restarts depend only on the options' seed and the target.
    pub fn solve(&mut self, target: &PadTarget, start: &[f64]) -> Result<Vec<f64>, IkError> {
        let normal = target.normal.try_normalize().ok_or(IkError::BadTarget)?;
        if !target.center_m.is_finite() {
            return Err(IkError::BadTarget);
        }
        self.calls += 1;
        let target_bits = target
            .center_m
            .to_array()
            .iter()
            .chain(normal.to_array().iter())
            .fold(0u64, |h, v| rng::substream(h, v.to_bits()));
        let mut restarts = rng::stream(self.options.seed, target_bits);
        let mut best = (f64::INFINITY, f64::INFINITY);
        for attempt in 0..self.options.attempts {
            let mut q: Vec<f64> = if attempt == 0 {
                start.to_vec()
            } else {
                self.arm
                    .joints()
                    .iter()
                    .map(|j| restarts.random_range(j.range_rad[0]..=j.range_rad[1]))
                    .collect()
            };
            self.arm.clamp(&mut q);
            match self.descend(&mut q, target.center_m, normal, None) {
                Ok(()) => return Ok(q),
                Err((dp, da)) => {
                    if dp + da * self.options.orientation_weight_m
                        < best.0 + best.1 * self.options.orientation_weight_m
                    {
                        best = (dp, da);
                    }
                }
            }
        }
        Err(IkError::Unreachable {
            best_position_error_m: best.0,
            best_angle_deg: best.1.to_degrees(),
        })
    }

    /// As [`solve`](Self::solve), also turning the pad about its normal so that its image "up" is
    /// `up` (the 6-D task, the projector `P` dropped), tried from `start` alone; where that fails,
    /// the 5-D solve with the roll free. The controllers command the pad's whole frame (Orient turns
    /// it the short way, Press keeps it, `control::orient`): holding the roll through them makes the
    /// arm settle as the free-floating pad does from the same start. With the roll left to the
    /// redundancy the taxel grid turned by up to 40 degrees over a settle on the dragon, and with it
    /// the image that Orient fitted its plane to.
    pub fn solve_with_up(
        &mut self,
        target: &PadTarget,
        up: DVec3,
        start: &[f64],
    ) -> Result<Vec<f64>, IkError> {
        let normal = target.normal.try_normalize().ok_or(IkError::BadTarget)?;
        if let Some(up) = (up - normal * up.dot(normal)).try_normalize()
            && target.center_m.is_finite()
        {
            let mut q = start.to_vec();
            self.arm.clamp(&mut q);
            if self.descend(&mut q, target.center_m, normal, Some(up)).is_ok() {
                return Ok(q);
            }
        }
        self.solve(target, start)
    }

    /// Damped least-squares descent from `q`; `Err` carries the final (position, angle) error.
    /// With `target_up` the angle is that of the whole rotation to the frame (normal, up).
    fn descend(
        &mut self,
        q: &mut [f64],
        target_p: DVec3,
        target_n: DVec3,
        target_up: Option<DVec3>,
    ) -> Result<(), (f64, f64)> {
        let target_rotation = target_up
            .map(|up| DQuat::from_mat3(&DMat3::from_cols(up.cross(target_n), up, target_n)).normalize());
        let w = self.options.orientation_weight_m;
        let lambda2 = self.options.damping * self.options.damping;
        let n_dof = self.arm.dof();
        let nv = self.data.qvel().len();
        let mut error = (f64::INFINITY, f64::INFINITY);
        for _ in 0..self.options.max_iterations {
            self.arm.set_q(&mut self.data, q);
            self.data.kinematics();
            self.data.com_pos();
            let pose = self.arm.site_pose(&self.data);
            let n = pose.transform_vector(DVec3::Z);
            let dp = target_p - pose.position_m;
            let (axis, angle) = match target_rotation {
                Some(r) => shortest_axis_angle(r * pose.rotation.inverse()),
                None => rotation_between(n, target_n),
            };
            error = (dp.length(), angle);
            if error.0 <= self.options.position_tolerance_m && error.1 <= self.options.angle_tolerance_rad {
                return Ok(());
            }
            let (jacp, jacr) = self.data.jac_site(true, true, self.arm.site());
            let proj = match target_rotation {
                Some(_) => nalgebra::Matrix3::identity(),
                None => {
                    nalgebra::Matrix3::identity()
                        - nalgebra::Vector3::new(n.x, n.y, n.z) * nalgebra::RowVector3::new(n.x, n.y, n.z)
                }
            };
            let mut jac = DMatrix::<f64>::zeros(6, n_dof);
            for (c, joint) in self.arm.joints().iter().enumerate() {
                let d = joint.dof_adr;
                let jr = nalgebra::Vector3::new(jacr[d], jacr[nv + d], jacr[2 * nv + d]);
                let pjr = proj * jr * w;
                for r in 0..3 {
                    jac[(r, c)] = jacp[r * nv + d];
                    jac[(3 + r, c)] = pjr[r];
                }
            }
            let rot = axis * angle * w;
            let e = Vector6::new(dp.x, dp.y, dp.z, rot.x, rot.y, rot.z);
            let jjt: Matrix6<f64> = (&jac * jac.transpose()).fixed_view::<6, 6>(0, 0).into_owned()
                + Matrix6::identity() * lambda2;
            let Some(y) = jjt.cholesky().map(|c| c.solve(&e)) else {
                return Err(error);
            };
            let dq: DVector<f64> = jac.transpose() * DVector::from_column_slice(y.as_slice());
            let scale = (0.3 / dq.amax().max(1e-12)).min(1.0);
            for (v, d) in q.iter_mut().zip(dq.iter()) {
                *v += d * scale;
            }
            self.arm.clamp(q);
        }
        Err(error)
    }
}

/// Unit axis and angle (radians, in [0, π]) of rotation `r`, the short way round.
fn shortest_axis_angle(r: DQuat) -> (DVec3, f64) {
    let r = if r.w < 0.0 { -r } else { r };
    let (axis, angle) = r.to_axis_angle();
    (axis.try_normalize().unwrap_or(DVec3::Z), angle)
}

/// Unit axis and angle (radians, in [0, π]) of the shortest rotation taking unit `from` to unit `to`.
pub fn rotation_between(from: DVec3, to: DVec3) -> (DVec3, f64) {
    let cross = from.cross(to);
    let angle = cross.length().atan2(from.dot(to));
    let axis = cross
        .try_normalize()
        .unwrap_or_else(|| from.any_orthonormal_vector());
    (axis, angle)
}
