//! Datasets: collected from Python (the training sampler or the planner, Sec. III-A, V-A3), read
//! from and written to the CLI's file, and handed to numpy and pandas column by column.

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use taction::active_touch::{ArmData, ArmTrainingObserver, ArmTrainingRecipe};
use taction::dataset::{ColumnType, ExportFormat, Reading, Shortfall, describe_shortfalls};
use taction::explore::{CollectModeName, CollectRequest, ModeChoices};
use taction::sim::{FreeBody, ObjectSpec};
use taction::tactile::SensorConfig;

use crate::args::{self, Objects, Whole, max_heading};
use crate::array;
use crate::error::{bad_argument, refused};
use crate::object::spec_of;
use crate::sensor::Sensor;

/// Readings of a set of objects, with the header saying how they were made. Columns come out as
/// numpy arrays in file order: `images (N, rows, cols)` float32, `pad_pose (N, 9)` float64 (NaN
/// where a reading has no pose), `object`, `status`, `strategy`, `cause`, `touched_bodies`
/// (strings), `iterations` (int64).
#[pyclass(module = "taction", frozen)]
pub struct Dataset {
    pub inner: Arc<taction::dataset::Dataset>,
}

impl Dataset {
    fn strings(&self, py: Python<'_>, column: impl Fn(&Reading) -> String) -> PyResult<Py<PyAny>> {
        let items = self.inner.readings().iter().map(column).collect();
        Ok(array::strings(py, items)?.unbind())
    }

    /// An int64 column of every reading.
    fn integers<'py>(
        &self,
        py: Python<'py>,
        column: impl Fn(&Reading) -> i64,
    ) -> PyResult<Bound<'py, PyAny>> {
        array::from_i64(py, self.inner.readings().iter().map(column).collect())
    }
}

