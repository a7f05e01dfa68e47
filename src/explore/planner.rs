//! The sampling-based exploration planner (Sec. III-A): blind test-time exploration with the arm.
//!
//! The planner knows only the workspace box. Each iteration picks the local strategy with probability
//! L (once a reading exists), else the global one:
//! - global: a target p uniform in the workspace, expanded from the tree vertex whose pad is nearest p
//!   (RRT-style, pulling exploration toward new places);
//! - local: a target p in a small ball around a reading location drawn from a sparsely read grid cell
//!   ([`ReadingGrid`]), expanded from the nearest vertex.
//!
//! Expansion takes small steps: from the pad toward p to a nearby point p', inverse kinematics for p',
//! a slow guarded `move_to` while the sensor is watched. When the sensor feels the object on the way,
//! surface contact control takes over (Sec. III-B) and its reading is recorded; a converged reading's
//! location enters the grid, and the configuration lifted off the surface along the pad normal joins the
//! tree, so local expansions start facing the surface they read.
//!
//! Returning to a vertex: the arm's state is reset to the vertex configuration. A real arm would retrace
//! the tree's collision-free edges back to it; simulating that retrace would cost time and change no
//! reading, so it is skipped.

use glam::DVec3;
use rand::RngExt;
use serde::{Deserialize, Serialize};

use crate::control::arm_pad::{ArmPad, pad_pose_of_site};
use crate::control::{ContactStatus, ControlConfig, ControlError, settle};
use crate::explore::grid::ReadingGrid;
use crate::explore::reading::{ExplorationReport, Reading};
use crate::explore::strategy::Strategy;
use crate::explore::tree::ExplorationTree;
use crate::rng::Rng;
use crate::sim::{
    IkOptions, InverseKinematics, MoveOptions, MoveOutcome, PadTarget, PerturbationBounds, Scene,
};
use crate::tactile::{SensorConfig, TactileImage};

/// The planner's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerConfig {
    /// Lower corner of the workspace box, metres (the only thing the planner knows of the object).
    pub workspace_min_m: DVec3,
    /// Upper corner of the workspace box, metres.
    pub workspace_max_m: DVec3,
    /// L: probability of the local strategy at each iteration (Sec. V-B3).
    pub local_probability: f64,
    /// Length of one expansion step toward the target, metres.
    pub step_m: f64,
    /// Expansion steps per iteration at most.
    pub max_steps_per_iteration: usize,
    /// Radius of the "small sphere" around a reading location for local targets, metres.
    pub local_radius_m: f64,
    /// Side of the local strategy's grid cells, metres.
    pub grid_cell_m: f64,
    /// Distance the pad is lifted off the surface after a reading, metres.
    pub lift_off_m: f64,
    /// Largest turn of the pad normal toward the direction of motion per global expansion step,
    /// radians: the pad comes to lead the motion (so it meets the object with its covering) without
    /// demanding a wrist flip in one step.
    pub max_turn_per_step_rad: f64,
    /// Iterations allowed before giving up on reaching the requested number of readings.
    pub max_iterations: usize,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            workspace_min_m: DVec3::new(-0.15, -0.15, 0.005),
            workspace_max_m: DVec3::new(0.15, 0.15, 0.22),
            local_probability: 0.5,
            step_m: 0.02,
            max_steps_per_iteration: 12,
            local_radius_m: 0.025,
            grid_cell_m: 0.03,
            lift_off_m: 0.01,
            max_turn_per_step_rad: 30f64.to_radians(),
            max_iterations: 20_000,
        }
    }
}

impl PlannerConfig {
    /// Checks ranges; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        if !(0.0..=1.0).contains(&self.local_probability) {
            return Err(format!(
                "local_probability {} is outside [0, 1]",
                self.local_probability
            ));
        }
        if !(self.workspace_min_m.cmplt(self.workspace_max_m).all()) {
            return Err("workspace_min_m must be below workspace_max_m on every axis".into());
        }
        for (name, v) in [
            ("step_m", self.step_m),
            ("local_radius_m", self.local_radius_m),
            ("grid_cell_m", self.grid_cell_m),
            ("lift_off_m", self.lift_off_m),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(format!("{name} {v} must be a positive length"));
            }
        }
        Ok(())
    }
}

