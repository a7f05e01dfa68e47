//! Every threshold and gain of the surface contact controllers, with units.

use serde::{Deserialize, Serialize};

use crate::valid::{Check, FieldChecks, RangeError};

/// Configuration of Approach, Press and Orient (Sec. III-B). Pressures are fractions of the sensing
/// range (taxel values in [0, 1]); lengths are metres or multiples of the covering thickness t.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlConfig {
    /// A taxel above this value (fraction of range) is in contact ("significantly above zero",
    /// Approach, Fig. 3c), on top of the noise allowance below.
    pub contact_threshold: f64,
    /// Additive noise amplitude the controllers should expect (fraction of range, as the sensor's
    /// `noise_fraction`): contact needs a taxel above `contact_threshold + noise_fraction / 2`, the
    /// largest value noise alone can produce, and tolerances widen with it.
    pub expected_noise_fraction: f64,
    /// Approach step as a fraction of t: small enough that first contact does not push through.
    pub approach_step_thickness: f64,
    /// Distance Approach travels before giving up with `NoContact`, metres.
    pub approach_max_distance_m: f64,
    /// Press target: the mean taxel value ("the average pressure of all sensor elements", Sec. III-B,
    /// which gives no value). A firmer press shows more of a curved patch but converges less often
    /// through noise; 0.3 keeps the controllers converging at high noise (Fig. 14). The
    /// measurements behind the choice: `docs/measurements.md`, "How firmly Press presses".
    pub target_mean_pressure: f64,
    /// Press stops commanding when |target - mean| is below this (fraction of range).
    pub pressure_tolerance: f64,
    /// Press proportional gain: metres per unit pressure error, in multiples of t.
    pub press_kp: f64,
    /// Press derivative gain: metres per unit change of pressure error, in multiples of t.
    pub press_kd: f64,
    /// Largest Press step, in multiples of t.
    pub press_max_step_thickness: f64,
    /// Press steps allowed in one Press phase.
    pub press_max_steps: usize,
    /// Press's second termination: a taxel at or above this value is "close to fully saturated"
    /// (Sec. III-B gives no value). Kept below the clip level: at the clip level Press oscillates
    /// between clipping and backing off wherever the pad cannot reach the target without bottoming
    /// out, and the patches it would have read drop out of the data (`docs/measurements.md`, "How
    /// firmly Press presses").
    pub saturation_threshold: f64,
    /// Orient rotates the pad normal this fraction of the way to the fitted surface normal
    /// (Algorithm 1, line 11: step = 0.3).
    pub orient_step: f64,
    /// Orient issues no command when pad and surface normals agree within this angle, radians.
    /// Deliberately not widened with the expected noise: a wider tolerance converges no more
    /// often and leaves the converged pad more misaligned (`docs/measurements.md`, "How Orient
    /// turns").
    pub orient_tolerance_rad: f64,
    /// Largest rotation of one Orient command, radians.
    pub orient_max_step_rad: f64,
    /// Press/Orient alternations before `MaxIterations`.
    pub max_iterations: usize,
    /// Keep Orient from tilting over an edge (`orient.rs`, `surface_normal`):
    /// fit the plane to the taxels inside the contact patch, whose coverage is whole, and issue no
    /// tilt when the fitted plane says the surface comes well into the covering where a taxel reads
    /// no contact. Off by default, because it costs recognition: a pad tipped over a stroke's edge
    /// onto the plate shows the stroke's edge and the plate, which tells letters apart better than
    /// a level stroke top (`docs/measurements.md`, "How Orient turns").
    pub orient_edge_guard: bool,
}

impl Default for ControlConfig {
    fn default() -> Self {
        Self {
            contact_threshold: 0.05,
            expected_noise_fraction: 0.0,
            approach_step_thickness: 0.25,
            approach_max_distance_m: 0.05,
            target_mean_pressure: 0.3,
            pressure_tolerance: 0.01,
            press_kp: 0.8,
            press_kd: 0.1,
            press_max_step_thickness: 0.5,
            press_max_steps: 40,
            saturation_threshold: 0.95,
            orient_step: 0.3,
            orient_tolerance_rad: 1.0_f64.to_radians(),
            orient_max_step_rad: 15.0_f64.to_radians(),
            max_iterations: 40,
            orient_edge_guard: false,
        }
    }
}

impl Check for ControlConfig {
    type Error = RangeError;

