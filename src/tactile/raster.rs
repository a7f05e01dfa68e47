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
//! **Cost.** Near a 6x6 pad a face is about one sample wide, so what a face costs before its
//! samples dominates: each BVH leaf's vertices are placed once, with the sample cells their
//! coordinates bound ([`PadVertex`]); a face's sample rectangle is then integer min/max over its
//! corners; and a face over at most two sample columns is written without a loop over columns.
//!
//! **Inside test.** A sample whose pad point lies inside a solid reads full penetration (the
//! object pushed through the covering). For a closed, outward-oriented mesh the pad point is
//! inside iff the nearest surface crossing *behind* it (largest z < 0) is an entering face; the
//! rasteriser records that crossing per sample in [`Behind`].

use glam::{DMat3, DVec3};

use crate::simd::has_avx2;
use crate::tactile::grid::{CellBounds, SampleGrid};
use crate::tactile::mesh_bvh::{Leaf, MeshBvh};

/// Relative tolerance of the edge test: samples on a shared edge belong to both triangles (both
/// give the same depth there), so rounding never opens a crack between neighbours.
const EDGE_EPS: f64 = 1e-12;

/// Faces spanning more sample columns than this are scanned row by row over the span their
/// edges cut out of the row (cheaper than testing every sample of their bounding box).
const SPAN_MIN_COLUMNS: usize = 4;

/// The same for faces wholly in front of the pad plane, whose samples are tested without
/// branches, several at once: below this width a row's span costs more than the samples it skips.
const SPAN_MIN_COLUMNS_IN_FRONT: usize = 24;

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
    corners: [DVec3; 3],
    far_m: f64,
    nearest_m: &mut [f64],
    behind: &mut Behind,
) {
    let [a, b, c] = corners;
    let at = |p: DVec3| PadVertex::new(grid, p);
    rasterise_face(grid, [at(a), at(b), at(c)], far_m, nearest_m, behind);
}

/// [`rasterise_triangle`] with the corners' cell bounds known.
#[inline(always)]
pub fn rasterise_face(
    grid: &SampleGrid,
    corners: [PadVertex; 3],
    far_m: f64,
    nearest_m: &mut [f64],
    behind: &mut Behind,
) {
    if let Some(face) = FaceSetup::new(grid, corners, far_m) {
        face.draw(grid, far_m, nearest_m, behind);
    }
}

/// A mesh vertex in the pad frame with the sample columns and rows its coordinates bound
/// ([`CellBounds`]): the part of a face's set-up that belongs to its corners, computed once per
/// vertex of a BVH leaf near the pad, although neighbouring faces share it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PadVertex {
    /// Pad-frame position, metres.
    pub p: DVec3,
    cols: CellBounds,
    rows: CellBounds,
}

impl PadVertex {
    #[inline]
    pub fn new(grid: &SampleGrid, p: DVec3) -> Self {
        let (cols, rows) = grid.cell_bounds(p.x, p.y);
        Self { p, cols, rows }
    }
}

/// The per-sample depths of one reading: the nearest surface at or in front of the pad plane, and
/// the crossings behind it for the inside test, with the scratch space for a leaf's vertices.
#[derive(Debug, Clone)]
pub struct DepthBuffer {
    /// Pad-frame depth of the nearest surface in `[0, far]` per sample (+inf: none; -inf: the pad
    /// point is inside a solid).
    pub nearest_m: Vec<f64>,
    pub behind: Behind,
    leaf_vertices: Vec<PadVertex>,
    /// Whether the processor has AVX2 (the sample loops then run four lanes wide).
    avx2: bool,
}

impl DepthBuffer {
    pub fn new(grid: &SampleGrid) -> Self {
        Self {
            nearest_m: vec![f64::INFINITY; grid.len()],
            behind: Behind::new(grid.len()),
            leaf_vertices: Vec::new(),
            avx2: has_avx2(),
        }
    }

