//! Objects: a mesh file of the user's, or the pieces of a built-in set, checked as the CLI checks
//! them (faced outward, sized, a plausible table-top solid).

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;
use taction::mesh::{BuildOptions, ObjectSet, sizes_its_own_objects};
use taction::sim::ObjectSpec;

use crate::error::{bad_argument, refused};

/// One object the sensor can touch: a name and a checked triangle mesh in metres.
#[pyclass(module = "taction", frozen)]
pub struct Object {
    pub inner: Arc<taction::mesh::Object>,
}

/// An object's fields, as a pickle carries them.
#[derive(serde::Serialize, serde::Deserialize)]
struct Parts {
    name: String,
    mesh: taction::mesh::TriMesh,
    warnings: taction::mesh::ValidationReport,
    flipped: bool,
}

impl Parts {
    fn of(object: &taction::mesh::Object) -> Self {
        Self {
            name: object.name.clone(),
            mesh: object.mesh.clone(),
            warnings: object.warnings,
            flipped: object.flipped,
        }
    }
}

impl Object {
    pub fn spec(&self) -> ObjectSpec {
        spec_of(&self.inner)
    }
}

/// The library's specification of a built object, as the scenes take it.
pub fn spec_of(object: &taction::mesh::Object) -> ObjectSpec {
    ObjectSpec::from(object.clone())
}

#[pymethods]
impl Object {
    /// The mesh in `path` (OBJ, OFF or STL), named after the file's stem. Coordinates are metres
    /// unless `size_m` is given: then the mesh is rescaled to that bounding diagonal, centred and
    /// resting on z = 0. A broken or implausible mesh raises `TactionError` naming the file.
    #[staticmethod]
    #[pyo3(signature = (path, size_m=None))]
    fn from_file(py: Python<'_>, path: PathBuf, size_m: Option<f64>) -> PyResult<Self> {
        if let Some(size) = size_m {
            positive_size(size)?;
        }
        let object = py
            .detach(|| match size_m {
                Some(d) => taction::mesh::Object::from_file_with_size(&path, d),
                None => taction::mesh::Object::from_file(&path),
            })
            .map_err(refused)?;
        Ok(Self {
            inner: Arc::new(object),
        })
    }

    /// An object does not change: copies are the object itself (Gymnasium copies an environment's
    /// arguments).
    fn __copy__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __deepcopy__<'py>(slf: PyRef<'py, Self>, _memo: &Bound<'py, PyAny>) -> PyRef<'py, Self> {
        slf
    }

    /// Pickled as its name, mesh and checks (what vector environments in subprocesses need).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let json = serde_json::to_string(&Parts::of(&self.inner)).map_err(refused)?;
        Ok((py.get_type::<Self>().getattr("_from_parts")?, (json,)))
    }

    /// The object [`__reduce__`](Self::__reduce__) pickled; its mesh was checked when it was made.
    #[staticmethod]
    fn _from_parts(json: &str) -> PyResult<Self> {
        let parts: Parts = serde_json::from_str(json).map_err(|e| bad_argument("pickle", e))?;
        Ok(Self {
            inner: Arc::new(taction::mesh::Object {
                name: parts.name,
                mesh: parts.mesh,
                warnings: parts.warnings,
                flipped: parts.flipped,
            }),
        })
    }

    #[getter]
    fn name(&self) -> &str {
        &self.inner.name
    }

    /// How many triangles the mesh has.
    #[getter]
    fn triangles(&self) -> usize {
        self.inner.mesh.triangles.len()
    }

    /// The bounding box's diagonal, metres.
    #[getter]
    fn size_m(&self) -> Option<f64> {
        self.inner.mesh.bounding_diagonal_m()
    }

    /// The axis-aligned bounding box, metres: `[[min x, y, z], [max x, y, z]]`.
    #[getter]
    fn bounds_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let vertices = &self.inner.mesh.vertices;
        let min = vertices.iter().fold(glam::DVec3::INFINITY, |a, v| a.min(*v));
        let max = vertices.iter().fold(glam::DVec3::NEG_INFINITY, |a, v| a.max(*v));
        let values = [min.to_array(), max.to_array()].concat();
        crate::array::from_f64(py, &values, &[2, 3], "float64")
    }

    fn __repr__(&self) -> String {
        format!(
            "Object({:?}, {} triangles, {:.4} m across)",
            self.inner.name,
            self.inner.mesh.triangles.len(),
            self.inner.mesh.bounding_diagonal_m().unwrap_or(0.0)
        )
    }
}

/// `size_m` as a bounding diagonal: a positive number of metres.
fn positive_size(size: f64) -> PyResult<()> {
    if size.is_finite() && size > 0.0 {
        Ok(())
    } else {
        Err(bad_argument(
            "size_m",
            format!("{size} is not a positive number of metres"),
        ))
    }
}

/// The objects of a set: a built-in set's name (`shapes`, `chess`, `letters`), a folder of meshes or
/// a set manifest (`.json`), as `taction objects list` takes it. The `shapes` meshes are fetched into
/// the user's cache on first use. `size_m` rescales a folder's meshes to that bounding diagonal
/// (centred, resting on z = 0); built-in sets and manifests have their own sizes and refuse it.
#[pyfunction]
#[pyo3(signature = (set, size_m=None))]
pub fn objects(py: Python<'_>, set: PathBuf, size_m: Option<f64>) -> PyResult<Vec<Object>> {
    if let Some(size) = size_m {
        positive_size(size)?;
        if sizes_its_own_objects(&set) {
            return Err(bad_argument(
                "size_m",
                format!(
                    "'{}' sizes its own objects; size_m rescales a folder of meshes",
                    set.display()
                ),
            ));
        }
    }
    let built = py
        .detach(|| {
            let set = ObjectSet::resolve(&[set], None, size_m)?;
            set.build(&BuildOptions {
                fetch: true,
                ..BuildOptions::default()
            })
        })
        .map_err(refused)?;
    Ok(built.into_iter().map(|o| Object { inner: Arc::new(o) }).collect())
}
