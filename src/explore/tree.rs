//! The planner's tree (Sec. III-A): "rooted at the initial configuration of the robot arm. The tree
//! vertices consist of collision-free configurations, while edges indicate collision-free motions
//! between the configurations that they connect."

use glam::DVec3;

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
}

impl ExplorationTree {
    pub fn new(root_q: Vec<f64>, pad_m: DVec3, pad_normal: DVec3) -> Self {
        Self {
            vertices: vec![Vertex {
                q: root_q,
                pad_m,
                pad_normal,
                parent: None,
                blocked: false,
            }],
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
        self.vertices.len() - 1
    }

    /// Marks vertex `i` as in collision (see [`Vertex::blocked`]).
    pub fn block(&mut self, i: usize) {
        self.vertices[i].blocked = true;
    }

    /// The vertex whose pad position is nearest to `p` (the first of equals, so ties are
    /// deterministic), among those not blocked; the root when every other one is.
    pub fn nearest(&self, p: DVec3) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, v) in self.vertices.iter().enumerate().filter(|(_, v)| !v.blocked) {
            let d = v.pad_m.distance_squared(p);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
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
}
