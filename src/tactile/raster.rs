//! Orthographic depth rasterisation: the exact ray-casting answer for the pad's parallel rays.
//!
//! All the pad's rays are parallel to the pad normal (+z in the pad frame), one through each
//! sample `(x_s, y_s)` of the [`SampleGrid`]. The ray through a sample hits triangle `(a, b, c)`
//! iff the sample lies in the triangle's projection onto the pad plane, at the depth given by the
//! barycentric interpolation
//!
//! ```text
//! z = w_a z_a + w_b z_b + w_c z_c,   w_a = E(b, c, s) / A,  w_b = E(c, a, s) / A,  w_c = E(a, b, s) / A,
//! E(p, q, s) = (q_x - p_x)(s_y - p_y) - (q_y - p_y)(s_x - p_x),   A = E(a, b, c),
//! ```
//!
//! which is the ray-triangle intersection distance. So instead of casting each ray through a
//! BVH, each triangle near the pad is visited once and writes the samples it covers (a z-buffer).
//! Along a sample row each weight is affine in x, so `w >= 0` holds on a half-line and the
//! triangle covers one span of the row: a wide triangle scans only that span (widened by a sample
//! so that rounding of its ends never drops one), a narrow one its bounding columns.
//! `A` is twice the signed projected area: with the pad frame right-handed, the triangle's normal
//! has z-component `A`, so `A < 0` marks a face the ray *enters* (outward normal against the ray).
//!
//! **Inside test.** A sample whose pad point lies inside a solid reads full penetration (the
//! object pushed through the covering). For a closed, outward-oriented mesh the pad point is
//! inside iff the nearest surface crossing *behind* it (largest z < 0) is an entering face; the
//! rasteriser records that crossing per sample in [`Behind`].

use glam::DVec3;

use crate::tactile::grid::SampleGrid;

/// Relative tolerance of the edge test: samples on a shared edge belong to both triangles (both
/// give the same depth there), so rounding never opens a crack between neighbours.
const EDGE_EPS: f64 = 1e-12;

/// Faces spanning more sample columns than this are scanned row by row over the span their
/// edges cut out of the row (cheaper than testing every sample of their bounding box).
const SPAN_MIN_COLUMNS: usize = 4;

/// The nearest surface crossing behind the pad plane at one sample, for the inside test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// Pad-frame z of the crossing (negative), or -inf when none was seen.
    pub z_m: f64,
    /// Whether the ray enters the solid there.
    pub entering: bool,
}

impl Crossing {
    pub const NONE: Self = Self {
        z_m: f64::NEG_INFINITY,
        entering: false,
    };
}

/// Per-sample crossings behind the pad of one mesh, and the sample rectangle they were written in
/// (so resetting costs only what was touched).
#[derive(Debug, Clone)]
pub struct Behind {
    crossings: Vec<Crossing>,
    touched_rows: (usize, usize),
    touched_cols: (usize, usize),
}

impl Behind {
    pub fn new(samples: usize) -> Self {
        Self {
            crossings: vec![Crossing::NONE; samples],
            touched_rows: (usize::MAX, 0),
            touched_cols: (usize::MAX, 0),
        }
    }

    fn touch(&mut self, rows: &std::ops::Range<usize>, cols: &std::ops::Range<usize>) {
        self.touched_rows = (
            self.touched_rows.0.min(rows.start),
            self.touched_rows.1.max(rows.end),
        );
        self.touched_cols = (
            self.touched_cols.0.min(cols.start),
            self.touched_cols.1.max(cols.end),
        );
    }

    /// Marks every sample whose pad point is inside the mesh (nearest crossing behind it enters
    /// the solid) as fully penetrated (`nearest = -inf`), then forgets all crossings.
    pub fn resolve_into(&mut self, grid: &SampleGrid, nearest_m: &mut [f64]) {
        let (r0, r1) = self.touched_rows;
        let (c0, c1) = self.touched_cols;
        for i in r0..r1.min(grid.rows) {
            for j in c0..c1.min(grid.cols) {
                let s = i * grid.cols + j;
                if self.crossings[s].entering {
                    nearest_m[s] = f64::NEG_INFINITY;
                }
                self.crossings[s] = Crossing::NONE;
            }
        }
        self.touched_rows = (usize::MAX, 0);
        self.touched_cols = (usize::MAX, 0);
    }

    /// The recorded crossing at sample `s`.
    pub fn crossing(&self, s: usize) -> Crossing {
        self.crossings[s]
    }
}

