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
    /// `x_j` and `y_i` of every column and row, computed once (the rasteriser reads them for every
    /// face, and an integer-to-float conversion costs several instructions without AVX-512).
    xs_m: Vec<f64>,
    ys_m: Vec<f64>,
}

impl SampleGrid {
    /// The grid of a valid config.
    pub fn new(config: &SensorConfig) -> Self {
        let k = config.rays_per_side();
        let (cols, rows) = (config.cols * k, config.rows * k);
        let (half_dx_m, half_dy_m) = (
            config.pad_width_m / (2 * cols) as f64,
            config.pad_height_m / (2 * rows) as f64,
        );
        Self {
            cols,
            rows,
            half_dx_m,
            half_dy_m,
            inv_dx: cols as f64 / config.pad_width_m,
            inv_dy: rows as f64 / config.pad_height_m,
            half_width_m: 0.5 * config.pad_width_m,
            half_height_m: 0.5 * config.pad_height_m,
            xs_m: (0..cols)
                .map(|j| ((2 * j + 1) as f64 - cols as f64) * half_dx_m)
                .collect(),
            ys_m: (0..rows)
                .map(|i| (rows as f64 - (2 * i + 1) as f64) * half_dy_m)
                .collect(),
        }
    }

    /// The largest `|x|` and `|y|` of the sample rays: they pierce the pad plane within this
    /// rectangle, half a sample inside the pad's edges.
    pub fn ray_half_extent_m(&self) -> (f64, f64) {
        (self.xs_m[self.cols - 1], self.ys_m[0])
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
        self.xs_m[j]
    }

    /// x of every sample column, in column order.
    #[inline]
    pub fn xs_m(&self) -> &[f64] {
        &self.xs_m
    }

    /// y of sample row `i`.
    #[inline]
    pub fn y(&self, i: usize) -> f64 {
        self.ys_m[i]
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
        if lo.is_nan() || hi.is_nan() {
            return 0..0;
        }
        self.cols_in(CellBounds::from_to(self.col_bounds(lo), self.col_bounds(hi)))
    }

    /// The sample rows whose y lies in `[lo, hi]` (rows count downward from `+up`).
    #[inline]
    pub fn row_range(&self, lo: f64, hi: f64) -> Range<usize> {
        if lo.is_nan() || hi.is_nan() {
            return 0..0;
        }
        self.rows_in(CellBounds::from_to(self.row_bounds(hi), self.row_bounds(lo)))
    }

    /// The column bounds of one x, for [`Self::cols_in`].
    #[inline]
    pub fn col_bounds(&self, x: f64) -> CellBounds {
        CellBounds::new(x, self.half_width_m, self.inv_dx)
    }

    /// The row bounds of one y, for [`Self::rows_in`] (rows count downward, so the bounds are
    /// those of `-y`).
    #[inline]
    pub fn row_bounds(&self, y: f64) -> CellBounds {
        CellBounds::new(-y, self.half_height_m, self.inv_dy)
    }

    /// The column bounds of `x` and the row bounds of `y` together: a vertex's, computed in the
    /// two lanes of one SSE2 register on x86-64 (bit for bit the same as
    /// `(col_bounds(x), row_bounds(y))`, which other targets use).
    #[inline]
    pub fn cell_bounds(&self, x: f64, y: f64) -> (CellBounds, CellBounds) {
        #[cfg(target_arch = "x86_64")]
        {
            let [cols, rows] = CellBounds::pair(
                [x, -y],
                [self.half_width_m, self.half_height_m],
                [self.inv_dx, self.inv_dy],
            );
            (cols, rows)
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            (self.col_bounds(x), self.row_bounds(y))
        }
    }

    /// The sample columns within `bounds`.
    #[inline]
    pub fn cols_in(&self, bounds: CellBounds) -> Range<usize> {
        bounds.clip(self.cols)
    }

    /// The sample rows within `bounds`.
    #[inline]
    pub fn rows_in(&self, bounds: CellBounds) -> Range<usize> {
        bounds.clip(self.rows)
    }
}

/// Where one coordinate falls among cells of width `1 / inv_d` starting at `-half`, with cell
/// centres at whole numbers of `w(x) = (x + half) inv_d - 1/2`: `first` is the first centre at
/// or above it and `last` the last at or below it, each widened by a relative 1e-9 of a cell so
/// that rounding never drops a centre on the boundary.
///
/// Both are monotone in `x` (rounding keeps the order of `+` and `*`), so for a set of points the
/// bounds of their lowest coordinate are the least `first` and those of the highest the greatest
/// `last`: a face's sample rectangle is a min and a max over its corners' bounds, which a mesh
/// vertex shared by six faces computes once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CellBounds {
    first: i32,
    last: i32,
}

