//! An indexed triangle mesh in metres.

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Vertices (metres) and triangles as vertex indices, counter-clockwise seen from outside.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TriMesh {
    pub vertices: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
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

    /// Axis-aligned bounds (min, max); `None` for a mesh with no vertices.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let first = *self.vertices.first()?;
        Some(
            self.vertices
                .iter()
                .fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v))),
        )
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
