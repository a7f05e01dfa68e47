//! The training sampler (Sec. V-A3): the object's pose and mesh are known, so readings come from
//! area-weighted random surface points, approached by the free-floating pad.
//!
//! "First a triangle is selected from the triangular mesh with probability proportional to its area. A
//! point p is then sampled uniformly at random inside the selected triangle and the point p is then moved
//! back some distance in the direction opposite the triangle normal. The sensor is then placed at this
//! location facing toward the triangle. A small perturbation is applied to the sensor orientation and then
//! the local controllers are used to approach the surface and take a measurement."
//!
//! The pad's rotation about its normal is drawn uniformly: the controllers leave it free (Sec. IV), so
//! training sees every in-plane orientation.

use glam::{DQuat, DVec3};
use rand::RngExt;
use serde::{Deserialize, Serialize};

use crate::control::free_pad::FreePad;
use crate::control::{ControlError, settle};
use crate::dataset::{Reading, Strategy};
use crate::explore::reach::{ArmReach, carried};
use crate::explore::report::{ExplorationReport, aborted_reading, attempt_reading};
use crate::explore::setup::TouchSetup;
use crate::explore::surface_sampling::SurfaceSampler;
use crate::mesh::TriMesh;
use crate::pose::PadPose;
use crate::pose::Pose;
use crate::rng::Rng;
use crate::sim::{ObjectSpec, Scene, SimError};
use crate::valid::{Check, FieldChecks, RangeError, Valid};

/// The sampler's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SamplerConfig {
    /// Distance the pad starts from the surface point, along the triangle normal, metres.
    pub back_off_m: f64,
    /// Largest tilt of the pad normal away from the triangle's inward normal, degrees.
    pub orientation_noise_deg: f64,
    /// Approach only from above (the raised letters, Sec. V-D): only faces whose normal points up
    /// (z > cos 30°) are sampled, and the pad looks straight down before the tilt.
    pub from_above_only: bool,
    /// Draws allowed per requested converged reading before giving up.
    pub max_attempts_per_reading: usize,
    /// Only starts the exploring arm could take (`explore::reach`), the object resting as it is
    /// but turned to a random heading about the vertical: the draws the arm cannot reach (the
    /// underside on the table, patches the links cannot get to) are skipped, and the pad starts
    /// with the arm's roll. Off by default: the paper's sampler approaches from every direction.
    pub reachable_by_arm: bool,
}

impl Default for SamplerConfig {
    fn default() -> Self {
        Self {
            back_off_m: 0.006,
            orientation_noise_deg: 10.0,
            from_above_only: false,
            max_attempts_per_reading: 20,
            reachable_by_arm: false,
        }
    }
}

impl Check for SamplerConfig {
    type Error = RangeError;

    /// Every field against its range; the error names the first offender.
    fn check(&self) -> Result<(), RangeError> {
        let Self {
            back_off_m,
            orientation_noise_deg,
            from_above_only: _,
            max_attempts_per_reading,
            reachable_by_arm: _,
        } = *self;
        FieldChecks::of("sampler config")
            .real("back_off_m", back_off_m, back_off_m > 0.0, "(0, inf)")
            // Beyond 90 degrees the pad would face away from the surface point it was aimed at.
            .real(
                "orientation_noise_deg",
                orientation_noise_deg,
                (0.0..=90.0).contains(&orientation_noise_deg),
                "[0, 90]",
            )
            .count(
                "max_attempts_per_reading",
                max_attempts_per_reading,
                max_attempts_per_reading > 0,
                "1 or more",
            )
            .finish()
    }
}

/// A uniformly random unit vector perpendicular to `n`.
fn random_perpendicular(n: DVec3, rng: &mut Rng) -> DVec3 {
    let (a, b) = n.any_orthonormal_pair();
    let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    a * phi.cos() + b * phi.sin()
}

/// The training sampler of one object's run (Sec. V-A3): its parameters, what every touch
/// shares and its random stream; the free pad it moves carries the sensor's reader.
pub struct TrainingSampler {
    config: Valid<SamplerConfig>,
    setup: TouchSetup,
    rng: Rng,
}

impl TrainingSampler {
    pub fn new(config: Valid<SamplerConfig>, setup: TouchSetup, rng: Rng) -> Self {
        Self { config, setup, rng }
    }

    /// Collects `converged_target` converged readings of the object in `pad`'s scene with that
    /// free-floating pad, perturbing the object after each reading if the setup's
    /// perturbation allows; every attempt, whatever its status, is returned in order.
    pub fn sample(
        self,
        pad: &mut FreePad,
        object: &str,
        converged_target: usize,
    ) -> Result<ExplorationReport, ControlError> {
        self.sample_reporting(pad, object, converged_target, &mut || {})
    }

    /// [`sample`](Self::sample), running `on_converged` after each converged reading (progress
    /// reports).
    pub fn sample_reporting(
        self,
        pad: &mut FreePad,
        object: &str,
        converged_target: usize,
        on_converged: &mut dyn FnMut(),
    ) -> Result<ExplorationReport, ControlError> {
        let Self {
            config,
            setup,
            mut rng,
        } = self;
        let mut starts = Starts::on(pad.scene(), object, &config)?;
        let mut report = ExplorationReport::default();
        let max_attempts = converged_target
            .saturating_mul(config.max_attempts_per_reading)
            .max(1);
        while report.converged() < converged_target && report.iterations < max_attempts {
            report.iterations += 1;
            let object_pose = pad.scene().object_pose().ok_or(SimError::NoObject)?;
            let Some(start) = starts.draw(object_pose, &mut rng) else {
                continue;
            };
            let reading = settle_from(pad, &start, &setup, object, object_pose)?;
            let converged = reading.is_converged();
            report.readings.push(reading);
            if converged {
                on_converged();
            }
            if let Some(motion) = setup.perturb(pad.scene_mut(), &mut rng)? {
                report.perturbation_motions.push(motion);
            }
        }
        Ok(report)
    }
}

