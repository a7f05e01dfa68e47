//! BVHs shared by the plugin instances that read the same mesh (issue 39).
//!
//! MuJoCo's compiler makes a data of every model it compiles and steps it once as a test, which
//! initialises the plugin, and so builds its BVHs, on a data it then frees; the scene's own data
//! initialises the plugin again. On a 1.3M-triangle scan each build takes half a second, a quarter
//! of the time from the file to the first reading. An instance therefore takes the BVH of a mesh
//! from this registry when one was built for the same mesh, compared exactly (every vertex
//! coordinate to the bit, every face): a BVH is a deterministic function of its mesh, so the
//! readings are the same bits whichever instance built it.
//!
//! The registry finds every BVH some instance still uses (it holds them weakly) and keeps the most
//! recently used ones alive up to [`RECENT_BUDGET_BYTES`], so that a BVH outlives the test data's
//! teardown. That budget is what a process may hold of BVHs no scene reads any more.

use std::collections::VecDeque;
use std::sync::{Arc, Mutex, PoisonError, Weak};

use crate::tactile::mesh_bvh::{CheckedMesh, MeshBvh};

/// Bytes of BVHs no instance uses that the registry keeps alive, most recently used first: more
/// than a 1.3M-triangle scan's BVH with its mesh (about 130 MB), so the scan's is built once. A
/// BVH larger than the budget is not kept once unused (a larger scan is built twice, as before).
pub const RECENT_BUDGET_BYTES: usize = 256 << 20;

/// The process's registry, used by every plugin instance.
pub(crate) static SHARED_BVHS: SharedBvhs = SharedBvhs::new(RECENT_BUDGET_BYTES);

/// A registry of BVHs by the mesh they were built from.
#[derive(Debug)]
pub struct SharedBvhs {
    budget_bytes: usize,
    registry: Mutex<Registry>,
}

#[derive(Debug)]
struct Registry {
    /// Every BVH handed out, while anything holds it.
    live: Vec<Weak<MeshBvh>>,
    /// The most recently used, kept alive within the budget.
    recent: VecDeque<Arc<MeshBvh>>,
}

impl SharedBvhs {
    /// An empty registry that keeps at most `budget_bytes` of unused BVHs alive.
    pub const fn new(budget_bytes: usize) -> Self {
        Self {
            budget_bytes,
            registry: Mutex::new(Registry {
                live: Vec::new(),
                recent: VecDeque::new(),
            }),
        }
    }

    /// The BVH of `mesh`: one already built for the same mesh, else built now. The flag says
    /// whether it was built now.
    pub fn find_or_build(&self, mesh: CheckedMesh) -> (Arc<MeshBvh>, bool) {
        if let Some(found) = self.find(&mesh) {
            return (found, false);
        }
        // Built outside the lock: other threads keep finding and building meanwhile.
        let built = Arc::new(MeshBvh::build(mesh));
        let mut registry = self.lock();
        registry.live.push(Arc::downgrade(&built));
        registry.use_recently(&built, self.budget_bytes);
        (built, true)
    }

    fn find(&self, mesh: &CheckedMesh) -> Option<Arc<MeshBvh>> {
        let mut registry = self.lock();
        registry.live.retain(|bvh| bvh.strong_count() > 0);
        let found = registry
            .live
            .iter()
            .filter_map(Weak::upgrade)
            .find(|bvh| bvh.is_built_from(mesh))?;
        registry.use_recently(&found, self.budget_bytes);
        Some(found)
    }

    /// BVHs the registry keeps alive, bytes on the heap.
    #[cfg(test)]
    fn kept_bytes(&self) -> usize {
        self.lock().recent.iter().map(|bvh| bvh.heap_bytes()).sum()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Registry> {
        // The registry's state is valid after any panic (each change is one push or removal).
        self.registry.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl Registry {
    /// Moves `bvh` to the front of the recent ones, then drops the oldest beyond the budget.
    fn use_recently(&mut self, bvh: &Arc<MeshBvh>, budget_bytes: usize) {
        self.recent.retain(|kept| !Arc::ptr_eq(kept, bvh));
        self.recent.push_front(Arc::clone(bvh));
        let mut bytes = 0;
        self.recent.retain(|kept| {
            bytes += kept.heap_bytes();
            bytes <= budget_bytes
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tactile::mesh_bvh::bumpy_ball_mesh;

    fn checked(radius_m: f64) -> CheckedMesh {
        let (vertex_xyz, face) = bumpy_ball_mesh(radius_m);
        CheckedMesh::new(&vertex_xyz, &face).unwrap()
    }

    #[test]
    fn the_same_mesh_gets_the_same_bvh_and_another_mesh_its_own() {
        let shared = SharedBvhs::new(RECENT_BUDGET_BYTES);
        let (first, built) = shared.find_or_build(checked(0.008));
        assert!(built);
        let (again, built) = shared.find_or_build(checked(0.008));
        assert!(!built);
        assert!(Arc::ptr_eq(&first, &again));
        // One vertex coordinate one bit away is another mesh.
        let (mut vertex_xyz, face) = bumpy_ball_mesh(0.008);
        vertex_xyz[7] = f32::from_bits(vertex_xyz[7].to_bits() + 1);
        let (other, built) = shared.find_or_build(CheckedMesh::new(&vertex_xyz, &face).unwrap());
        assert!(built);
        assert!(!Arc::ptr_eq(&first, &other));
        // A sign of zero is a bit too.
        let (mut vertex_xyz, face) = bumpy_ball_mesh(0.008);
        let zero = vertex_xyz.iter().position(|&c| c == 0.0).unwrap();
        vertex_xyz[zero] = -vertex_xyz[zero];
        let (signed, built) = shared.find_or_build(CheckedMesh::new(&vertex_xyz, &face).unwrap());
        assert!(built);
        assert!(!Arc::ptr_eq(&first, &signed));
    }

    #[test]
    fn an_unused_bvh_is_kept_within_the_budget_only() {
        let one = checked(0.008);
        let (bvh, _) = SharedBvhs::new(0).find_or_build(one.clone());
        let bytes = bvh.heap_bytes();
        drop(bvh);
        // A budget for one: the BVH outlives its last user, until a newer one takes its place.
        let shared = SharedBvhs::new(bytes);
        drop(shared.find_or_build(one.clone()));
        assert_eq!(shared.kept_bytes(), bytes);
        assert!(!shared.find_or_build(one.clone()).1, "kept while unused");
        drop(shared.find_or_build(checked(0.009)));
        assert!(shared.find_or_build(one.clone()).1, "dropped for the newer one");
        // No budget: found only while in use.
        let shared = SharedBvhs::new(0);
        let (held, _) = shared.find_or_build(one.clone());
        assert_eq!(shared.kept_bytes(), 0);
        assert!(!shared.find_or_build(one.clone()).1, "found while held");
        drop(held);
        assert!(shared.find_or_build(one).1, "built again once unused");
    }
}
