//! One `obvhs` BVH per mesh of the compiled model, built once, queried with the pad's slab.
//!
//! The pad's rays are parallel and only depths in a thin range matter, so instead of traversing
//! the BVH once per ray, the BVH is traversed once per image with the oriented box that contains
//! every ray segment of interest (the pad rectangle swept along the normal over `[z_lo, t]`).
//! The few leaves that overlap that box are then rasterised onto the sample grid
//! ([`crate::tactile::raster`]), which gives exactly the ray-casting depths. Each leaf lists its
//! distinct vertices at build time, so a reading moves each vertex near the pad into the pad frame
//! once, not once for each of the (about six) faces that share it.
//!
//! Vertices are read from the compiled model's `mesh_vert` (MuJoCo re-centres and re-orients them
//! into the mesh's inertial frame, which is the geom frame), or, for a large scan whose asset is a
//! coarse copy, from its exact surface placed the same way (`covering::sensed_surface`), so
//! together with `geom_xpos` and `geom_xmat` they give world positions with no further bookkeeping.

use std::time::Duration;

use glam::{DMat3, DVec3, Mat3A, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::triangle::Triangle;

/// An oriented box in a mesh's frame: `centre + sum_i u_i axes[i]`, `|u_i| <= half[i]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientedBox {
    pub centre: DVec3,
    /// Orthonormal axes.
    pub axes: [DVec3; 3],
    pub half: DVec3,
}

impl OrientedBox {
    /// The axis-aligned cube of half-side `half_m` about the origin (for tests: a box that holds
    /// a whole small mesh).
    #[cfg(test)]
    pub(crate) fn cube(half_m: f64) -> Self {
        Self {
            centre: DVec3::ZERO,
            axes: [DVec3::X, DVec3::Y, DVec3::Z],
            half: DVec3::splat(half_m),
        }
    }

    /// Whether the box may overlap the axis-aligned box `[lo, hi]`: the separating-axis test on
    /// the three coordinate axes and the three box axes (conservative: the nine edge-cross axes are
    /// skipped, and the test runs in `f32` widened by more than its rounding, so rare
    /// non-overlapping pairs pass, never the reverse).
    #[inline]
    pub fn may_overlap(&self, lo: DVec3, hi: DVec3) -> bool {
        let scale = lo.abs().max(hi.abs()).max_element() as f32;
        OverlapTest::new(self, scale).may_overlap(lo.as_vec3a(), hi.as_vec3a())
    }
}

/// [`OrientedBox::may_overlap`] with the parts that depend on the oriented box alone computed
/// once, for the many boxes of one BVH query, in `f32` (the BVH's own precision: four lanes per
/// vector, half the bytes).
///
/// For a node with centre `c` and half-extent `e`, and `t = centre - c`, the axes separate the
/// boxes where `|t_k| > reach_k + e_k` (coordinate axis `k`, `reach` the box's half-extent along
/// it) or `|a_i . t| > half_i + |a_i| . e` (box axis `a_i`). `f32` rounding moves each side by at
/// most a few ulps of the largest coordinate involved; both right-hand sides are widened by
/// [`Self::SLACK`] times that magnitude, far more than the rounding, so an overlapping pair always
/// passes.
#[derive(Debug, Clone, Copy)]
struct OverlapTest {
    centre: Vec3A,
    /// Rows are the box axes: `to_box * t` is `t` along each.
    to_box: Mat3A,
    abs_to_box: Mat3A,
    half: Vec3A,
    /// The box's half-extent along each coordinate axis.
    reach: Vec3A,
}

impl OverlapTest {
    /// Relative widening of the test's bounds, against `f32` rounding (about 1e-7 per operation).
    const SLACK: f32 = 1e-5;