    /// Draws the faces of `leaves` of `mesh` placed in the pad frame by
    /// `x -> placement.0 x + placement.1`, then marks the samples inside the mesh. Each leaf's
    /// vertices are placed once.
    pub fn draw_mesh(
        &mut self,
        grid: &SampleGrid,
        mesh: &MeshBvh,
        leaves: &[Leaf],
        placement: (&DMat3, DVec3),
        far_m: f64,
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where the processor has AVX2 (checked at construction).
            unsafe { self.draw_mesh_avx2(grid, mesh, leaves, placement, far_m) };
        } else {
            self.draw_mesh_body(grid, mesh, leaves, placement, far_m);
        }
        #[cfg(not(target_arch = "x86_64"))]
        self.draw_mesh_body(grid, mesh, leaves, placement, far_m);
    }

    /// [`Self::draw_mesh_body`] compiled with AVX2, the sample loops four lanes wide: the same
    /// operations lane by lane, so the same depths bit for bit ([`crate::simd`]).
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn draw_mesh_avx2(
        &mut self,
        grid: &SampleGrid,
        mesh: &MeshBvh,
        leaves: &[Leaf],
        placement: (&DMat3, DVec3),
        far_m: f64,
    ) {
        self.draw_mesh_body(grid, mesh, leaves, placement, far_m);
    }

    #[inline(always)]
    fn draw_mesh_body(
        &mut self,
        grid: &SampleGrid,
        mesh: &MeshBvh,
        leaves: &[Leaf],
        placement: (&DMat3, DVec3),
        far_m: f64,
    ) {
        let (rotation, offset) = placement;
        for &leaf in leaves {
            self.leaf_vertices.clear();
            self.leaf_vertices.extend(
                mesh.leaf_vertices(leaf)
                    .iter()
                    .map(|&v| PadVertex::new(grid, mesh.vertex(v, rotation, offset))),
            );
            for (_, [i, j, k]) in mesh.leaf_faces(leaf) {
                let v = &self.leaf_vertices;
                let corners = [v[i as usize], v[j as usize], v[k as usize]];
                rasterise_face(grid, corners, far_m, &mut self.nearest_m, &mut self.behind);
            }
        }
        self.behind.resolve_into(grid, &mut self.nearest_m);
    }
}

/// What the sample loops need of one face: its sample rectangle and the barycentric weights and
/// depth as affine functions of the sample position,
///
/// ```text
/// w_a = ax x + ay y + a0,   w_b = bx x + by y + b0,   w_c = 1 - w_a - w_b,
/// z = w_a z_a + w_b z_b + w_c z_c = zx x + zy y + z0.
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
struct FaceSetup {
    rows: (u32, u32),
    cols: (u32, u32),
    ax: f64,
    ay: f64,
    a0: f64,
    bx: f64,
    by: f64,
    b0: f64,
    zx: f64,
    zy: f64,
    z0: f64,
    /// The ray enters the solid through the face (`A < 0`).
    entering: bool,
    /// Part of the face lies behind the pad plane.
    behind_possible: bool,
}

