//! Press (Fig. 3d): a PD controller along the pad normal toward a target mean taxel value, with a
//! second termination when any taxel nears saturation (Sec. III-B).
//!
//! With error `e_k = target - mean_k`, the step along the normal is
//! `Δ_k = t (k_p e_k + k_d (e_k - e_{k-1}))`, limited to `press_max_step_thickness * t`. For a flat
//! surface the mean changes by `Δ / t` per step, so `k_p = 1` would be dead-beat; a little less damps
//! the overshoot on curved surfaces, where the mean grows faster than linearly with depth.

use crate::control::carrier::{ControlError, PadCarrier, PadMotion};
use crate::control::config::ControlConfig;
use crate::control::trace::{Command, Trace};
use crate::tactile::TactileImage;

/// A taxel at this value is clipped: the object has reached the pad's rigid back.
pub const CLIPPED: f64 = 0.999;

/// How a Press phase ended.
#[derive(Debug, Clone, PartialEq)]
pub enum PressOutcome {
    /// Press terminated; `commanded` tells whether it moved the pad at all in this phase.
    Done { image: TactileImage, commanded: bool },
    /// The carrier could not move.
    Blocked(PadMotion),
}

/// Runs Press until it terminates (mean within tolerance, or a taxel near saturation while the mean
/// is still below target) or `press_max_steps` commands were issued.
pub fn press<C: PadCarrier + ?Sized>(
    carrier: &mut C,
    config: &ControlConfig,
    trace: &mut Trace,
) -> Result<PressOutcome, ControlError> {
    let t = carrier.sensor().thickness_m;
    let mut image = carrier.read()?;
    let tolerance = config.effective_pressure_tolerance(image.values().len());
    let mut previous_error = None;
    let mut commanded = false;
    for _ in 0..config.press_max_steps {
        let error = config.target_mean_pressure - image.mean();
        let near_saturation = image.max() >= config.saturation_threshold;
        let step_m = if image.max() >= CLIPPED {
            // Pushed through the covering: back off whatever the mean says.
            -config.press_max_step_thickness * t * 0.5
        } else if error.abs() <= tolerance || (near_saturation && error > 0.0) {
            break;
        } else {
            let derivative = previous_error.map_or(0.0, |p| error - p);
            let limit = config.press_max_step_thickness * t;
            (t * (config.press_kp * error + config.press_kd * derivative)).clamp(-limit, limit)
        };
        previous_error = Some(error);
        let mut pose = carrier.pad_pose();
        pose.center_m += pose.normal * step_m;
        trace.push(Command::Press, pose);
        commanded = true;
        match carrier.move_pad(&pose)? {
            PadMotion::Moved => {}
            PadMotion::RigidContact => {
                // The covering is fully compressed under part of the pad: the strongest form of the
                // "close to fully saturated" termination.
                image = carrier.read()?;
                break;
            }
            blocked => return Ok(PressOutcome::Blocked(blocked)),
        }
        image = carrier.read()?;
    }
    Ok(PressOutcome::Done { image, commanded })
}