    /// The test for `region` against boxes whose coordinates are at most `scale` in magnitude.
    fn new(region: &OrientedBox, scale: f32) -> Self {
        let [a0, a1, a2] = region.axes;
        let h = region.half;
        let reach = DVec3::from_array(std::array::from_fn(|k| {
            h.x * a0[k].abs() + h.y * a1[k].abs() + h.z * a2[k].abs()
        }));
        let magnitude = scale.max((region.centre.abs().max_element() + reach.max_element()) as f32);
        let slack = Vec3A::splat(Self::SLACK * magnitude);
        let to_box = Mat3A::from_cols(a0.as_vec3a(), a1.as_vec3a(), a2.as_vec3a()).transpose();
        Self {
            centre: region.centre.as_vec3a(),
            to_box,
            abs_to_box: Mat3A::from_cols(to_box.x_axis.abs(), to_box.y_axis.abs(), to_box.z_axis.abs()),
            half: h.as_vec3a() + slack,
            reach: reach.as_vec3a() + slack,
        }
    }

    #[inline]
    fn may_overlap(&self, lo: Vec3A, hi: Vec3A) -> bool {
        let c = (lo + hi) * 0.5;
        let e = (hi - lo) * 0.5;
        let t = self.centre - c;
        if t.abs().cmpgt(self.reach + e).any() {
            return false;
        }
        let along = self.to_box * t;
        !along.abs().cmpgt(self.half + self.abs_to_box * e).any()
    }
}

/// A leaf of a mesh's BVH: its faces are `primitive_indices[first..first + count]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Leaf {
    first: u32,
    count: u32,
}

impl Leaf {
    pub fn face_count(&self) -> usize {
        self.count as usize
    }

    fn slots(&self) -> std::ops::Range<usize> {
        self.first as usize..(self.first + self.count) as usize
    }
}

/// A mesh of the model with its BVH.
///
/// Each leaf also lists its distinct vertices, and its faces' corners as positions in that list:
/// a reading places the vertices of a leaf near the pad once, although neighbouring faces share
/// them (a leaf of 8 faces has about 10 distinct vertices, not 24).
#[derive(Clone)]
pub struct MeshBvh {
    /// Vertices in the mesh (geom) frame, metres.
    vertices: Vec<DVec3>,
    faces: Vec<[u32; 3]>,
    bvh: Bvh2,
    /// For the first slot of each leaf in `bvh.primitive_indices`: the range of the leaf's
    /// distinct vertices in `leaf_vertices` (unused at other slots).
    leaf_vertex_range: Vec<(u32, u32)>,
    leaf_vertices: Vec<u32>,
    /// For each slot of `bvh.primitive_indices`: the face's corners as positions in its leaf's
    /// vertex range.
    slot_corners: Vec<[u16; 3]>,
    /// The largest vertex distance from the frame's origin, widened by a relative 1e-9.
    bounding_radius_m: f64,
}

impl std::fmt::Debug for MeshBvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshBvh")
            .field("vertices", &self.vertices.len())
            .field("faces", &self.faces.len())
            .field("nodes", &self.bvh.nodes.len())
            .finish()
    }
}

/// Why a mesh cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshBvhError {
    #[error("face {face} refers to vertex {vertex}, but the mesh has {count} vertices")]
    IndexOutOfRange { face: usize, vertex: i64, count: usize },
    #[error("vertex {vertex} is not finite")]
    NonFinite { vertex: usize },
}

/// A mesh checked for [`MeshBvh::build`] (finite vertices, every face's corners in range) with its
/// bound, its BVH not built yet: what the covering compares with the BVHs already built
/// (`tactile::shared_bvh`) before it builds one.
#[derive(Debug, Clone)]
pub struct CheckedMesh {
    /// Vertices in the mesh (geom) frame, metres.
    vertices: Vec<DVec3>,
    faces: Vec<[u32; 3]>,
    bounding_radius_m: f64,
}

impl CheckedMesh {
    /// Checks a mesh given as flat `xyz` vertex coordinates and vertex-index triples.
    pub fn new(vertex_xyz: &[f32], face_indices: &[i32]) -> Result<Self, MeshBvhError> {
        let vertices: Vec<DVec3> = vertex_xyz
            .chunks_exact(3)
            .map(|v| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
            .collect();
        if let Some(vertex) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(MeshBvhError::NonFinite { vertex });
        }
        let mut faces = Vec::with_capacity(face_indices.len() / 3);
        for (face, f) in face_indices.chunks_exact(3).enumerate() {
            let mut tri = [0u32; 3];
            for (slot, &v) in tri.iter_mut().zip(f) {
                if v < 0 || v as usize >= vertices.len() {
                    return Err(MeshBvhError::IndexOutOfRange {
                        face,
                        vertex: v as i64,
                        count: vertices.len(),
                    });
                }
                *slot = v as u32;
            }
            faces.push(tri);
        }
        // Widened so that the rounding of a placed vertex never puts it beyond the bound.
        let bounding_radius_m = vertices.iter().map(|v| v.length()).fold(0.0, f64::max) * (1.0 + 1e-9);
        Ok(Self {
            vertices,
            faces,
            bounding_radius_m,
        })
    }

