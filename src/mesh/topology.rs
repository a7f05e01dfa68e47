//! Edge topology of a triangle mesh: which edges are shared by how many triangles, and in which
//! directions. Watertightness, orientation and the Euler characteristic all come from here.
//!
//! A closed, consistently oriented 2-manifold uses every undirected edge {a, b} exactly twice, once
//! as a -> b and once as b -> a. An edge used once lies on an open boundary; an edge used more than
//! twice is non-manifold; an edge used twice in the same direction joins two triangles of opposite
//! orientation.

use std::collections::HashMap;

use super::TriMesh;

/// How the triangles of a mesh use each undirected edge.
#[derive(Debug, Clone)]
pub struct EdgeTopology {
    /// Each undirected edge (low, high), in increasing order, with (uses as low -> high, uses as
    /// high -> low).
    uses: Vec<((u32, u32), (u32, u32))>,
    vertex_count: usize,
    triangle_count: usize,
}

impl EdgeTopology {
    /// Counts the edge uses of `mesh`. Edges from a vertex to itself (in triangles that repeat a
    /// vertex) are not edges and are skipped.
    ///
    /// The directed edges are bucketed by their lower vertex (a counting sort), and each bucket,
    /// a vertex's few neighbours, is merged on its own: linear in the mesh, where a hash map of
    /// the edges took a third of a scanned mesh's load (issue 39, large meshes).
    pub fn new(mesh: &TriMesh) -> Self {
        let directed = || {
            mesh.triangles
                .iter()
                .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
                .filter(|(p, q)| p != q)
        };
        // Sized by the indices used (a hand-made mesh may name vertices it lacks).
        let bucket_count = directed().map(|(p, q)| p.max(q) as usize + 1).max().unwrap_or(0);
        let mut bucket_end = vec![0usize; bucket_count + 1];
        for (p, q) in directed() {
            bucket_end[p.min(q) as usize + 1] += 1;
        }
        for v in 0..bucket_count {
            bucket_end[v + 1] += bucket_end[v];
        }
        // (high, used low -> high) of each directed edge, filled bucket by bucket.
        let mut next = bucket_end.clone();
        let mut slots = vec![(0u32, false); bucket_end[bucket_count]];
        for (p, q) in directed() {
            let low = p.min(q) as usize;
            slots[next[low]] = (p.max(q), p < q);
            next[low] += 1;
        }
        let mut uses = Vec::with_capacity(slots.len() / 2 + 1);
        for low in 0..bucket_count {
            let bucket = &mut slots[bucket_end[low]..bucket_end[low + 1]];
            bucket.sort_unstable_by_key(|&(high, _)| high);
            for chunk in bucket.chunk_by(|a, b| a.0 == b.0) {
                let forward = chunk.iter().filter(|&&(_, f)| f).count() as u32;
                uses.push(((low as u32, chunk[0].0), (forward, chunk.len() as u32 - forward)));
            }
        }
        Self {
            uses,
            vertex_count: mesh.vertices.len(),
            triangle_count: mesh.triangles.len(),
        }
    }

    /// Each edge's (uses as low -> high, uses as high -> low).
    fn use_counts(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.uses.iter().map(|&(_, counts)| counts)
    }

    /// Number of distinct undirected edges.
    pub fn edge_count(&self) -> usize {
        self.uses.len()
    }

    /// Edges used by exactly one triangle: the open boundary.
    pub fn boundary_edges(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.uses.iter().filter(|(_, (f, b))| f + b == 1).map(|&(e, _)| e)
    }

    /// Number of edges used by more than two triangles.
    pub fn non_manifold_edge_count(&self) -> usize {
        self.use_counts().filter(|(f, b)| f + b > 2).count()
    }

    /// Number of two-triangle edges traversed twice in the same direction: their triangles have
    /// opposite orientations.
    pub fn misoriented_edge_count(&self) -> usize {
        self.use_counts().filter(|&(f, b)| f + b == 2 && f != 1).count()
    }

