//! Bringing meshes from any source to the common frame of the object sets: a given size, centred,
//! resting on the table, normals out.

use glam::DVec3;

use super::TriMesh;
use super::error::MeshError;

/// The mesh scaled uniformly so that its bounding-box diagonal is `diagonal_m`, then moved so that
/// its bounding box is centred on x = y = 0 and its lowest point is at z = 0 (resting on the table
/// plane). With bounds [lo, hi] and s = diagonal_m / |hi - lo|:
/// v' = s v - (s (lo.x + hi.x) / 2, s (lo.y + hi.y) / 2, s lo.z).
pub fn normalise_to_diagonal(mesh: &TriMesh, diagonal_m: f64) -> Result<TriMesh, MeshError> {
    if !(diagonal_m.is_finite() && diagonal_m > 0.0) {
        return Err(MeshError::InvalidParameter {
            field: "diagonal_m",
            what: format!("{diagonal_m} is not a positive length"),
        });
    }
    let (lo, hi) = mesh.bounds().ok_or_else(|| MeshError::Degenerate {
        what: "no vertices".into(),
    })?;
    let current = (hi - lo).length();
    if !(current > 0.0 && current.is_finite()) {
        return Err(MeshError::Degenerate {
            what: format!("bounding diagonal is {current}"),
        });
    }
    let s = diagonal_m / current;
    let offset = DVec3::new(-0.5 * s * (lo.x + hi.x), -0.5 * s * (lo.y + hi.y), -s * lo.z);
    Ok(TriMesh {
        vertices: mesh.vertices.iter().map(|&v| v * s + offset).collect(),
        triangles: mesh.triangles.clone(),
    })
}

/// The mesh with every triangle's winding reversed when its signed volume is negative, so that a
/// closed mesh ends with outward normals (as [`TriMesh`] promises). Returns the mesh and whether it
/// was flipped.
pub fn orient_outward(mesh: TriMesh) -> (TriMesh, bool) {
    if mesh.signed_volume() < 0.0 {
        (mesh.flipped(), true)
    } else {
        (mesh, false)
    }
}

/// The mesh rotated about the origin so that the axis it was authored with as up becomes +z (the
/// rotation of each case is given at [`UpAxis`]).
pub fn rotate_up_to_z(mesh: &TriMesh, up: UpAxis) -> TriMesh {
    let map = |v: DVec3| match up {
        UpAxis::Z => v,
        UpAxis::Y => DVec3::new(v.x, -v.z, v.y),
        UpAxis::X => DVec3::new(v.y, v.z, v.x),
        UpAxis::NegY => DVec3::new(v.x, v.z, -v.y),
        UpAxis::NegZ => DVec3::new(v.x, -v.y, -v.z),
    };
    TriMesh {
        vertices: mesh.vertices.iter().map(|&v| map(v)).collect(),
        triangles: mesh.triangles.clone(),
    }
}

/// The axis a mesh file treats as up. Each rotation to z-up is proper (determinant +1), so the
/// orientation of the triangles is kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum UpAxis {
    /// Already z-up: unchanged.
    Z,
    /// (x, y, z) -> (x, -z, y).
    Y,
    /// (x, y, z) -> (y, z, x), a cyclic permutation.
    X,
    /// (x, y, z) -> (x, z, -y).
    NegY,
    /// (x, y, z) -> (x, -y, -z).
    NegZ,
}