    /// [`MeshBvh::bounding_radius_m`] of the mesh's BVH.
    pub fn bounding_radius_m(&self) -> f64 {
        self.bounding_radius_m
    }
}

impl MeshBvh {
    /// Builds the BVH of a mesh given as flat `xyz` vertex coordinates and vertex-index triples.
    pub fn new(vertex_xyz: &[f32], face_indices: &[i32]) -> Result<Self, MeshBvhError> {
        Ok(Self::build(CheckedMesh::new(vertex_xyz, face_indices)?))
    }

    /// Builds the BVH of a checked mesh (in two halves at once above `SPLIT_BUILD_TRIANGLES`).
    pub fn build(mesh: CheckedMesh) -> Self {
        Self::build_split_above(mesh, SPLIT_BUILD_TRIANGLES)
    }

    /// [`Self::build`] with the triangle count above which the tree is built in two halves.
    pub(crate) fn build_split_above(mesh: CheckedMesh, split_above: usize) -> Self {
        let CheckedMesh {
            vertices,
            faces,
            bounding_radius_m,
        } = mesh;
        let triangles: Vec<Triangle> = faces
            .iter()
            .map(|f| {
                let p = |i: u32| Vec3A::from(vertices[i as usize].as_vec3());
                Triangle {
                    v0: p(f[0]),
                    v1: p(f[1]),
                    v2: p(f[2]),
                }
            })
            .collect();
        let bvh = build_tree(triangles, split_above);
        let mut mesh = Self {
            bounding_radius_m,
            vertices,
            faces,
            bvh,
            leaf_vertex_range: Vec::new(),
            leaf_vertices: Vec::new(),
            slot_corners: Vec::new(),
        };
        mesh.index_leaf_vertices();
        mesh
    }

    /// The nodes of the tree (for tests of its shape).
    #[cfg(test)]
    pub(crate) fn nodes(&self) -> &[Bvh2Node] {
        &self.bvh.nodes
    }

    /// Lists each leaf's distinct vertices and its faces' corners within them.
    fn index_leaf_vertices(&mut self) {
        let slots = self.bvh.primitive_indices.len();
        self.leaf_vertex_range = vec![(0, 0); slots];
        self.slot_corners = vec![[0; 3]; slots];
        self.leaf_vertices.clear();
        for node in &self.bvh.nodes {
            if node.prim_count == 0 {
                continue;
            }
            let leaf = Leaf {
                first: node.first_index,
                count: node.prim_count,
            };
            let start = self.leaf_vertices.len();
            for slot in leaf.slots() {
                let face = self.faces[self.bvh.primitive_indices[slot] as usize];
                for (corner, vertex) in self.slot_corners[slot].iter_mut().zip(face) {
                    let position = match self.leaf_vertices[start..].iter().position(|&v| v == vertex) {
                        Some(position) => position,
                        None => {
                            self.leaf_vertices.push(vertex);
                            self.leaf_vertices.len() - 1 - start
                        }
                    };
                    // A leaf holds at most 255 faces (obvhs), so at most 765 vertices.
                    *corner = position as u16;
                }
            }
            self.leaf_vertex_range[leaf.first as usize] =
                (start as u32, (self.leaf_vertices.len() - start) as u32);
        }
    }

    /// Whether this BVH was built from `mesh`: the same faces, and the same vertex coordinates to
    /// the bit (so a BVH found by `tactile::shared_bvh` gives the readings of one built
    /// now).
    pub fn is_built_from(&self, mesh: &CheckedMesh) -> bool {
        let bits = |v: &DVec3| v.to_array().map(f64::to_bits);
        self.faces == mesh.faces
            && self.vertices.len() == mesh.vertices.len()
            && self
                .vertices
                .iter()
                .zip(&mesh.vertices)
                .all(|(a, b)| bits(a) == bits(b))
    }

