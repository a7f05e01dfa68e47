//! Small shapes shared by the integration tests.
#![allow(dead_code)]

use glam::DVec3;
use taction::mesh::TriMesh;

/// Tests that provoke MuJoCo's warnings on purpose (a state gone bad, a full geom buffer) leave no
/// `MUJOCO_LOG.TXT` in the checkout: every test binary with these helpers switches the log file
/// off before `main`, while no thread runs MuJoCo, as `keep_mujoco_log_off_disk` requires.
#[ctor::ctor(unsafe)]
fn log_off_disk() {
    // SAFETY: constructors run before `main`, on the one thread there is, and after those of
    // libmujoco.so, a shared library the executable links (its globals are set up).
    unsafe { taction::sim::keep_mujoco_log_off_disk() };
}

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
        [0, 2, 1],
        [1, 2, 3], // bottom (-z)
        [4, 5, 6],
        [5, 7, 6], // top (+z)
        [0, 1, 4],
        [1, 5, 4], // -y
        [2, 6, 3],
        [3, 6, 7], // +y
        [0, 4, 2],
        [2, 4, 6], // -x
        [1, 3, 5],
        [3, 7, 5], // +x
    ];
    TriMesh { vertices, triangles }
}

/// A UV sphere of radius `r` centred at `center`, `n` latitude bands, closed and outward-facing.
pub fn sphere_mesh(r: f64, center: DVec3, n: usize) -> TriMesh {
    let mut vertices = vec![center + DVec3::new(0.0, 0.0, r)];
    for i in 1..n {
        let theta = std::f64::consts::PI * i as f64 / n as f64;
        for j in 0..2 * n {
            let phi = std::f64::consts::PI * j as f64 / n as f64;
            vertices
                .push(center + r * DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
        }
    }
    vertices.push(center - DVec3::new(0.0, 0.0, r));
    let ring = |i: usize, j: usize| (1 + (i - 1) * 2 * n + j % (2 * n)) as u32;
    let south = (vertices.len() - 1) as u32;
    let mut triangles = Vec::new();
    for j in 0..2 * n {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        triangles.push([south, ring(n - 1, j + 1), ring(n - 1, j)]);
    }
    for i in 1..n - 1 {
        for j in 0..2 * n {
            triangles.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            triangles.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    TriMesh { vertices, triangles }
}