#[pymethods]
impl Dataset {
    /// Reads a dataset file (`taction collect`'s CSV, any format version).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let dataset = py
            .detach(|| taction::dataset::Dataset::read(&path))
            .map_err(refused)?;
        Ok(Self {
            inner: Arc::new(dataset),
        })
    }

    /// Pickled as its file's contents.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let bytes = self.inner.to_file_bytes("the pickle").map_err(refused)?;
        let rebuild = py.get_type::<Self>().getattr("from_bytes")?;
        Ok((rebuild, (PyBytes::new(py, &bytes),)))
    }

    /// A dataset from the contents of its file.
    #[staticmethod]
    fn from_bytes(bytes: &[u8]) -> PyResult<Self> {
        let text = std::str::from_utf8(bytes).map_err(|e| bad_argument("bytes", e))?;
        let dataset = taction::dataset::Dataset::parse(text, "the dataset's bytes").map_err(refused)?;
        Ok(Self {
            inner: Arc::new(dataset),
        })
    }

    /// Writes the dataset file `taction train` reads.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.inner.write(&path)).map_err(refused)
    }

    /// Writes the dataset for the ML toolchain, as `taction dataset export` does: `format="npz"`
    /// (numpy's `np.load`, no pickles: `images`, `pad_pose`, `object`, `status`, `cause`, ...) or
    /// `"parquet"` (`pandas.read_parquet`: the file's columns).
    #[pyo3(signature = (path, format="npz"))]
    fn export(&self, py: Python<'_>, path: PathBuf, format: &str) -> PyResult<()> {
        let format: ExportFormat = format.parse().map_err(|e| bad_argument("format", e))?;
        py.detach(|| self.inner.export(&path, format)).map_err(refused)
    }

    /// The converged readings only (what training and recognition use).
    fn converged(&self) -> Self {
        Self {
            inner: Arc::new(self.inner.converged_only()),
        }
    }

    /// The dataset as a pandas DataFrame with the file's columns (`object`, `status`, ..., the pad
    /// pose's nine, `t_{row}_{col}` per taxel), each of the one type it has in every export
    /// (`taction::dataset::column_types`): names strings (empty where none), `iterations` int64,
    /// the poses float64 (the pad's NaN where a reading has none), the taxels float32. The values
    /// are the file's, read back exactly.
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = self.inner.to_file_bytes("to_pandas").map_err(refused)?;
        let buffer = py
            .import("io")?
            .call_method1("BytesIO", (PyBytes::new(py, &text),))?;
        let sensor = &self.inner.header().sensor;
        let (dtypes, missing) = (PyDict::new(py), PyDict::new(py));
        for (name, column) in taction::dataset::column_types(sensor.rows, sensor.cols) {
            dtypes.set_item(&name, column.numpy())?;
            // Only a number may be missing (an empty field); an empty name stays "".
            if column != ColumnType::Text {
                missing.set_item(&name, vec![""])?;
            }
        }
        let kwargs = PyDict::new(py);
        kwargs.set_item("comment", "#")?;
        kwargs.set_item("dtype", dtypes)?;
        kwargs.set_item("keep_default_na", false)?;
        kwargs.set_item("na_values", missing)?;
        let pandas = py.import("pandas")?;
        // The file's numbers read back exactly: pandas 3 parses them so by default (and deprecates
        // the choice), pandas 1 and 2 when asked.
        let version: String = pandas.getattr("__version__")?.extract()?;
        if version.split('.').next().and_then(|m| m.parse::<u32>().ok()) < Some(3) {
            kwargs.set_item("float_precision", "round_trip")?;
        }
        pandas.call_method("read_csv", (buffer,), Some(&kwargs))
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// The object names the header lists, in index order.
    #[getter]
    fn objects(&self) -> Vec<String> {
        self.inner.header().objects.clone()
    }

    /// The header (sensor, object set, objects, generator, seed) as a dict.
    #[getter]
    fn header(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        array::json_to_python(py, &serde_json::to_value(self.inner.header()).map_err(refused)?)
    }

    #[getter]
    fn images<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let sensor = &self.inner.header().sensor;
        let values: Vec<f64> = self
            .inner
            .readings()
            .iter()
            .flat_map(|r| r.image.values().iter().copied())
            .collect();
        array::from_f64(
            py,
            &values,
            &[self.inner.len(), sensor.rows, sensor.cols],
            "float32",
        )
    }

    #[getter]
    fn pad_pose<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let values: Vec<f64> = self
            .inner
            .readings()
            .iter()
            .flat_map(|r| match r.image.pose() {
                Some(p) => [p.center_m, p.normal, p.up].map(|v| v.to_array()).concat(),
                None => vec![f64::NAN; 9],
            })
            .collect();
        array::from_f64(py, &values, &[self.inner.len(), 9], "float64")
    }

    #[getter]
    fn object(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.strings(py, |r| r.object.clone())
    }

    #[getter]
    fn status(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.strings(py, |r| r.status.name().to_string())
    }

    #[getter]
    fn strategy(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.strings(py, |r| r.strategy.name().to_string())
    }

    #[getter]
    fn cause(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.strings(py, |r| r.cause.as_ref().map_or("", |c| c.name()).to_string())
    }

    #[getter]
    fn touched_bodies(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.strings(py, |r| {
            r.cause
                .as_ref()
                .and_then(|c| c.touched_bodies())
                .unwrap_or_default()
        })
    }

    #[getter]
    fn iterations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.integers(py, |r| i64::from(r.iterations))
    }

    /// The press each reading is one frame of (a recording's contact, numbered from 0 in the
    /// order of their first frames), -1 for a reading that is a contact of its own, as in
    /// `dataset export`'s npz.
    #[getter]
    fn contact<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.integers(py, Reading::contact_number)
    }

    fn __repr__(&self) -> String {
        let h = self.inner.header();
        format!(
            "Dataset({} readings of {} objects, {}x{}, generator {:?})",
            self.inner.len(),
            h.objects.len(),
            h.sensor.rows,
            h.sensor.cols,
            h.generator
        )
    }
}