    /// A radius about the frame's origin that holds every vertex, even once placed by a rigid
    /// motion with rounding (the largest vertex distance, widened by a relative 1e-9).
    pub fn bounding_radius_m(&self) -> f64 {
        self.bounding_radius_m
    }

    pub fn triangle_count(&self) -> usize {
        self.faces.len()
    }

    /// Bytes this mesh and its BVH hold on the heap (what a large scan costs in memory on top of
    /// MuJoCo's own copy of the mesh).
    pub fn heap_bytes(&self) -> usize {
        fn bytes<T>(v: &[T]) -> usize {
            std::mem::size_of_val(v)
        }
        bytes(&self.vertices)
            + bytes(&self.faces)
            + bytes(&self.bvh.nodes)
            + bytes(&self.bvh.primitive_indices)
            + bytes(&self.bvh.primitive_indices_freelist)
            + bytes(&self.bvh.primitives_to_nodes)
            + bytes(&self.bvh.parents)
            + bytes(&self.leaf_vertex_range)
            + bytes(&self.leaf_vertices)
            + bytes(&self.slot_corners)
    }

    /// The vertex indices of face `f`.
    #[inline]
    pub fn face(&self, f: u32) -> [u32; 3] {
        self.faces[f as usize]
    }

    /// Vertex `i` mapped by `x -> rotation x + offset`.
    #[inline]
    pub fn vertex(&self, i: u32, rotation: &DMat3, offset: DVec3) -> DVec3 {
        *rotation * self.vertices[i as usize] + offset
    }

    /// The corners of face `f` mapped by `x -> rotation x + offset`.
    #[inline]
    pub fn corners(&self, f: u32, rotation: &DMat3, offset: DVec3) -> [DVec3; 3] {
        let [a, b, c] = self.face(f);
        let map = |i: u32| self.vertex(i, rotation, offset);
        [map(a), map(b), map(c)]
    }

    /// The mesh vertices of `leaf`, each once.
    #[inline]
    pub fn leaf_vertices(&self, leaf: Leaf) -> &[u32] {
        let (start, count) = self.leaf_vertex_range[leaf.first as usize];
        &self.leaf_vertices[start as usize..(start + count) as usize]
    }

    /// The faces of `leaf`, each with its corners as positions in [`Self::leaf_vertices`].
    #[inline]
    pub fn leaf_faces(&self, leaf: Leaf) -> impl Iterator<Item = (u32, [u16; 3])> + '_ {
        let slots = leaf.slots();
        self.bvh.primitive_indices[slots.clone()]
            .iter()
            .copied()
            .zip(self.slot_corners[slots].iter().copied())
    }

    /// Appends to `out` every leaf that may overlap `region` (their faces are a superset of the
    /// faces that intersect it). `stack` is scratch space, reused across calls.
    pub fn leaves_near(&self, region: &OrientedBox, stack: &mut Vec<usize>, out: &mut Vec<Leaf>) {
        let nodes = &self.bvh.nodes;
        if nodes.is_empty() {
            return;
        }
        let bounds = |i: usize| {
            let aabb = nodes[i].aabb;
            (
                Vec3A::from_array(aabb.min.to_array()),
                Vec3A::from_array(aabb.max.to_array()),
            )
        };
        let (lo, hi) = bounds(0);
        let test = OverlapTest::new(region, lo.abs().max(hi.abs()).max_element());
        stack.clear();
        stack.push(0);
        while let Some(i) = stack.pop() {
            let (lo, hi) = bounds(i);
            if !test.may_overlap(lo, hi) {
                continue;
            }
            let node = &nodes[i];
            if node.prim_count > 0 {
                out.push(Leaf {
                    first: node.first_index,
                    count: node.prim_count,
                });
            } else {
                let child = node.first_index as usize;
                stack.push(child + 1);
                stack.push(child);
            }
        }
    }
}

