//! The mass properties of a solid mesh of uniform density: what a free object's body carries in
//! MuJoCo (issue 74), where a mocap object needs none.
//!
//! The closed surface is split into tetrahedra from the origin, one per triangle, each signed by
//! its orientation, so that the parts outside the solid cancel (the divergence theorem, as
//! [`TriMesh::signed_volume`]). A tetrahedron `(0, a, b, c)` has the second moment
//! `∫ x x^T dV = det(A) / 120 (A A^T + (a + b + c)(a + b + c)^T)`, `A = [a b c]`; summed and moved
//! to the centroid, the inertia tensor is `tr(C) I - C` times the density.

use glam::{DMat3, DVec3};

use crate::mesh::TriMesh;

/// A solid's volume, centroid and second moment about it, per unit density.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolidMoments {
    pub volume_m3: f64,
    /// The centre of mass of a uniform solid, metres in the mesh's frame.
    pub centroid_m: DVec3,
    /// `∫ (x - c)(x - c)^T dV`, m^5.
    second_moment_m5: DMat3,
}

impl SolidMoments {
    /// The moments of the solid `mesh` encloses; `None` when it encloses no volume (an open sheet,
    /// inward-facing triangles, a degenerate mesh).
    pub fn of(mesh: &TriMesh) -> Option<Self> {
        let mut volume = 0.0;
        let mut first = DVec3::ZERO;
        let mut second = DMat3::ZERO;
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.corners(t);
            let det = a.dot(b.cross(c));
            let sum = a + b + c;
            volume += det / 6.0;
            first += sum * (det / 24.0);
            let outer = |u: DVec3| DMat3::from_cols(u * u.x, u * u.y, u * u.z);
            second += (outer(a) + outer(b) + outer(c) + outer(sum)) * (det / 120.0);
        }
        if !(volume.is_finite() && volume > 0.0) {
            return None;
        }
        let centroid_m = first / volume;
        let at_centroid = DMat3::from_cols(
            centroid_m * centroid_m.x,
            centroid_m * centroid_m.y,
            centroid_m * centroid_m.z,
        );
        Some(Self {
            volume_m3: volume,
            centroid_m,
            second_moment_m5: second - at_centroid * volume,
        })
    }

    /// The inertia tensor about the centroid of the solid at `density_kg_m3`, kg m^2, in the mesh's
    /// axes.
    pub fn inertia_kg_m2(&self, density_kg_m3: f64) -> DMat3 {
        let c = self.second_moment_m5 * density_kg_m3;
        DMat3::from_diagonal(DVec3::splat(c.x_axis.x + c.y_axis.y + c.z_axis.z)) - c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An axis-aligned box from `lo` to `hi`, faced outward.
    fn cuboid(lo: DVec3, hi: DVec3) -> TriMesh {
        TriMesh::cuboid((hi - lo) * 0.5).translated((lo + hi) * 0.5)
    }

    #[test]
    fn a_box_has_the_textbook_volume_centroid_and_inertia_wherever_it_stands() {
        let (a, b, c) = (0.1, 0.06, 0.04);
        let box_mesh = cuboid(
            DVec3::new(0.3, -0.2, 0.05),
            DVec3::new(0.3 + a, -0.2 + b, 0.05 + c),
        );
        let moments = SolidMoments::of(&box_mesh).unwrap();
        assert!((moments.volume_m3 - a * b * c).abs() < 1e-15);
        assert!((moments.centroid_m - DVec3::new(0.35, -0.17, 0.07)).length() < 1e-12);
        let density = 800.0;
        let mass = density * a * b * c;
        let inertia = moments.inertia_kg_m2(density);
        let expected = DVec3::new(b * b + c * c, a * a + c * c, a * a + b * b) * (mass / 12.0);
        let diagonal = DVec3::new(inertia.x_axis.x, inertia.y_axis.y, inertia.z_axis.z);
        assert!(
            (diagonal - expected).abs().max_element() < 1e-12 * mass,
            "{diagonal} {expected}"
        );
        assert!(
            inertia.x_axis.y.abs() < 1e-15
                && inertia.x_axis.z.abs() < 1e-15
                && inertia.y_axis.z.abs() < 1e-15
        );
    }

    #[test]
    fn a_turned_box_has_products_of_inertia_and_an_open_sheet_has_no_solid() {
        let box_mesh = cuboid(DVec3::ZERO, DVec3::new(0.1, 0.02, 0.02));
        let turn = glam::DQuat::from_rotation_z(0.5);
        let turned = TriMesh {
            vertices: box_mesh.vertices.iter().map(|&v| turn * v).collect(),
            triangles: box_mesh.triangles.clone(),
        };
        let (straight, tilted) = (
            SolidMoments::of(&box_mesh).unwrap(),
            SolidMoments::of(&turned).unwrap(),
        );
        let r = DMat3::from_quat(turn);
        let rotated = r * straight.inertia_kg_m2(1000.0) * r.transpose();
        let difference = rotated - tilted.inertia_kg_m2(1000.0);
        assert!(difference.to_cols_array().iter().all(|v| v.abs() < 1e-15));
        assert!(tilted.inertia_kg_m2(1000.0).x_axis.y.abs() > 1e-6);

        let sheet = TriMesh {
            triangles: box_mesh.triangles[..2].to_vec(),
            ..box_mesh.clone()
        };
        assert!(SolidMoments::of(&sheet).is_none());
        let inside_out = TriMesh {
            triangles: box_mesh.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
            ..box_mesh
        };
        assert!(SolidMoments::of(&inside_out).is_none());
    }
}
