//! The planner's tree (Sec. III-A): "rooted at the initial configuration of the robot arm. The tree
//! vertices consist of collision-free configurations, while edges indicate collision-free motions
//! between the configurations that they connect."

use glam::DVec3;

use crate::explore::cells::PointCells;

/// The side of the cells the vertices are binned in, about the pad's own size: a tree near the
/// object holds a few vertices a cell.
const VERTEX_CELL_M: f64 = 0.01;

/// One vertex: a configuration and where it puts the pad.
#[derive(Debug, Clone, PartialEq)]
pub struct Vertex {
    pub q: Vec<f64>,
    /// Pad centre at `q`, metres.
    pub pad_m: DVec3,
    /// Pad normal at `q`.
    pub pad_normal: DVec3,
    /// The vertex this one was reached from (`None` for the root).
    pub parent: Option<usize>,
    /// The configuration is known to be in collision now (a perturbation moved the object into
    /// the arm there): nearest-vertex queries pass it over.
    pub blocked: bool,
}

/// Configurations connected by collision-free motions.
#[derive(Debug, Clone)]
pub struct ExplorationTree {
    vertices: Vec<Vertex>,
    /// The vertices' pad positions binned into cubes, for [`nearest`](Self::nearest).
    cells: PointCells<usize>,
}

impl ExplorationTree {
    pub fn new(root_q: Vec<f64>, pad_m: DVec3, pad_normal: DVec3) -> Self {
        let mut cells = PointCells::new(VERTEX_CELL_M);
        cells.insert(pad_m, 0);
        Self {
            vertices: vec![Vertex {
                q: root_q,
                pad_m,
                pad_normal,
                parent: None,
                blocked: false,
            }],
            cells,
        }
    }

    pub fn vertices(&self) -> &[Vertex] {
        &self.vertices
    }

    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// Adds a vertex reached from `parent`; returns its index.
    pub fn add(&mut self, parent: usize, q: Vec<f64>, pad_m: DVec3, pad_normal: DVec3) -> usize {
        self.vertices.push(Vertex {
            q,
            pad_m,
            pad_normal,
            parent: Some(parent),
            blocked: false,
        });
        let i = self.vertices.len() - 1;
        self.cells.insert(pad_m, i);
        i
    }

    /// Marks vertex `i` as in collision (see [`Vertex::blocked`]).
    pub fn block(&mut self, i: usize) {
        self.vertices[i].blocked = true;
    }

    /// The vertex whose pad position is nearest to `p` (the first of equals, so ties are
    /// deterministic), among those not blocked; the root when every other one is.
    ///
    /// Every planner iteration asks this once of a tree of up to tens of thousands of vertices, so
    /// it searches the cells around `p` ring by ring instead of every vertex (a linear scan was 62%
    /// of an active-touch run's time); the answer is the scan's, ties included.
    pub fn nearest(&self, p: DVec3) -> usize {
        let Some(centre) = self.cells.cell(p) else {
            return self.nearest_by_scan(p);
        };
        let mut best = Nearest::default();
        let offer = |best: &mut Nearest, i: usize| {
            let v = &self.vertices[i];
            if !v.blocked {
                best.offer(i, v.pad_m.distance_squared(p));
            }
        };
        self.cells.strays().iter().for_each(|&i| offer(&mut best, i));
        for ring in 0..=self.cells.rings_to_cover(centre) {
            for cell in self.cells.ring(centre, ring) {
                self.cells.members(cell).iter().for_each(|&i| offer(&mut best, i));
            }
            // Vertices outside rings 0..=ring are at least `ring` cells from `p` (less a margin
            // far above the rounding of `p / cell_m`).
            let reach_m = (ring as f64 * self.cells.cell_m() - 1e-9).max(0.0);
            if best.distance_sq < reach_m * reach_m {
                break;
            }
        }
        best.index
    }

    fn nearest_by_scan(&self, p: DVec3) -> usize {
        let mut best = Nearest::default();
        for (i, v) in self.vertices.iter().enumerate().filter(|(_, v)| !v.blocked) {
            best.offer(i, v.pad_m.distance_squared(p));
        }
        best.index
    }
}

/// The best vertex so far of a nearest-vertex search: smallest distance, then smallest index.
struct Nearest {
    index: usize,
    distance_sq: f64,
}

impl Default for Nearest {
    fn default() -> Self {
        Self {
            index: 0,
            distance_sq: f64::INFINITY,
        }
    }
}

impl Nearest {
    fn offer(&mut self, index: usize, distance_sq: f64) {
        if distance_sq < self.distance_sq || (distance_sq == self.distance_sq && index < self.index) {
            self.index = index;
            self.distance_sq = distance_sq;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_vertex_by_pad_position() {
        let mut tree = ExplorationTree::new(vec![0.0], DVec3::ZERO, DVec3::Z);
        let a = tree.add(0, vec![1.0], DVec3::new(1.0, 0.0, 0.0), DVec3::Z);
        let b = tree.add(a, vec![2.0], DVec3::new(0.0, 2.0, 0.0), DVec3::Z);
        assert_eq!(tree.nearest(DVec3::new(0.9, 0.1, 0.0)), a);
        assert_eq!(tree.nearest(DVec3::new(0.0, 1.8, 0.3)), b);
        assert_eq!(tree.nearest(DVec3::new(-0.1, 0.0, 0.0)), 0);
        assert_eq!(tree.vertices()[b].parent, Some(a));
    }

    /// The linear scan the cell search replaces: its answer, ties and blocked vertices included.
    fn nearest_by_scan(tree: &ExplorationTree, p: DVec3) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, v) in tree.vertices().iter().enumerate().filter(|(_, v)| !v.blocked) {
            let d = v.pad_m.distance_squared(p);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    #[test]
    fn the_cell_search_finds_what_a_scan_finds() {
        use rand::RngExt;
        let mut rng = crate::rng::rng(7);
        let mut point = |spread: f64| {
            DVec3::new(rng.random::<f64>(), rng.random::<f64>(), rng.random::<f64>()) * spread - spread / 2.0
        };
        let mut tree = ExplorationTree::new(vec![0.0], DVec3::new(0.0, 0.0, 0.5), DVec3::Z);
        for i in 0..3000 {
            // Clustered pads, some exactly repeated (ties), some blocked.
            let p = if i % 10 == 0 {
                tree.vertices()[i / 2].pad_m
            } else {
                point(0.3)
            };
            let v = tree.add(i / 3, vec![0.0], p, DVec3::Z);
            if i % 17 == 0 {
                tree.block(v);
            }
        }
        let queries: Vec<DVec3> = (0..500)
            .map(|i| match i % 4 {
                0 => point(0.3),
                1 => point(3.0),
                2 => tree.vertices()[i].pad_m,
                _ => point(0.3) + DVec3::new(40.0, -7.0, 0.0),
            })
            .collect();
        for q in queries {
            assert_eq!(tree.nearest(q), nearest_by_scan(&tree, q), "query {q}");
        }
        let mut all_blocked = ExplorationTree::new(vec![0.0], DVec3::ZERO, DVec3::Z);
        let v = all_blocked.add(0, vec![0.0], DVec3::X, DVec3::Z);
        all_blocked.block(v);
        assert_eq!(all_blocked.nearest(DVec3::X), 0);
    }
}
