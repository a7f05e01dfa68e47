//! Objects as triangle meshes: the shapes the arm explores.
//!
//! - loading OBJ, OFF and STL with validation ([`load()`], [`ValidationReport`]), writing OBJ;
//! - geometry: bounds, area, signed volume, normalisation to a common size ([`normalise_to_diagonal`]),
//!   and the edge topology behind watertightness and orientation checks ([`EdgeTopology`]);
//! - the objects: ten real meshes fetched from Debian ([`cgal`]), chess pieces as surfaces of
//!   revolution ([`chess`], [`revolution`]), raised letters from a font ([`letters`], [`glyph`]);
//! - one object, loaded, checked and plausible ([`Object::from_file`]);
//! - object sets: named, versioned manifests that datasets and models refer to ([`ObjectSet`]).

pub mod cgal;
pub(crate) mod checksum;
pub mod chess;
pub(crate) mod error;
pub mod glyph;
pub mod glyph_overlap;
pub mod letters;
pub mod load;
pub(crate) mod normalise;
pub(crate) mod obj;
mod object;
pub mod object_set;
mod off;
mod plausible;
pub mod revolution;
mod stl;
pub(crate) mod topology;
pub(crate) mod triangulate;
pub(crate) mod trimesh;
pub(crate) mod validate;

pub use cgal::{CGAL_MESHES, CgalMesh, ObjectCache, ensure_fetched};
pub use error::{Location, MeshError};
pub use load::{LoadedMesh, MeshFormat, load, parse};
pub use normalise::{UpAxis, normalise_to_diagonal, orient_outward, rotate_up_to_z};
pub use obj::{to_obj_string, write_obj};
pub use object::Object;
pub use object_set::{BuildOptions, NamedObject, ObjectSet, ObjectSetRef, ObjectSource};
pub use plausible::{Implausible, SizeLimit, check_plausible};
pub use topology::{EdgeTopology, connected_components};
pub use trimesh::TriMesh;
pub use validate::ValidationReport;