/// The planner's state for one exploration run.
pub struct Planner<R> {
    config: PlannerConfig,
    control: ControlConfig,
    sensor: SensorConfig,
    perturbation: PerturbationBounds,
    /// Precise solver for the controllers' small commands.
    ik: InverseKinematics,
    /// Solver for expansion steps, where a fraction of a millimetre does not matter.
    expansion_ik: InverseKinematics,
    motion: MoveOptions,
    expansion_motion: MoveOptions,
    tree: ExplorationTree,
    grid: ReadingGrid,
    rng: Rng,
    reader: R,
}

/// Tight solver and servo settings for controller commands: sub-millimetre Press steps must be executed
/// to a few hundredths of a millimetre.
pub fn precise_motion() -> (IkOptions, MoveOptions) {
    (
        IkOptions {
            position_tolerance_m: 2e-5,
            angle_tolerance_rad: 0.02_f64.to_radians(),
            ..IkOptions::default()
        },
        MoveOptions {
            tolerance_rad: 5e-5,
            settle_intervals: 300,
            ..MoveOptions::default()
        },
    )
}

impl<R> Planner<R>
where
    R: FnMut(&mut Scene) -> Result<TactileImage, ControlError>,
{
    /// A planner for `scene` (which must have an arm), starting from the arm's current configuration.
    pub fn new(
        scene: &Scene,
        config: PlannerConfig,
        control: ControlConfig,
        sensor: SensorConfig,
        perturbation: PerturbationBounds,
        rng: Rng,
        reader: R,
    ) -> Result<Self, ControlError> {
        config
            .validate()
            .map_err(|message| crate::sim::SimError::BadConfiguration { message })?;
        control.validate()?;
        let arm = scene.arm().cloned().ok_or(crate::sim::SimError::NoArm)?;
        let (ik_options, motion) = precise_motion();
        let ik = InverseKinematics::new(scene.model_arc(), arm.clone(), ik_options);
        let expansion_ik = InverseKinematics::new(scene.model_arc(), arm.clone(), IkOptions::default());
        let q = arm.q(scene.data());
        let pad = pad_pose_of_site(&arm.pad_pose(scene.data()));
        Ok(Self {
            config,
            control,
            sensor,
            perturbation,
            ik,
            expansion_ik,
            motion,
            expansion_motion: MoveOptions::default(),
            tree: ExplorationTree::new(q, pad.center_m, pad.normal),
            grid: ReadingGrid::new(config.workspace_min_m, config.grid_cell_m),
            rng,
            reader,
        })
    }

    pub fn tree(&self) -> &ExplorationTree {
        &self.tree
    }

    pub fn grid(&self) -> &ReadingGrid {
        &self.grid
    }

    /// Explores until `converged_target` converged readings (or the iteration budget); every reading
    /// attempt, whatever its status, is returned in order.
    pub fn explore(
        &mut self,
        scene: &mut Scene,
        object: &str,
        converged_target: usize,
    ) -> Result<ExplorationReport, ControlError> {
        let arm = scene.arm().cloned().ok_or(crate::sim::SimError::NoArm)?;
        let mut report = ExplorationReport::default();
        let threshold = self.control.effective_contact_threshold();
        while report.converged() < converged_target && report.iterations < self.config.max_iterations {
            report.iterations += 1;
            let strategy =
                if !self.grid.is_empty() && self.rng.random_range(0.0..1.0) < self.config.local_probability {
                    Strategy::Local
                } else {
                    Strategy::Global
                };
            let target = match strategy {
                Strategy::Local => match self.grid.local_target(self.config.local_radius_m, &mut self.rng) {
                    Some(p) => p,
                    None => continue,
                },
                _ => {
                    let (lo, hi) = (self.config.workspace_min_m, self.config.workspace_max_m);
                    DVec3::new(
                        self.rng.random_range(lo.x..=hi.x),
                        self.rng.random_range(lo.y..=hi.y),
                        self.rng.random_range(lo.z..=hi.z),
                    )
                }
            };
            let mut vertex = self.tree.nearest(target);
            arm.teleport(scene, &self.tree.vertices()[vertex].q.clone());
            let facing = self.tree.vertices()[vertex].pad_normal;

            for _ in 0..self.config.max_steps_per_iteration {
                let pad = pad_pose_of_site(&arm.pad_pose(scene.data()));
                let to_target = target - pad.center_m;
                let distance = to_target.length();
                if distance < 1e-3 {
                    break;
                }
                let direction = to_target / distance;
                let next = pad.center_m + direction * distance.min(self.config.step_m);
                let normal = match strategy {
                    Strategy::Local => facing,
                    _ => turn_toward(pad.normal, direction, self.config.max_turn_per_step_rad),
                };
                let start = arm.q(scene.data());
                // If the turned pad cannot be reached, try the step keeping the pad's orientation.
                let solved = self
                    .expansion_ik
                    .solve(
                        &PadTarget {
                            center_m: next,
                            normal,
                        },
                        &start,
                    )
                    .or_else(|_| {
                        self.expansion_ik.solve(
                            &PadTarget {
                                center_m: next,
                                normal: pad.normal,
                            },
                            &start,
                        )
                    });
                let Ok(q) = solved else {
                    report.unreachable_steps += 1;
                    break;
                };
                let reader = &mut self.reader;
                let mut sensed = false;
                let mut read_error = None;
                let outcome = arm.move_to(scene, &q, &self.expansion_motion, |s| match reader(s) {
                    Ok(image) => {
                        sensed = image.max() > threshold;
                        sensed
                    }
                    Err(e) => {
                        read_error = Some(e);
                        true
                    }
                })?;
                if let Some(e) = read_error {
                    return Err(e);
                }
                if let MoveOutcome::Collided(_) = outcome {
                    report.collisions += 1;
                    break;
                }
                if !sensed {
                    let pad = pad_pose_of_site(&arm.pad_pose(scene.data()));
                    vertex = self
                        .tree
                        .add(vertex, arm.q(scene.data()), pad.center_m, pad.normal);
                    continue;
                }
                let reading = self.settle_here(scene, object, strategy)?;
                let converged = reading.status == ContactStatus::Converged;
                if converged {
                    let pose = reading.image.pose().copied().unwrap_or(pad);
                    self.grid.add(pose.center_m);
                    let lifted = PadTarget {
                        center_m: pose.center_m - pose.normal * self.config.lift_off_m,
                        normal: pose.normal,
                    };
                    let start = arm.q(scene.data());
                    if let Ok(q_lift) = self.expansion_ik.solve(&lifted, &start) {
                        self.tree.add(vertex, q_lift, lifted.center_m, lifted.normal);
                    }
                }
                report.readings.push(reading);
                if !self.perturbation.is_none() {
                    let width = scene.object_width_m().ok_or(crate::sim::SimError::NoObject)?;
                    let p = self.perturbation.draw(width, &mut self.rng);
                    scene.perturb_object(&p)?;
                }
                break;
            }
        }
        Ok(report)
    }

    /// Hands over to surface contact control at the current pose and packages the outcome.
    fn settle_here(
        &mut self,
        scene: &mut Scene,
        object: &str,
        strategy: Strategy,
    ) -> Result<Reading, ControlError> {
        let object_pose = scene.object_pose().unwrap_or_default();
        let Self {
            ik,
            reader,
            sensor,
            control,
            motion,
            ..
        } = self;
        let mut carrier = ArmPad::new(scene, ik, *sensor, |s: &mut Scene| reader(s), *motion)?;
        let outcome = settle(&mut carrier, control)?;
        Ok(Reading {
            image: outcome.image,
            object: object.to_string(),
            object_pose,
            status: outcome.status,
            iterations: outcome.iterations,
            strategy,
        })
    }
}

/// `from` turned toward `to` (both unit) by at most `max_rad`.
pub fn turn_toward(from: DVec3, to: DVec3, max_rad: f64) -> DVec3 {
    let angle = from.angle_between(to);
    if angle <= max_rad {
        return to;
    }
    let axis = from
        .cross(to)
        .try_normalize()
        .unwrap_or_else(|| from.any_orthonormal_vector());
    glam::DQuat::from_axis_angle(axis, max_rad) * from
}
