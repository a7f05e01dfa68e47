//! Objects as triangle meshes: the shapes the arm explores.
//!
//! - loading OBJ, OFF and STL with validation ([`load()`], [`ValidationReport`]), writing OBJ;
//! - geometry: bounds, area, signed volume, normalisation to a common size ([`normalise_to_diagonal`]),
//!   the edge topology behind watertightness and orientation checks ([`EdgeTopology`]), and a
//!   coarse copy of a large mesh for MuJoCo to draw ([`cluster_vertices`]);
//! - the objects: ten real meshes fetched from Debian ([`CgalMesh`]), chess pieces as surfaces of
//!   revolution ([`ChessPiece`], [`Profile`]), raised letters from a font ([`raised_letter`], [`Font`]);
//! - one object, loaded, checked and plausible ([`Object::from_file`]);
//! - object sets: named, versioned manifests that datasets and models refer to ([`ObjectSet`]).

mod builder;
pub(crate) mod cgal;
pub(crate) mod checksum;
pub(crate) mod chess;
pub(crate) mod decimate;
pub(crate) mod error;
pub(crate) mod glyph;
pub(crate) mod glyph_overlap;
pub(crate) mod letters;
pub(crate) mod load;
pub(crate) mod mass;
pub(crate) mod normalise;
pub(crate) mod obj;
mod object;
pub(crate) mod object_set;
mod off;
mod plausible;
pub(crate) mod revolution;
mod stl;
pub(crate) mod topology;
pub(crate) mod triangulate;
pub(crate) mod trimesh;
pub(crate) mod validate;

// One object: a mesh file loaded, validated, and checked for a plausible size.
pub use error::{Location, MeshError};
pub use load::{LoadedMesh, MeshFormat, load, parse};
pub use mass::SolidMoments;
pub use object::Object;
pub use plausible::{Implausible, SizeLimit, check_plausible};
pub use validate::ValidationReport;

// The mesh and its geometry: normalisation, orientation, topology, writing OBJ.
pub use decimate::cluster_vertices;
pub use normalise::{UpAxis, normalise_to_diagonal, orient_outward, rotate_up_to_z};
pub use obj::{to_obj_string, write_obj};
pub use topology::{EdgeTopology, connected_components};
pub use trimesh::TriMesh;

// Object sets: named, versioned manifests that datasets and models refer to.
pub use object_set::{
    BUILTIN_SETS, BuildOptions, NamedObject, ObjectSet, ObjectSetRef, ObjectSource, sizes_its_own_objects,
};

// The paper's objects: the CGAL meshes fetched from Debian, chess pieces as surfaces of
// revolution, raised letters from a font.
pub use cgal::{
    CGAL_MESHES, CgalMesh, DEB_FILE, ObjectCache, cache_root, cache_root_from, cgal_mesh, ensure_fetched,
};
pub use chess::ChessPiece;
pub use glyph::{BUILTIN_FONT_PREFIX, CAPITAL_I_FONT, DEFAULT_FONT, Font};
pub use glyph_overlap::{LetterPair, letter_pairs};
pub use letters::{LetterStyle, alphabet, letter_from_name, letter_name, letter_outline, raised_letter};
pub use revolution::{Profile, ProfileBuilder};
