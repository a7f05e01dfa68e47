//! Recognition (Sec. IV-A): a bag-of-features model trained on a dataset, and its posterior over
//! the objects' identity, updated after every touch (Eq. 15-16).

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyBytes;
use taction::active_touch::ArmTrainingRecipe;
use taction::describe::Feature;
use taction::locate::GeometryModel;
use taction::mesh::TriMesh;
use taction::recognize::{
    Belief, CodebookKind, DescriptorChoice, PseudoCount, Recognizer, TrainChoices, TrainData,
    VarianceFraction, train_recognizer,
};
use taction::tactile::TactileImage;
use taction::valid::Valid;

use crate::args::{Objects, Whole, max_heading};
use crate::array;
use crate::dataset::{Dataset, Shortfalls, arm_recipe_inputs, warn};
use crate::error::{bad_argument, refused};
use crate::object::Object;
use crate::sensor::Sensor;

/// A trained recogniser: one descriptor's model, or several fused (`"mnti+sift"`). Files are the
/// ones `taction train` writes and `taction recognize` reads.
#[pyclass(module = "taction", frozen)]
pub struct Model {
    pub inner: Arc<Recognizer>,
}

#[pymethods]
impl Model {
    /// Reads a model file (`taction train`'s JSON, or what `save` wrote).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let model = py.detach(|| Recognizer::load(&path)).map_err(refused)?;
        Ok(Self {
            inner: Arc::new(model),
        })
    }

    /// Writes the model file `taction recognize --model` reads.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.inner.save(&path)).map_err(refused)
    }

    /// A model does not change: copies are the model itself (Gymnasium copies an environment's
    /// arguments).
    fn __copy__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __deepcopy__<'py>(slf: PyRef<'py, Self>, _memo: &Bound<'py, PyAny>) -> PyRef<'py, Self> {
        slf
    }

    /// Pickled as its model file's contents (what vector environments in subprocesses need).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let bytes = self.inner.to_json().map_err(refused)?;
        let rebuild = py.get_type::<Self>().getattr("from_json")?;
        Ok((rebuild, (PyBytes::new(py, &bytes),)))
    }

    /// A model from the contents of a model file.
    #[staticmethod]
    fn from_json(bytes: &[u8]) -> PyResult<Self> {
        let model = Recognizer::from_json(bytes, "the model's bytes").map_err(refused)?;
        Ok(Self {
            inner: Arc::new(model),
        })
    }

    /// The objects it tells apart, in the order of the posterior's probabilities.
    #[getter]
    fn objects(&self) -> Vec<String> {
        self.inner.objects().to_vec()
    }

    /// The descriptor name (`mnti`, `mnti+sift`).
    #[getter]
    fn descriptor(&self) -> String {
        self.inner.choice().name()
    }

    /// Whether the model also weighs where each touch landed (trained with `objects`): its
    /// posterior's `observe` then reads a `pad_pose`.
    #[getter]
    fn contacts(&self) -> bool {
        self.inner.weighs_contacts()
    }

    /// The sensor's `(rows, cols)`: the shape of the images it recognises.
    #[getter]
    fn sensor_shape(&self) -> (usize, usize) {
        let sensor = self.inner.sensor();
        (sensor.rows, sensor.cols)
    }

    /// Each model's chosen codebook size.
    #[getter]
    fn k(&self) -> Vec<usize> {
        self.inner.chosen_ks()
    }

    /// The posterior's calibration (`recognize::calibration`): `{"tau", "beta", "floor",
    /// "confidence_map"}`, the map a list of `[confidence, accuracy]` points or `None` (fitted only
    /// when the model was calibrated on the arm's explorations). 1, 1, 0 and no map is the paper's
    /// Eq. 15.
    #[getter]
    fn calibration(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let t = self.inner.tempering();
        let map = t.confidence_map().map(|map| map.points().collect::<Vec<_>>());
        let calibration = serde_json::json!({
            "tau": t.tau(),
            "beta": t.beta(),
            "floor": t.floor(),
            "confidence_map": map,
        });
        array::json_to_python(py, &calibration)
    }

    /// The same model recognising with the posterior `rule`: "calibrated" (the default) or
    /// "eq15" (the paper's Eq. 15-16, readings as independent evidence).
    fn with_posterior(&self, rule: &str) -> PyResult<Self> {
        let rule = taction::recognize::PosteriorRule::parse(rule).map_err(refused)?;
        Ok(Self {
            inner: Arc::new(Recognizer::clone(&self.inner).with_posterior(rule)),
        })
    }

    /// A fresh posterior: uniform over the objects until it observes a reading.
    fn posterior(&self) -> PyResult<Posterior> {
        let _ = self.inner.posterior().map_err(refused)?;
        Ok(Posterior::of(self.inner.clone()))
    }

    /// Recognition accuracy on `dataset` in trials of `readings` consecutive converged readings per
    /// object, as `taction recognize` scores it: `{"accuracy": [after 1, ..., after readings],
    /// "trials": n}`.
    #[pyo3(signature = (dataset, readings=Whole(30)), text_signature = "($self, dataset, readings=30)")]
    fn evaluate(&self, py: Python<'_>, dataset: &Dataset, readings: Whole<usize>) -> PyResult<Py<PyAny>> {
        let Whole(readings) = readings;
        let range = taction::recognize::ReadingRange::new(1, readings).map_err(refused)?;
        let (evaluation, trials) = py
            .detach(|| self.inner.evaluate(&dataset.inner, range))
            .map_err(refused)?;
        let accuracy: Vec<Option<f64>> = (1..=readings).map(|n| evaluation.accuracy_at(n)).collect();
        let result = serde_json::json!({ "accuracy": accuracy, "trials": trials });
        array::json_to_python(py, &result)
    }

    fn __repr__(&self) -> String {
        format!(
            "Model({}{}, k={:?}, objects={:?})",
            self.inner.choice().name(),
            if self.contacts() { " with contacts" } else { "" },
            self.inner.chosen_ks(),
            self.inner.objects()
        )
    }
}

