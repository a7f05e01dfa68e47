//! One active-touch episode (beyond the paper; its Sec. VI): the arm explores an unknown object one
//! touch at a time toward a target the caller picks among the planner's candidates, and the
//! recogniser's belief follows every converged reading. `taction/ActiveTouch-v0` steps it.

use std::sync::Arc;

use pyo3::prelude::*;
use taction::active_touch::EpisodeConfig;
use taction::explore::PlannerConfig;
use taction::sim::{ObjectSpec, PerturbationBounds};
use taction::valid::Valid;

use crate::array;
use crate::error::refused;
use crate::model::Model;
use crate::object::Object;

/// An episode of `object` (one of `model`'s objects) before the arm, seeded by `seed`: K =
/// `candidates` targets offered before every touch, drawn by the planner's rule with local
/// probability `local_probability`, in a workspace fitted to `workspace` (all the objects that
/// could be there, so that it tells nothing of which one is; default: `object` alone), the object
/// perturbed after every reading within `perturb_deg` / `perturb_frac`.
#[pyclass(module = "taction", unsendable)]
pub struct TouchEpisode {
    inner: taction::active_touch::TouchEpisode,
}

#[pymethods]
impl TouchEpisode {
    #[new]
    #[pyo3(signature = (model, object, seed=1, candidates=12, local_probability=0.5, perturb_deg=0.0, perturb_frac=0.0, workspace=None))]
    #[allow(clippy::too_many_arguments)] // Python keyword arguments, each an episode parameter
    fn new(
        py: Python<'_>,
        model: &Model,
        object: &Object,
        seed: u64,
        candidates: usize,
        local_probability: f64,
        perturb_deg: f64,
        perturb_frac: f64,
        workspace: Option<Vec<PyRef<'_, Object>>>,
    ) -> PyResult<Self> {
        let spec = object.spec();
        let fitted_to: Vec<ObjectSpec> = match workspace {
            Some(objects) => objects.iter().map(|o| o.spec()).collect(),
            None => vec![spec.clone()],
        };
        let planner = PlannerConfig {
            local_probability,
            ..PlannerConfig::default()
        }
        .fitted_to(&fitted_to);
        let config = EpisodeConfig {
            planner: Valid::new(planner).map_err(refused)?,
            perturbation: PerturbationBounds::new(perturb_deg, perturb_frac).map_err(refused)?,
            candidates,
            ..EpisodeConfig::new(*model.inner.sensor())
        };
        let config = Valid::new(config).map_err(refused)?;
        let recognizer = Arc::clone(&model.inner);
        let inner = py
            .detach(|| taction::active_touch::TouchEpisode::new(recognizer, &spec, &config, seed))
            .map_err(refused)?;
        Ok(Self { inner })
    }

    /// The targets the next touch may go toward, `(K, 3)` metres (fewer rows only when the
    /// planner's draws keep failing).
    #[getter]
    fn candidates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let targets = self.inner.candidates();
        let values: Vec<f64> = targets.iter().flat_map(|t| t.to_array()).collect();
        array::from_f64(py, &values, &[targets.len(), 3], "float64")
    }

    /// The expected information gain of a touch toward each candidate, nats.
    fn gains<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let gains = self.inner.gains().map_err(refused)?;
        array::from_f64(py, &gains, &[gains.len()], "float64")
    }

    /// One planner iteration toward candidate `index`; `True` when it ended in a converged reading
    /// (the belief now includes it). New candidates are drawn either way.
    fn touch(&mut self, index: usize) -> PyResult<bool> {
        Ok(self.inner.touch(index).map_err(refused)?.is_some())
    }

    /// The last converged reading, `(rows, cols)` float32; zeros before one.
    #[getter]
    fn image<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let sensor = self.inner.model().sensor();
        let shape = [sensor.rows, sensor.cols];
        match self.inner.last_image() {
            Some(image) => array::from_f64(py, image.values(), &shape, "float32"),
            None => array::from_f64(py, &vec![0.0; sensor.rows * sensor.cols], &shape, "float32"),
        }
    }

    /// Where the pad is now: centre (m), normal, up.
    #[getter]
    fn pad_pose<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let p = self.inner.pad_pose();
        let values = [p.center_m, p.normal, p.up].map(|v| v.to_array()).concat();
        array::from_f64(py, &values, &[9], "float64")
    }

    /// P(object | readings so far), in the model's object order.
    #[getter]
    fn probabilities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let p = self.inner.belief().probabilities();
        array::from_f64(py, p, &[p.len()], "float64")
    }

    /// Converged touches so far.
    #[getter]
    fn touches(&self) -> usize {
        self.inner.touches()
    }

    /// Reading attempts so far, converged or not.
    #[getter]
    fn attempts(&self) -> usize {
        self.inner.attempts()
    }

    /// The explored object's name (the truth).
    #[getter]
    fn object(&self) -> String {
        self.inner.object_name().to_string()
    }

    /// The explored object's index in the model's objects.
    #[getter]
    fn object_index(&self) -> usize {
        self.inner.object_index()
    }
}
