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
use crate::control::{ControlConfig, ControlError, settle};
use crate::dataset::{ContactStatus, Strategy};
use crate::explore::reach::{ArmReach, carried};
use crate::explore::report::{ExplorationReport, aborted_reading, attempt_reading};
use crate::explore::surface_sampling::SurfaceSampler;
use crate::mesh::TriMesh;
use crate::pose::Pose;
use crate::rng::Rng;
use crate::sim::{ObjectSpec, PerturbationBounds, SimError};
use crate::tactile::{PadPose, SensorConfig};
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

/// Collects `converged_target` converged readings of the object in `scene` (which holds the object and
/// a free-floating pad), perturbing the object after each reading if `perturbation` allows;
/// `on_converged` runs after each converged reading (progress reports).
#[allow(clippy::too_many_arguments)]
pub fn sample_readings(
    pad: &mut FreePad,
    object: &str,
    sensor: SensorConfig,
    control: &Valid<ControlConfig>,
    config: &Valid<SamplerConfig>,
    perturbation: PerturbationBounds,
    converged_target: usize,
    rng: &mut Rng,
    on_converged: &mut dyn FnMut(),
) -> Result<ExplorationReport, ControlError> {
    let mesh: TriMesh = pad.scene().object().ok_or(SimError::NoObject)?.mesh.clone();
    let up_only = config.from_above_only;
    let surface =
        SurfaceSampler::new(&mesh, |n| !up_only || n.z > 30f64.to_radians().cos()).ok_or_else(|| {
            SimError::Object {
                name: object.to_string(),
                message: "no surface area to sample".into(),
            }
        })?;
    let mut reach = match config.reachable_by_arm {
        true => Some(ArmReach::new(ObjectSpec::new(object, mesh.clone()))?),
        false => None,
    };
    let mut report = ExplorationReport::default();
    let max_attempts = converged_target
        .saturating_mul(config.max_attempts_per_reading)
        .max(1);
    let tilt_max = config.orientation_noise_deg.to_radians();
    while report.converged() < converged_target && report.iterations < max_attempts {
        report.iterations += 1;
        let object_pose = pad.scene().object_pose().ok_or(SimError::NoObject)?;
        let local = surface.sample(&mesh, rng);
        let point = object_pose.transform_point(local.point_m);
        let outward = if up_only {
            DVec3::Z
        } else {
            object_pose.transform_vector(local.normal)
        };
        let tilt_axis = random_perpendicular(outward, rng);
        let tilt = DQuat::from_axis_angle(tilt_axis, rng.random_range(0.0..=1.0) * tilt_max);
        let normal = (tilt * -outward).normalize();
        let up = random_perpendicular(normal, rng);
        let mut start = PadPose {
            center_m: point + outward * config.back_off_m,
            normal,
            up,
        };
        if let Some(reach) = &mut reach {
            // The arm knows neither the object nor its heading on the table (Sec. III-A): the
            // start is tested with the object turned about the vertical by a random angle.
            let heading = DQuat::from_rotation_z(rng.random_range(0.0..std::f64::consts::TAU));
            let to_arm = reach
                .object_pose()
                .compose(&Pose::new(DVec3::ZERO, heading))
                .compose(&object_pose.inverse());
            match reach.start_pose(&carried(&start, &to_arm)) {
                Some(arm_start) => start = carried(&arm_start, &to_arm.inverse()),
                None => continue,
            }
        }
        // A physics fault during the attempt puts the world back as it was before it.
        let checkpoint = pad.scene_mut().checkpoint()?;
        pad.place(&start);
        let reading = match settle(pad, control) {
            Ok(outcome) => attempt_reading(outcome, object, object_pose, Strategy::Sampler),
            Err(e) if e.is_physics_fault() => {
                pad.scene_mut().restore(&checkpoint)?;
                aborted_reading(&sensor, start, object, object_pose, Strategy::Sampler)?
            }
            Err(e) => return Err(e),
        };
        let converged = reading.status == ContactStatus::Converged;
        report.readings.push(reading);
        if converged {
            on_converged();
        }
        if !perturbation.is_none() {
            let scene = pad.scene_mut();
            let width = scene.object_width_m().ok_or(SimError::NoObject)?;
            let p = perturbation.draw(width, rng);
            scene.perturb_object(&p)?;
        }
    }
    Ok(report)
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