/// The probability over the model's objects after the readings observed so far (Eq. 15-16).
#[pyclass(module = "taction")]
pub struct Posterior {
    model: Arc<Recognizer>,
    /// Every observed reading, in order.
    observed: Vec<Observed>,
    /// The belief after them; `None` before any (uniform).
    belief: Option<Belief>,
}

/// One reading a posterior observed.
struct Observed {
    /// The image, with its pad pose when given.
    image: TactileImage,
    /// The pad pose's numbers as given (a pickle carries them: the pose normalises its vectors).
    pad_pose: Option<Vec<f64>>,
    /// Its features under each of the model's descriptors.
    features: Vec<Vec<Feature>>,
}

impl Posterior {
    /// Uniform over `model`'s objects.
    fn of(model: Arc<Recognizer>) -> Self {
        Self {
            model,
            observed: Vec::new(),
            belief: None,
        }
    }

    /// Adds one reading: the image's `shape` and `values`, and the pad pose's numbers if given.
    fn add(&mut self, shape: Vec<usize>, values: Vec<f64>, pad_pose: Option<Vec<f64>>) -> PyResult<()> {
        let sensor = self.model.sensor();
        if shape[..] != [sensor.rows, sensor.cols] {
            return Err(bad_argument(
                "image",
                format!(
                    "want the model's {}x{} taxels, got an array of shape {shape:?}",
                    sensor.rows, sensor.cols
                ),
            ));
        }
        let mut image =
            TactileImage::new(sensor.rows, sensor.cols, values).map_err(|e| bad_argument("image", e))?;
        if let Some(pose) = &pad_pose {
            image = image.with_pose(crate::sensor::pad_pose_of(pose)?);
        }
        // The posterior borrows the model, so it is rebuilt from the observed readings: adding a
        // reading's features is cheap next to describing its image, which happens once.
        let mut posterior = self.model.posterior().map_err(refused)?;
        let features = posterior.describe(&image);
        for earlier in &self.observed {
            posterior
                .observe_described(&earlier.image, earlier.features.clone())
                .map_err(refused)?;
        }
        let belief = posterior
            .observe_described(&image, features.clone())
            .map_err(|e| bad_argument("image", e))?;
        self.observed.push(Observed {
            image,
            pad_pose,
            features,
        });
        self.belief = Some(belief);
        Ok(())
    }
}

