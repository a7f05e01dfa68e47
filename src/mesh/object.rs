//! One object the arm explores: a name and a mesh the library has checked. Every way to an object
//! (a user's file, a built-in set's piece, letter or CGAL mesh) ends in [`Object::checked`], so a
//! mesh that reaches the simulator faces outward, has the size asked for and is a plausible
//! table-top solid ([`check_plausible`] with [`SizeLimit::TABLE_TOP`]).

use std::fmt;
use std::path::Path;

use super::TriMesh;
use super::error::MeshError;
use super::load::load;
use super::normalise::{normalise_to_diagonal, orient_outward};
use super::plausible::{SizeLimit, check_plausible};
use super::validate::ValidationReport;

/// An object ready to place in a scene: its mesh faces outward, rests as its source placed it (or,
/// rescaled, centred on x = y = 0 on z = 0) and is a solid of table-top size in metres.
///
/// ```
/// use taction::mesh::Object;
///
/// // A 5 cm tetrahedron written in millimetres, as CAD tools often write meshes.
/// let path = std::env::temp_dir().join(format!("taction_doc_{}_tetra.obj", std::process::id()));
/// std::fs::write(&path, "v 0 0 0\nv 50 0 0\nv 0 50 0\nv 0 0 50\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")?;
/// // Read as metres it is 86.6 m across: no table-top object, and the error says how to fix it.
/// let refused = Object::from_file(&path).unwrap_err().to_string();
/// assert!(refused.contains("--object-size-m"), "{refused}");
/// // Given its size (a bounding diagonal in metres), it is one.
/// let object = Object::from_file_with_size(&path, 0.1)?;
/// assert!(object.name.ends_with("_tetra"));
/// assert!((object.mesh.bounding_diagonal_m().unwrap() - 0.1).abs() < 1e-9);
/// let spec = taction::sim::ObjectSpec::from(object);
/// # std::fs::remove_file(&path)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    pub name: String,
    pub mesh: TriMesh,
    /// Validation of the mesh as read (user files, CGAL meshes) or generated.
    pub warnings: ValidationReport,
    /// Whether the triangles were flipped to face outward.
    pub flipped: bool,
}

impl Object {
    /// The mesh in `path` (OBJ, OFF or STL, coordinates in metres), named after the file's stem.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, MeshError> {
        Self::from_file_sized(path.as_ref(), None)
    }

    /// The mesh in `path` rescaled to a bounding diagonal of `size_m` metres, centred and resting
    /// on z = 0: a mesh written in other units (what `--object-size-m` gives the commands).
    pub fn from_file_with_size(path: impl AsRef<Path>, size_m: f64) -> Result<Self, MeshError> {
        Self::from_file_sized(path.as_ref(), Some(size_m))
    }

    fn from_file_sized(path: &Path, diagonal_m: Option<f64>) -> Result<Self, MeshError> {
        let name = name_of_file(path)?;
        let loaded = load(path)?;
        let source = format!("file {}", path.display());
        Self::checked(name, &source, loaded.mesh, loaded.warnings, diagonal_m)
    }

    /// The one way a mesh becomes an object: faces turned outward, scaled to `diagonal_m` when
    /// given, then refused unless plausible; `source` names where it came from in the error.
    pub(super) fn checked(
        name: String,
        source: &dyn fmt::Display,
        mesh: TriMesh,
        warnings: ValidationReport,
        diagonal_m: Option<f64>,
    ) -> Result<Self, MeshError> {
        let (mesh, flipped) = orient_outward(mesh);
        let mesh = match diagonal_m {
            Some(d) => normalise_to_diagonal(&mesh, d)?,
            None => mesh,
        };
        check_plausible(&mesh, SizeLimit::TABLE_TOP).map_err(|problem| MeshError::Implausible {
            object: format!("{name} ({source})"),
            problem,
        })?;
        Ok(Self {
            name,
            mesh,
            warnings,
            flipped,
        })
    }
}

/// An object's name from its file: the file's stem.
pub(super) fn name_of_file(path: &Path) -> Result<String, MeshError> {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .ok_or_else(|| MeshError::ObjectSet {
            what: format!("{}: cannot name an object from this file name", path.display()),
        })
}
