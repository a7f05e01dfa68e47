//! A coarse copy of a large mesh by vertex clustering: what MuJoCo is given to draw a scanned
//! object, while the tactile sensor reads the exact surface (issue 39, large meshes).
//!
//! MuJoCo processes every mesh asset in full when it compiles a model (normals, inertia, a BVH of
//! all faces): for a 1.3M-triangle scan that is a 256 MB model and over a gigabyte while it
//! compiles, for a geom that takes part in no contact (the collision shell does) and that the
//! sensor reads from its own BVH. Vertex clustering (Rossignac and Borrel 1993) is linear in the
//! mesh and keeps the shape within a cell of the grid: each vertex moves to the mean of the
//! vertices in its cell, and triangles whose corners fall in fewer than three cells vanish.

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use super::TriMesh;

/// How many times the grid may be coarsened when a cell size gives too many triangles.
const MAX_COARSENINGS: usize = 16;

/// A copy of `mesh` with at most about `max_triangles` triangles (never more than `mesh`'s), or
/// `mesh` itself when it is no larger. The copy's vertices lie within one grid cell of the
/// original surface; its triangles keep the winding of those they come from, none degenerate and
/// none repeated.
pub fn cluster_vertices(mesh: &TriMesh, max_triangles: usize) -> TriMesh {
    if mesh.triangles.len() <= max_triangles {
        return mesh.clone();
    }
    let Some((lo, hi)) = mesh.bounds() else {
        return mesh.clone();
    };
    // A cell per two triangles of the copy (a closed surface has about twice as many triangles
    // as vertices), sized from the surface's area; then coarser until the copy is small enough.
    let area = mesh.total_area();
    let mut cell_m = (2.0 * area / max_triangles.max(1) as f64).sqrt();
    if !(cell_m.is_finite() && cell_m > 0.0) {
        cell_m = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    }
    let mut coarse = clustered(mesh, lo, cell_m);
    for _ in 0..MAX_COARSENINGS {
        if coarse.triangles.len() <= max_triangles {
            break;
        }
        cell_m *= 1.25;
        coarse = clustered(mesh, lo, cell_m);
    }
    coarse
}

/// The mesh with its vertices merged per cube of side `cell_m` of a grid anchored at `origin`.
fn clustered(mesh: &TriMesh, origin: DVec3, cell_m: f64) -> TriMesh {
    let mut cluster_of_cell: HashMap<[i64; 3], u32> = HashMap::new();
    let mut sums: Vec<(DVec3, u32)> = Vec::new();
    let cluster: Vec<u32> = mesh
        .vertices
        .iter()
        .map(|&v| {
            let cell = ((v - origin) / cell_m).floor().as_i64vec3().to_array();
            let id = *cluster_of_cell.entry(cell).or_insert_with(|| {
                sums.push((DVec3::ZERO, 0));
                (sums.len() - 1) as u32
            });
            let (sum, count) = &mut sums[id as usize];
            *sum += v;
            *count += 1;
            id
        })
        .collect();
    let vertices: Vec<DVec3> = sums.iter().map(|&(sum, count)| sum / f64::from(count)).collect();
    let mut seen: HashSet<[u32; 3]> = HashSet::new();
    let mut triangles = Vec::new();
    for &[a, b, c] in &mesh.triangles {
        let t = [cluster[a as usize], cluster[b as usize], cluster[c as usize]];
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            continue;
        }
        let mut key = t;
        key.sort_unstable();
        if seen.insert(key) {
            triangles.push(t);
        }
    }
    // Vertices no triangle kept (a cell whose every triangle collapsed) are dropped.
    let mut index = vec![u32::MAX; vertices.len()];
    let mut kept = Vec::new();
    for t in &mut triangles {
        for i in t.iter_mut() {
            if index[*i as usize] == u32::MAX {
                index[*i as usize] = kept.len() as u32;
                kept.push(vertices[*i as usize]);
            }
            *i = index[*i as usize];
        }
    }
    TriMesh {
        vertices: kept,
        triangles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed sphere of `2 * 4^level * 10`-ish triangles (a subdivided octahedron).
    fn sphere(radius_m: f64, level: u32) -> TriMesh {
        let mut mesh = TriMesh::cuboid(DVec3::splat(radius_m));
        for _ in 0..level {
            let mut next = TriMesh::default();
            for t in 0..mesh.triangles.len() {
                let [a, b, c] = mesh.corners(t);
                let (ab, bc, ca) = ((a + b) / 2.0, (b + c) / 2.0, (c + a) / 2.0);
                for tri in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
                    let base = next.vertices.len() as u32;
                    next.vertices.extend(tri);
                    next.triangles.push([base, base + 1, base + 2]);
                }
            }
            mesh = next;
        }
        // Weld the corners written once per triangle, then push every vertex onto the sphere.
        let mut id: HashMap<[u64; 3], u32> = HashMap::new();
        let mut welded = TriMesh::default();
        let remap: Vec<u32> = mesh
            .vertices
            .iter()
            .map(|v| {
                *id.entry(v.to_array().map(f64::to_bits)).or_insert_with(|| {
                    welded.vertices.push(v.normalize() * radius_m);
                    (welded.vertices.len() - 1) as u32
                })
            })
            .collect();
        welded.triangles = mesh
            .triangles
            .iter()
            .map(|t| t.map(|i| remap[i as usize]))
            .collect();
        welded
    }

    #[test]
    fn a_large_mesh_becomes_a_small_one_close_to_its_surface() {
        let radius_m = 0.04;
        let fine = sphere(radius_m, 5);
        assert!(fine.triangles.len() > 10_000, "{}", fine.triangles.len());
        let coarse = cluster_vertices(&fine, 2_000);
        assert!(coarse.triangles.len() <= 2_000, "{}", coarse.triangles.len());
        assert!(coarse.triangles.len() > 500, "{}", coarse.triangles.len());
        // Every vertex within a cell of the surface: the mean of points on the sphere in a cell
        // of side h lies at most h * sqrt(3) from it.
        let cell_m = (2.0 * fine.total_area() / 2_000.0).sqrt() * 1.25f64.powi(MAX_COARSENINGS as i32);
        for v in &coarse.vertices {
            assert!((v.length() - radius_m).abs() < cell_m * 3f64.sqrt(), "{v}");
        }
        for &[a, b, c] in &coarse.triangles {
            assert!(a != b && b != c && c != a);
        }
        // The winding is kept: the copy still encloses positive volume, about the sphere's.
        let volume = 4.0 / 3.0 * std::f64::consts::PI * radius_m.powi(3);
        assert!(
            (coarse.signed_volume() / volume - 1.0).abs() < 0.1,
            "{}",
            coarse.signed_volume()
        );
    }

    #[test]
    fn a_mesh_within_the_limit_is_returned_as_it_is() {
        let mesh = sphere(0.04, 2);
        assert_eq!(cluster_vertices(&mesh, mesh.triangles.len()), mesh);
        assert_eq!(cluster_vertices(&TriMesh::default(), 0), TriMesh::default());
    }
}