impl CellBounds {
    /// The widening of a cell's bounds, as a fraction of a cell.
    const SLACK: f64 = 1e-9;
    /// Beyond 1e8 cells a coordinate is as far off the grid as infinity.
    const FAR: f64 = 1e8;

    /// The bounds of `x` (a NaN as if it were `-FAR`: its bounds alone cover no cell).
    #[inline]
    fn new(x: f64, half: f64, inv_d: f64) -> Self {
        let (slack, far) = (Self::SLACK, Self::FAR);
        let w = (x + half) * inv_d - 0.5;
        // Comparisons rather than `clamp`, for one instruction each and no branch on NaN.
        let w = if w > -far { w } else { -far };
        let w = if w < far { w } else { far };
        // With n = floor(w): n - 1 < w - SLACK < n + 1 and n <= w + SLACK < n + 2, also as
        // rounded, so ceil(w - SLACK) = n + [w - SLACK > n] and floor(w + SLACK) =
        // n + [w + SLACK >= n + 1]: one floor for both bounds.
        let n = floor(w);
        let whole = small_int(n);
        Self {
            first: whole + i32::from(w - slack > n),
            last: whole + i32::from(w + slack >= n + 1.0),
        }
    }

    /// [`Self::new`] of two coordinates at once, lane by lane the same operations.
    #[cfg(target_arch = "x86_64")]
    #[inline]
    fn pair(x: [f64; 2], half: [f64; 2], inv_d: [f64; 2]) -> [Self; 2] {
        use std::arch::x86_64::{
            __m128i, _mm_add_pd, _mm_and_pd, _mm_castpd_si128, _mm_cmpge_pd, _mm_cmpgt_pd, _mm_cvtsi128_si32,
            _mm_max_pd, _mm_min_pd, _mm_mul_pd, _mm_set_pd, _mm_set1_pd, _mm_shuffle_epi32, _mm_sub_epi32,
            _mm_sub_pd,
        };
        // SAFETY: SSE2 is part of the x86-64 baseline: every x86-64 processor has these
        // instructions, and they only read their register arguments.
        let (first, last) = unsafe {
            let lanes = |v: [f64; 2]| _mm_set_pd(v[1], v[0]);
            let w = _mm_sub_pd(
                _mm_mul_pd(_mm_add_pd(lanes(x), lanes(half)), lanes(inv_d)),
                _mm_set1_pd(0.5),
            );
            // maxpd and minpd return their second operand on NaN, as `new`'s comparisons do.
            let w = _mm_min_pd(_mm_max_pd(w, _mm_set1_pd(-Self::FAR)), _mm_set1_pd(Self::FAR));
            let round = _mm_set1_pd(ROUND);
            let one = _mm_set1_pd(1.0);
            let nearest = _mm_sub_pd(_mm_add_pd(w, round), round);
            let n = _mm_sub_pd(nearest, _mm_and_pd(_mm_cmpgt_pd(nearest, w), one));
            let whole = _mm_castpd_si128(_mm_add_pd(n, round));
            // A true comparison is all ones, -1 in the low 32 bits: subtracting it adds one.
            let slack = _mm_set1_pd(Self::SLACK);
            let first = _mm_sub_epi32(whole, _mm_castpd_si128(_mm_cmpgt_pd(_mm_sub_pd(w, slack), n)));
            let last = _mm_sub_epi32(
                whole,
                _mm_castpd_si128(_mm_cmpge_pd(_mm_add_pd(w, slack), _mm_add_pd(n, one))),
            );
            // The low 32 bits of lane 0 and of lane 1 (32-bit element 2).
            let lane = |v: __m128i| [_mm_cvtsi128_si32(v), _mm_cvtsi128_si32(_mm_shuffle_epi32::<2>(v))];
            (lane(first), lane(last))
        };
        [
            Self {
                first: first[0],
                last: last[0],
            },
            Self {
                first: first[1],
                last: last[1],
            },
        ]
    }

    /// The bounds of a set: the least `first` and the greatest `last`.
    #[inline]
    pub fn hull(self, other: Self) -> Self {
        Self {
            first: self.first.min(other.first),
            last: self.last.max(other.last),
        }
    }