/// Meshes of more triangles than this have their BVH built as two halves at once: a scan's BVH
/// (half a second for 1.3M triangles on one core) is the largest step from its file to its first
/// reading (issue 39). Every built-in object has fewer, so its BVH is built whole.
pub const SPLIT_BUILD_TRIANGLES: usize = 100_000;

/// The BVH of `triangles`, its primitives their indices: built whole, or for a large mesh as the
/// two halves of its triangles on either side of the median centroid along the longest axis,
/// built on two threads and joined under one root. A reading draws the faces of the leaves over
/// its rays, whatever tree holds them ([`crate::tactile::raster`]).
fn build_tree(triangles: Vec<Triangle>, split_above: usize) -> Bvh2 {
    let whole = |triangles: &[Triangle]| {
        if triangles.is_empty() {
            Bvh2::default()
        } else {
            build_bvh2_from_tris(triangles, BvhBuildParams::fast_build(), &mut Duration::default())
        }
    };
    if triangles.len() <= split_above.max(1) {
        return whole(&triangles);
    }
    let (low, high) = median_split(&triangles);
    let subset = |faces: &[u32]| faces.iter().map(|&f| triangles[f as usize]).collect::<Vec<_>>();
    let (low_triangles, high_triangles) = (subset(&low), subset(&high));
    // The halves hold every triangle: the whole list is not kept through the builds.
    drop(triangles);
    let (low_tree, high_tree) = std::thread::scope(|scope| {
        let high_tree = scope.spawn(|| whole(&high_triangles));
        let low_tree = whole(&low_triangles);
        // A build cannot panic on finite triangles; were its thread lost, it is built here.
        (
            low_tree,
            high_tree.join().unwrap_or_else(|_| whole(&high_triangles)),
        )
    });
    join_trees((low_tree, &low), (high_tree, &high))
}

/// The faces on either side of the median centroid along the longest axis of the centroids'
/// bounds (ties by face index, so the split is the same on every run).
fn median_split(triangles: &[Triangle]) -> (Vec<u32>, Vec<u32>) {
    let centroids: Vec<Vec3A> = triangles.iter().map(|t| (t.v0 + t.v1 + t.v2) / 3.0).collect();
    let (lo, hi) = centroids.iter().fold(
        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
        |(lo, hi), &c| (lo.min(c), hi.max(c)),
    );
    let extent = hi - lo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let key = |f: u32| (centroids[f as usize][axis], f);
    let mut faces: Vec<u32> = (0..triangles.len() as u32).collect();
    let half = faces.len() / 2;
    faces.select_nth_unstable_by(half, |&a, &b| {
        let ((ka, a), (kb, b)) = (key(a), key(b));
        ka.total_cmp(&kb).then(a.cmp(&b))
    });
    let high = faces.split_off(half);
    (faces, high)
}

/// One tree of two: a root over `low`'s and `high`'s roots, their nodes after it, their leaves'
/// primitives the faces (`low.1`, `high.1`: the face of each of the subtree's primitives).
fn join_trees((low, low_faces): (Bvh2, &[u32]), (high, high_faces): (Bvh2, &[u32])) -> Bvh2 {
    // Nodes: [root, low's root, high's root, low's others, high's others].
    let low_nodes = low.nodes.len() as u32;
    let low_at = |i: u32| if i == 0 { 1 } else { i + 2 };
    let high_at = |i: u32| if i == 0 { 2 } else { low_nodes + 1 + i };
    let high_primitives = low.primitive_indices.len() as u32;
    let place = |node: &Bvh2Node, at: &dyn Fn(u32) -> u32, primitive_offset: u32| {
        let first_index = if node.is_leaf() {
            node.first_index + primitive_offset
        } else {
            at(node.first_index)
        };
        Bvh2Node::new(node.aabb, node.prim_count, first_index)
    };
    let mut nodes = Vec::with_capacity(low.nodes.len() + high.nodes.len() + 1);
    nodes.push(Bvh2Node::new(low.nodes[0].aabb.union(&high.nodes[0].aabb), 0, 1));
    nodes.push(place(&low.nodes[0], &low_at, 0));
    nodes.push(place(&high.nodes[0], &high_at, high_primitives));
    nodes.extend(low.nodes[1..].iter().map(|n| place(n, &low_at, 0)));
    nodes.extend(
        high.nodes[1..]
            .iter()
            .map(|n| place(n, &high_at, high_primitives)),
    );
    let primitive_indices = (low.primitive_indices.iter().map(|&p| low_faces[p as usize]))
        .chain(high.primitive_indices.iter().map(|&p| high_faces[p as usize]))
        .collect();
    Bvh2 {
        nodes,
        primitive_indices,
        ..Bvh2::default()
    }
}

