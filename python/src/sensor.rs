//! The covering sensor (Sec. V-A2) on the free-floating pad: one reading of an object at a pad pose,
//! no controllers, exactly what `taction sense` reads.

use std::sync::{Arc, Mutex};

use glam::DVec3;
use pyo3::prelude::*;
use taction::control::FreePad;
use taction::pose::PadPose;
use taction::tactile::{SensorConfig, TactileImage, arm_with_sensor};
use taction::valid::Valid;

use crate::args::Whole;
use crate::array;
use crate::error::{bad_argument, refused};
use crate::object::Object;

/// The tactile sensor: `rows x cols` taxels over a square pad `pad_m` wide (or a rectangular
/// one, `pad_width_m` along a row by `pad_height_m` along a column) under a covering
/// `thickness_m` thick (default 10% of the pad's shorter side), blurred by a Gaussian point-spread (default
/// sigma 0.48 t), each taxel averaging `rays_per_taxel` rays, with additive noise `noise` (a
/// fraction of the range) drawn from `seed`. The defaults are `taction sense`'s (the paper's
/// 6x6 sensor).
#[pyclass(module = "taction")]
pub struct Sensor {
    pub config: Valid<SensorConfig>,
    /// One free pad per object read so far (building its MuJoCo scene is the expensive part); one
    /// thread reads at a time.
    pads: Mutex<Vec<(Arc<taction::mesh::Object>, FreePad)>>,
}

impl Sensor {
    /// The paper's sensor, checked.
    pub fn paper_config() -> PyResult<Valid<SensorConfig>> {
        Valid::new(SensorConfig::paper()).map_err(refused)
    }

    /// One reading of `object` at `pose` by its pad (made on first use).
    fn read_at(&self, object: &Object, pose: &PadPose) -> PyResult<TactileImage> {
        let mut pads = self
            .pads
            .lock()
            .map_err(|_| refused("the sensor was poisoned by an earlier failure"))?;
        let index = match pads.iter().position(|(o, _)| Arc::ptr_eq(o, &object.inner)) {
            Some(i) => i,
            None => {
                let pad = FreePad::new(object.spec(), &self.config).map_err(refused)?;
                pads.push((object.inner.clone(), pad));
                pads.len() - 1
            }
        };
        pads[index].1.read_at(pose).map_err(refused)
    }
}

/// The nine numbers of a pad pose, as a dataset's `pad_*` columns: the centre (metres), the normal
/// (from the pad into the covering, toward the object) and the up direction (row 0's edge).
pub fn pad_pose(value: &Bound<'_, PyAny>) -> PyResult<PadPose> {
    pad_pose_of(&array::to_f64(value, "pad_pose")?.1)
}

/// [`pad_pose`] of the numbers given.
pub fn pad_pose_of(v: &[f64]) -> PyResult<PadPose> {
    if v.len() != 9 || v.iter().any(|x| !x.is_finite()) {
        return Err(bad_argument(
            "pad_pose",
            format!("want 9 finite numbers (centre xyz in metres, normal xyz, up xyz), got {v:?}"),
        ));
    }
    let vec = |i: usize| DVec3::new(v[i], v[i + 1], v[i + 2]);
    PadPose::new(vec(0), vec(3), vec(6))
        .ok_or_else(|| bad_argument("pad_pose", "the normal and up must be non-zero and not parallel"))
}