/// The lesser of two numbers, one instruction (no care for NaN: a face with a NaN coordinate
/// writes no sample, as its area is NaN or its depths are and fail every comparison).
#[inline(always)]
fn lesser(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

#[inline(always)]
fn greater(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

impl FaceSetup {
    /// The set-up of the triangle with these corners, or `None` when it can write no sample: all
    /// of it beyond `far_m`, its bounding box over no sample, or edge-on to the rays (or
    /// degenerate: a ray grazes such a face at most along a line).
    #[inline(always)]
    fn new(grid: &SampleGrid, [va, vb, vc]: [PadVertex; 3], far_m: f64) -> Option<Self> {
        let (a, b, c) = (va.p, vb.p, vc.p);
        // The cheap rejections first: most faces near the pad lie beyond the covering or cover no
        // sample (at 6x6 taxels the samples are 1 mm apart, about a face's size).
        let zmin = lesser(lesser(a.z, b.z), c.z);
        if zmin > far_m {
            return None;
        }
        let cols = grid.cols_in(va.cols.hull(vb.cols).hull(vc.cols));
        let rows = grid.rows_in(va.rows.hull(vb.rows).hull(vc.rows));
        if cols.is_empty() || rows.is_empty() {
            return None;
        }
        let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        let scale = greater(
            (b - a).truncate().length_squared(),
            (c - a).truncate().length_squared(),
        );
        if !(area.is_finite() && area.abs() > 1e-9 * scale) {
            return None;
        }
        let inv = 1.0 / area;
        let (ax, ay) = (-(c.y - b.y) * inv, (c.x - b.x) * inv);
        let a0 = -(ax * b.x + ay * b.y);
        let (bx, by) = (-(a.y - c.y) * inv, (a.x - c.x) * inv);
        let b0 = -(bx * c.x + by * c.y);
        let (dza, dzb) = (a.z - c.z, b.z - c.z);
        Some(Self {
            rows: (rows.start as u32, rows.end as u32),
            cols: (cols.start as u32, cols.end as u32),
            ax,
            ay,
            a0,
            bx,
            by,
            b0,
            zx: ax * dza + bx * dzb,
            zy: ay * dza + by * dzb,
            z0: c.z + a0 * dza + b0 * dzb,
            entering: area < 0.0,
            behind_possible: zmin < 0.0,
        })
    }

    /// `(w_a, w_b, z)` at `x = 0` on the sample row at `y`.
    #[inline(always)]
    fn at_row(&self, y: f64) -> (f64, f64, f64) {
        (
            self.ay * y + self.a0,
            self.by * y + self.b0,
            self.zy * y + self.z0,
        )
    }

    /// For a face wholly in front of the pad plane: its depth at `x` on a row (`row` from
    /// [`Self::at_row`]) replaces `nearest` where the face covers the sample, within the covering
    /// and nearer, and `on`; without branches.
    #[inline(always)]
    fn write_in_front(
        &self,
        x: f64,
        (wa_row, wb_row, z_row): (f64, f64, f64),
        far_m: f64,
        on: bool,
        nearest: &mut f64,
    ) {
        let tol = -EDGE_EPS;
        let wa = self.ax * x + wa_row;
        let wb = self.bx * x + wb_row;
        let z = self.zx * x + z_row;
        let covers = (wa >= tol) & (wb >= tol) & (1.0 - wa - wb >= tol);
        let nearer = (z >= 0.0) & (z <= far_m) & (z < *nearest);
        *nearest = if on & covers & nearer { z } else { *nearest };
    }

    /// Writes the face into the samples it covers.
    #[inline(always)]
    fn draw(&self, grid: &SampleGrid, far_m: f64, nearest_m: &mut [f64], behind: &mut Behind) {
        if !self.behind_possible && self.cols.1 - self.cols.0 <= 2 {
            self.draw_narrow(grid, far_m, nearest_m);
        } else {
            self.draw_rows(grid, far_m, nearest_m, behind);
        }
    }

    /// [`Self::draw_rows`] for most faces near a coarse pad: wholly in front of the pad plane and
    /// over at most two sample columns. Each row's two samples are tested at once, without a loop
    /// over columns (SSE2 on x86-64), the second masked off when the face has one column.
    #[inline(always)]
    fn draw_narrow(&self, grid: &SampleGrid, far_m: f64, nearest_m: &mut [f64]) {
        let (rows, cols) = (self.rows, self.cols);
        let j0 = cols.0 as usize;
        let j1 = (j0 + 1).min(grid.cols - 1);
        let two_cols = cols.1 - cols.0 == 2;
        let (x0, x1) = (grid.x(j0), grid.x(j1));
        for i in rows.0 as usize..rows.1 as usize {
            let (wa_row, wb_row, z_row) = self.at_row(grid.y(i));
            let (s0, s1) = (i * grid.cols + j0, i * grid.cols + j1);
            #[cfg(target_arch = "x86_64")]
            {
                use std::arch::x86_64::{
                    _mm_add_pd, _mm_and_pd, _mm_andnot_pd, _mm_castsi128_pd, _mm_cmpge_pd, _mm_cmple_pd,
                    _mm_cmplt_pd, _mm_cvtsd_f64, _mm_mul_pd, _mm_or_pd, _mm_set_epi64x, _mm_set_pd,
                    _mm_set1_pd, _mm_sub_pd, _mm_unpackhi_pd,
                };
                // SAFETY: SSE2 is part of the x86-64 baseline: every x86-64 processor has these
                // instructions, and they only read their register arguments.
                let (new0, new1) = unsafe {
                    let x = _mm_set_pd(x1, x0);
                    let along = |slope: f64, at_zero: f64| {
                        _mm_add_pd(_mm_mul_pd(_mm_set1_pd(slope), x), _mm_set1_pd(at_zero))
                    };
                    let (wa, wb, z) = (
                        along(self.ax, wa_row),
                        along(self.bx, wb_row),
                        along(self.zx, z_row),
                    );
                    let wc = _mm_sub_pd(_mm_sub_pd(_mm_set1_pd(1.0), wa), wb);
                    let nearest = _mm_set_pd(nearest_m[s1], nearest_m[s0]);
                    let tol = _mm_set1_pd(-EDGE_EPS);
                    let covers = _mm_and_pd(
                        _mm_and_pd(_mm_cmpge_pd(wa, tol), _mm_cmpge_pd(wb, tol)),
                        _mm_cmpge_pd(wc, tol),
                    );
                    let nearer = _mm_and_pd(
                        _mm_and_pd(
                            _mm_cmpge_pd(z, _mm_set1_pd(0.0)),
                            _mm_cmple_pd(z, _mm_set1_pd(far_m)),
                        ),
                        _mm_cmplt_pd(z, nearest),
                    );
                    let on = _mm_castsi128_pd(_mm_set_epi64x(-i64::from(two_cols), -1));
                    let take = _mm_and_pd(_mm_and_pd(covers, nearer), on);
                    let out = _mm_or_pd(_mm_and_pd(take, z), _mm_andnot_pd(take, nearest));
                    (_mm_cvtsd_f64(out), _mm_cvtsd_f64(_mm_unpackhi_pd(out, out)))
                };
                // Sample 1 first: when the face has one column, it is sample 0 again, unchanged.
                nearest_m[s1] = new1;
                nearest_m[s0] = new0;
            }
            #[cfg(not(target_arch = "x86_64"))]
            for (s, x, on) in [(s1, x1, two_cols), (s0, x0, true)] {
                self.write_in_front(x, (wa_row, wb_row, z_row), far_m, on, &mut nearest_m[s]);
            }
        }
    }

    /// Writes the face into the samples it covers, row by row.
    #[inline(always)]
    fn draw_rows(&self, grid: &SampleGrid, far_m: f64, nearest_m: &mut [f64], behind: &mut Behind) {
        let &Self {
            rows,
            cols,
            ax,
            bx,
            zx,
            entering,
            behind_possible,
            ..
        } = self;
        let tol = -EDGE_EPS;
        let rows = rows.0 as usize..rows.1 as usize;
        let cols = cols.0 as usize..cols.1 as usize;
        if behind_possible {
            behind.touch(&rows, &cols);
        }
        // w_c = 1 - w_a - w_b = cx x + (1 - w_a,row - w_b,row).
        let cx = -(ax + bx);
        // Narrow faces are scanned over their bounding columns; wider ones over each row's span.
        let span_min = if behind_possible {
            SPAN_MIN_COLUMNS
        } else {
            SPAN_MIN_COLUMNS_IN_FRONT
        };
        let spans = (cols.len() > span_min).then(|| [ax, bx, cx].map(|slope| (slope, 1.0 / slope)));
        for i in rows {
            let (wa_row, wb_row, z_row) = self.at_row(grid.y(i));
            let scan = match &spans {
                Some(slopes) => row_span(grid, slopes, [wa_row, wb_row, 1.0 - wa_row - wb_row], &cols),
                None => cols.clone(),
            };
            let row = i * grid.cols;
            if !behind_possible {
                // The whole face is at or in front of the pad plane: a branch-free z-buffer update.
                let (first, last) = (scan.start, scan.end);
                for (&x, nearest) in grid.xs_m()[first..last]
                    .iter()
                    .zip(&mut nearest_m[row + first..row + last])
                {
                    self.write_in_front(x, (wa_row, wb_row, z_row), far_m, true, nearest);
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
}

/// The columns of `cols` a face may cover on one sample row: each weight is affine in x
/// (`slopes`: its slope and the slope's inverse; `at_zero`: its value at x = 0), so `w >= tol`
/// is a half-line. Widened by a sample on each side, the span only skips samples the exact test
/// rejects, whatever the rounding of its bounds.
#[inline(always)]
fn row_span(
    grid: &SampleGrid,
    slopes: &[(f64, f64); 3],
    at_zero: [f64; 3],
    cols: &std::ops::Range<usize>,
) -> std::ops::Range<usize> {
    let tol = -EDGE_EPS;
    let mut span = (f64::NEG_INFINITY, f64::INFINITY);
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
    let widen_m = grid.dx_m();
    let in_span = grid.col_range(span.0 - widen_m, span.1 + widen_m);
    let first = in_span.start.max(cols.start);
    first..in_span.end.min(cols.end).max(first)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tactile::SensorConfig;
    use crate::tactile::mesh_bvh::{OrientedBox, random_rotation};

    #[test]
    fn narrow_faces_drawn_without_column_loops_equal_the_row_loops() {
        use rand::RngExt;
        // Faces over at most two sample columns and any number of rows, everywhere on the pad
        // including its last row and column, into a buffer with earlier depths: both ways must
        // write the same bits.
        let g = SampleGrid::new(&SensorConfig::default());
        let mut rng = crate::rng::rng(17);
        let (mut narrow, mut tall_faces, mut written) = (0, 0, 0);
        for _ in 0..20_000 {
            let centre = DVec3::new(
                rng.random_range(-0.0065..0.0065),
                rng.random_range(-0.0065..0.0065),
                rng.random_range(-0.0002..0.0025),
            );
            let tall = if rng.random_bool(0.3) { 4.0 } else { 1.0 };
            let mut corner = || {
                centre
                    + DVec3::new(
                        rng.random_range(-0.0009..0.0009),
                        tall * rng.random_range(-0.0009..0.0009),
                        rng.random_range(0.0..0.0004),
                    )
            };
            let corners = [corner(), corner(), corner()];
            let Some(face) = FaceSetup::new(&g, corners.map(|p| PadVertex::new(&g, p)), 0.002) else {
                continue;
            };
            if face.behind_possible || face.cols.1 - face.cols.0 > 2 {
                continue;
            }
            narrow += 1;
            tall_faces += usize::from(face.rows.1 - face.rows.0 > 2);
            let before: Vec<f64> = (0..g.len())
                .map(|_| {
                    if rng.random_bool(0.5) {
                        f64::INFINITY
                    } else {
                        rng.random_range(0.0..0.002)
                    }
                })
                .collect();
            let (mut by_rows, mut by_pairs) = (before.clone(), before.clone());
            face.draw_rows(&g, 0.002, &mut by_rows, &mut Behind::new(g.len()));
            face.draw_narrow(&g, 0.002, &mut by_pairs);
            assert_eq!(
                by_rows.iter().map(|z| z.to_bits()).collect::<Vec<_>>(),
                by_pairs.iter().map(|z| z.to_bits()).collect::<Vec<_>>(),
                "{corners:?}"
            );
            written += usize::from(by_rows != before);
        }
        assert!(
            narrow > 5000 && tall_faces > 500 && written > 2000,
            "{narrow} narrow faces ({tall_faces} over more than two rows), {written} wrote"
        );
    }

    #[test]
    fn drawing_leaves_equals_drawing_each_face() {
        use rand::RngExt;
        // Placing each leaf's vertices once must give, bit for bit, the image of placing every
        // face's corners: across the covering, pushed through the pad (inside test), and off it.
        let g = SampleGrid::new(&SensorConfig::default());
        let mesh = crate::tactile::mesh_bvh::bumpy_box(0.006);
        let far_m = 0.002;
        let mut leaves = Vec::new();
        mesh.leaves_near(&OrientedBox::cube(1.0), &mut Vec::new(), &mut leaves);
        assert!(leaves.len() > 20, "{} leaves", leaves.len());
        let mut rng = crate::rng::rng(3);
        let (mut covered, mut inside) = (0, 0);
        for _ in 0..60 {
            let rotation = random_rotation(&mut rng);
            // The box's near side from 2 mm in front of the pad to 3 mm through it.
            let offset = DVec3::new(
                rng.random_range(-0.008..0.008),
                rng.random_range(-0.008..0.008),
                0.006 + rng.random_range(-0.003..0.002),
            );
            let mut each = DepthBuffer::new(&g);
            for &leaf in &leaves {
                for (face, _) in mesh.leaf_faces(leaf) {
                    let corners = mesh.corners(face, &rotation, offset);
                    rasterise_triangle(&g, corners, far_m, &mut each.nearest_m, &mut each.behind);
                }
            }
            each.behind.resolve_into(&g, &mut each.nearest_m);
            let mut by_leaf = DepthBuffer::new(&g);
            by_leaf.draw_mesh(&g, &mesh, &leaves, (&rotation, offset), far_m);
            for (s, (a, b)) in each.nearest_m.iter().zip(&by_leaf.nearest_m).enumerate() {
                assert_eq!(a.to_bits(), b.to_bits(), "sample {s}: {a} vs {b}");
            }
            covered += each.nearest_m.iter().filter(|z| z.is_finite()).count();
            inside += each.nearest_m.iter().filter(|&&z| z == f64::NEG_INFINITY).count();
        }
        // Not vacuous: both the surface in the covering and the inside test were exercised.
        assert!(
            covered > 1000 && inside > 1000,
            "{covered} covered, {inside} inside"
        );
    }

    #[test]
    fn the_four_lane_sample_loops_write_the_same_depths_as_the_baseline() {
        use rand::RngExt;
        // The AVX2 build of the drawing against the baseline build, bit for bit: a bumpy box and
        // a bumpy ball at random poses from off the pad (no contact) across the covering (edges
        // of the object, grazing faces) to pushed through the pad plane (inside test, full
        // contact), at 6x6 with 4 rays and at 14x14 and 26x26 with 16.
        if !has_avx2() {
            return;
        }
        let meshes = [
            crate::tactile::mesh_bvh::bumpy_box(0.006),
            crate::tactile::mesh_bvh::bumpy_ball(0.008),
        ];
        let mut rng = crate::rng::rng(29);
        let (mut covered, mut inside, mut empty) = (0, 0, 0);
        for (n, rays) in [(6, 4), (14, 16), (26, 16)] {
            let config = SensorConfig {
                rows: n,
                cols: n,
                rays_per_taxel: rays,
                ..SensorConfig::default()
            };
            let g = SampleGrid::new(&config);
            for mesh in &meshes {
                let mut leaves = Vec::new();
                mesh.leaves_near(&OrientedBox::cube(1.0), &mut Vec::new(), &mut leaves);
                for _ in 0..40 {
                    let rotation = random_rotation(&mut rng);
                    let r = mesh.bounding_radius_m();
                    let offset = DVec3::new(
                        rng.random_range(-0.012..0.012),
                        rng.random_range(-0.012..0.012),
                        r + rng.random_range(-0.004..0.002),
                    );
                    let (mut wide, mut base) = (DepthBuffer::new(&g), DepthBuffer::new(&g));
                    assert!(wide.avx2);
                    base.avx2 = false;
                    for depth in [&mut wide, &mut base] {
                        depth.draw_mesh(&g, mesh, &leaves, (&rotation, offset), config.thickness_m);
                    }
                    for (s, (a, b)) in wide.nearest_m.iter().zip(&base.nearest_m).enumerate() {
                        assert_eq!(a.to_bits(), b.to_bits(), "sample {s}: {a} vs {b}");
                    }
                    covered += usize::from(base.nearest_m.iter().any(|z| z.is_finite()));
                    inside += usize::from(base.nearest_m.contains(&f64::NEG_INFINITY));
                    empty += usize::from(base.nearest_m.iter().all(|&z| z == f64::INFINITY));
                }
            }
        }
        // Not vacuous: surfaces in the covering, pad points inside the object, and no contact.
        assert!(
            covered > 60 && inside > 30 && empty > 10,
            "{covered} covered, {inside} inside, {empty} empty"
        );
    }

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