/// A pickled posterior's readings: each image `(rows, cols)` and pad pose (or `None`), float64.
type ObservedArrays<'py> = Vec<(Bound<'py, PyAny>, Option<Bound<'py, PyAny>>)>;

#[pymethods]
impl Posterior {
    /// Adds one tactile image (an array `(rows, cols)` of the model's sensor) and returns the
    /// probabilities after it. `pad_pose` (the nine numbers of a dataset's `pad_pose` row: centre
    /// in metres, normal, up) says where the touch landed: a model trained with `objects` weighs
    /// that contact too (an object that stays where it is); without it, or for a model of
    /// appearance alone, only the image counts.
    #[pyo3(signature = (image, pad_pose=None), text_signature = "($self, image, pad_pose=None)")]
    fn observe<'py>(
        &mut self,
        py: Python<'py>,
        image: &Bound<'py, PyAny>,
        pad_pose: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (shape, values) = array::to_f64(image, "image")?;
        let pad_pose = pad_pose
            .map(|p| array::to_f64(p, "pad_pose").map(|(_, v)| v))
            .transpose()?;
        self.add(shape, values, pad_pose)?;
        self.probabilities(py)
    }

    /// Pickled as its model and the readings it observed (images and pad poses as given), which
    /// the unpickled posterior observes again in order: the same probabilities, bit for bit.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (Model, ObservedArrays<'py>))> {
        let sensor = self.model.sensor();
        let observed = self
            .observed
            .iter()
            .map(|o| {
                let image = array::from_f64(py, o.image.values(), &[sensor.rows, sensor.cols], "float64")?;
                let pose = o
                    .pad_pose
                    .as_ref()
                    .map(|p| array::from_f64(py, p, &[p.len()], "float64"))
                    .transpose()?;
                Ok((image, pose))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let model = Model {
            inner: self.model.clone(),
        };
        Ok((py.get_type::<Self>().getattr("_from_state")?, (model, observed)))
    }

    /// The posterior [`__reduce__`](Self::__reduce__) pickled: `model`'s, after `observed`.
    #[staticmethod]
    fn _from_state(model: &Model, observed: ObservedArrays<'_>) -> PyResult<Self> {
        let mut posterior = Self::of(model.inner.clone());
        for (image, pad_pose) in observed {
            let (shape, values) = array::to_f64(&image, "image")?;
            let pad_pose = pad_pose
                .map(|p| array::to_f64(&p, "pad_pose").map(|(_, v)| v))
                .transpose()?;
            posterior.add(shape, values, pad_pose)?;
        }
        Ok(posterior)
    }

    /// P(object | readings so far), in the order of `Model.objects`.
    #[getter]
    fn probabilities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model.objects().len();
        let p = match &self.belief {
            Some(belief) => belief.probabilities().to_vec(),
            None => vec![1.0 / n as f64; n],
        };
        array::from_f64(py, &p, &[n], "float64")
    }

    /// The most probable object (the first of equal ones).
    #[getter]
    fn guess(&self) -> String {
        // Before any reading the posterior is uniform and the first object is the guess.
        let best = self.belief.as_ref().map_or(0, Belief::guess);
        self.model.objects()[best].clone()
    }

    /// Readings observed.
    #[getter]
    fn readings(&self) -> usize {
        self.observed.len()
    }

    #[getter]
    fn objects(&self) -> Vec<String> {
        self.model.objects().to_vec()
    }
}