/// Touches `objects` and gathers the readings into a `Dataset`, objects in parallel (`threads`, 0:
/// one per core; the readings do not depend on it), as `taction collect` does:
/// - `mode="sampler"`: the training sampler (Sec. V-A3) on area-weighted random surface points,
///   `readings` converged readings per object (`from_above`: approach only from above;
///   `reachable_by_arm`: only from starts the arm can take);
/// - `mode="planner"`: the arm explores with the paper's planner (Sec. III-A), local with
///   probability `local_probability` (0.5 by default).
///
/// An argument of the other mode is refused rather than ignored.
/// `perturb_deg` and `perturb_frac` move the object after every reading (Sec. V-B3);
/// `start_pose="random"` stands each object at a start drawn from the seed (a heading within
/// `start_heading_deg`, a tilt and a shift) as `taction collect --start-pose` does, which the
/// header and `object_pose` record. `free_object=True` (the planner's) stands each object on a
/// free joint, a solid of `object_density` kg/m3 (1000) with sliding friction `object_friction`
/// (0.8), pushed by the covering, as `taction collect --free-object` does; the header records it.
/// `perturb_by="push"` (a free object's only) pushes it toward each perturbation's draw rather
/// than putting it there, as `taction collect --perturb-by push` does.
/// Same seed, same dataset, bit for bit.
#[pyfunction]
#[pyo3(signature = (objects, mode="sampler", readings=Whole(100), seed=Whole(1), sensor=None, threads=Whole(0), local_probability=None, perturb_deg=0.0, perturb_frac=0.0, from_above=false, reachable_by_arm=false, object_set="python", start_pose="canonical", start_heading_deg=180.0, free_object=false, object_density=None, object_friction=None, perturb_by="teleport"), text_signature = "(objects, mode='sampler', readings=100, seed=1, sensor=None, threads=0, local_probability=None, perturb_deg=0.0, perturb_frac=0.0, from_above=False, reachable_by_arm=False, object_set='python', start_pose='canonical', start_heading_deg=180.0, free_object=False, object_density=None, object_friction=None, perturb_by='teleport')")]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each a collection parameter
pub fn collect(
    py: Python<'_>,
    objects: Objects,
    mode: &str,
    readings: Whole<usize>,
    seed: Whole<u64>,
    sensor: Option<PyRef<'_, Sensor>>,
    threads: Whole<usize>,
    local_probability: Option<f64>,
    perturb_deg: f64,
    perturb_frac: f64,
    from_above: bool,
    reachable_by_arm: bool,
    object_set: &str,
    start_pose: &str,
    start_heading_deg: f64,
    free_object: bool,
    object_density: Option<f64>,
    object_friction: Option<f64>,
    perturb_by: &str,
) -> PyResult<Dataset> {
    let (Whole(readings), Whole(seed), Whole(threads)) = (readings, seed, threads);
    let free_body = FreeBody::requested(free_object, object_density, object_friction).map_err(refused)?;
    let (sensor, specs) = touch_inputs(&objects, sensor)?;
    let start_pose = args::start_pose(start_pose, start_heading_deg)?;
    let perturbation = args::perturbation(perturb_deg, perturb_frac, perturb_by)?;
    let mode = CollectModeName::parse(mode).ok_or_else(|| {
        bad_argument(
            "mode",
            format!("'{mode}' is not one of {}", CollectModeName::NAMES.join(", ")),
        )
    })?;
    let choices = ModeChoices {
        from_above,
        reachable_by_arm,
        local_probability,
        max_iterations: None,
    };
    // An argument of the other mode would be ignored: the dataset would not be the one asked for.
    let request = CollectRequest::of_mode(mode, choices).map_err(refused)?;
    let collect = request
        .collection(sensor, &specs, readings)
        .seed(seed)
        .threads(threads)
        .perturbation(perturbation)
        .start_pose(start_pose)
        .free_object(free_body);
    let dataset = py
        .detach(|| collect.dataset(object_set, &specs))
        .map_err(refused)?;
    warn_of_shortfalls(py, "collect", &dataset, readings)?;
    Ok(Dataset {
        inner: Arc::new(dataset),
    })
}