    /// Every field against its range (and finite); the error names the first offender.
    fn check(&self) -> Result<(), RangeError> {
        let Self {
            contact_threshold,
            expected_noise_fraction,
            approach_step_thickness,
            approach_max_distance_m,
            target_mean_pressure,
            pressure_tolerance,
            press_kp,
            press_kd,
            press_max_step_thickness,
            press_max_steps,
            saturation_threshold,
            orient_step,
            orient_tolerance_rad,
            orient_max_step_rad,
            max_iterations,
            orient_edge_guard: _,
        } = *self;
        let mut checks = FieldChecks::of("control config");
        check_contact(&mut checks, contact_threshold, expected_noise_fraction);
        check_approach(&mut checks, approach_step_thickness, approach_max_distance_m);
        check_press(
            &mut checks,
            PressFields {
                target_mean_pressure,
                pressure_tolerance,
                press_kp,
                press_kd,
                press_max_step_thickness,
                press_max_steps,
                saturation_threshold,
            },
        );
        check_orient(
            &mut checks,
            orient_step,
            orient_tolerance_rad,
            orient_max_step_rad,
        )
        .count("max_iterations", max_iterations, max_iterations > 0, "1 or more")
        .finish()
    }
}

/// What counts as contact: the threshold and the noise the controllers expect.
fn check_contact(
    checks: &mut FieldChecks,
    contact_threshold: f64,
    expected_noise_fraction: f64,
) -> &mut FieldChecks {
    checks
        .real(
            "contact_threshold",
            contact_threshold,
            (0.0..1.0).contains(&contact_threshold),
            "[0, 1)",
        )
        .real(
            "expected_noise_fraction",
            expected_noise_fraction,
            (0.0..=2.0).contains(&expected_noise_fraction),
            "[0, 2]",
        )
}

/// Approach's step and reach.
fn check_approach(
    checks: &mut FieldChecks,
    approach_step_thickness: f64,
    approach_max_distance_m: f64,
) -> &mut FieldChecks {
    checks
        .real(
            "approach_step_thickness",
            approach_step_thickness,
            approach_step_thickness > 0.0 && approach_step_thickness <= 1.0,
            "(0, 1]",
        )
        .real(
            "approach_max_distance_m",
            approach_max_distance_m,
            approach_max_distance_m > 0.0,
            "(0, inf)",
        )
}

/// Press's fields, as [`ControlConfig`] names them.
struct PressFields {
    target_mean_pressure: f64,
    pressure_tolerance: f64,
    press_kp: f64,
    press_kd: f64,
    press_max_step_thickness: f64,
    press_max_steps: usize,
    saturation_threshold: f64,
}

/// Press's target, gains, steps and saturation.
fn check_press(checks: &mut FieldChecks, press: PressFields) -> &mut FieldChecks {
    let PressFields {
        target_mean_pressure,
        pressure_tolerance,
        press_kp,
        press_kd,
        press_max_step_thickness,
        press_max_steps,
        saturation_threshold,
    } = press;
    checks
        .real(
            "target_mean_pressure",
            target_mean_pressure,
            target_mean_pressure > 0.0 && target_mean_pressure < 1.0,
            "(0, 1)",
        )
        .real(
            "pressure_tolerance",
            pressure_tolerance,
            pressure_tolerance > 0.0,
            "(0, inf)",
        )
        .real("press_kp", press_kp, press_kp > 0.0 && press_kp <= 2.0, "(0, 2]")
        .real("press_kd", press_kd, (0.0..=2.0).contains(&press_kd), "[0, 2]")
        .real(
            "press_max_step_thickness",
            press_max_step_thickness,
            press_max_step_thickness > 0.0,
            "(0, inf)",
        )
        .count(
            "press_max_steps",
            press_max_steps,
            press_max_steps > 0,
            "1 or more",
        )
        .real(
            "saturation_threshold",
            saturation_threshold,
            saturation_threshold > target_mean_pressure && saturation_threshold <= 1.0,
            "(target_mean_pressure, 1]",
        )
}

/// Orient's step, tolerance and largest turn.
fn check_orient(
    checks: &mut FieldChecks,
    orient_step: f64,
    orient_tolerance_rad: f64,
    orient_max_step_rad: f64,
) -> &mut FieldChecks {
    checks
        .real(
            "orient_step",
            orient_step,
            orient_step > 0.0 && orient_step <= 1.0,
            "(0, 1]",
        )
        .real(
            "orient_tolerance_rad",
            orient_tolerance_rad,
            orient_tolerance_rad > 0.0,
            "(0, inf)",
        )
        // A negative step would turn the pad away from the surface; beyond a half turn the
        // rotation is no longer the short way round.
        .real(
            "orient_max_step_rad",
            orient_max_step_rad,
            orient_max_step_rad > 0.0 && orient_max_step_rad <= std::f64::consts::PI,
            "(0, pi]",
        )
}

impl ControlConfig {
    /// The taxel value that counts as contact: the threshold above the largest value noise alone gives.
    pub fn effective_contact_threshold(&self) -> f64 {
        (self.contact_threshold + self.expected_noise_fraction * 0.5).min(0.99)
    }

    /// Pressure tolerance widened by the noise on the mean of `taxels` values (its standard deviation,
    /// `a / sqrt(3 n)` for uniform noise of half-width `a`, times 3).
    pub fn effective_pressure_tolerance(&self, taxels: usize) -> f64 {
        let half_width = self.expected_noise_fraction * 0.5;
        self.pressure_tolerance + 3.0 * half_width / (3.0 * taxels.max(1) as f64).sqrt()
    }