/// Trains a recogniser on `dataset` as `taction train` does: `descriptor` one of `vectorize`,
/// `sift`, `mr8`, `mn`, `pf`, `mnti`, `shape-index` or several joined by `+` (fused), `codebook`
/// `knn`, `mlp` (a network over the objects), `gmm` (the paper's) or `kmeans`, by default the
/// product's for the descriptor (mlp for `shape-index` alone, knn otherwise); the codebook size chosen among `ks`
/// (default: a grid sized to the data) on `validation` (default: the last 1/11 of each object's
/// readings). `calibration`, the arm's explorations, calibrates the posterior (in trials of
/// `calibration_trial_readings`, default each object's readings as one); `objects`, the objects the
/// dataset was collected on, adds where each touch landed, weighed on `calibration` (else
/// `validation`).
#[pyfunction]
#[pyo3(signature = (dataset, descriptor="mnti", codebook=None, validation=None, ks=None, restarts=Whole(3), seed=Whole(1), variance_kept=None, pseudo_count=1.0, trial_readings=Whole(10), objects=None, calibration=None, start_heading_deg=180.0, calibration_trial_readings=None), text_signature = "(dataset, descriptor='mnti', codebook=None, validation=None, ks=None, restarts=3, seed=1, variance_kept=None, pseudo_count=1.0, trial_readings=10, objects=None, calibration=None, start_heading_deg=180.0, calibration_trial_readings=None)")]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each a training parameter
pub fn train(
    py: Python<'_>,
    dataset: &Dataset,
    descriptor: &str,
    codebook: Option<&str>,
    validation: Option<PyRef<'_, Dataset>>,
    ks: Option<Vec<Whole<usize>>>,
    restarts: Whole<usize>,
    seed: Whole<u64>,
    variance_kept: Option<f64>,
    pseudo_count: f64,
    trial_readings: Whole<usize>,
    objects: Option<Vec<PyRef<'_, Object>>>,
    calibration: Option<Vec<PyRef<'_, Dataset>>>,
    start_heading_deg: f64,
    calibration_trial_readings: Option<Whole<usize>>,
) -> PyResult<Model> {
    let descriptor = DescriptorChoice::parse(descriptor).map_err(|e| bad_argument("descriptor", e))?;
    let codebook = match codebook {
        Some(name) => CodebookKind::parse(name).map_err(|e| bad_argument("codebook", e))?,
        None => TrainChoices::default_codebook(&descriptor),
    };
    let choices = TrainChoices {
        descriptor,
        codebook,
        ks: ks.map(|ks| ks.into_iter().map(|Whole(k)| k).collect()),
        restarts: restarts.0,
        seed: seed.0,
        variance_kept: variance_kept
            .map(VarianceFraction::new)
            .transpose()
            .map_err(refused)?,
        pseudo_count: PseudoCount::new(pseudo_count).map_err(refused)?,
        trial_readings: trial_readings.0,
        calibration_trial_readings: calibration_trial_readings.map(|Whole(n)| n),
    };
    let choices = Valid::new(choices).map_err(refused)?;
    let training = dataset.inner.clone();
    let contacts = objects
        .map(|objects| contact_geometry(&objects, &training.header().objects, start_heading_deg))
        .transpose()?;
    let validation = validation.map(|v| v.inner.clone());
    let calibration = shared(calibration);
    let model = py
        .detach(|| {
            let data = TrainData {
                training: &training,
                validation: validation.as_deref(),
                calibration: &calibration.iter().map(AsRef::as_ref).collect::<Vec<_>>(),
                contacts: contacts.as_ref(),
            };
            train_recognizer(&choices, data, &mut ())
        })
        .map_err(refused)?;
    Ok(Model {
        inner: Arc::new(model),
    })
}

/// The library's datasets behind Python's (none for `None`), shared, to use without the GIL.
fn shared(datasets: Option<Vec<PyRef<'_, Dataset>>>) -> Vec<Arc<taction::dataset::Dataset>> {
    datasets
        .unwrap_or_default()
        .iter()
        .map(|d| d.inner.clone())
        .collect()
}

