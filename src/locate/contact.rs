//! Where one touch landed: a point on the object's surface and the surface's outward normal there,
//! in the world, read from a converged reading's pad pose and image.
//!
//! The pad pose (`PadPose`: centre of the pad surface, normal toward the object) is what the arm's
//! forward kinematics knows at the end of Algorithm 1; the image says how deep the object pressed
//! into the covering under each taxel. A taxel of value `v` saw the surface at `t (1 - v)` along the
//! normal from the pad (the sensor model, Sec. V-A2: penetration `t - distance`, scaled to the
//! range), so the contact point is the pressed taxels' surface points averaged with the pressure
//! as weight. Orient has turned the pad normal onto the surface's (Algorithm 1), so the outward
//! surface normal is the pad normal reversed.

use glam::DVec3;
use rand::RngExt;
use serde::{Deserialize, Serialize};

use crate::dataset::Dataset;
use crate::pose::PadPose;
use crate::rng;
use crate::tactile::{SensorConfig, TactileImage};

/// One contact in the world: a surface point (metres) and the unit outward normal there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    pub point_m: DVec3,
    pub normal: DVec3,
}

impl Contact {
    /// The contact a reading felt: `None` when the image carries no pad pose (recorded frames) or
    /// nothing pressed the covering.
    pub fn of_image(image: &TactileImage, sensor: &SensorConfig) -> Option<Self> {
        let pose = image.pose()?;
        let (rows, cols) = (image.rows(), image.cols());
        let (mut weighted, mut total) = (DVec3::ZERO, 0.0);
        for row in 0..rows {
            for col in 0..cols {
                let v = image.get(row, col);
                if v <= 0.0 {
                    continue;
                }
                let point = taxel_surface_point(pose, sensor, (row, col), v);
                weighted += point * v;
                total += v;
            }
        }
        let point_m = weighted / total;
        (total > 0.0 && point_m.is_finite()).then_some(Self {
            point_m,
            normal: -pose.normal,
        })
    }

    /// The contact as a real arm would know it: the documented pose error of `noise` added, drawn
    /// from a stream seeded by the contact itself, so that one reading reads the same wherever it
    /// is recognised (and whatever else the dataset holds, its `object_pose` included).
    pub fn with_noise(self, noise: &ContactNoise) -> Self {
        if noise.is_none() {
            return self;
        }
        let seed = [self.point_m, self.normal]
            .iter()
            .flat_map(|v| v.to_array())
            .fold(CONTACT_NOISE_STREAM, |s, x| rng::substream(s, x.to_bits()));
        let mut r = rng::rng(seed);
        let mut gaussian = || {
            // Box-Muller: one standard normal from two uniforms.
            let u: f64 = r.random_range(f64::MIN_POSITIVE..1.0);
            let w: f64 = r.random_range(0.0..std::f64::consts::TAU);
            (-2.0 * u.ln()).sqrt() * w.cos()
        };
        let offset = DVec3::new(gaussian(), gaussian(), gaussian()) * noise.position_sigma_m;
        // A tilt of the normal about a random axis perpendicular to it, of RMS angle
        // `angle_sigma_rad` (two components of sigma / sqrt 2).
        let (a, b) = perpendicular_basis(self.normal);
        let per_axis = noise.angle_sigma_rad / std::f64::consts::SQRT_2;
        let tilt = a * (gaussian() * per_axis) + b * (gaussian() * per_axis);
        let normal = glam::DQuat::from_scaled_axis(tilt) * self.normal;
        Self {
            point_m: self.point_m + offset,
            normal: normal.normalize(),
        }
    }
}

/// The stream the contact noise is drawn from (mixed with the contact's own bits).
const CONTACT_NOISE_STREAM: u64 = 0x6c6f_6361_7465; // "locate"

/// The world point under taxel `(row, col)` of value `v`: the taxel's centre on the pad, moved
/// along the normal to where the covering met the surface.
fn taxel_surface_point(pose: &PadPose, sensor: &SensorConfig, (row, col): (usize, usize), v: f64) -> DVec3 {
    let (x_m, y_m) = sensor.taxel_centre_m(row, col);
    pose.transform_point(DVec3::new(x_m, y_m, sensor.thickness_m * (1.0 - v)))
}

/// Two unit vectors perpendicular to the unit vector `n` and to each other.
pub(crate) fn perpendicular_basis(n: DVec3) -> (DVec3, DVec3) {
    let a = n.any_orthonormal_vector();
    (a, n.cross(a))
}

/// The error of a contact as a real arm knows it (Sec. VI's arm would know its pad pose from joint
/// encoders and a calibrated kinematic model): Gaussian position error of `position_sigma_m` per
/// axis and a tilt of the normal of RMS `angle_sigma_rad`. The default, 1 mm per axis (1.7 mm RMS
/// in 3-D) and 2 deg, is what a well-calibrated industrial arm with a compliant fingertip gives;
/// the recogniser is judged with it so that it does not lean on the simulator's exactness.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactNoise {
    pub position_sigma_m: f64,
    pub angle_sigma_rad: f64,
}

impl ContactNoise {
    /// No error: the simulator's contact.
    pub const NONE: Self = Self {
        position_sigma_m: 0.0,
        angle_sigma_rad: 0.0,
    };

