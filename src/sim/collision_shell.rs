//! The object's collision shape for MuJoCo: a shell of small convex pieces hugging its surface.
//!
//! MuJoCo collides a mesh geom through its convex hull. For a concave object (a camel, a person, a
//! dinosaur) the hull spans the gaps between legs and arms and the dips of the surface, so the arm
//! would collide with empty space long before the covering reaches the surface: the planner read
//! nothing at all of such objects (Sec. III-A asks for motions that are collision-free with the
//! object, not with its hull). The tactile sensor raycasts the exact triangles; the contacts must see
//! nearly the same solid.
//!
//! The shell is a convex decomposition of the surface, not of the volume: triangles are split
//! recursively at the median of their centroids along the longest side of their bounding box until
//! each piece is convex within `tolerance_m` (no vertex of the piece lies more than that in front of
//! the plane of any of its triangles, so the piece's hull rises at most that far above its
//! triangles) or its bounding diagonal is at most `min_extent_m`. Each piece's points are thickened
//! inward along the piece's mean normal by `thickness_m`, so that a flat piece still has a volume for
//! MuJoCo's hull. Convex parts of the surface become a few large pieces, concave parts many small
//! ones. An arm link moving in from outside meets the shell where it meets the surface (within the
//! tolerance); the inside of the object is left hollow, which no motion starting outside can reach
//! without crossing the shell.

use glam::DVec3;

use crate::mesh::TriMesh;

/// How finely the shell follows the surface.
///
/// Only the arm's links collide with the shell (the pad's rigid back does not: its contact with the
/// object is the covering's to measure, see `mjcf/arm.xml`), so the shell may stand a little above
/// the surface: a link passing a few millimetres from the object is not a motion the planner needs.
/// The defaults were chosen by measurement on the `shapes` set (`taction collect --mode planner`):
/// 40-200 pieces an object; a finer shell (0.2 mm, 3 mm pieces: 350-8,300 pieces) converged no
/// more readings and cost ten times the collision-checking time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellOptions {
    /// Largest rise of a piece's hull above its own triangles, metres.
    pub tolerance_m: f64,
    /// Pieces this small (bounding diagonal, metres) are not split further, however concave.
    pub min_extent_m: f64,
    /// Pieces are split regardless of shape above this bounding diagonal, metres.
    pub max_extent_m: f64,
    /// Inward thickness given to each piece, metres.
    pub thickness_m: f64,
}

impl Default for ShellOptions {
    fn default() -> Self {
        Self {
            tolerance_m: 2e-3,
            min_extent_m: 0.02,
            max_extent_m: 0.1,
            thickness_m: 0.5e-3,
        }
    }
}

/// Pieces of the shell: each a point cloud whose convex hull is one collision geom.
pub fn collision_shell(mesh: &TriMesh, options: &ShellOptions) -> Vec<Vec<DVec3>> {
    let mut pieces = Vec::new();
    let mut stack = vec![(0..mesh.triangles.len()).collect::<Vec<usize>>()];
    let centroid = |t: usize| {
        let [a, b, c] = mesh.corners(t);
        (a + b + c) / 3.0
    };
    while let Some(mut triangles) = stack.pop() {
        if triangles.is_empty() {
            continue;
        }
        let (lo, hi) = triangles
            .iter()
            .flat_map(|&t| mesh.corners(t))
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            });
        let extent = (hi - lo).length();
        let done = triangles.len() == 1
            || extent <= options.min_extent_m
            || (extent <= options.max_extent_m && is_convex_piece(mesh, &triangles, options.tolerance_m));
        if done {
            pieces.push(thickened_points(mesh, &triangles, options));
            continue;
        }
        let axis = (hi - lo).max_position();
        let middle = triangles.len() / 2;
        triangles.select_nth_unstable_by(middle, |&a, &b| {
            centroid(a)[axis].total_cmp(&centroid(b)[axis]).then(a.cmp(&b))
        });
        let upper = triangles.split_off(middle);
        stack.push(upper);
        stack.push(triangles);
    }
    pieces
}

/// Vertex-plane tests allowed for one piece's convexity check; a larger piece counts as not convex
/// and is split, so the check stays linear in the mesh size (a convex 1M-triangle scan becomes a few
/// hundred pieces instead of a quadratic test).
const CONVEXITY_TEST_BUDGET: usize = 20_000_000;

