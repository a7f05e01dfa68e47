//! Small shapes shared by the integration tests.
#![allow(dead_code)]

use glam::DVec3;
use taction::mesh::TriMesh;

/// A closed box mesh with its bottom face on z = 0, centred in x and y, outward-facing triangles.
pub fn box_mesh(size_m: DVec3) -> TriMesh {
    let h = size_m * 0.5;
    let vertices = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { 0.0 } else { size_m.z },
            )
        })
        .collect();
    let triangles = vec![
        [0, 2, 1], [1, 2, 3], // bottom (-z)
        [4, 5, 6], [5, 7, 6], // top (+z)
        [0, 1, 4], [1, 5, 4], // -y
        [2, 6, 3], [3, 6, 7], // +y
        [0, 4, 2], [2, 4, 6], // -x
        [1, 3, 5], [3, 7, 5], // +x
    ];
    TriMesh { vertices, triangles }
}
