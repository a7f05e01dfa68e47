//! Orient (Algorithm 1): fit a plane to the taxels in contact and turn the pad normal part of the way
//! toward the fitted surface normal.
//!
//! Each taxel `i` above the contact threshold gives a surface point in the pad frame
//! `p_i = (x_i, y_i, t (1 - v_i))`: its centre on the pad and the depth at which the surface lies,
//! since the value `v_i` is the penetration `t - d_i` as a fraction of the thickness t
//! (`estimateDepth`). The least-squares plane through the `p_i` has as normal the right singular vector
//! of the centred points with the smallest singular value. Oriented with positive z, it is the direction
//! the pad normal should take (into the surface). The command is the rotation taking the pad normal `s`
//! to `0.3 n + 0.7 s` (lines 11-13), about the centroid of the contact points so the contact stays put.

use glam::{DQuat, DVec3};
use nalgebra::{Matrix3xX, SVD};

use crate::control::config::ControlConfig;
use crate::pose::PadPose;
use crate::tactile::{SensorConfig, TactileImage};

/// The outcome of a plane fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlaneFit {
    /// Unit normal with positive z (pad frame) and the centroid of the points.
    Plane { normal: DVec3, centroid: DVec3 },
    /// Fewer than 3 points, or all (nearly) on a line: no unique plane.
    Degenerate,
}

/// Least-squares plane through `points` (total least squares, by SVD).
pub fn fit_plane(points: &[DVec3]) -> PlaneFit {
    if points.len() < 3 {
        return PlaneFit::Degenerate;
    }
    let centroid = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let centred = Matrix3xX::from_iterator(
        points.len(),
        points.iter().flat_map(|p| (*p - centroid).to_array()),
    );
    let svd = SVD::new(centred, true, false);
    let Some(u) = svd.u else {
        return PlaneFit::Degenerate;
    };
    let s = svd.singular_values;
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| s[b].total_cmp(&s[a]));
    // Collinear (or coincident) points: the second-largest spread is negligible next to the largest.
    if s[order[1]] <= 1e-6 * s[order[0]].max(f64::MIN_POSITIVE) {
        return PlaneFit::Degenerate;
    }
    let n = u.column(order[2]);
    let normal = DVec3::new(n[0], n[1], n[2]);
    let normal = if normal.z < 0.0 { -normal } else { normal };
    match normal.try_normalize() {
        Some(normal) => PlaneFit::Plane { normal, centroid },
        None => PlaneFit::Degenerate,
    }
}

/// The surface points of Algorithm 1, lines 1-7, in the pad frame (metres).
pub fn contact_points(image: &TactileImage, sensor: &SensorConfig, threshold: f64) -> Vec<DVec3> {
    surface_points(image, sensor, |row, col| image.get(row, col) > threshold)
}

/// The surface point `(x_i, y_i, t (1 - v_i))` of every taxel `keep` accepts, in the pad frame.
fn surface_points(
    image: &TactileImage,
    sensor: &SensorConfig,
    keep: impl Fn(usize, usize) -> bool,
) -> Vec<DVec3> {
    let mut points = Vec::new();
    for row in 0..image.rows() {
        for col in 0..image.cols() {
            if keep(row, col) {
                let (x, y) = sensor.taxel_centre_m(row, col);
                points.push(DVec3::new(x, y, sensor.thickness_m * (1.0 - image.get(row, col))));
            }
        }
    }
    points
}

/// The surface points of the taxels inside the contact patch: those in contact whose four neighbours
/// on the pad are in contact too (a neighbour off the pad counts as in contact, since the pad's edge is
/// not the patch's edge).
///
/// A taxel on the patch's boundary may be only partly covered: over the edge of a raised stroke its
/// value is the covered fraction of the penetration, which [`contact_points`] reads as a deeper
/// surface, a slope that is not there. An interior taxel is covered whole, so its depth is the
/// surface's.
pub fn interior_contact_points(image: &TactileImage, sensor: &SensorConfig, threshold: f64) -> Vec<DVec3> {
    let (rows, cols) = (image.rows(), image.cols());
    let touching = |row: usize, col: usize| image.get(row, col) > threshold;
    surface_points(image, sensor, |row, col| {
        touching(row, col)
            && (row == 0 || touching(row - 1, col))
            && (row + 1 == rows || touching(row + 1, col))
            && (col == 0 || touching(row, col - 1))
            && (col + 1 == cols || touching(row, col + 1))
    })
}

/// A rotation of the pad about a pivot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientCommand {
    /// Rotation in the world frame.
    pub rotation: DQuat,
    /// Point that stays fixed, world frame.
    pub pivot_m: DVec3,
    /// Angle between the pad normal and the fitted surface normal before the command, radians.
    pub misalignment_rad: f64,
}