/// Where the sampler's touches start: area-weighted points of the object's faces (only the
/// upward ones from above), and the arm's reach when only its starts are wanted.
struct Starts {
    mesh: TriMesh,
    surface: SurfaceSampler,
    reach: Option<ArmReach>,
    back_off_m: f64,
    tilt_max_rad: f64,
    from_above: bool,
}

impl Starts {
    /// The starts on the object in `scene` named `object`; an error when it has no face to sample.
    fn on(scene: &Scene, object: &str, config: &SamplerConfig) -> Result<Self, ControlError> {
        let mesh: TriMesh = scene.object().ok_or(SimError::NoObject)?.mesh.clone();
        let up_only = config.from_above_only;
        let surface =
            SurfaceSampler::new(&mesh, |n| !up_only || n.z > 30f64.to_radians().cos()).ok_or_else(|| {
                SimError::Object {
                    name: object.to_string(),
                    message: "no surface area to sample".into(),
                }
            })?;
        let reach = match config.reachable_by_arm {
            true => Some(ArmReach::new(ObjectSpec::new(object, mesh.clone()))?),
            false => None,
        };
        Ok(Self {
            mesh,
            surface,
            reach,
            back_off_m: config.back_off_m,
            tilt_max_rad: config.orientation_noise_deg.to_radians(),
            from_above: up_only,
        })
    }

    /// One start with the object at `object_pose`, or `None` when the arm cannot take it.
    fn draw(&mut self, object_pose: Pose, rng: &mut Rng) -> Option<PadPose> {
        let start = self.facing_a_surface_point(object_pose, rng);
        match &mut self.reach {
            Some(reach) => reachable_start(reach, start, object_pose, rng),
            None => Some(start),
        }
    }

    /// The paper's start (Sec. V-A3): a surface point drawn by area, moved back along the
    /// triangle's normal, the pad facing it with a small random tilt and a uniform roll.
    fn facing_a_surface_point(&self, object_pose: Pose, rng: &mut Rng) -> PadPose {
        let local = self.surface.sample(&self.mesh, rng);
        let point = object_pose.transform_point(local.point_m);
        let outward = if self.from_above {
            DVec3::Z
        } else {
            object_pose.transform_vector(local.normal)
        };
        let tilt_axis = random_perpendicular(outward, rng);
        let tilt = DQuat::from_axis_angle(tilt_axis, rng.random_range(0.0..=1.0) * self.tilt_max_rad);
        let normal = (tilt * -outward).normalize();
        let up = random_perpendicular(normal, rng);
        PadPose {
            center_m: point + outward * self.back_off_m,
            normal,
            up,
        }
    }
}

/// `start` as the arm would take it, or `None` when it cannot. The arm knows neither the object
/// nor its heading on the table (Sec. III-A): the start is tested with the object turned about the
/// vertical by a random angle, and the pad gets the arm's roll.
fn reachable_start(
    reach: &mut ArmReach,
    start: PadPose,
    object_pose: Pose,
    rng: &mut Rng,
) -> Option<PadPose> {
    let heading = DQuat::from_rotation_z(rng.random_range(0.0..std::f64::consts::TAU));
    let to_arm = reach
        .object_pose()
        .compose(&Pose::new(DVec3::ZERO, heading))
        .compose(&object_pose.inverse());
    let arm_start = reach.start_pose(&carried(&start, &to_arm))?;
    Some(carried(&arm_start, &to_arm.inverse()))
}

/// Places the pad at `start` and lets the local controllers approach and take a measurement
/// (Sec. V-A3); a physics fault during the attempt puts the world back as it was before it and
/// gives an `aborted` reading.
fn settle_from(
    pad: &mut FreePad,
    start: &PadPose,
    setup: &TouchSetup,
    object: &str,
    object_pose: Pose,
) -> Result<Reading, ControlError> {
    let checkpoint = pad.scene_mut().checkpoint()?;
    pad.place(start);
    match settle(pad, &setup.control) {
        Ok(outcome) => Ok(attempt_reading(outcome, object, object_pose, Strategy::Sampler)),
        Err(e) if e.is_physics_fault() => {
            pad.scene_mut().restore(&checkpoint)?;
            Ok(aborted_reading(
                &setup.sensor,
                *start,
                object,
                object_pose,
                Strategy::Sampler,
            )?)
        }
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_with_a_range_is_checked_and_named() {
        assert_eq!(SamplerConfig::default().check(), Ok(()));
        for (bad, field) in [
            (
                SamplerConfig {
                    back_off_m: 0.0,
                    ..SamplerConfig::default()
                },
                "back_off_m",
            ),
            (
                SamplerConfig {
                    orientation_noise_deg: 91.0,
                    ..SamplerConfig::default()
                },
                "orientation_noise_deg",
            ),
            (
                SamplerConfig {
                    orientation_noise_deg: f64::NAN,
                    ..SamplerConfig::default()
                },
                "orientation_noise_deg",
            ),
            (
                SamplerConfig {
                    max_attempts_per_reading: 0,
                    ..SamplerConfig::default()
                },
                "max_attempts_per_reading",
            ),
        ] {
            assert_eq!(bad.check().unwrap_err().field, field);
        }
    }
}
