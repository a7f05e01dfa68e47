//! The largest inscribed circle about the image centre (Sec. IV-B4, reused by IV-B5 and IV-B6).
//!
//! Rotating the pad about its normal moves content through the image corners but keeps the
//! inscribed disc onto itself, so the rotation-invariant descriptors look only inside it:
//!
//! ```text
//! keep (x, y)  <=>  x^2 + y^2 <= R^2,   R = min(rows, cols) / 2
//! ```
//!
//! in the centred coordinates of [`Plane`]. `R` reaches the image edges (not the outermost pixel
//! centres), so a 6x6 image keeps 32 of its 36 taxels, dropping the four corners.

use super::plane::Plane;

/// The inscribed disc of a `rows x cols` image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InscribedDisc {
    radius_px: f64,
}

impl InscribedDisc {
    /// The disc of `plane`'s shape.
    pub fn of(plane: &Plane) -> Self {
        Self::for_shape(plane.rows(), plane.cols())
    }

    pub fn for_shape(rows: usize, cols: usize) -> Self {
        Self {
            radius_px: rows.min(cols) as f64 / 2.0,
        }
    }

    /// `R`, in pixels.
    pub fn radius_px(&self) -> f64 {
        self.radius_px
    }

    /// Whether centred point `(x, y)` lies in the disc.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        x * x + y * y <= self.radius_px * self.radius_px
    }

    /// Sets every pixel outside the disc to zero.
    pub fn mask(&self, plane: &mut Plane) {
        for row in 0..plane.rows() {
            for col in 0..plane.cols() {
                let (x, y) = plane.xy(row, col);
                if !self.contains(x, y) {
                    plane.set(row, col, 0.0);
                }
            }
        }
    }

    /// Mean value over the pixels inside the disc (0 when none is).
    pub fn mean_inside(&self, plane: &Plane) -> f64 {
        let (mut sum, mut count) = (0.0, 0usize);
        for row in 0..plane.rows() {
            for col in 0..plane.cols() {
                let (x, y) = plane.xy(row, col);
                if self.contains(x, y) {
                    sum += plane.get(row, col);
                    count += 1;
                }
            }
        }
        if count == 0 { 0.0 } else { sum / count as f64 }
    }

    /// Divides `plane` by its mean inside the disc, so the result is invariant to a global intensity
    /// scale `I -> k I` (k > 0): the "intensity-invariant" aim of Sec. IV-B. A plane with no
    /// intensity in the disc (no contact) is left as it is (all zero after masking).
    pub fn normalize_mean(&self, plane: &mut Plane) {
        let mean = self.mean_inside(plane);
        if mean > 0.0 && mean.is_finite() {
            plane.values_mut().iter_mut().for_each(|v| *v /= mean);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn six_by_six_drops_exactly_the_corners() {
        let mut p = Plane::from_values(6, 6, vec![1.0; 36]).unwrap();
        let disc = InscribedDisc::of(&p);
        disc.mask(&mut p);
        let kept: f64 = p.values().iter().sum();
        assert_eq!(kept, 32.0);
        for (r, c) in [(0, 0), (0, 5), (5, 0), (5, 5)] {
            assert_eq!(p.get(r, c), 0.0);
        }
        assert_eq!(p.get(0, 1), 1.0);
    }

    #[test]
    fn normalize_mean_undoes_intensity_scale() {
        let values: Vec<f64> = (0..16).map(|i| (i % 5) as f64 / 4.0).collect();
        let mut a = Plane::from_values(4, 4, values.clone()).unwrap();
        let mut b = Plane::from_values(4, 4, values.iter().map(|v| v * 0.3).collect()).unwrap();
        let disc = InscribedDisc::of(&a);
        disc.normalize_mean(&mut a);
        disc.normalize_mean(&mut b);
        assert!((disc.mean_inside(&a) - 1.0).abs() < 1e-12);
        for (x, y) in a.values().iter().zip(b.values()) {
            assert!((x - y).abs() < 1e-12);
        }
        let mut zero = Plane::zeros(4, 4);
        disc.normalize_mean(&mut zero);
        assert!(zero.values().iter().all(|&v| v == 0.0));
    }
}