impl OrientCommand {
    /// The pad pose after the command.
    pub fn apply(&self, pose: &PadPose) -> PadPose {
        PadPose {
            center_m: self.pivot_m + self.rotation * (pose.center_m - self.pivot_m),
            normal: (self.rotation * pose.normal).normalize(),
            up: (self.rotation * pose.up).normalize(),
        }
    }
}

/// Tilt of the stand-in surface normal used when the contact is a line off the pad centre, radians.
const LINE_CONTACT_TILT_RAD: f64 = 0.35;

/// The surface normal in the pad frame estimated from `image`, and the contact centroid; `None` when
/// nothing can be estimated.
///
/// A contact along a single line of taxels (the first touch of a steeply tilted surface, or an edge)
/// fits no unique plane. If that line passes near the pad centre it is an edge under the pad, and the
/// pad stays as it is; if it lies off-centre, the surface is closer on that side, so the stand-in normal
/// leans toward the contact by `LINE_CONTACT_TILT_RAD`, bringing the rest of the pad down onto it.
///
/// With [`ControlConfig::orient_edge_guard`] the plane is fitted to the patch's interior
/// ([`interior_contact_points`]) when it spans a plane, else to every contact taxel, and a plane that
/// a taxel reading no contact refutes gives the pad's own normal (no tilt). On a raised bar 3 mm high
/// the guarded pad, started level, stays level wherever the bar crosses the pad but one case: a bar
/// covering the pad's border column and part of the next. That image is also the first touch of a
/// plane tilted some 15 degrees, and one image cannot tell the two apart.
pub fn surface_normal(
    image: &TactileImage,
    sensor: &SensorConfig,
    config: &ControlConfig,
) -> Option<(DVec3, DVec3)> {
    let threshold = config.effective_contact_threshold();
    let points = contact_points(image, sensor, threshold);
    if config.orient_edge_guard {
        let interior = interior_contact_points(image, sensor, threshold);
        for fitted in [&interior, &points] {
            if let Some((normal, centroid)) = plane_through(fitted, sensor) {
                if refuted_by_a_drop(image, sensor, threshold, normal, centroid) {
                    return Some((DVec3::Z, centroid));
                }
                return Some((normal, centroid));
            }
        }
    } else if let Some(plane) = plane_through(&points, sensor) {
        return Some(plane);
    }
    if points.is_empty() {
        return None;
    }
    let centroid = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let pitch = (sensor.pad_width_m / sensor.cols as f64).min(sensor.pad_height_m / sensor.rows as f64);
    let offset = DVec3::new(centroid.x, centroid.y, 0.0);
    if offset.length() < pitch {
        return None;
    }
    let lean = offset.normalize() * LINE_CONTACT_TILT_RAD.tan();
    Some(((lean + DVec3::Z).normalize(), centroid))
}

/// The least-squares plane through `points` (normal, centroid), unless they fit none or lie along a
/// line.
fn plane_through(points: &[DVec3], sensor: &SensorConfig) -> Option<(DVec3, DVec3)> {
    match fit_plane(points) {
        PlaneFit::Plane { normal, centroid } if !is_line_like(points, sensor) => Some((normal, centroid)),
        _ => None,
    }
}

/// Whether the fitted plane says the surface comes well into the covering at a taxel that reads no
/// contact: the surface ends before it (a stroke's or a step's edge), so the fitted slope is the
/// edge's partial coverage, not a slope of the surface.
fn refuted_by_a_drop(
    image: &TactileImage,
    sensor: &SensorConfig,
    threshold: f64,
    normal: DVec3,
    centroid: DVec3,
) -> bool {
    (0..image.rows()).any(|row| {
        (0..image.cols()).any(|col| {
            let (x, y) = sensor.taxel_centre_m(row, col);
            let depth = centroid.z - (normal.x * (x - centroid.x) + normal.y * (y - centroid.y)) / normal.z;
            let predicted = 1.0 - depth / sensor.thickness_m;
            predicted > threshold + 0.5 && image.get(row, col) <= threshold
        })
    })
}

