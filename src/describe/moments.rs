//! Spatial moments about the image centre (Sec. IV-B4, following Hu [50]).
//!
//! With the centred coordinates of [`Plane`] (y up) and intensities `I`:
//!
//! ```text
//! mu_pq  = sum over pixels of I(x, y) x^p y^q            (about the image centre, not the centroid)
//! eta_pq = mu_pq / mu_00^((p + q) / 2 + 1)               (scale-normalised)
//! theta  = 1/2 atan2(2 mu_11, mu_20 - mu_02)             (direction of the major principal axis)
//! s      = sum I (x cos theta + y sin theta)^3
//!        = c^3 mu_30 + 3 c^2 s mu_21 + 3 c s^2 mu_12 + s^3 mu_03,   c = cos theta, s = sin theta
//! ```
//!
//! `theta` fixes the axis up to a half turn; the sign of the third-order moment `s` along it (the
//! skew of the mass along the axis) picks the end: the orientation is `theta` when `s >= 0`, else
//! `theta + pi`. Both are unchanged by an intensity scale `I -> k I`, and rotating the image by
//! `alpha` adds `alpha` to the orientation, which is what makes Moment-Normalized rotation-invariant.
//! The paper notes the failure mode: for shapes with a symmetry the axis or the skew vanishes;
//! [`orientation_rad`](CentredMoments::orientation_rad) then falls back to 0 / no flip.

use super::plane::Plane;

/// Relative size below which an anisotropy or skew counts as zero (symmetric shapes): without it,
/// rounding noise in exactly symmetric images would pick arbitrary angles.
const DEGENERATE: f64 = 1e-12;

/// The moments `mu_pq`, `p + q <= 3`, of a plane about its centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentredMoments {
    /// `mu[p][q]`; entries with `p + q > 3` are unused zeros.
    mu: [[f64; 4]; 4],
    /// Scales for the degeneracy tests: `sum |I| r^2` and `sum |I| r^3`.
    abs_second: f64,
    abs_third: f64,
}

impl CentredMoments {
    /// The moments of `plane` about its centre.
    pub fn of(plane: &Plane) -> Self {
        let mut mu = [[0.0; 4]; 4];
        let (mut abs_second, mut abs_third) = (0.0, 0.0);
        for row in 0..plane.rows() {
            for col in 0..plane.cols() {
                let v = plane.get(row, col);
                if v == 0.0 {
                    continue;
                }
                let (x, y) = plane.xy(row, col);
                let xs = [1.0, x, x * x, x * x * x];
                let ys = [1.0, y, y * y, y * y * y];
                for p in 0..4 {
                    for q in 0..4 - p {
                        mu[p][q] += v * xs[p] * ys[q];
                    }
                }
                let r2 = x * x + y * y;
                abs_second += v.abs() * r2;
                abs_third += v.abs() * r2 * r2.sqrt();
            }
        }
        Self {
            mu,
            abs_second,
            abs_third,
        }
    }

    /// `mu_pq`; `p + q` must be at most 3.
    pub fn mu(&self, p: usize, q: usize) -> f64 {
        assert!(p + q <= 3, "moments are kept up to order 3, asked for mu_{p}{q}");
        self.mu[p][q]
    }

    /// `eta_pq = mu_pq / mu_00^((p+q)/2 + 1)`; 0 when `mu_00 <= 0` (no intensity).
    pub fn eta(&self, p: usize, q: usize) -> f64 {
        let m00 = self.mu[0][0];
        if m00 <= 0.0 {
            return 0.0;
        }
        self.mu(p, q) / m00.powf((p + q) as f64 / 2.0 + 1.0)
    }

    /// `theta`, the direction of the major principal axis in (-pi/2, pi/2]; `None` when the second
    /// moments are isotropic (a disc, a centred square, an empty image), where no axis exists.
    pub fn principal_angle_rad(&self) -> Option<f64> {
        let (a, b) = (self.mu[2][0] - self.mu[0][2], 2.0 * self.mu[1][1]);
        if a.hypot(b) <= DEGENERATE * self.abs_second || !(a.is_finite() && b.is_finite()) {
            return None;
        }
        Some(0.5 * b.atan2(a))
    }

    /// `s(theta)`: the third moment of the mass projected on the direction `theta`.
    pub fn skew_along(&self, theta_rad: f64) -> f64 {
        let (s, c) = theta_rad.sin_cos();
        let m = &self.mu;
        c * c * c * m[3][0] + 3.0 * c * c * s * m[2][1] + 3.0 * c * s * s * m[1][2] + s * s * s * m[0][3]
    }