/// A reading's values lie in [0, 1]: an integer dtype would truncate them to zeros.
fn image_dtype(dtype: &Bound<'_, PyAny>) -> PyResult<&'static str> {
    let name = dtype
        .py()
        .import("numpy")?
        .call_method1("dtype", (dtype,))
        .and_then(|d| d.str())
        .map(|s| s.to_string())
        .map_err(|_| bad_argument("dtype", format!("{dtype} is not a numpy dtype")))?;
    match name.as_str() {
        "float32" => Ok("float32"),
        "float64" => Ok("float64"),
        other => Err(bad_argument(
            "dtype",
            format!("{other}: want float32 or float64 (values lie in [0, 1])"),
        )),
    }
}

#[pymethods]
impl Sensor {
    #[new]
    #[pyo3(signature = (rows=Whole(6), cols=Whole(6), pad_m=0.012, thickness_m=None, psf_sigma_m=None, rays_per_taxel=Whole(4), noise=0.0, seed=Whole(1), pad_width_m=None, pad_height_m=None), text_signature = "(rows=6, cols=6, pad_m=0.012, thickness_m=None, psf_sigma_m=None, rays_per_taxel=4, noise=0.0, seed=1, pad_width_m=None, pad_height_m=None)")]
    #[allow(clippy::too_many_arguments)] // Python keyword arguments, each a sensor parameter
    fn new(
        rows: Whole<usize>,
        cols: Whole<usize>,
        pad_m: f64,
        thickness_m: Option<f64>,
        psf_sigma_m: Option<f64>,
        rays_per_taxel: Whole<usize>,
        noise: f64,
        seed: Whole<u64>,
        pad_width_m: Option<f64>,
        pad_height_m: Option<f64>,
    ) -> PyResult<Self> {
        let (Whole(rows), Whole(cols), Whole(rays_per_taxel), Whole(seed)) =
            (rows, cols, rays_per_taxel, seed);
        let config = SensorConfig {
            rays_per_taxel,
            noise_fraction: noise,
            noise_seed: seed,
            ..SensorConfig::of_pad(
                rows,
                cols,
                pad_width_m.unwrap_or(pad_m),
                pad_height_m.unwrap_or(pad_m),
                thickness_m,
                psf_sigma_m,
            )
        };
        Ok(Self {
            config: Valid::new(config).map_err(refused)?,
            pads: Mutex::new(Vec::new()),
        })
    }

    /// Pickled as its configuration (the pads it built are made again on first use).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let json = serde_json::to_string(&*self.config).map_err(refused)?;
        Ok((py.get_type::<Self>().getattr("_from_config")?, (json,)))
    }

    /// The sensor [`__reduce__`](Self::__reduce__) pickled, checked again.
    #[staticmethod]
    fn _from_config(json: &str) -> PyResult<Self> {
        let config: SensorConfig = serde_json::from_str(json).map_err(|e| bad_argument("pickle", e))?;
        Ok(Self {
            config: Valid::new(config).map_err(refused)?,
            pads: Mutex::new(Vec::new()),
        })
    }

    /// One reading of `object` with the pad at `pad_pose` (9 numbers: centre xyz in metres,
    /// normal xyz, up xyz): an array `(rows, cols)` of values in [0, 1], row 0 the pad's up edge,
    /// of `dtype` `float32` (the default) or `float64` (a name or a numpy dtype).
    #[pyo3(signature = (object, pad_pose, dtype=None))]
    fn read<'py>(
        &self,
        py: Python<'py>,
        object: PyRef<'py, Object>,
        pad_pose: &Bound<'py, PyAny>,
        dtype: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let dtype = dtype.map_or(Ok("float32"), image_dtype)?;
        let pose = self::pad_pose(pad_pose)?;
        let image = self.read_at(&object, &pose)?;
        array::from_f64(py, image.values(), &[image.rows(), image.cols()], dtype)
    }

    #[getter]
    fn rows(&self) -> usize {
        self.config.rows
    }

    #[getter]
    fn cols(&self) -> usize {
        self.config.cols
    }

    /// The configuration as a dataset's header writes it.
    fn config(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        array::json_to_python(py, &serde_json::to_value(*self.config).map_err(refused)?)
    }

    fn __repr__(&self) -> String {
        let c = &*self.config;
        let pad = if c.is_square_pad() {
            format!("pad_m={}", c.pad_width_m)
        } else {
            format!("pad_width_m={}, pad_height_m={}", c.pad_width_m, c.pad_height_m)
        };
        format!(
            "Sensor(rows={}, cols={}, {pad}, thickness_m={}, psf_sigma_m={}, rays_per_taxel={}, noise={}, seed={})",
            c.rows, c.cols, c.thickness_m, c.psf_sigma_m, c.rays_per_taxel, c.noise_fraction, c.noise_seed
        )
    }
}

/// The MJCF world the arm explores, for stock `mujoco`: the arm, the table, `object` (its mesh
/// inline) and the `taction.covering` sensor named `tactile` on the pad (the paper's 6x6 sensor
/// unless `sensor` is given). `import taction` registers the plugin, so
/// `mujoco.MjModel.from_xml_string(taction.scene(obj))` compiles.
#[pyfunction]
#[pyo3(signature = (object, sensor=None))]
pub fn scene(object: &Object, sensor: Option<PyRef<'_, Sensor>>) -> PyResult<String> {
    let config = match sensor {
        Some(s) => s.config,
        None => Sensor::paper_config()?,
    };
    arm_with_sensor(object.spec(), &config).to_xml().map_err(refused)
}
