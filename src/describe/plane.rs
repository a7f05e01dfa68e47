//! A plain `rows x cols` intensity grid with the centred coordinates the descriptors share.
//!
//! Coordinates: pixel (`row`, `col`) sits at
//!
//! ```text
//! x = col - (cols - 1) / 2        (right)
//! y = (rows - 1) / 2 - row        (up: row 0 is the pad's +up edge)
//! ```
//!
//! so the image centre is the origin whatever the parity of the size, and rotations about the pad
//! normal are rotations about the origin. Outside the pixel centres the grid is extended by zero,
//! which is what a tactile image means there (no contact is sensed beyond the pad).

use crate::tactile::TactileImage;

/// A `rows x cols` row-major grid of intensities (any finite values, unlike a [`TactileImage`]:
/// intermediate images such as normalised or padded ones leave [0, 1]).
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    rows: usize,
    cols: usize,
    values: Vec<f64>,
}

impl Plane {
    /// An all-zero plane.
    pub fn zeros(rows: usize, cols: usize) -> Self {
        Self {
            rows,
            cols,
            values: vec![0.0; rows * cols],
        }
    }

    /// The plane of a tactile image (same layout, same values).
    pub fn from_image(image: &TactileImage) -> Self {
        Self {
            rows: image.rows(),
            cols: image.cols(),
            values: image.values().to_vec(),
        }
    }

    /// A plane from row-major values; `None` when the length is not `rows * cols`.
    pub fn from_values(rows: usize, cols: usize, values: Vec<f64>) -> Option<Self> {
        (values.len() == rows * cols).then_some(Self { rows, cols, values })
    }

    pub fn rows(&self) -> usize {
        self.rows
    }

    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Row-major values, row 0 first.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// The value at (`row`, `col`); both must be inside the plane.
    pub fn get(&self, row: usize, col: usize) -> f64 {
        self.values[row * self.cols + col]
    }

    pub fn set(&mut self, row: usize, col: usize, value: f64) {
        self.values[row * self.cols + col] = value;
    }

    /// The value at integer (`row`, `col`), zero outside the plane.
    fn get_or_zero(&self, row: isize, col: isize) -> f64 {
        if row < 0 || col < 0 || row as usize >= self.rows || col as usize >= self.cols {
            0.0
        } else {
            self.values[row as usize * self.cols + col as usize]
        }
    }

    /// Centred coordinates `(x, y)` of pixel (`row`, `col`) (module docs).
    pub fn xy(&self, row: usize, col: usize) -> (f64, f64) {
        (col as f64 - self.half_width(), self.half_height() - row as f64)
    }

    /// `(cols - 1) / 2`: the column of the origin.
    fn half_width(&self) -> f64 {
        (self.cols as f64 - 1.0) / 2.0
    }

    /// `(rows - 1) / 2`: the row of the origin.
    fn half_height(&self) -> f64 {
        (self.rows as f64 - 1.0) / 2.0
    }

    /// Bilinear interpolation at centred coordinates `(x, y)`, zero beyond the pixel centres:
    ///
    /// ```text
    /// I(x, y) = sum over the 4 neighbours (r, c) of (1 - |row(y) - r|)(1 - |col(x) - c|) I(r, c)
    /// ```
    ///
    /// Non-finite coordinates read as outside (zero).
    pub fn sample(&self, x: f64, y: f64) -> f64 {
        let col = x + self.half_width();
        let row = self.half_height() - y;
        if !(col.is_finite() && row.is_finite()) || col <= -1.0 || row <= -1.0 {
            return 0.0;
        }
        if col >= self.cols as f64 || row >= self.rows as f64 {
            return 0.0;
        }
        let (c0, r0) = (col.floor(), row.floor());
        let (fc, fr) = (col - c0, row - r0);
        let (c0, r0) = (c0 as isize, r0 as isize);
        let top = (1.0 - fc) * self.get_or_zero(r0, c0) + fc * self.get_or_zero(r0, c0 + 1);
        let bottom = (1.0 - fc) * self.get_or_zero(r0 + 1, c0) + fc * self.get_or_zero(r0 + 1, c0 + 1);
        (1.0 - fr) * top + fr * bottom
    }

    /// The plane sampled on its own grid after rotating its content by `angle_rad` counter-clockwise
    /// about the centre: `out(p) = in(R(-angle) p)` (bilinear, zero outside).
    pub fn rotated(&self, angle_rad: f64) -> Plane {
        let (s, c) = (-angle_rad).sin_cos();
        let mut out = Plane::zeros(self.rows, self.cols);
        for row in 0..self.rows {
            for col in 0..self.cols {
                let (x, y) = self.xy(row, col);
                out.set(row, col, self.sample(c * x - s * y, s * x + c * y));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(rows: usize, cols: usize) -> Plane {
        Plane::from_values(rows, cols, (0..rows * cols).map(|i| i as f64).collect()).unwrap()
    }

    #[test]
    fn coordinates_are_centred_with_y_up() {
        let p = Plane::zeros(3, 4);
        assert_eq!(p.xy(0, 0), (-1.5, 1.0));
        assert_eq!(p.xy(2, 3), (1.5, -1.0));
        assert_eq!(p.xy(1, 2), (0.5, 0.0));
    }

    #[test]
    fn sampling_hits_pixels_interpolates_and_is_zero_outside() {
        let p = ramp(3, 3);
        for row in 0..3 {
            for col in 0..3 {
                let (x, y) = p.xy(row, col);
                assert_eq!(p.sample(x, y), p.get(row, col));
            }
        }
        // Halfway between (1, 1) = 4 and (1, 2) = 5; a quarter of the way down to row 2.
        assert!((p.sample(0.5, 0.0) - 4.5).abs() < 1e-12);
        assert!((p.sample(0.0, -0.25) - (0.75 * 4.0 + 0.25 * 7.0)).abs() < 1e-12);
        // Half a pixel beyond the right edge: half of the edge pixel, half of the zero outside.
        assert!((p.sample(1.5, 0.0) - 2.5).abs() < 1e-12);
        assert_eq!(p.sample(2.0, 0.0), 0.0);
        assert_eq!(p.sample(f64::NAN, 0.0), 0.0);
    }

    #[test]
    fn quarter_turn_permutes_pixels() {
        let p = ramp(3, 3);
        let q = p.rotated(std::f64::consts::FRAC_PI_2);
        // Counter-clockwise: the right-middle pixel (1, 2) moves to the top-middle (0, 1).
        assert!((q.get(0, 1) - p.get(1, 2)).abs() < 1e-12);
        assert!((q.get(0, 0) - p.get(0, 2)).abs() < 1e-12);
        assert!((q.get(1, 1) - p.get(1, 1)).abs() < 1e-12);
    }
}