    /// The orientation of the image: the major axis direction with its half-turn ambiguity resolved
    /// by the skew (module docs). 0 when there is no axis; no flip when the skew vanishes.
    pub fn orientation_rad(&self) -> f64 {
        let Some(theta) = self.principal_angle_rad() else {
            return 0.0;
        };
        let skew = self.skew_along(theta);
        if skew < 0.0 && skew.abs() > DEGENERATE * self.abs_third {
            theta + std::f64::consts::PI
        } else {
            theta
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_4, PI};

    /// A 3x3 plane with the given (x, y) -> value pixels (centre pixel is (0, 0), y up).
    fn plane3(pixels: &[((i32, i32), f64)]) -> Plane {
        let mut p = Plane::zeros(3, 3);
        for &((x, y), v) in pixels {
            p.set((1 - y) as usize, (x + 1) as usize, v);
        }
        p
    }

    #[test]
    fn hand_computed_moments_of_two_pixels() {
        // I = 1 at (1, 0), 0.5 at (0, 1).
        let m = CentredMoments::of(&plane3(&[((1, 0), 1.0), ((0, 1), 0.5)]));
        let expect = [
            ((0, 0), 1.5),
            ((1, 0), 1.0),
            ((0, 1), 0.5),
            ((2, 0), 1.0),
            ((0, 2), 0.5),
            ((1, 1), 0.0),
            ((3, 0), 1.0),
            ((0, 3), 0.5),
            ((2, 1), 0.0),
            ((1, 2), 0.0),
        ];
        for ((p, q), v) in expect {
            assert!(
                (m.mu(p, q) - v).abs() < 1e-15,
                "mu_{p}{q} = {} != {v}",
                m.mu(p, q)
            );
        }
        // eta_20 = 1 / 1.5^2, eta_02 = 0.5 / 1.5^2, eta_30 = 1 / 1.5^2.5.
        assert!((m.eta(2, 0) - 1.0 / 2.25).abs() < 1e-15);
        assert!((m.eta(0, 2) - 0.5 / 2.25).abs() < 1e-15);
        assert!((m.eta(3, 0) - 1.0 / 1.5f64.powf(2.5)).abs() < 1e-15);
        // mu_20 > mu_02, mu_11 = 0: the major axis is x; the skew along +x is mu_30 = 1 > 0.
        assert_eq!(m.principal_angle_rad(), Some(0.0));
        assert_eq!(m.orientation_rad(), 0.0);
    }

    #[test]
    fn diagonal_axis_and_its_end_come_from_the_skew() {
        // Mass on the diagonal y = x, heavier at (1, 1): mu_11 = mu_20 = mu_02 = 1.5.
        let heavy_up = CentredMoments::of(&plane3(&[((1, 1), 1.0), ((-1, -1), 0.5)]));
        assert!((heavy_up.mu(1, 1) - 1.5).abs() < 1e-15);
        assert!((heavy_up.principal_angle_rad().unwrap() - FRAC_PI_4).abs() < 1e-15);
        // s = 2^(3/2) (1 - 0.5) > 0.
        assert!((heavy_up.skew_along(FRAC_PI_4) - 2f64.powf(1.5) * 0.5).abs() < 1e-12);
        assert!((heavy_up.orientation_rad() - FRAC_PI_4).abs() < 1e-15);
        let heavy_down = CentredMoments::of(&plane3(&[((1, 1), 0.5), ((-1, -1), 1.0)]));
        assert!((heavy_down.orientation_rad() - (FRAC_PI_4 + PI)).abs() < 1e-15);
    }

    #[test]
    fn symmetric_and_empty_images_have_no_axis() {
        let cross = CentredMoments::of(&plane3(&[
            ((1, 0), 1.0),
            ((-1, 0), 1.0),
            ((0, 1), 1.0),
            ((0, -1), 1.0),
        ]));
        assert_eq!(cross.principal_angle_rad(), None);
        assert_eq!(cross.orientation_rad(), 0.0);
        let empty = CentredMoments::of(&Plane::zeros(3, 3));
        assert_eq!(empty.principal_angle_rad(), None);
        assert_eq!(empty.eta(2, 0), 0.0);
        // A bar along x, symmetric about the centre: an axis but no skew, so no flip.
        let bar = CentredMoments::of(&plane3(&[((1, 0), 1.0), ((-1, 0), 1.0), ((0, 0), 1.0)]));
        assert_eq!(bar.orientation_rad(), 0.0);
    }

    #[test]
    fn intensity_scale_keeps_eta_ratios_and_orientation() {
        let a = plane3(&[((1, 1), 0.9), ((-1, 0), 0.2), ((0, -1), 0.4)]);
        let mut b = a.clone();
        b.values_mut().iter_mut().for_each(|v| *v *= 0.25);
        let (ma, mb) = (CentredMoments::of(&a), CentredMoments::of(&b));
        assert!((ma.orientation_rad() - mb.orientation_rad()).abs() < 1e-12);
        // eta_pq scales as k^-((p+q)/2): the ratio eta_20 / eta_02 is scale-free.
        assert!((ma.eta(2, 0) / ma.eta(0, 2) - mb.eta(2, 0) / mb.eta(0, 2)).abs() < 1e-12);
    }
}