/// Whether no vertex of the piece lies more than `tolerance_m` in front of any of its triangles'
/// planes (a convex cap: its hull is the surface itself, up to the tolerance).
///
/// Each plane is tested against boxes of nearby vertices first ([`VertexBoxes`]); only the
/// vertices of a box that may reach past the tolerance are tested one by one, with the very
/// expression of the one-by-one test, so the answer is the one-by-one answer. On a 1.3M-triangle
/// sphere this took the shell from most of the scene's MJCF time to a small part of it (issue 39).
fn is_convex_piece(mesh: &TriMesh, triangles: &[usize], tolerance_m: f64) -> bool {
    let mut vertices: Vec<u32> = triangles.iter().flat_map(|&t| mesh.triangles[t]).collect();
    vertices.sort_unstable();
    vertices.dedup();
    if triangles.len().saturating_mul(vertices.len()) > CONVEXITY_TEST_BUDGET {
        return false;
    }
    let boxes = VertexBoxes::new(vertices.iter().map(|&v| mesh.vertices[v as usize]).collect());
    triangles.iter().all(|&t| {
        let [a, b, c] = mesh.corners(t);
        let Some(n) = (b - a).cross(c - a).try_normalize() else {
            return true;
        };
        boxes.all_behind(n, a, tolerance_m)
    })
}

/// Vertices per box of [`VertexBoxes`].
const BOX_VERTICES: usize = 16;

/// Bound on the rounding of `n . (p - a)` for coordinates of table-top size (metres): a box whose
/// bound stays this far inside the tolerance cannot hold a vertex the exact test would reject.
const BOUND_MARGIN_M: f64 = 1e-9;

/// A piece's vertices grouped into small axis-aligned boxes of neighbours (median splits along
/// the longest side), so that a plane far above a box clears all of its vertices at once.
struct VertexBoxes {
    points: Vec<DVec3>,
    /// (centre, half-size, range of `points`) of each box.
    boxes: Vec<(DVec3, DVec3, std::ops::Range<usize>)>,
}

impl VertexBoxes {
    fn new(mut points: Vec<DVec3>) -> Self {
        let mut boxes = Vec::new();
        let mut stack = Vec::new();
        stack.push(0..points.len());
        while let Some(range) = stack.pop() {
            let (lo, hi) = points[range.clone()]
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                    (lo.min(p), hi.max(p))
                });
            if range.len() <= BOX_VERTICES {
                boxes.push(((lo + hi) * 0.5, (hi - lo) * 0.5, range));
                continue;
            }
            let axis = (hi - lo).max_position();
            let middle = range.len() / 2;
            points[range.clone()].select_nth_unstable_by(middle, |p, q| p[axis].total_cmp(&q[axis]));
            let split = range.start + middle;
            stack.push(range.start..split);
            stack.push(split..range.end);
        }
        Self { points, boxes }
    }

    /// Whether every vertex `p` has `n . (p - a) <= tolerance_m`.
    fn all_behind(&self, n: DVec3, a: DVec3, tolerance_m: f64) -> bool {
        self.boxes.iter().all(|(centre, half, range)| {
            let bound = n.dot(*centre - a) + n.abs().dot(*half);
            bound <= tolerance_m - BOUND_MARGIN_M
                || self.points[range.clone()]
                    .iter()
                    .all(|&p| n.dot(p - a) <= tolerance_m)
        })
    }
}

/// Surface vertices up to which a piece goes to MuJoCo whole. The pieces of every built-in object
/// have at most 1,729 (the rook's), so their shells are the exact vertex sets; a mesh finer than
/// the shell's tolerance (a scan: 1.3M triangles make pieces of about 2,300 vertices, hundreds of
/// them) has its pieces thinned by [`one_vertex_per_cell`], since MuJoCo's compile of their hulls
/// was most of the time from such a file to its first reading (issue 39).
const WHOLE_PIECE_VERTICES: usize = 2048;

/// The piece's vertices (thinned to one per cell of half the tolerance when there are more than
/// [`WHOLE_PIECE_VERTICES`]) and the same pushed `thickness_m` against its area-weighted mean
/// normal.
fn thickened_points(mesh: &TriMesh, triangles: &[usize], options: &ShellOptions) -> Vec<DVec3> {
    let mut vertices: Vec<u32> = triangles.iter().flat_map(|&t| mesh.triangles[t]).collect();
    vertices.sort_unstable();
    vertices.dedup();
    if vertices.len() > WHOLE_PIECE_VERTICES {
        vertices = one_vertex_per_cell(mesh, &vertices, options.tolerance_m / 2.0);
    }
    let thickness_m = options.thickness_m;
    let area_normal = |t: usize| {
        let [a, b, c] = mesh.corners(t);
        (b - a).cross(c - a)
    };
    let summed: DVec3 = triangles.iter().map(|&t| area_normal(t)).sum();
    // A piece wrapping both sides of a thin part has a vanishing mean normal but is no flat sheet;
    // the largest triangle's normal still thickens it.
    let normal = summed
        .try_normalize()
        .filter(|_| summed.length() > 1e-3 * triangles.iter().map(|&t| area_normal(t).length()).sum::<f64>())
        .or_else(|| {
            triangles
                .iter()
                .map(|&t| area_normal(t))
                .max_by(|a, b| a.length().total_cmp(&b.length()))
                .and_then(DVec3::try_normalize)
        })
        .unwrap_or(DVec3::Z);
    let points = vertices.iter().map(|&v| mesh.vertices[v as usize]);
    points
        .clone()
        .chain(points.map(|p| p - normal * thickness_m))
        .collect()
}

