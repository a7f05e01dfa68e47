//! Physical plausibility of what the user hands in, checked before any simulation starts: a mesh
//! file can be well formed and still describe no object the simulated sensor can touch (a single
//! triangle, or a statue in millimetres read as metres), and those runs otherwise end in an
//! all-zero reading or hundreds of failed attempts that say nothing of the cause.

use taction::explore::PlannerConfig;
use taction::mesh::{BuildOptions, ObjectSet, TriMesh};
use taction::sim::ObjectSpec;
use taction::units::length;

/// A mesh no simulated sensor can explore, and why. A failure of the input file (exit code 1), not
/// of a flag.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct MeshImplausible(pub String);

/// Largest bounding diagonal of an object sensed by the free-floating pad, metres: ten metres is
/// no table-top object, so coordinates beyond it are read as not being metres at all.
pub const MAX_FREE_OBJECT_DIAGONAL_M: f64 = 10.0;

/// Largest bounding diagonal of an object the arm explores, metres: the diagonal of the planner's
/// default workspace box (Sec. III-A), the only region its targets are drawn from.
pub fn max_arm_object_diagonal_m() -> f64 {
    let planner = PlannerConfig::default();
    (planner.workspace_max_m - planner.workspace_min_m).length()
}

/// Where a mesh goes, which sets how large it may be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Carrier {
    /// The free-floating pad of the training sampler (Sec. V-A3) and of `sense`.
    FreePad,
    /// The arm (Sec. V-A1).
    Arm,
}

impl Carrier {
    fn max_diagonal_m(self) -> f64 {
        match self {
            Carrier::FreePad => MAX_FREE_OBJECT_DIAGONAL_M,
            Carrier::Arm => max_arm_object_diagonal_m(),
        }
    }

    fn limit(self) -> String {
        match self {
            Carrier::FreePad => format!(
                "larger than {} (no table-top object)",
                length(self.max_diagonal_m())
            ),
            Carrier::Arm => format!(
                "larger than the arm's workspace ({} diagonal)",
                length(self.max_diagonal_m())
            ),
        }
    }
}

/// Checks that `mesh` (named `what` in messages) is a solid the simulator can hold and of a size
/// `carrier` can explore; `rescale` tells how to fix the size (a flag or an edit of the file).
pub fn check_mesh(
    what: &str,
    mesh: &TriMesh,
    carrier: Carrier,
    rescale: &str,
) -> Result<(), MeshImplausible> {
    let used = used_vertex_count(mesh);
    if used < 4 {
        return Err(MeshImplausible(format!(
            "{what}: the mesh has {used} vertices in its faces; a solid needs at least 4 not in one plane \
             (the simulator builds the object's collision hull from them)"
        )));
    }
    if is_flat(mesh) {
        return Err(MeshImplausible(format!(
            "{what}: all {used} vertices lie in one plane; a solid needs thickness (the simulator builds \
             the object's collision hull from them)"
        )));
    }
    let diagonal_m = mesh.bounding_diagonal_m().unwrap_or(0.0);
    if diagonal_m > carrier.max_diagonal_m() {
        return Err(MeshImplausible(format!(
            "{what}: bounding diagonal {} is {}: are the coordinates metres? {rescale}",
            length(diagonal_m),
            carrier.limit()
        )));
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
    if normal == glam::DVec3::ZERO {
        return true;
    }
    let tolerance = 1e-9 * diagonal;
    mesh.vertices
        .iter()
        .all(|v| (*v - a).dot(normal).abs() <= tolerance)
}

/// Builds every object of `set` (fetching CGAL meshes if missing), warns on stderr (prefixed
/// `command`) about each object's validation problems (open, non-manifold, ...), checks each with
/// [`check_mesh`], and returns them resting at the origin as the set places them.
pub fn build_objects(
    set: &ObjectSet,
    command: &str,
    carrier: Carrier,
    rescale: &str,
) -> Result<Vec<ObjectSpec>, Box<dyn std::error::Error>> {
    let built = set.build(&BuildOptions {
        fetch: true,
        ..BuildOptions::default()
    })?;
    let mut objects = Vec::with_capacity(built.len());
    for (object, named) in built.into_iter().zip(&set.objects) {
        let what = format!("object '{}' ({})", object.name, named.source);
        if !object.warnings.is_clean() {
            eprintln!("taction {command}: warning: {what}: {}", object.warnings);
        }
        check_mesh(&what, &object.mesh, carrier, rescale)?;
        objects.push(ObjectSpec::new(object.name, object.mesh));
    }
    Ok(objects)
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

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

    #[test]
    fn a_tetrahedron_passes_and_flat_tiny_or_huge_meshes_do_not() {
        check_mesh("t", &tetrahedron(0.05), Carrier::Arm, "").unwrap();
        let mut flat = tetrahedron(0.05);
        flat.vertices[3] = DVec3::new(0.02, 0.02, 0.0);
        assert!(
            check_mesh("t", &flat, Carrier::FreePad, "")
                .unwrap_err()
                .0
                .contains("one plane")
        );
        let triangle = TriMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            triangles: vec![[0, 1, 2]],
        };
        assert!(
            check_mesh("t", &triangle, Carrier::FreePad, "")
                .unwrap_err()
                .0
                .contains("3 vertices")
        );
        let e = check_mesh("t", &tetrahedron(1e30), Carrier::FreePad, "use --object-size-m")
            .unwrap_err()
            .0;
        assert!(
            e.contains("bounding diagonal 1.732e30 m") && e.contains("--object-size-m"),
            "{e}"
        );
        assert!(
            check_mesh("t", &tetrahedron(1.0), Carrier::Arm, "")
                .unwrap_err()
                .0
                .contains("workspace")
        );
        check_mesh("t", &tetrahedron(1.0), Carrier::FreePad, "").unwrap();
    }
}