/// The arm's own blind explorations that `train_for_arm` calibrates its posterior on, collected as
/// `taction demo` collects them (`ArmTrainingRecipe::calibration_plans`), a list of datasets: a
/// thirtieth of `training_readings` (10 to 100) converged readings per object in fresh
/// explorations of 10 each, the planner at L = 0.5, the object fixed at a random start within
/// `start_heading_deg` of its canonical heading, each on a random stream of `seed` the training
/// data does not use. Successive touches of one exploration are correlated, which readings held
/// out of the sampler's training data cannot show: calibrated on those, the posterior is
/// overconfident on the arm's touches.
#[pyfunction]
#[pyo3(signature = (objects, training_readings=Whole(1000), seed=Whole(1), sensor=None, threads=Whole(0), object_set="python", start_heading_deg=180.0), text_signature = "(objects, training_readings=1000, seed=1, sensor=None, threads=0, object_set='python', start_heading_deg=180.0)")]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each a recipe parameter
pub fn collect_arm_calibration(
    py: Python<'_>,
    objects: Objects,
    training_readings: Whole<usize>,
    seed: Whole<u64>,
    sensor: Option<PyRef<'_, Sensor>>,
    threads: Whole<usize>,
    object_set: &str,
    start_heading_deg: f64,
) -> PyResult<Vec<Dataset>> {
    let (recipe, sensor, specs) =
        arm_recipe_inputs(&objects, (training_readings, seed, start_heading_deg), sensor)?;
    let Whole(threads) = threads;
    let mut shortfalls = Shortfalls::default();
    let datasets = py
        .detach(|| recipe.collect_calibration(object_set, &specs, sensor, threads, &mut shortfalls))
        .map_err(refused)?;
    shortfalls.warn(py, "collect_arm_calibration")?;
    Ok(datasets
        .into_iter()
        .map(|dataset| Dataset {
            inner: Arc::new(dataset),
        })
        .collect())
}

/// The recipe's collections that fell short, to warn of once the GIL is back.
#[derive(Default)]
pub struct Shortfalls(Vec<String>);

impl ArmTrainingObserver for Shortfalls {
    fn collected(&mut self, data: ArmData, _converged: usize, short: &[Shortfall]) {
        if !short.is_empty() {
            let what = match data {
                ArmData::Training => "training",
                ArmData::Calibration => "calibration",
            };
            self.0.push(format!(
                "{what}: fewer readings than asked: {}",
                describe_shortfalls(short)
            ));
        }
    }
}

impl Shortfalls {
    /// Warns of each collection that fell short, as `taction.{function}`.
    pub fn warn(self, py: Python<'_>, function: &str) -> PyResult<()> {
        for message in self.0 {
            warn(py, &format!("taction.{function}: {message}"))?;
        }
        Ok(())
    }
}

/// The demo's recipe at `training_readings` per object, `seed` and `start_heading_deg`, the
/// sensor and the objects to touch: what `arm_model` and `collect_arm_calibration` both start
/// from, so they collect alike.
pub fn arm_recipe_inputs(
    objects: &Objects,
    (Whole(training_readings), Whole(seed), start_heading_deg): (Whole<usize>, Whole<u64>, f64),
    sensor: Option<PyRef<'_, Sensor>>,
) -> PyResult<(ArmTrainingRecipe, SensorConfig, Vec<ObjectSpec>)> {
    let (sensor, specs) = touch_inputs(objects, sensor)?;
    let recipe = ArmTrainingRecipe {
        readings_per_object: training_readings,
        seed,
        start_heading: max_heading(start_heading_deg)?,
    };
    Ok((recipe, sensor, specs))
}

/// The objects to touch as the library's specifications, and the sensor (the paper's by default).
fn touch_inputs(
    objects: &Objects,
    sensor: Option<PyRef<'_, Sensor>>,
) -> PyResult<(SensorConfig, Vec<ObjectSpec>)> {
    let Objects(objects) = objects;
    if objects.is_empty() {
        return Err(bad_argument("objects", "no object to touch"));
    }
    let sensor = match sensor {
        Some(s) => s.config,
        None => Sensor::paper_config()?,
    }
    .into_inner();
    Ok((sensor, objects.iter().map(|o| spec_of(o)).collect()))
}

/// A run that gathered fewer readings than asked says so, as a Python warning (the planner may run
/// out of iterations on an object it cannot reach well).
fn warn_of_shortfalls(
    py: Python<'_>,
    function: &str,
    dataset: &taction::dataset::Dataset,
    readings: usize,
) -> PyResult<()> {
    let shortfalls = dataset.shortfalls(readings);
    if !shortfalls.is_empty() {
        let message = format!(
            "taction.{function}: fewer readings than asked: {}",
            describe_shortfalls(&shortfalls)
        );
        warn(py, &message)?;
    }
    Ok(())
}

/// `message` as a Python `UserWarning`.
pub fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    py.import("warnings")?.call_method1("warn", (message,))?;
    Ok(())
}