    /// Number of closed loops the boundary edges form (connected components of the boundary graph).
    pub fn boundary_loop_count(&self) -> usize {
        let mut parent: HashMap<u32, u32> = HashMap::new();
        fn find(parent: &mut HashMap<u32, u32>, v: u32) -> u32 {
            let mut root = v;
            while let Some(&p) = parent.get(&root) {
                if p == root {
                    break;
                }
                root = p;
            }
            let mut cur = v;
            while cur != root {
                let next = parent[&cur];
                parent.insert(cur, root);
                cur = next;
            }
            root
        }
        let edges: Vec<(u32, u32)> = self.boundary_edges().collect();
        for &(a, b) in &edges {
            parent.entry(a).or_insert(a);
            parent.entry(b).or_insert(b);
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            if ra != rb {
                parent.insert(ra.max(rb), ra.min(rb));
            }
        }
        let vertices: Vec<u32> = parent.keys().copied().collect();
        vertices
            .into_iter()
            .filter(|&v| find(&mut parent, v) == v)
            .count()
    }

    /// True when every edge is shared by exactly two triangles (closed, manifold at edges).
    pub fn is_closed(&self) -> bool {
        self.use_counts().all(|(f, b)| f + b == 2)
    }

    /// True when the mesh is closed and each edge is traversed once in each direction, i.e. all
    /// triangles of each connected shell wind the same way.
    pub fn is_consistently_oriented(&self) -> bool {
        self.use_counts().all(|(f, b)| f == 1 && b == 1)
    }

    /// Euler characteristic chi = V - E + F, counting only vertices that some triangle uses. For a
    /// closed orientable surface of c shells with total genus g, chi = 2c - 2g.
    pub fn euler_characteristic(&self, mesh: &TriMesh) -> i64 {
        let mut used = vec![false; self.vertex_count];
        for t in &mesh.triangles {
            for &i in t {
                used[i as usize] = true;
            }
        }
        let v = used.iter().filter(|&&u| u).count() as i64;
        v - self.uses.len() as i64 + self.triangle_count as i64
    }
}

/// Number of connected components of `mesh`, triangles being connected when they share a vertex.
pub fn connected_components(mesh: &TriMesh) -> usize {
    let mut parent: Vec<u32> = (0..mesh.vertices.len() as u32).collect();
    fn find(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            parent[v as usize] = parent[parent[v as usize] as usize];
            v = parent[v as usize];
        }
        v
    }
    let mut used = vec![false; mesh.vertices.len()];
    for &[a, b, c] in &mesh.triangles {
        for (p, q) in [(a, b), (b, c)] {
            let (rp, rq) = (find(&mut parent, p), find(&mut parent, q));
            if rp != rq {
                parent[rp.max(rq) as usize] = rp.min(rq);
            }
        }
        for i in [a, b, c] {
            used[i as usize] = true;
        }
    }
    (0..mesh.vertices.len() as u32)
        .filter(|&v| used[v as usize] && find(&mut parent, v) == v)
        .count()
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;

    #[test]
    fn edges_are_counted_per_direction_in_order_even_past_the_vertices_given() {
        // Two triangles on the edge {1, 2}, both as 1 -> 2 (opposite orientations), a third on it
        // (non-manifold), and one naming a vertex the list lacks (a hand-made mesh).
        let mesh = TriMesh {
            vertices: vec![DVec3::ZERO; 4],
            triangles: vec![[0, 1, 2], [3, 1, 2], [2, 1, 0], [0, 3, 9]],
        };
        let topology = EdgeTopology::new(&mesh);
        assert_eq!(
            topology.uses,
            [
                ((0, 1), (1, 1)),
                ((0, 2), (1, 1)),
                ((0, 3), (1, 0)),
                ((0, 9), (0, 1)),
                ((1, 2), (2, 1)),
                ((1, 3), (0, 1)),
                ((2, 3), (1, 0)),
                ((3, 9), (1, 0)),
            ]
        );
        assert_eq!(topology.non_manifold_edge_count(), 1);
        assert_eq!(topology.boundary_edges().count(), 5);
    }
}
