//! Mesh validation: the defects that do not stop a mesh from being explored but that the user
//! should know about. (Defects that make a mesh unusable — no vertices, non-finite coordinates,
//! indices out of range — are [`MeshError`](super::MeshError)s raised while parsing.)

use std::fmt;

use serde::{Deserialize, Serialize};

use super::TriMesh;
use super::topology::EdgeTopology;

/// A triangle counts as zero-area when its area is at most this fraction of the squared bounding
/// diagonal: far below any feature a 6x6 sensor with 2 mm taxels can resolve, and robust to the
/// rounding of coordinates printed with few digits.
pub const ZERO_AREA_RELATIVE: f64 = 1e-14;

/// Warnings about a mesh, as counts; all zero for a clean, closed, consistently oriented mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ValidationReport {
    /// Triangles with (near) zero area, including those that repeat a vertex.
    pub zero_area_faces: usize,
    /// Edges shared by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges used by one triangle only: the mesh is open there.
    pub boundary_edges: usize,
    /// Closed loops formed by the boundary edges (the holes in an open surface).
    pub boundary_loops: usize,
    /// Two-triangle edges whose triangles wind in opposite directions.
    pub misoriented_edges: usize,
}

impl ValidationReport {
    /// Validates `mesh`, whose indices must be in range (as any mesh from [`load()`](super::load()) is).
    pub fn of(mesh: &TriMesh) -> Self {
        let diagonal = mesh.bounding_diagonal_m().unwrap_or(0.0);
        let min_area = ZERO_AREA_RELATIVE * diagonal * diagonal;
        let zero_area_faces = (0..mesh.triangles.len())
            .filter(|&t| {
                let [a, b, c] = mesh.triangles[t];
                a == b || b == c || c == a || mesh.triangle_area(t) <= min_area
            })
            .count();
        let topology = EdgeTopology::new(mesh);
        Self {
            zero_area_faces,
            non_manifold_edges: topology.non_manifold_edge_count(),
            boundary_edges: topology.boundary_edges().count(),
            boundary_loops: topology.boundary_loop_count(),
            misoriented_edges: topology.misoriented_edge_count(),
        }
    }

    /// No warnings at all.
    pub fn is_clean(&self) -> bool {
        *self == Self::default()
    }

    /// The warnings as sentences, one per kind of defect found.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        let mut add = |n: usize, what: &str| {
            if n > 0 {
                out.push(format!("{n} {what}"));
            }
        };
        add(self.zero_area_faces, "zero-area face(s)");
        add(
            self.non_manifold_edges,
            "non-manifold edge(s) shared by more than two faces",
        );
        add(self.boundary_edges, "open boundary edge(s)");
        add(self.boundary_loops, "open boundary loop(s)");
        add(
            self.misoriented_edges,
            "edge(s) between faces of opposite orientation",
        );
        out
    }
}

impl fmt::Display for ValidationReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let warnings = self.warnings();
        if warnings.is_empty() {
            write!(f, "clean")
        } else {
            write!(f, "{}", warnings.join("; "))
        }
    }
}