/// Of `vertices` (sorted), the lowest-numbered in each cube of side `cell_m` of a grid, sorted.
/// Every dropped vertex lies within a cube's diagonal `sqrt(3) cell_m` of a kept one, so the hull
/// of the kept points lies inside the hull of all of them by at most that: the shell stands at
/// most 1.7 mm below its tolerance for the default 2 mm (the arm's links may come that much
/// closer to such an object; the sensor reads the exact mesh).
fn one_vertex_per_cell(mesh: &TriMesh, vertices: &[u32], cell_m: f64) -> Vec<u32> {
    let cell = |v: u32| {
        (mesh.vertices[v as usize] / cell_m)
            .floor()
            .as_i64vec3()
            .to_array()
    };
    let mut keyed: Vec<([i64; 3], u32)> = vertices.iter().map(|&v| (cell(v), v)).collect();
    keyed.sort_unstable();
    keyed.dedup_by_key(|(key, _)| *key);
    let mut kept: Vec<u32> = keyed.into_iter().map(|(_, v)| v).collect();
    kept.sort_unstable();
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_convex_solid_is_one_piece() {
        let mesh = TriMesh::cuboid(DVec3::new(0.01, 0.008, 0.005));
        let pieces = collision_shell(&mesh, &ShellOptions::default());
        assert_eq!(pieces.len(), 1);
    }

    #[test]
    fn a_concave_solid_is_split_and_no_piece_spans_the_notch() {
        // Two boxes side by side with a 2 cm gap between them, as one mesh: the hull of the whole
        // would fill the gap.
        let left = TriMesh::cuboid(DVec3::splat(0.01));
        let mut mesh = left.clone();
        let offset = mesh.vertices.len() as u32;
        mesh.vertices
            .extend(left.vertices.iter().map(|v| *v + DVec3::new(0.04, 0.0, 0.0)));
        mesh.triangles
            .extend(left.triangles.iter().map(|t| t.map(|i| i + offset)));
        let pieces = collision_shell(&mesh, &ShellOptions::default());
        assert!(pieces.len() >= 2);
        // The gap's middle plane x = 0.02 lies strictly between pieces: no piece has points on
        // both sides of it.
        for piece in &pieces {
            let below = piece.iter().any(|p| p.x < 0.015);
            let above = piece.iter().any(|p| p.x > 0.025);
            assert!(!(below && above), "a piece spans the gap");
        }
    }

    #[test]
    fn a_flat_piece_is_thickened_inward() {
        let mesh = TriMesh {
            vertices: vec![
                DVec3::ZERO,
                DVec3::new(0.001, 0.0, 0.0),
                DVec3::new(0.0, 0.001, 0.0),
            ],
            triangles: vec![[0, 1, 2]],
        };
        let pieces = collision_shell(&mesh, &ShellOptions::default());
        assert_eq!(pieces.len(), 1);
        let z: Vec<f64> = pieces[0].iter().map(|p| p.z).collect();
        assert_eq!(z.iter().filter(|&&z| z == 0.0).count(), 3);
        assert_eq!(z.iter().filter(|&&z| (z + 0.5e-3).abs() < 1e-12).count(), 3);
    }

    #[test]
    fn pieces_cover_every_vertex() {
        let mut mesh = TriMesh::cuboid(DVec3::splat(0.02));
        // A dent: push the top face's corner vertex in, making the top concave.
        mesh.vertices[7].z -= 0.015;
        let pieces = collision_shell(&mesh, &ShellOptions::default());
        for v in &mesh.vertices {
            assert!(pieces.iter().flatten().any(|p| p == v));
        }
    }

    #[test]
    fn a_finely_tessellated_convex_solid_stays_a_few_pieces_each_within_the_tolerance() {
        // A 12 cm sphere of 2 x 64 x 128 triangles: convex, so every piece is a cap of it (no
        // point outside the sphere), and few pieces are needed.
        let (rings, segments) = (64, 128);
        let mut mesh = TriMesh {
            vertices: vec![DVec3::new(0.0, 0.0, 0.06), DVec3::new(0.0, 0.0, -0.06)],
            triangles: Vec::new(),
        };
        for i in 1..rings {
            let polar = std::f64::consts::PI * i as f64 / rings as f64;
            for j in 0..segments {
                let azimuth = std::f64::consts::TAU * j as f64 / segments as f64;
                mesh.vertices.push(
                    0.06 * DVec3::new(
                        polar.sin() * azimuth.cos(),
                        polar.sin() * azimuth.sin(),
                        polar.cos(),
                    ),
                );
            }
        }
        let at = |i: u32, j: u32| 2 + (i - 1) * segments + j % segments;
        for j in 0..segments {
            mesh.triangles.push([0, at(1, j), at(1, j + 1)]);
            mesh.triangles.push([1, at(rings - 1, j + 1), at(rings - 1, j)]);
            for i in 1..rings - 1 {
                mesh.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                mesh.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        let options = ShellOptions::default();
        let pieces = collision_shell(&mesh, &options);
        assert!((2..=64).contains(&pieces.len()), "{} pieces", pieces.len());
        for piece in &pieces {
            for p in piece {
                assert!(p.length() <= 0.06 + 1e-9, "a shell point outside the sphere: {p}");
            }
        }
    }

    /// A square grid of `n x n` cells of side `spacing_m` from the origin, the surface
    /// `z = height(x, y)`, two triangles a cell.
    fn grid_mesh(n: u32, spacing_m: f64, height: impl Fn(f64, f64) -> f64) -> TriMesh {
        let mut mesh = TriMesh::default();
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (i as f64 * spacing_m, j as f64 * spacing_m);
                mesh.vertices.push(DVec3::new(x, y, height(x, y)));
            }
        }
        let at = |i: u32, j: u32| i * (n + 1) + j;
        for i in 0..n {
            for j in 0..n {
                mesh.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                mesh.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        mesh
    }

    /// A piece finer than the tolerance (a 1 cm plate of 101 x 101 vertices, one piece) goes to
    /// MuJoCo thinned to one vertex per 1 mm cell: a few hundred points instead of 20,402, every
    /// one a vertex of the plate or its thickened copy, and every vertex of the plate within a
    /// cell's diagonal of a kept one.
    #[test]
    fn a_piece_finer_than_the_tolerance_keeps_one_vertex_per_cell() {
        let mesh = grid_mesh(100, 1e-4, |_, _| 0.0);
        let options = ShellOptions::default();
        let pieces = collision_shell(&mesh, &options);
        assert_eq!(pieces.len(), 1);
        let piece = &pieces[0];
        let surface: Vec<DVec3> = piece.iter().copied().filter(|p| p.z == 0.0).collect();
        assert_eq!(surface.len() * 2, piece.len());
        assert!((100..=2 * 11 * 11).contains(&surface.len()), "{}", surface.len());
        assert!(surface.iter().all(|p| mesh.vertices.contains(p)));
        let reach = 3f64.sqrt() * options.tolerance_m / 2.0;
        for v in &mesh.vertices {
            assert!(
                surface.iter().any(|p| p.distance(*v) <= reach),
                "{v} far from the shell"
            );
        }
    }

    /// The one-by-one test the boxes must agree with.
    fn convex_one_by_one(mesh: &TriMesh, triangles: &[usize], tolerance_m: f64) -> bool {
        let mut vertices: Vec<u32> = triangles.iter().flat_map(|&t| mesh.triangles[t]).collect();
        vertices.sort_unstable();
        vertices.dedup();
        triangles.iter().all(|&t| {
            let [a, b, c] = mesh.corners(t);
            let Some(n) = (b - a).cross(c - a).try_normalize() else {
                return true;
            };
            vertices
                .iter()
                .all(|&v| n.dot(mesh.vertices[v as usize] - a) <= tolerance_m)
        })
    }

    #[test]
    fn the_boxed_convexity_test_answers_as_the_one_by_one_test() {
        // A wavy 40 x 40 grid (concave and convex patches) and its sub-patches, at tolerances
        // around the waves' height: both answers occur and every answer agrees.
        let mesh = grid_mesh(40, 1e-3, |x, y| {
            1e-3 * (x * 300.0).sin() * (y * 200.0).cos() - 2.0 * (x * x + y * y)
        });
        let mut answers = [0usize; 2];
        for size in [4usize, 10, 25, 40] {
            for start in [0usize, 7, 300, 1000] {
                let triangles: Vec<usize> =
                    (start..(start + size * size * 2).min(mesh.triangles.len())).collect();
                for tolerance_m in [0.0, 1e-5, 1e-4, 5e-4, 1e-3, 2e-3, 5e-3] {
                    let boxed = is_convex_piece(&mesh, &triangles, tolerance_m);
                    assert_eq!(boxed, convex_one_by_one(&mesh, &triangles, tolerance_m));
                    answers[boxed as usize] += 1;
                }
            }
        }
        assert!(answers[0] > 0 && answers[1] > 0, "{answers:?}");
    }
}