/// Writes triangle `[a, b, c]` (pad-frame metres) into the per-sample nearest depth at or in front of
/// the pad plane (`nearest_m`, for z in `[0, far_m]`) and into the crossings behind it.
#[inline]
pub fn rasterise_triangle(
    grid: &SampleGrid,
    [a, b, c]: [DVec3; 3],
    far_m: f64,
    nearest_m: &mut [f64],
    behind: &mut Behind,
) {
    // The cheap rejections first: most faces near the pad lie beyond the covering or cover no
    // sample (at 6x6 taxels the samples are 1 mm apart, about a face's size).
    let zmin = a.z.min(b.z).min(c.z);
    if zmin > far_m {
        return;
    }
    let cols = grid.col_range(a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
    let rows = grid.row_range(a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
    if cols.is_empty() || rows.is_empty() {
        return;
    }
    let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    let scale = (b - a)
        .truncate()
        .length_squared()
        .max((c - a).truncate().length_squared());
    if !area.is_finite() || area.abs() <= 1e-9 * scale {
        // Edge-on to the rays (or degenerate): a ray grazes it at most along a line.
        return;
    }
    let behind_possible = zmin < 0.0;
    if behind_possible {
        behind.touch(&rows, &cols);
    }
    // Barycentric weights and depth as affine functions of the sample position:
    // w_a = ax x + ay y + a0,  w_b = bx x + by y + b0,  w_c = 1 - w_a - w_b,
    // z = w_a z_a + w_b z_b + w_c z_c = zx x + zy y + z0.
    let inv = 1.0 / area;
    let (ax, ay) = (-(c.y - b.y) * inv, (c.x - b.x) * inv);
    let a0 = -(ax * b.x + ay * b.y);
    let (bx, by) = (-(a.y - c.y) * inv, (a.x - c.x) * inv);
    let b0 = -(bx * c.x + by * c.y);
    let (dza, dzb) = (a.z - c.z, b.z - c.z);
    let (zx, zy, z0) = (
        ax * dza + bx * dzb,
        ay * dza + by * dzb,
        c.z + a0 * dza + b0 * dzb,
    );
    let tol = -EDGE_EPS;
    let entering = area < 0.0;
    // w_c = 1 - w_a - w_b = cx x + (1 - w_a,row - w_b,row).
    let cx = -(ax + bx);
    // Narrow faces are scanned over their bounding columns; wider ones over each row's span.
    let spans = (cols.len() > SPAN_MIN_COLUMNS).then(|| [ax, bx, cx].map(|slope| (slope, 1.0 / slope)));
    let widen_m = grid.dx_m();
    for i in rows {
        let y = grid.y(i);
        let (wa_row, wb_row, z_row) = (ay * y + a0, by * y + b0, zy * y + z0);
        let mut scan = cols.clone();
        if let Some(slopes) = &spans {
            // The row's span inside the triangle: each weight is affine in x, so `w >= tol` is a
            // half-line. Widened by a sample on each side, the span only skips samples the exact
            // test below rejects, whatever the rounding of its bounds.
            let mut span = (f64::NEG_INFINITY, f64::INFINITY);
            let at_zero = [wa_row, wb_row, 1.0 - wa_row - wb_row];
            for ((slope, inv_slope), w0) in slopes.iter().zip(at_zero) {
                let bound = (tol - w0) * inv_slope;
                if *slope > 0.0 {
                    span.0 = span.0.max(bound);
                } else if *slope < 0.0 {
                    span.1 = span.1.min(bound);
                } else if w0 < tol {
                    span = (f64::INFINITY, f64::NEG_INFINITY);
                }
            }
            let in_span = grid.col_range(span.0 - widen_m, span.1 + widen_m);
            let first = in_span.start.max(cols.start);
            scan = first..in_span.end.min(cols.end).max(first);
        }
        let row = i * grid.cols;
        if !behind_possible {
            // The whole face is at or in front of the pad plane: a branch-free z-buffer update.
            let (first, last) = (scan.start, scan.end);
            for (j, nearest) in (first..last).zip(&mut nearest_m[row + first..row + last]) {
                let x = grid.x(j);
                let wa = ax * x + wa_row;
                let wb = bx * x + wb_row;
                let z = zx * x + z_row;
                let covers = (wa >= tol) & (wb >= tol) & (1.0 - wa - wb >= tol);
                let nearer = (z >= 0.0) & (z <= far_m) & (z < *nearest);
                *nearest = if covers & nearer { z } else { *nearest };
            }
            continue;
        }
        for j in scan {
            let x = grid.x(j);
            let wa = ax * x + wa_row;
            let wb = bx * x + wb_row;
            if wa < tol || wb < tol || 1.0 - wa - wb < tol {
                continue;
            }
            let z = zx * x + z_row;
            let s = row + j;
            if z >= 0.0 {
                if z <= far_m && z < nearest_m[s] {
                    nearest_m[s] = z;
                }
            } else if z > behind.crossings[s].z_m {
                behind.crossings[s] = Crossing { z_m: z, entering };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tactile::SensorConfig;

    fn grid() -> SampleGrid {
        SampleGrid::new(&SensorConfig {
            rows: 8,
            cols: 8,
            rays_per_taxel: 1,
            ..SensorConfig::default()
        })
    }

    #[test]
    fn depth_is_the_ray_plane_intersection() {
        let g = grid();
        let mut nearest = vec![f64::INFINITY; g.len()];
        let mut behind = Behind::new(g.len());
        // Plane z = 0.0003 + 0.02 x - 0.01 y, covering the whole pad, as two triangles.
        let z = |x: f64, y: f64| 0.0003 + 0.02 * x - 0.01 * y;
        let p = |x: f64, y: f64| DVec3::new(x, y, z(x, y));
        let (l, h) = (-0.01, 0.01);
        rasterise_triangle(&g, [p(l, l), p(h, l), p(h, h)], 1.0, &mut nearest, &mut behind);
        rasterise_triangle(&g, [p(l, l), p(h, h), p(l, h)], 1.0, &mut nearest, &mut behind);
        for i in 0..g.rows {
            for j in 0..g.cols {
                assert!((nearest[i * g.cols + j] - z(g.x(j), g.y(i))).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn wide_faces_write_exactly_the_samples_they_cover() {
        use rand::RngExt;
        // Random faces in front of the pad, wide and narrow, against a per-sample barycentric
        // test over the whole grid: the row spans must not drop a covered sample.
        let g = SampleGrid::new(&SensorConfig {
            rows: 10,
            cols: 10,
            rays_per_taxel: 16,
            ..SensorConfig::default()
        });
        let mut rng = crate::rng::rng(11);
        for _ in 0..300 {
            let mut corner = || {
                DVec3::new(
                    rng.random_range(-0.008..0.008),
                    rng.random_range(-0.008..0.008),
                    rng.random_range(0.0..0.002),
                )
            };
            let tri = [corner(), corner(), corner()];
            let mut nearest = vec![f64::INFINITY; g.len()];
            let mut behind = Behind::new(g.len());
            rasterise_triangle(&g, tri, 1.0, &mut nearest, &mut behind);
            let [a, b, c] = tri;
            let e = |p: DVec3, q: DVec3, x: f64, y: f64| (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x);
            let area = e(a, b, c.x, c.y);
            for i in 0..g.rows {
                for j in 0..g.cols {
                    let (x, y) = (g.x(j), g.y(i));
                    let w = [e(b, c, x, y) / area, e(c, a, x, y) / area, e(a, b, x, y) / area];
                    let s = i * g.cols + j;
                    // Clear of the edges, the sample is covered iff all weights are positive.
                    if w.iter().all(|&w| w > 1e-9) {
                        let z = w[0] * a.z + w[1] * b.z + w[2] * c.z;
                        assert!((nearest[s] - z).abs() < 1e-15, "sample ({i}, {j}) of {tri:?}");
                    } else if w.iter().any(|&w| w < -1e-9) {
                        assert_eq!(nearest[s], f64::INFINITY, "sample ({i}, {j}) of {tri:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn far_and_edge_on_triangles_are_ignored() {
        let g = grid();
        let mut nearest = vec![f64::INFINITY; g.len()];
        let mut behind = Behind::new(g.len());
        let tri = [
            DVec3::new(-0.01, -0.01, 0.002),
            DVec3::new(0.01, -0.01, 0.002),
            DVec3::new(0.0, 0.01, 0.002),
        ];
        rasterise_triangle(&g, tri, 0.001, &mut nearest, &mut behind);
        let edge_on = [
            DVec3::new(-0.01, 0.0, 0.0),
            DVec3::new(0.01, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 0.001),
        ];
        rasterise_triangle(&g, edge_on, 1.0, &mut nearest, &mut behind);
        assert!(nearest.iter().all(|z| z.is_infinite()));
    }

    #[test]
    fn entering_face_behind_the_pad_marks_inside() {
        let g = grid();
        let mut nearest = vec![f64::INFINITY; g.len()];
        let mut behind = Behind::new(g.len());
        // A face at z = -0.001 whose normal points toward -z (clockwise seen from +z): the ray enters there.
        let tri = [
            DVec3::new(-0.02, -0.02, -0.001),
            DVec3::new(0.0, 0.02, -0.001),
            DVec3::new(0.02, -0.02, -0.001),
        ];
        rasterise_triangle(&g, tri, 1.0, &mut nearest, &mut behind);
        let centre = (g.rows / 2) * g.cols + g.cols / 2;
        assert!(behind.crossing(centre).entering);
        behind.resolve_into(&g, &mut nearest);
        assert_eq!(nearest[centre], f64::NEG_INFINITY);
        assert_eq!(behind.crossing(centre), Crossing::NONE);
        // The same face wound the other way leaves the solid there: the pad point is outside.
        let mut nearest = vec![f64::INFINITY; g.len()];
        rasterise_triangle(&g, [tri[0], tri[2], tri[1]], 1.0, &mut nearest, &mut behind);
        behind.resolve_into(&g, &mut nearest);
        assert!(nearest.iter().all(|&z| z == f64::INFINITY));
    }
}