/// Whether the points' pad-plane positions lie along one line (spread across it below half a taxel).
fn is_line_like(points: &[DVec3], sensor: &SensorConfig) -> bool {
    let n = points.len() as f64;
    let mean = points
        .iter()
        .map(|p| glam::DVec2::new(p.x, p.y))
        .sum::<glam::DVec2>()
        / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in points {
        let d = glam::DVec2::new(p.x, p.y) - mean;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    // Smallest eigenvalue of the 2x2 scatter matrix: the variance across the best line.
    let (tr, det) = (sxx + syy, sxx * syy - sxy * sxy);
    let across_var = (tr * 0.5 - ((tr * 0.5).powi(2) - det).max(0.0).sqrt()) / n;
    let pitch = (sensor.pad_width_m / sensor.cols as f64).min(sensor.pad_height_m / sensor.rows as f64);
    across_var.max(0.0).sqrt() < 0.5 * pitch
}

/// Algorithm 1: the Orient command for `image` taken at `pose`, or `None` (no command) when the
/// normals already agree within the tolerance or no plane can be fitted.
pub fn orient_command(
    image: &TactileImage,
    pose: &PadPose,
    sensor: &SensorConfig,
    config: &ControlConfig,
) -> Option<OrientCommand> {
    let (normal_pad, centroid_pad) = surface_normal(image, sensor, config)?;
    let sensor_n = pose.normal;
    let surface_n = pose.transform_vector(normal_pad).normalize();
    let misalignment_rad = sensor_n.angle_between(surface_n);
    if misalignment_rad <= config.orient_tolerance_rad {
        return None;
    }
    let target = (config.orient_step * surface_n + (1.0 - config.orient_step) * sensor_n).try_normalize()?;
    let mut rotation = DQuat::from_rotation_arc(sensor_n, target);
    let (axis, angle) = rotation.to_axis_angle();
    if angle > config.orient_max_step_rad {
        rotation = DQuat::from_axis_angle(axis, config.orient_max_step_rad);
    }
    Some(OrientCommand {
        rotation,
        pivot_m: pose.center_m + pose.transform_vector(centroid_pad),
        misalignment_rad,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_fit_recovers_a_known_plane() {
        // z = 0.001 + 0.2 x - 0.1 y: normal proportional to (-0.2, 0.1, 1).
        let pts: Vec<DVec3> = (0..5)
            .flat_map(|i| (0..5).map(move |j| (i as f64 * 0.002, j as f64 * 0.002)))
            .map(|(x, y)| DVec3::new(x, y, 0.001 + 0.2 * x - 0.1 * y))
            .collect();
        let PlaneFit::Plane { normal, .. } = fit_plane(&pts) else {
            panic!("degenerate")
        };
        let expected = DVec3::new(-0.2, 0.1, 1.0).normalize();
        assert!((normal - expected).length() < 1e-9, "{normal:?}");
    }

    #[test]
    fn degenerate_fits_are_reported() {
        assert_eq!(fit_plane(&[DVec3::ZERO, DVec3::X]), PlaneFit::Degenerate);
        let line: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(i as f64, 2.0 * i as f64, 0.5))
            .collect();
        assert_eq!(fit_plane(&line), PlaneFit::Degenerate);
    }

    /// A 6x6 image whose every row is `row`.
    fn striped(row: [f64; 6]) -> TactileImage {
        TactileImage::new(6, 6, (0..6).flat_map(|_| row).collect()).unwrap()
    }

    fn tilt_deg(image: &TactileImage, guard: bool) -> f64 {
        let sensor = SensorConfig::square(6, 6, 0.012, 0.0012);
        let config = ControlConfig {
            orient_edge_guard: guard,
            ..ControlConfig::default()
        };
        let (normal, _) = surface_normal(image, &sensor, &config).unwrap();
        normal.angle_between(DVec3::Z).to_degrees()
    }

    #[test]
    fn the_edge_guard_sees_a_partly_covered_column_as_an_edge_not_a_slope() {
        // A raised stroke under the left of a level pad (a press on upper_I, 2 mm off its stem):
        // column 0 is 70% covered, column 1 whole, column 2 holds the blur's tail.
        let stroke = striped([0.51, 0.92, 0.08, 0.0, 0.0, 0.0]);
        assert!(tilt_deg(&stroke, false) > 5.0, "{}", tilt_deg(&stroke, false));
        assert_eq!(tilt_deg(&stroke, true), 0.0);
        // The interior alone decides when it spans a plane: column 1, beside a column out of
        // contact, is partly covered.
        let wide = striped([0.0, 0.25, 0.5, 0.5, 0.5, 0.5]);
        assert!(tilt_deg(&wide, true) < 1e-9, "{}", tilt_deg(&wide, true));
        assert!(tilt_deg(&wide, false) > 1.0);
    }

    #[test]
    fn the_edge_guard_leaves_a_plane_that_fills_the_pad_alone() {
        // Depth falling by 0.1 t a column: the surface rises toward column 0, where the pad touches.
        let ramp = striped([0.8, 0.7, 0.6, 0.5, 0.4, 0.3]);
        let (guarded, plain) = (tilt_deg(&ramp, true), tilt_deg(&ramp, false));
        let expected = (0.1 * 0.0012 / 0.002f64).atan().to_degrees();
        assert!((plain - expected).abs() < 1e-9, "{plain} vs {expected}");
        assert!((guarded - plain).abs() < 1e-9, "{guarded} vs {plain}");
    }
}
