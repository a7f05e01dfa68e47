//! Physical plausibility of an object: a mesh file can be well formed and still describe nothing
//! the simulated sensor can touch (a single triangle, or a statue in millimetres read as metres).
//! Such runs otherwise end in an all-zero reading or hundreds of failed attempts that say nothing
//! of the cause, so every way into the library ([`ObjectSet::build`](super::ObjectSet::build)) and
//! every command checks its objects here before any simulation starts.

use glam::DVec3;

use crate::units::length;

use super::TriMesh;

/// The largest object a carrier can explore, as a bounding diagonal, and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SizeLimit {
    pub max_diagonal_m: f64,
    /// Completes "larger than ...": what the limit is.
    pub reason: &'static str,
}

impl SizeLimit {
    /// Ten metres is no table-top object: beyond it the coordinates are read as not being metres
    /// at all. The limit of the free-floating pad (Sec. V-A3), and of every object the library
    /// builds.
    pub const TABLE_TOP: SizeLimit = SizeLimit {
        max_diagonal_m: 10.0,
        reason: "no table-top object",
    };
}

/// Why a mesh is no object the simulator can hold or a carrier explore.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Implausible {
    #[error(
        "the mesh has {used} vertices in its faces; a solid needs at least 4 not in one plane \
         (the simulator builds the object's collision hull from them)"
    )]
    TooFewVertices { used: usize },
    #[error(
        "all {used} vertices lie in one plane; a solid needs thickness (the simulator builds the \
         object's collision hull from them)"
    )]
    Flat { used: usize },
    #[error(
        "bounding diagonal {} is larger than {} ({}): are the coordinates metres? give the \
         object's size with --object-size-m (a bounding diagonal in metres) or write its \
         coordinates in metres",
        length(*diagonal_m),
        length(limit.max_diagonal_m),
        limit.reason
    )]
    TooLarge { diagonal_m: f64, limit: SizeLimit },
}

/// Checks that `mesh` is a solid the simulator can hold (four vertices not in one plane) and no
/// larger than `limit`.
pub fn check_plausible(mesh: &TriMesh, limit: SizeLimit) -> Result<(), Implausible> {
    let used = used_vertex_count(mesh);
    if used < 4 {
        return Err(Implausible::TooFewVertices { used });
    }
    if is_flat(mesh) {
        return Err(Implausible::Flat { used });
    }
    let diagonal_m = mesh.bounding_diagonal_m().unwrap_or(0.0);
    if diagonal_m > limit.max_diagonal_m {
        return Err(Implausible::TooLarge { diagonal_m, limit });
    }
    Ok(())
}

fn used_vertex_count(mesh: &TriMesh) -> usize {
    let mut used = vec![false; mesh.vertices.len()];
    for &i in mesh.triangles.iter().flatten() {
        if let Some(slot) = used.get_mut(i as usize) {
            *slot = true;
        }
    }
    used.into_iter().filter(|&u| u).count()
}

/// Whether every vertex lies (to rounding) in the plane of the mesh's largest triangle.
fn is_flat(mesh: &TriMesh) -> bool {
    let diagonal = mesh.bounding_diagonal_m().unwrap_or(0.0);
    let Some(largest) =
        (0..mesh.triangles.len()).max_by(|&a, &b| mesh.triangle_area(a).total_cmp(&mesh.triangle_area(b)))
    else {
        return true;
    };
    let [a, b, c] = mesh.corners(largest);
    let normal = (b - a).cross(c - a).normalize_or_zero();
    if normal == DVec3::ZERO {
        return true;
    }
    let tolerance = 1e-9 * diagonal;
    mesh.vertices
        .iter()
        .all(|v| (*v - a).dot(normal).abs() <= tolerance)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetrahedron(scale: f64) -> TriMesh {
        TriMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]
                .into_iter()
                .map(|v| v * scale)
                .collect(),
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        }
    }

    const ARM: SizeLimit = SizeLimit {
        max_diagonal_m: 0.5,
        reason: "the arm's workspace",
    };

    #[test]
    fn a_tetrahedron_passes_and_flat_tiny_or_huge_meshes_do_not() {
        check_plausible(&tetrahedron(0.05), ARM).unwrap();
        let mut flat = tetrahedron(0.05);
        flat.vertices[3] = DVec3::new(0.02, 0.02, 0.0);
        assert_eq!(
            check_plausible(&flat, SizeLimit::TABLE_TOP),
            Err(Implausible::Flat { used: 4 })
        );
        let triangle = TriMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            triangles: vec![[0, 1, 2]],
        };
        assert_eq!(
            check_plausible(&triangle, SizeLimit::TABLE_TOP),
            Err(Implausible::TooFewVertices { used: 3 })
        );
        let e = check_plausible(&tetrahedron(1e30), SizeLimit::TABLE_TOP)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bounding diagonal 1.732e30 m") && e.contains("--object-size-m"),
            "{e}"
        );
        let e = check_plausible(&tetrahedron(1.0), ARM).unwrap_err().to_string();
        assert!(e.contains("the arm's workspace"), "{e}");
        check_plausible(&tetrahedron(1.0), SizeLimit::TABLE_TOP).unwrap();
    }
}