    /// The documented arm: 1 mm per axis, 2 deg.
    pub const ARM: Self = Self {
        position_sigma_m: 0.001,
        angle_sigma_rad: 2.0 * std::f64::consts::PI / 180.0,
    };

    pub fn is_none(&self) -> bool {
        self.position_sigma_m == 0.0 && self.angle_sigma_rad == 0.0
    }

    /// This error scaled by `factor` (the experiment's doubled noise).
    pub fn scaled(self, factor: f64) -> Self {
        Self {
            position_sigma_m: self.position_sigma_m * factor,
            angle_sigma_rad: self.angle_sigma_rad * factor,
        }
    }
}

impl Default for ContactNoise {
    fn default() -> Self {
        Self::ARM
    }
}

/// One touch as the geometric recogniser takes it: the contact it felt, if any, and which attempt
/// of its exploration it was (0 for the first). The attempt counts the moves of a perturbed
/// object: Sec. V-B4 perturbs it after every reading, converged or not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Touch {
    pub contact: Option<Contact>,
    pub attempt: usize,
}

impl Touch {
    /// The touch of a reading's `image`, its exploration's `attempt`-th attempt: its contact with
    /// `noise` added (none when the image has no pad pose).
    pub fn of_image(
        image: &TactileImage,
        sensor: &SensorConfig,
        noise: &ContactNoise,
        attempt: usize,
    ) -> Self {
        Self {
            contact: Contact::of_image(image, sensor).map(|c| c.with_noise(noise)),
            attempt,
        }
    }

    /// The converged readings of every object of `dataset` (in the header's object order, each
    /// object's readings in order, as recognition takes them) as touches: each one's contact
    /// with `noise` added, and its attempt among all of that object's recorded readings.
    pub fn of_dataset(dataset: &Dataset, noise: &ContactNoise) -> Vec<Vec<Touch>> {
        let sensor = &dataset.header().sensor;
        let mut per_object = vec![Vec::new(); dataset.header().objects.len()];
        let mut attempts = vec![0usize; per_object.len()];
        for reading in dataset.readings() {
            let Some(j) = dataset.header().object_index(&reading.object) else {
                continue;
            };
            let attempt = attempts[j];
            attempts[j] += 1;
            if reading.is_converged() {
                per_object[j].push(Touch::of_image(&reading.image, sensor, noise, attempt));
            }
        }
        per_object
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sensor() -> SensorConfig {
        SensorConfig::square(6, 6, 0.012, 0.0012)
    }

    fn pose() -> PadPose {
        PadPose::new(DVec3::new(0.1, 0.0, 0.2), -DVec3::Z, DVec3::Y).expect("a pose")
    }

    #[test]
    fn an_even_press_touches_below_the_pad_centre_at_the_covering_depth() {
        let image = TactileImage::new(6, 6, vec![0.25; 36])
            .expect("image")
            .with_pose(pose());
        let c = Contact::of_image(&image, &sensor()).expect("a contact");
        // The surface at t (1 - v) = 0.9 mm along the pad normal (down) from the pad's centre.
        assert!(
            (c.point_m - DVec3::new(0.1, 0.0, 0.2 - 0.0009)).length() < 1e-12,
            "{}",
            c.point_m
        );
        assert_eq!(c.normal, DVec3::Z);
    }

    #[test]
    fn a_press_under_one_taxel_is_there() {
        let mut values = vec![0.0; 36];
        values[0] = 0.5; // row 0 (toward up = +y), column 0 (left of right = -y x ... )
        let image = TactileImage::new(6, 6, values).expect("image").with_pose(pose());
        let c = Contact::of_image(&image, &sensor()).expect("a contact");
        let p = pose();
        let expected = p.center_m + p.right() * (-0.005) + p.up * 0.005 + p.normal * 0.0006;
        assert!((c.point_m - expected).length() < 1e-12);
    }

    #[test]
    fn no_pose_or_no_press_is_no_contact() {
        let pressed = TactileImage::new(6, 6, vec![0.5; 36]).expect("image");
        assert!(Contact::of_image(&pressed, &sensor()).is_none());
        let empty = TactileImage::zeros(6, 6).expect("image").with_pose(pose());
        assert!(Contact::of_image(&empty, &sensor()).is_none());
    }

    #[test]
    fn noise_is_the_contact_own_and_of_the_documented_size() {
        let noise = ContactNoise::ARM;
        let (mut square_m, mut square_rad) = (0.0, 0.0);
        let n = 2_000;
        for i in 0..n {
            let c = Contact {
                point_m: DVec3::new(i as f64 * 1e-3, 0.0, 0.0),
                normal: DVec3::Z,
            };
            let noisy = c.with_noise(&noise);
            assert_eq!(noisy, c.with_noise(&noise), "the same contact, the same error");
            square_m += (noisy.point_m - c.point_m).length_squared();
            square_rad += noisy.normal.angle_between(c.normal).powi(2);
        }
        let rms_m = (square_m / n as f64).sqrt();
        let rms_rad = (square_rad / n as f64).sqrt();
        // 1 mm per axis: 1.73 mm in 3-D; 2 degrees RMS.
        assert!((rms_m - 0.001 * 3f64.sqrt()).abs() < 1e-4, "{rms_m}");
        assert!(
            (rms_rad - 2f64.to_radians()).abs() < 0.1 * 2f64.to_radians(),
            "{rms_rad}"
        );
    }
}
