//! Objects as triangle meshes: the shapes the arm explores.

pub mod trimesh;

pub use trimesh::TriMesh;