/// A closed, bumpy box: `TriMesh::cuboid` split three times into four (shared edge midpoints,
/// so it stays watertight and outward), its vertices pushed out by a ripple.
#[cfg(test)]
pub(crate) fn bumpy_box(half_m: f64) -> MeshBvh {
    let (xyz, faces) = bumpy(half_m, false);
    MeshBvh::new(&xyz, &faces).unwrap()
}

/// [`bumpy_box`] split once more (faces about 1 mm at 8 mm radius), its vertices moved onto the
/// sphere of radius `radius_m` before the ripple: a bumpy ball, whose bounding sphere is tight.
#[cfg(test)]
pub(crate) fn bumpy_ball(radius_m: f64) -> MeshBvh {
    let (xyz, faces) = bumpy_ball_mesh(radius_m);
    MeshBvh::new(&xyz, &faces).unwrap()
}

/// [`bumpy_ball`]'s mesh as [`MeshBvh::new`] takes it.
#[cfg(test)]
pub(crate) fn bumpy_ball_mesh(radius_m: f64) -> (Vec<f32>, Vec<i32>) {
    bumpy(radius_m, true)
}

/// A random rotation for the tests' poses: about the axis `(u, v, 1)` normalised, `u` and `v`
/// drawn in `[-1, 1)`, by an angle drawn in `[0, 6.3)` rad.
#[cfg(test)]
pub(crate) fn random_rotation(rng: &mut crate::rng::Rng) -> DMat3 {
    use rand::RngExt;
    let axis = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 1.0).normalize();
    DMat3::from_axis_angle(axis, rng.random_range(0.0..6.3))
}