/// The surfaces of `names` (the training dataset's objects, in its order) picked from `objects`,
/// standing within `start_heading_deg` of their canonical heading (`taction train --objects`).
fn contact_geometry(
    objects: &[PyRef<'_, Object>],
    names: &[String],
    start_heading_deg: f64,
) -> PyResult<GeometryModel> {
    let max_heading = max_heading(start_heading_deg)?;
    let meshes: Vec<(String, &TriMesh)> = objects
        .iter()
        .map(|o| (o.inner.name.clone(), &o.inner.mesh))
        .collect();
    GeometryModel::of_named(names, &meshes, max_heading).map_err(|e| bad_argument("objects", e))
}

/// The recogniser `taction demo` trains for the arm's own touches (`ArmTrainingRecipe`): sampler
/// readings from starts the arm can reach, MNTI and SIFT fused over the neighbour codebook.
/// `training` is a dataset collected by `collect(..., reachable_by_arm=True)`; `calibration`, the
/// arm's own explorations (`collect_arm_calibration`, as the demo collects them), calibrates the
/// posterior (without it, the readings held out of `training` do, and the arm's correlated touches
/// make it overconfident; a list of datasets, each an exploration). `objects`, the objects
/// `training` was collected on, adds where each touch landed, standing within `start_heading_deg`
/// of their canonical heading, weighed on `calibration` (which it then needs), as the demo's model
/// does.
#[pyfunction]
#[pyo3(signature = (training, seed=Whole(1), calibration=None, objects=None, start_heading_deg=180.0), text_signature = "(training, seed=1, calibration=None, objects=None, start_heading_deg=180.0)")]
pub fn train_for_arm(
    py: Python<'_>,
    training: &Dataset,
    seed: Whole<u64>,
    calibration: Option<Vec<PyRef<'_, Dataset>>>,
    objects: Option<Vec<PyRef<'_, Object>>>,
    start_heading_deg: f64,
) -> PyResult<Model> {
    let Whole(seed) = seed;
    // The recipe's count is per object (it sizes the calibration explorations, which `fit` does
    // not collect): the training data's readings shared among its objects.
    let per_object = training.inner.header().objects.len().max(1);
    let recipe = ArmTrainingRecipe {
        readings_per_object: training.inner.len() / per_object,
        seed,
        start_heading: max_heading(start_heading_deg)?,
    };
    let data = training.inner.clone();
    let contacts = objects
        .map(|objects| contact_geometry(&objects, &data.header().objects, start_heading_deg))
        .transpose()?;
    let arm = shared(calibration);
    let model = py
        .detach(|| {
            let arm: Vec<&taction::dataset::Dataset> = arm.iter().map(AsRef::as_ref).collect();
            recipe.fit(&data, &arm, contacts.as_ref())
        })
        .map_err(refused)?;
    Ok(Model {
        inner: Arc::new(model),
    })
}

/// The recogniser `taction demo` trains, all of it in one call (`ArmTrainingRecipe::train`): the
/// sampler's `training_readings` converged readings per object from starts the arm can reach, the
/// arm's own explorations to calibrate the posterior (`collect_arm_calibration`'s), MNTI and SIFT
/// fused over the neighbour codebook. Collection runs on `threads` threads (0: one per core; the
/// model does not depend on it). Same objects, sensor and seed, same model as the demo's, bit for
/// bit. The model also weighs where each touch landed (the objects standing within
/// `start_heading_deg` of their canonical heading: 180 for objects, 10 for the raised letters,
/// whose heading is part of their identity). Fewer readings than asked, or a calibration that
/// gathered none (the model then weighs appearance alone), is a Python warning.
#[pyfunction]
#[pyo3(signature = (objects, training_readings=Whole(1000), seed=Whole(1), sensor=None, threads=Whole(0), object_set="python", start_heading_deg=180.0), text_signature = "(objects, training_readings=1000, seed=1, sensor=None, threads=0, object_set='python', start_heading_deg=180.0)")]
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each a recipe parameter
pub fn arm_model(
    py: Python<'_>,
    objects: Objects,
    training_readings: Whole<usize>,
    seed: Whole<u64>,
    sensor: Option<PyRef<'_, Sensor>>,
    threads: Whole<usize>,
    object_set: &str,
    start_heading_deg: f64,
) -> PyResult<Model> {
    let (recipe, sensor, specs) =
        arm_recipe_inputs(&objects, (training_readings, seed, start_heading_deg), sensor)?;
    let Whole(threads) = threads;
    let mut shortfalls = Shortfalls::default();
    let trained = py
        .detach(|| recipe.train(object_set, &specs, sensor, threads, &mut shortfalls))
        .map_err(refused)?;
    shortfalls.warn(py, "arm_model")?;
    if !trained.calibrated_on_the_arm() {
        warn(
            py,
            "taction.arm_model: the arm's calibration explorations gave no converged reading: the \
             posterior is calibrated on held-out sampler readings and overconfident on the arm's touches, \
             and the model weighs appearance alone",
        )?;
    }
    Ok(Model {
        inner: Arc::new(trained.model),
    })
}
