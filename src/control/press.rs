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

/// How hard the most pressed part of the pad is pressed, as a noise-free taxel value in [0, 1]: the
/// image's maximum without noise. With expected noise a single taxel says little (at 75% noise a
/// taxel at 0.7 reads 1.0 one time in ten, so on a curved patch pressed to a mean of 0.3 some taxel
/// reads "clipped" in most readings, and Press backed off until the iteration budget ran out;
/// Sec. V-C), so the peak is taken over the 3x3 neighbourhood
/// means (the point-spread makes the true image smooth on that scale, while the noise is independent
/// per taxel), and the clamp's bias is undone ([`ControlConfig::signal_of_reading`]).
pub fn pressed_peak(image: &TactileImage, config: &ControlConfig) -> f64 {
    if config.expected_noise_fraction <= 0.0 {
        return image.max();
    }
    let (rows, cols) = (image.rows(), image.cols());
    let mut peak = 0.0_f64;
    for r in 0..rows {
        for c in 0..cols {
            let (mut sum, mut n) = (0.0, 0.0);
            for rr in r.saturating_sub(1)..(r + 2).min(rows) {
                for cc in c.saturating_sub(1)..(c + 2).min(cols) {
                    sum += image.get(rr, cc);
                    n += 1.0;
                }
            }
            peak = peak.max(sum / n);
        }
    }
    config.signal_of_reading(peak)
}

/// Whether the covering is pushed through somewhere (the object at the pad's rigid back). With noise
/// the estimated peak is itself uncertain, so "clipped" is halfway between the saturation threshold
/// and full range rather than the full range exactly.
pub fn is_clipped(image: &TactileImage, config: &ControlConfig) -> bool {
    let level = if config.expected_noise_fraction > 0.0 {
        0.5 * (config.saturation_threshold + 1.0)
    } else {
        CLIPPED
    };
    pressed_peak(image, config) >= level
}

/// How a Press phase ended.
#[derive(Debug, Clone, PartialEq)]
pub enum PressOutcome {
    /// Press terminated; `commanded` tells whether it moved the pad at all in this phase (a command
    /// the carrier refused moved nothing).
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
    let mut moved = false;
    for _ in 0..config.press_max_steps {
        let error = config.target_mean_pressure - image.mean();
        let near_saturation = pressed_peak(&image, config) >= config.saturation_threshold;
        let step_m = if is_clipped(&image, config) {
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
        match carrier.move_pad(&pose)? {
            PadMotion::Moved => moved = true,
            PadMotion::RigidContact => {
                // The covering is fully compressed under part of the pad: the paper's "any single
                // sensor element close to fully saturated" termination, in its strongest form, seen
                // on the covering's samples before the point-spread blurs them (a tip or a ridge
                // narrower than a taxel bottoms out while its blurred taxel reads well below 1).
                // The refused command moved nothing, so the controllers may converge where they
                // are, the rigid back resting on the object.
                image = carrier.read()?;
                break;
            }
            blocked => return Ok(PressOutcome::Blocked(blocked)),
        }
        image = carrier.read()?;
    }
    Ok(PressOutcome::Done {
        image,
        commanded: moved,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(values: impl Fn(usize, usize) -> f64) -> TactileImage {
        let v = (0..36).map(|i| values(i / 6, i % 6)).collect();
        TactileImage::new(6, 6, v).unwrap()
    }

    #[test]
    fn noise_aware_clipping_needs_a_clipped_neighbourhood() {
        let noisy = ControlConfig {
            expected_noise_fraction: 0.75,
            ..ControlConfig::default()
        };
        // One taxel at full range among taxels at 0.7: noise, not a pushed-through covering.
        let one = image(|r, c| if (r, c) == (2, 3) { 1.0 } else { 0.7 });
        assert!(is_clipped(&one, &ControlConfig::default()));
        assert!(!is_clipped(&one, &noisy));
        // A saturated corner read through noise (1 + u clamped: 1 or a bit less).
        let corner = image(|r, c| {
            if r < 3 && c < 3 {
                if (r + c) % 2 == 0 { 1.0 } else { 0.8 }
            } else {
                0.2
            }
        });
        assert!(is_clipped(&corner, &noisy));
        assert!(pressed_peak(&corner, &noisy) <= 1.0);
    }
}