    /// The expected reading of a taxel whose noise-free value is `signal`: uniform noise of the
    /// expected width, then the sensor's clamp to [0, 1] (`E[clamp(s + u)]`, `u ~ U(-a, a)`). The
    /// clamp biases the mean of a taxel near 0 up and near 1 down (a saturated taxel reads
    /// `1 - a/4` on average).
    pub fn expected_reading(&self, signal: f64) -> f64 {
        let a = self.expected_noise_fraction * 0.5;
        if a <= 0.0 {
            return signal.clamp(0.0, 1.0);
        }
        // Antiderivative of clamp(x, 0, 1).
        let f = |x: f64| {
            if x <= 0.0 {
                0.0
            } else if x <= 1.0 {
                0.5 * x * x
            } else {
                x - 0.5
            }
        };
        (f(signal + a) - f(signal - a)) / (2.0 * a)
    }

    /// The noise-free value whose [`expected_reading`](Self::expected_reading) is `reading`
    /// (bisection; the function increases with the signal), in [0, 1].
    pub fn signal_of_reading(&self, reading: f64) -> f64 {
        if self.expected_noise_fraction <= 0.0 {
            return reading.clamp(0.0, 1.0);
        }
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
        if reading <= self.expected_reading(lo) {
            return lo;
        }
        if reading >= self.expected_reading(hi) {
            return hi;
        }
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.expected_reading(mid) < reading {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        assert_eq!(ControlConfig::default().check(), Ok(()));
        let bad = ControlConfig {
            orient_step: 1.5,
            ..ControlConfig::default()
        };
        let e = bad.check().unwrap_err();
        assert_eq!(e.field, "orient_step");
        assert!(e.to_string().contains("(0, 1]"));
        let bad = ControlConfig {
            saturation_threshold: 0.2,
            ..ControlConfig::default()
        };
        assert_eq!(bad.check().unwrap_err().field, "saturation_threshold");
    }

    #[test]
    fn every_field_is_checked() {
        // Each field in turn set out of range (negative, or zero for the counts) must be the one named.
        let defaults = serde_json::to_value(ControlConfig::default()).unwrap();
        let fields = defaults.as_object().unwrap();
        assert_eq!(fields.len(), 16);
        // The one switch has no range to leave; serde refuses a non-boolean for it.
        for (name, value) in fields.iter().filter(|(_, v)| !v.is_boolean()) {
            let mut bad = fields.clone();
            let out_of_range = if value.is_u64() {
                serde_json::json!(0)
            } else {
                serde_json::json!(-1.0)
            };
            bad.insert(name.clone(), out_of_range);
            let config: ControlConfig = serde_json::from_value(serde_json::Value::Object(bad)).unwrap();
            let error = config.check().expect_err(name);
            assert_eq!(error.field, name.as_str());
        }
        let mut not_a_switch = fields.clone();
        not_a_switch.insert("orient_edge_guard".into(), serde_json::json!(1.0));
        let error =
            serde_json::from_value::<ControlConfig>(serde_json::Value::Object(not_a_switch)).unwrap_err();
        assert!(error.to_string().contains("boolean"), "{error}");
        let nan = ControlConfig {
            orient_max_step_rad: f64::NAN,
            ..ControlConfig::default()
        };
        assert_eq!(nan.check().unwrap_err().field, "orient_max_step_rad");
    }

    #[test]
    fn expected_reading_models_the_clamp_and_inverts() {
        let c = ControlConfig {
            expected_noise_fraction: 0.75,
            ..ControlConfig::default()
        };
        let a = 0.375;
        // Saturated: reads 1 - a/4 on average; nothing touched: a/4; mid-range: unbiased.
        assert!((c.expected_reading(1.0) - (1.0 - a / 4.0)).abs() < 1e-12);
        assert!((c.expected_reading(0.0) - a / 4.0).abs() < 1e-12);
        assert!((c.expected_reading(0.5) - 0.5).abs() < 1e-12);
        for s in [0.0, 0.05, 0.3, 0.7, 0.95, 1.0] {
            assert!(
                (c.signal_of_reading(c.expected_reading(s)) - s).abs() < 1e-9,
                "{s}"
            );
        }
        assert_eq!(c.signal_of_reading(0.0), 0.0);
        assert_eq!(c.signal_of_reading(1.0), 1.0);
        let clean = ControlConfig::default();
        assert_eq!(clean.expected_reading(0.4), 0.4);
        assert_eq!(clean.signal_of_reading(1.2), 1.0);
    }

    #[test]
    fn unknown_json_fields_are_rejected() {
        let e = serde_json::from_str::<ControlConfig>("{\"orient_stp\": 0.3}")
            .unwrap_err()
            .to_string();
        assert!(e.contains("orient_stp"), "{e}");
        let c: ControlConfig = serde_json::from_str("{\"orient_step\": 0.5}").unwrap();
        assert_eq!(c.orient_step, 0.5);
    }
}
