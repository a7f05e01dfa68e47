//! The command line's side of plausibility (`taction::mesh::check_plausible`): which size limit a
//! command's carrier sets, and warnings about each object on stderr.

use taction::explore::PlannerConfig;
use taction::mesh::{BuildOptions, ObjectSet, SizeLimit, TriMesh, check_plausible};
use taction::sim::ObjectSpec;

/// A mesh no simulated sensor can explore, and why. A failure of the input file (exit code 1), not
/// of a flag.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct MeshImplausible(pub String);

/// Where a mesh goes, which sets how large it may be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Carrier {
    /// The free-floating pad of the training sampler (Sec. V-A3) and of `sense`.
    FreePad,
    /// The arm (Sec. V-A1).
    Arm,
}

impl Carrier {
    pub fn size_limit(self) -> SizeLimit {
        match self {
            Carrier::FreePad => SizeLimit::TABLE_TOP,
            Carrier::Arm => PlannerConfig::default().object_size_limit(),
        }
    }
}

/// Checks that `mesh` (named `what` in messages) is a solid the simulator can hold and of a size
/// `carrier` can explore.
pub fn check_mesh(what: &str, mesh: &TriMesh, carrier: Carrier) -> Result<(), MeshImplausible> {
    check_plausible(mesh, carrier.size_limit())
        .map_err(|problem| MeshImplausible(format!("{what}: {problem}")))
}

/// Builds every object of `set` (fetching CGAL meshes if missing; the library refuses implausible
/// ones), warns on stderr (prefixed `command`) about each object's validation problems (open,
/// non-manifold, ...), checks each against `carrier`'s size limit, and returns them resting at the
/// origin as the set places them.
pub fn build_objects(
    set: &ObjectSet,
    command: &str,
    carrier: Carrier,
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
        check_mesh(&what, &object.mesh, carrier)?;
        objects.push(ObjectSpec::from(object));
    }
    Ok(objects)
}
