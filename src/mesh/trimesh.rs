//! An indexed triangle mesh in metres.

use glam::DVec3;

use crate::pose::Pose;
use serde::{Deserialize, Serialize};

/// Vertices (metres) and triangles as vertex indices, counter-clockwise seen from outside.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TriMesh {
    pub vertices: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// A closed box centred at the origin with half-sizes `half_m`, two triangles per face,
    /// counter-clockwise from outside: vertex `i` has the sign of `half_m.x` from bit 0 of `i`,
    /// `y` from bit 1, `z` from bit 2.
    pub fn cuboid(half_m: DVec3) -> TriMesh {
        let vertices = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { -half_m.x } else { half_m.x },
                    if i & 2 == 0 { -half_m.y } else { half_m.y },
                    if i & 4 == 0 { -half_m.z } else { half_m.z },
                )
            })
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect();
        TriMesh { vertices, triangles }
    }

    /// The three corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// Area of triangle `t`: |(b - a) x (c - a)| / 2.
    pub fn triangle_area(&self, t: usize) -> f64 {
        let [a, b, c] = self.corners(t);
        0.5 * (b - a).cross(c - a).length()
    }

    /// The lowest world z of the mesh placed at `pose` (where it would rest on a table at z = 0);
    /// `None` for a mesh with no vertices.
    pub fn lowest_z_at(&self, pose: &Pose) -> Option<f64> {
        self.vertices
            .iter()
            .map(|&v| pose.transform_point(v).z)
            .reduce(f64::min)
    }

    /// Axis-aligned bounds (min, max); `None` for a mesh with no vertices.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let first = *self.vertices.first()?;
        Some(
            self.vertices
                .iter()
                .fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v))),
        )
    }

    /// The centre of the bounding box: where an object's shift along the table is measured
    /// (`sim::ObjectMotion`); `None` for a mesh with no vertices.
    pub fn bounding_box_centre(&self) -> Option<DVec3> {
        let (lo, hi) = self.bounds()?;
        Some((lo + hi) * 0.5)
    }

    /// Length of the bounding-box diagonal, |max - min|; `None` for a mesh with no vertices.
    pub fn bounding_diagonal_m(&self) -> Option<f64> {
        self.bounds().map(|(lo, hi)| (hi - lo).length())
    }

    /// Total surface area, the sum of the triangle areas.
    pub fn total_area(&self) -> f64 {
        (0..self.triangles.len()).map(|t| self.triangle_area(t)).sum()
    }

    /// Signed enclosed volume by the divergence theorem,
    /// V = (1/6) sum_t a_t . (b_t x c_t),
    /// exact for a closed mesh and positive when its triangles are counter-clockwise seen from
    /// outside (normals point out). For an open mesh it depends on the origin.
    pub fn signed_volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                a.dot(b.cross(c))
            })
            .sum::<f64>()
            / 6.0
    }

    /// The mesh moved by `offset_m`.
    pub fn translated(&self, offset_m: DVec3) -> TriMesh {
        TriMesh {
            vertices: self.vertices.iter().map(|&v| v + offset_m).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// The mesh scaled about the origin by `factor` (a positive factor keeps the orientation).
    pub fn scaled(&self, factor: f64) -> TriMesh {
        TriMesh {
            vertices: self.vertices.iter().map(|&v| v * factor).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// The same surface with every triangle's winding reversed, so every normal flips.
    pub fn flipped(&self) -> TriMesh {
        TriMesh {
            vertices: self.vertices.clone(),
            triangles: self.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
        }
    }

    /// Adds `other`'s vertices and triangles to this mesh (as separate shells).
    pub fn append(&mut self, other: &TriMesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cuboid_is_closed_and_faces_outward() {
        let half = DVec3::new(0.01, 0.02, 0.03);
        let mesh = TriMesh::cuboid(half);
        assert_eq!(mesh.bounds(), Some((-half, half)));
        // The divergence theorem: sum of a . (b x c) / 6 over outward triangles is the volume.
        let volume: f64 = (0..mesh.triangles.len())
            .map(|t| {
                let [a, b, c] = mesh.corners(t);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        assert!((volume - 8.0 * half.x * half.y * half.z).abs() < 1e-15);
        // Closed: every edge is shared by exactly two triangles, in opposite directions.
        let mut directed = std::collections::HashSet::new();
        for &[a, b, c] in &mesh.triangles {
            for edge in [(a, b), (b, c), (c, a)] {
                assert!(directed.insert(edge), "edge {edge:?} twice in one direction");
            }
        }
        assert!(directed.iter().all(|&(a, b)| directed.contains(&(b, a))));
    }
}