#[cfg(test)]
fn bumpy(size_m: f64, ball: bool) -> (Vec<f32>, Vec<i32>) {
    let mut mesh = crate::mesh::TriMesh::cuboid(DVec3::splat(size_m));
    for _ in 0..if ball { 4 } else { 3 } {
        let mut midpoints = std::collections::HashMap::new();
        let mut triangles = Vec::new();
        for [a, b, c] in mesh.triangles.clone() {
            let mut mid = |p: u32, q: u32| {
                *midpoints.entry((p.min(q), p.max(q))).or_insert_with(|| {
                    mesh.vertices
                        .push(0.5 * (mesh.vertices[p as usize] + mesh.vertices[q as usize]));
                    mesh.vertices.len() as u32 - 1
                })
            };
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        mesh.triangles = triangles;
    }
    for v in &mut mesh.vertices {
        if ball {
            *v = v.normalize() * size_m;
        }
        *v *= 1.0 + 0.05 * (900.0 * v.x).sin() * (700.0 * v.y).cos();
    }
    let xyz: Vec<f32> = mesh
        .vertices
        .iter()
        .flat_map(|v| v.as_vec3().to_array())
        .collect();
    let faces: Vec<i32> = mesh.triangles.iter().flatten().map(|&i| i as i32).collect();
    (xyz, faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed 10 x 10 grid-tessellated unit square pair: many small faces in the plane z = 0.
    fn square_grid(n: usize) -> (Vec<f32>, Vec<i32>) {
        let mut v = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                v.extend_from_slice(&[j as f32 / n as f32, i as f32 / n as f32, 0.0]);
            }
        }
        let mut f = Vec::new();
        let id = |i: usize, j: usize| (i * (n + 1) + j) as i32;
        for i in 0..n {
            for j in 0..n {
                f.extend_from_slice(&[id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
                f.extend_from_slice(&[id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
            }
        }
        (v, f)
    }

    #[test]
    fn query_returns_every_face_in_the_box_and_few_others() {
        let (v, f) = square_grid(40);
        let mesh = MeshBvh::new(&v, &f).unwrap();
        assert_eq!(mesh.triangle_count(), 3200);
        let angle = 0.3f64;
        let axes = [
            DVec3::new(angle.cos(), angle.sin(), 0.0),
            DVec3::new(-angle.sin(), angle.cos(), 0.0),
            DVec3::Z,
        ];
        let region = OrientedBox {
            centre: DVec3::new(0.5, 0.5, 0.0),
            axes,
            half: DVec3::new(0.1, 0.05, 0.01),
        };
        let mut leaves = Vec::new();
        mesh.leaves_near(&region, &mut Vec::new(), &mut leaves);
        let near: Vec<u32> = leaves
            .iter()
            .flat_map(|&leaf| mesh.leaf_faces(leaf).map(|(face, _)| face))
            .collect();
        // Every face with a corner strictly inside the box must be found.
        let inside = |p: DVec3| {
            let d = p - region.centre;
            (0..3).all(|i| d.dot(axes[i]).abs() < region.half[i])
        };
        for face in 0..mesh.triangle_count() as u32 {
            if mesh
                .corners(face, &DMat3::IDENTITY, DVec3::ZERO)
                .into_iter()
                .any(inside)
            {
                assert!(near.contains(&face), "face {face} missed");
            }
        }
        assert!(near.len() < 400, "{} candidates", near.len());
    }

    /// The separating-axis test of [`OverlapTest`] in `f64` without widening: the reference the
    /// `f32` test must never be stricter than.
    fn exact_may_overlap(region: &OrientedBox, lo: DVec3, hi: DVec3) -> bool {
        let (c, e) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let t = region.centre - c;
        let [a0, a1, a2] = region.axes;
        let h = region.half;
        let separated_on_coordinates =
            (0..3).any(|k| t[k].abs() > h.x * a0[k].abs() + h.y * a1[k].abs() + h.z * a2[k].abs() + e[k]);
        let separated_on_box_axes = (0..3).any(|i| {
            let a = region.axes[i];
            t.dot(a).abs() > h[i] + e.dot(a.abs())
        });
        !(separated_on_coordinates || separated_on_box_axes)
    }

    #[test]
    fn the_f32_overlap_test_keeps_every_box_the_exact_test_keeps_and_little_else() {
        use rand::RngExt;
        let mut rng = crate::rng::rng(11);
        let (mut kept, mut extra, mut separated) = (0, 0, 0);
        for _ in 0..200_000 {
            let rotation = DMat3::from_quat(glam::DQuat::from_scaled_axis(DVec3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
            )));
            let scale = 10f64.powi(rng.random_range(-3..2));
            let random = |rng: &mut rand_chacha::ChaCha8Rng, k: f64| {
                DVec3::new(
                    rng.random_range(-k..k),
                    rng.random_range(-k..k),
                    rng.random_range(-k..k),
                )
            };
            let region = OrientedBox {
                centre: random(&mut rng, scale),
                axes: [rotation.x_axis, rotation.y_axis, rotation.z_axis],
                half: random(&mut rng, 0.3 * scale).abs(),
            };
            // Node boxes as the BVH stores them (f32 corners), many of them touching or nearly
            // touching the region on one axis: the cases rounding could get wrong.
            let centre = region.centre + random(&mut rng, 0.6 * scale);
            let half = random(&mut rng, 0.3 * scale).abs();
            let mut lo = (centre - half).as_vec3().as_dvec3();
            let mut hi = (centre + half).as_vec3().as_dvec3();
            let touching = rng.random_range(0..2) == 0;
            if touching {
                let k = rng.random_range(0..3);
                let reach: f64 = (0..3).map(|i| region.half[i] * region.axes[i][k].abs()).sum();
                let gap = (hi[k] - lo[k])
                    + if rng.random_range(0..2) == 0 {
                        0.0
                    } else {
                        1e-9 * scale
                    };
                lo[k] = region.centre[k] + reach + rng.random_range(-1e-7..1e-7) * scale;
                hi[k] = lo[k] + gap;
                (lo, hi) = (lo.as_vec3().as_dvec3(), hi.as_vec3().as_dvec3());
            }
            let exact = exact_may_overlap(&region, lo, hi);
            let fast = region.may_overlap(lo, hi);
            assert!(
                fast || !exact,
                "{region:?} rejected [{lo}, {hi}], which it overlaps"
            );
            kept += usize::from(exact);
            if !touching {
                // Away from the boundary, the widening keeps almost nothing the exact test rejects.
                separated += usize::from(!exact);
                extra += usize::from(fast && !exact);
            }
        }
        assert!(
            kept > 10_000 && separated > 10_000,
            "{kept} kept, {separated} separated"
        );
        assert!(
            extra * 1000 < separated,
            "{extra} of {separated} separated boxes kept"
        );
    }

    #[test]
    fn the_bounding_radius_holds_every_placed_vertex_and_little_more() {
        use rand::RngExt;
        let mesh = bumpy_ball(0.008);
        let r = mesh.bounding_radius_m();
        let farthest = (0..mesh.triangle_count() as u32)
            .flat_map(|f| mesh.corners(f, &DMat3::IDENTITY, DVec3::ZERO))
            .map(DVec3::length)
            .fold(0.0, f64::max);
        assert!(
            r >= farthest && r <= farthest * (1.0 + 2e-9),
            "{r} for {farthest}"
        );
        let mut rng = crate::rng::rng(4);
        for _ in 0..50 {
            let rotation = random_rotation(&mut rng);
            let offset = DVec3::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5), 0.3);
            for f in 0..mesh.triangle_count() as u32 {
                // The covering's use: every placed vertex within `r` of the offset, per coordinate.
                for p in mesh.corners(f, &rotation, offset) {
                    assert!((0..3).all(|k| p[k] >= offset[k] - r && p[k] <= offset[k] + r));
                }
            }
        }
    }

    #[test]
    fn each_leaf_lists_its_faces_vertices_once() {
        let (v, f) = square_grid(30);
        let mesh = MeshBvh::new(&v, &f).unwrap();
        let mut leaves = Vec::new();
        mesh.leaves_near(&OrientedBox::cube(10.0), &mut Vec::new(), &mut leaves);
        let mut seen = vec![0; mesh.triangle_count()];
        let (mut corners, mut distinct) = (0, 0);
        for &leaf in &leaves {
            let vertices = mesh.leaf_vertices(leaf);
            let mut sorted = vertices.to_vec();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(sorted.len(), vertices.len(), "a vertex listed twice");
            for (face, local) in mesh.leaf_faces(leaf) {
                seen[face as usize] += 1;
                assert_eq!(local.map(|i| vertices[i as usize]), mesh.face(face));
                corners += 3;
            }
            distinct += vertices.len();
        }
        assert!(seen.iter().all(|&n| n == 1), "every face in exactly one leaf");
        // Neighbouring faces share vertices: a leaf places far fewer than three per face.
        assert!(
            distinct * 2 < corners,
            "{distinct} vertices for {corners} corners"
        );
    }

    #[test]
    fn heap_bytes_count_the_mesh_and_grow_linearly_with_it() {
        let size = |n: usize| {
            let (v, f) = square_grid(n);
            let mesh = MeshBvh::new(&v, &f).unwrap();
            // At least the f64 vertices, the faces and one BVH node per leaf.
            let floor = (n + 1) * (n + 1) * 24 + 2 * n * n * 12;
            assert!(mesh.heap_bytes() > floor, "{} <= {floor}", mesh.heap_bytes());
            mesh.heap_bytes() as f64 / (2 * n * n) as f64
        };
        let (small, large) = (size(20), size(80));
        // Bytes per triangle stay about constant (a BVH is linear in the primitives).
        assert!(
            (large / small - 1.0).abs() < 0.25,
            "{small} vs {large} bytes per triangle"
        );
    }

    #[test]
    fn bad_indices_are_errors() {
        let e = MeshBvh::new(&[0.0; 9], &[0, 1, 3]).unwrap_err();
        assert_eq!(
            e,
            MeshBvhError::IndexOutOfRange {
                face: 0,
                vertex: 3,
                count: 3
            }
        );
        assert!(MeshBvh::new(&[0.0, 0.0, f32::NAN], &[]).is_err());
    }
}