    /// The cells from the lowest coordinate's bounds `lo` to the highest's `hi`.
    #[inline]
    fn from_to(lo: Self, hi: Self) -> Self {
        Self {
            first: lo.first,
            last: hi.last,
        }
    }

    /// Cells `first..=last` clipped to `0..n`, empty when they miss it.
    #[inline]
    fn clip(self, n: usize) -> Range<usize> {
        let first = self.first.max(0) as usize;
        let end = ((self.last.max(-1) + 1) as usize).min(n);
        if first < end { first..end } else { 0..0 }
    }
}

/// 1.5 * 2^52: adding it to an `|x| < 2^51` rounds `x` to an integer in the low bits of the sum.
const ROUND: f64 = 6_755_399_441_055_744.0;

/// `x.floor()` for `|x| < 2^51`, exactly, in a few instructions without branches (without SSE4.1,
/// `f64::floor` is a library call, and a saturating `as` cast costs a handful of checks; a face's
/// cell range needs four).
#[inline]
fn floor(x: f64) -> f64 {
    let nearest = (x + ROUND) - ROUND;
    nearest - f64::from(u8::from(nearest > x))
}

/// The integer `x` (a whole number, `|x| < 2^31`) as `i32`: the low bits of `x + ROUND`.
#[inline]
fn small_int(x: f64) -> i32 {
    (x + ROUND).to_bits() as u32 as i32
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

    /// The ranges with `f64::ceil` and `f64::floor` of the widened cell coordinates, the textbook
    /// form of what [`CellBounds`] computes without them.
    fn reference_range(lo: f64, hi: f64, half: f64, inv_d: f64, n: usize) -> Range<usize> {
        const SLACK: f64 = 1e-9;
        let first = ((lo + half) * inv_d - 0.5 - SLACK).ceil().max(0.0);
        let end = (((hi + half) * inv_d - 0.5 + SLACK).floor() + 1.0).min(n as f64);
        if first.is_nan() || end.is_nan() || first >= end {
            return 0..0;
        }
        first as usize..end as usize
    }

    #[test]
    fn paired_bounds_equal_single_bounds() {
        use rand::RngExt;
        let g = grid(14, 14, 16);
        let mut rng = crate::rng::rng(9);
        let mut values: Vec<f64> = (0..5000).map(|_| rng.random_range(-0.02..0.02)).collect();
        for j in 0..g.cols {
            let x = g.x(j);
            values.extend([
                x,
                x + 1e-12,
                x - 1e-12,
                x + 0.5 * g.dx_m(),
                x.next_up(),
                x.next_down(),
            ]);
        }
        values.extend([0.0, -0.0, 1e30, -1e30, f64::INFINITY, f64::NEG_INFINITY, f64::NAN]);
        for (&x, &y) in values.iter().zip(values.iter().rev()) {
            assert_eq!(
                g.cell_bounds(x, y),
                (g.col_bounds(x), g.row_bounds(y)),
                "({x}, {y})"
            );
        }
    }

    #[test]
    fn ranges_equal_the_textbook_ceil_and_floor() {
        use rand::RngExt;
        let g = grid(6, 6, 4);
        let mut rng = crate::rng::rng(5);
        let half = g.half_width_m;
        // Random bounds, and bounds on and a hair off the sample centres and cell edges.
        let mut points: Vec<f64> = (0..2000).map(|_| rng.random_range(-0.01..0.01)).collect();
        for j in 0..g.cols {
            for offset in [0.0, 1e-12, -1e-12, 1e-9 * g.dx_m(), g.dx_m() / 2.0] {
                points.push(g.x(j) + offset);
            }
        }
        points.extend([-half, half, 0.0, -1.0, 1.0, 1e30, -1e30]);
        for (k, &lo) in points.iter().enumerate() {
            for &hi in points.iter().skip(k % 7).step_by(37) {
                let inv_d = g.cols as f64 / (2.0 * half);
                let want = reference_range(lo, hi, half, inv_d, g.cols);
                let got = g.col_range(lo, hi);
                assert_eq!(got.is_empty(), want.is_empty(), "[{lo}, {hi}]");
                if !want.is_empty() {
                    assert_eq!(got, want, "[{lo}, {hi}]");
                }
                let want = reference_range(-hi, -lo, half, inv_d, g.rows);
                let got = g.row_range(lo, hi);
                if !want.is_empty() {
                    assert_eq!(got, want, "rows [{lo}, {hi}]");
                } else {
                    assert!(got.is_empty(), "rows [{lo}, {hi}]");
                }
            }
        }
    }
}
