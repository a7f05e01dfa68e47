//! The supersampling grid: where the pad's parallel rays pierce the pad plane.
//!
//! Pad frame: x = right, y = up, z = the pad normal (into the covering). A `rows x cols` taxel
//! image supersampled `k x k` has `(rows k) x (cols k)` samples; sample (i, j) sits at the centre
//! of its cell,
//!
//! ```text
//! x_j = (2 j + 1 - C) * W / (2 C),   y_i = -(2 i + 1 - R) * H / (2 R),   C = cols k, R = rows k,
//! ```
//!
//! so row 0 is the `+up` edge and column 0 the left edge seen from behind the pad. The integer
//! factor makes the grid exactly symmetric (x_{C-1-j} = -x_j in floating point), so a square grid
//! maps onto itself under a 90° turn about the normal.

use std::ops::Range;

use crate::tactile::SensorConfig;

/// Sample positions of one sensor, in the pad frame (metres).
#[derive(Debug, Clone, PartialEq)]
pub struct SampleGrid {
    /// Samples per row (`cols * k`).
    pub cols: usize,
    /// Sample rows (`rows * k`).
    pub rows: usize,
    /// Half the sample spacing along x and y.
    half_dx_m: f64,
    half_dy_m: f64,
    /// 1 / spacing, for index arithmetic.
    inv_dx: f64,
    inv_dy: f64,
    pub half_width_m: f64,
    pub half_height_m: f64,
}

impl SampleGrid {
    /// The grid of a valid config.
    pub fn new(config: &SensorConfig) -> Self {
        let k = config.rays_per_side();
        let (cols, rows) = (config.cols * k, config.rows * k);
        Self {
            cols,
            rows,
            half_dx_m: config.pad_width_m / (2 * cols) as f64,
            half_dy_m: config.pad_height_m / (2 * rows) as f64,
            inv_dx: cols as f64 / config.pad_width_m,
            inv_dy: rows as f64 / config.pad_height_m,
            half_width_m: 0.5 * config.pad_width_m,
            half_height_m: 0.5 * config.pad_height_m,
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.rows * self.cols
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// x of sample column `j`.
    #[inline]
    pub fn x(&self, j: usize) -> f64 {
        ((2 * j + 1) as f64 - self.cols as f64) * self.half_dx_m
    }

    /// y of sample row `i`.
    #[inline]
    pub fn y(&self, i: usize) -> f64 {
        (self.rows as f64 - (2 * i + 1) as f64) * self.half_dy_m
    }

    /// Sample spacing along x.
    pub fn dx_m(&self) -> f64 {
        2.0 * self.half_dx_m
    }

    /// Sample spacing along y.
    pub fn dy_m(&self) -> f64 {
        2.0 * self.half_dy_m
    }

    /// The sample columns whose x lies in `[lo, hi]` (with a hair of slack).
    #[inline]
    pub fn col_range(&self, lo: f64, hi: f64) -> Range<usize> {
        index_range(lo, hi, self.half_width_m, self.inv_dx, self.cols)
    }

    /// The sample rows whose y lies in `[lo, hi]` (rows count downward from `+up`).
    #[inline]
    pub fn row_range(&self, lo: f64, hi: f64) -> Range<usize> {
        index_range(-hi, -lo, self.half_height_m, self.inv_dy, self.rows)
    }
}

/// Indices `j` of `n` cells of width `1 / inv_d` starting at `-half` whose centres lie in
/// `[lo, hi]`, widened by a relative 1e-9 of a cell so that rounding never drops a centre on the
/// boundary.
#[inline]
fn index_range(lo: f64, hi: f64, half: f64, inv_d: f64, n: usize) -> Range<usize> {
    const SLACK: f64 = 1e-9;
    let u = (lo + half) * inv_d - 0.5 - SLACK;
    let v = (hi + half) * inv_d - 0.5 + SLACK;
    // NaN fails the comparisons and yields an empty range.
    if !(v >= 0.0 && u <= v && u < n as f64) {
        return 0..0;
    }
    // u < n and v >= 0 here, so the casts below are in range (v is clamped first).
    let first = if u <= 0.0 {
        0
    } else {
        (u as i64 + ((u as i64 as f64) < u) as i64) as usize
    };
    let last = (v.min(n as f64) as i64 + 1).min(n as i64) as usize;
    first..last.max(first)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(rows: usize, cols: usize, k2: usize) -> SampleGrid {
        SampleGrid::new(&SensorConfig {
            rows,
            cols,
            rays_per_taxel: k2,
            ..SensorConfig::default()
        })
    }

    #[test]
    fn samples_sit_at_cell_centres_row_zero_up() {
        let g = grid(6, 6, 1);
        assert_eq!(g.len(), 36);
        assert!((g.x(0) - (-0.005)).abs() < 1e-15);
        assert!((g.x(5) - 0.005).abs() < 1e-15);
        assert!((g.y(0) - 0.005).abs() < 1e-15);
        assert!((g.y(5) + 0.005).abs() < 1e-15);
        let g = grid(6, 6, 4);
        assert_eq!((g.rows, g.cols), (12, 12));
        assert!((g.x(0) + 0.0055).abs() < 1e-15);
    }

    #[test]
    fn grid_is_exactly_symmetric() {
        let g = grid(26, 26, 4);
        for j in 0..g.cols {
            assert_eq!(g.x(g.cols - 1 - j), -g.x(j));
            assert_eq!(g.y(j), -g.x(j));
        }
    }

    #[test]
    fn ranges_cover_every_sample_inside() {
        let g = grid(14, 14, 1);
        for (lo, hi) in [
            (-0.0031, 0.0012),
            (-1.0, 1.0),
            (0.0059, 0.0061),
            (-0.006, -0.0055),
        ] {
            let cols = g.col_range(lo, hi);
            for j in 0..g.cols {
                if (lo..=hi).contains(&g.x(j)) {
                    assert!(cols.contains(&j), "{lo} {hi} {j} {cols:?}");
                }
            }
            let rows = g.row_range(lo, hi);
            for i in 0..g.rows {
                if (lo..=hi).contains(&g.y(i)) {
                    assert!(rows.contains(&i), "{lo} {hi} {i} {rows:?}");
                }
            }
        }
        assert!(g.col_range(0.02, 0.03).is_empty());
        assert!(g.col_range(f64::NAN, 0.0).is_empty());
    }
}
