//! One active-touch episode (beyond the paper; its Sec. VI): the arm explores an unknown object one
//! touch at a time toward a target the caller picks among the planner's candidates, and the
//! recogniser's belief follows every converged reading. `taction/ActiveTouch-v1` (and `-v0`)
//! step it.

use std::sync::{Arc, Mutex, MutexGuard};

use pyo3::prelude::*;
use taction::active_touch::{EpisodeConfig, TouchAction};
use taction::explore::PlannerConfig;
use taction::sim::{MaxHeading, ObjectSpec, PerturbationBounds, StartPose};
use taction::valid::Valid;

use crate::args::Whole;
use crate::array;
use crate::error::{bad_argument, refused};
use crate::model::Model;
use crate::object::Object;

/// An episode of `object` (one of `model`'s objects) before the arm, seeded by `seed`: K =
/// `candidates` targets offered before every touch, drawn by the planner's rule with local
/// probability `local_probability`, in a workspace fitted to `workspace` (all the objects that
/// could be there, so that it tells nothing of which one is; default: `object` alone), the object
/// starting at `start_pose` (`"canonical"`, where it was built, or `"random"`, a pose drawn from
/// the seed that the planner is not told, turned at most `start_heading_deg` about the vertical:
/// 180 for any heading, 10 for the raised letters, whose heading is part of their identity) and
/// perturbed after every reading within `perturb_deg` / `perturb_frac`. A touch is `touch`:
/// `"guarded"` (the pad moved along a ray through the candidate until it meets a surface, then
/// settled: a reading attempt every touch, two when the first met the object and failed) or
/// `"iteration"` (one planner iteration toward it).
///
/// Its touches release the GIL; one episode is used by one thread at a time (a lock).
#[pyclass(module = "taction")]
pub struct TouchEpisode {
    inner: Mutex<taction::active_touch::TouchEpisode>,
}

impl TouchEpisode {
    fn episode(&self) -> PyResult<MutexGuard<'_, taction::active_touch::TouchEpisode>> {
        self.inner
            .lock()
            .map_err(|_| refused("the episode was poisoned by an earlier failure"))
    }
}

#[pymethods]
impl TouchEpisode {
    #[new]
    #[pyo3(signature = (model, object, seed=Whole(1), candidates=Whole(12), local_probability=0.5, perturb_deg=0.0, perturb_frac=0.0, workspace=None, start_pose="canonical", start_heading_deg=180.0, touch="guarded"), text_signature = "(model, object, seed=1, candidates=12, local_probability=0.5, perturb_deg=0.0, perturb_frac=0.0, workspace=None, start_pose='canonical', start_heading_deg=180.0, touch='guarded')")]
    #[allow(clippy::too_many_arguments)] // Python keyword arguments, each an episode parameter
    fn new(
        py: Python<'_>,
        model: &Model,
        object: &Object,
        seed: Whole<u64>,
        candidates: Whole<usize>,
        local_probability: f64,
        perturb_deg: f64,
        perturb_frac: f64,
        workspace: Option<Vec<PyRef<'_, Object>>>,
        start_pose: &str,
        start_heading_deg: f64,
        touch: &str,
    ) -> PyResult<Self> {
        let (Whole(seed), Whole(candidates)) = (seed, candidates);
        let heading = MaxHeading::from_deg(start_heading_deg).ok_or_else(|| {
            bad_argument(
                "start_heading_deg",
                format!("{start_heading_deg} is outside [0, 180]"),
            )
        })?;
        let start_pose = StartPose::parse(start_pose, heading).ok_or_else(|| {
            bad_argument(
                "start_pose",
                format!("'{start_pose}' is none of {}", StartPose::NAMES.join(", ")),
            )
        })?;
        let touch = TouchAction::parse(touch).ok_or_else(|| {
            bad_argument(
                "touch",
                format!("'{touch}' is none of {}", TouchAction::NAMES.join(", ")),
            )
        })?;
        let spec = object.spec();
        let fitted_to: Vec<ObjectSpec> = match workspace {
            Some(objects) => {
                // The planner's box is fitted to these objects; the episode's must be among them.
                if !objects.iter().any(|o| o.inner.name == object.inner.name) {
                    let names: Vec<&str> = objects.iter().map(|o| o.inner.name.as_str()).collect();
                    return Err(bad_argument(
                        "workspace",
                        format!(
                            "{names:?} does not include the episode's object '{}'",
                            object.inner.name
                        ),
                    ));
                }
                objects.iter().map(|o| o.spec()).collect()
            }
            None => vec![spec.clone()],
        };
        let planner = PlannerConfig::exploring(&fitted_to, local_probability);
        let config = EpisodeConfig {
            planner: Valid::new(planner).map_err(refused)?,
            perturbation: PerturbationBounds::new(perturb_deg, perturb_frac).map_err(refused)?,
            start_pose,
            candidates,
            touch,
            ..EpisodeConfig::new(*model.inner.sensor())
        };
        let config = Valid::new(config).map_err(refused)?;
        let recognizer = Arc::clone(&model.inner);
        let inner = py
            .detach(|| taction::active_touch::TouchEpisode::new(recognizer, &spec, &config, seed))
            .map_err(refused)?;
        Ok(Self {
            inner: Mutex::new(inner),
        })
    }

    /// The box every candidate target of an episode among `objects` lies in, metres: `[[min x, y,
    /// z], [max x, y, z]]`.
    #[staticmethod]
    fn workspace_m<'py>(py: Python<'py>, objects: Vec<PyRef<'py, Object>>) -> PyResult<Bound<'py, PyAny>> {
        let specs: Vec<ObjectSpec> = objects.iter().map(|o| o.spec()).collect();
        let planner = PlannerConfig::exploring(&specs, 0.5);
        let values = [
            planner.workspace_min_m.to_array(),
            planner.workspace_max_m.to_array(),
        ]
        .concat();
        array::from_f64(py, &values, &[2, 3], "float64")
    }

    /// The targets the next touch may go toward, `(K, 3)` metres (fewer rows only when the
    /// planner's draws keep failing).
    #[getter]
    fn candidates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let episode = self.episode()?;
        let targets = episode.candidates();
        let values: Vec<f64> = targets.iter().flat_map(|t| t.to_array()).collect();
        array::from_f64(py, &values, &[targets.len(), 3], "float64")
    }

    /// The expected information gain of a touch toward each candidate, nats: what a touch there
    /// would teach times the chance it touches at all.
    fn gains<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mut episode = self.episode()?;
        let episode = &mut *episode;
        let gains = py.detach(move || episode.gains()).map_err(refused)?;
        array::from_f64(py, &gains, &[gains.len()], "float64")
    }

    /// One touch toward candidate `index` (guarded, or one planner iteration, as the episode was
    /// made); `True` when it ended in a converged reading (the belief now includes it). New
    /// candidates are drawn either way.
    fn touch(&self, py: Python<'_>, index: Whole<usize>) -> PyResult<bool> {
        let Whole(index) = index;
        let mut episode = self.episode()?;
        let episode = &mut *episode;
        Ok(py
            .detach(move || episode.touch(index))
            .map_err(refused)?
            .is_some())
    }

    /// The last converged reading, `(rows, cols)` float32; zeros before one.
    #[getter]
    fn image<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let episode = self.episode()?;
        let sensor = episode.model().sensor();
        let shape = [sensor.rows, sensor.cols];
        match episode.last_image() {
            Some(image) => array::from_f64(py, image.values(), &shape, "float32"),
            None => array::from_f64(py, &vec![0.0; sensor.rows * sensor.cols], &shape, "float32"),
        }
    }

    /// Where the pad is now: centre (m), normal, up.
    #[getter]
    fn pad_pose<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let p = self.episode()?.pad_pose();
        let values = [p.center_m, p.normal, p.up].map(|v| v.to_array()).concat();
        array::from_f64(py, &values, &[9], "float64")
    }

    /// Where the last converged touch met the surface: `(6,)` float64, the contact point (m) and
    /// the outward surface normal; zeros before one.
    #[getter]
    fn contact<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let values = match self.episode()?.last_contact() {
            Some(c) => [c.point_m.to_array(), c.normal.to_array()].concat(),
            None => vec![0.0; 6],
        };
        array::from_f64(py, &values, &[6], "float64")
    }

    /// How the last touch's reading attempt ended, in the dataset's vocabulary (`"converged"`,
    /// `"no_contact"`, `"collision"`, `"unreachable"`, ...); `None` before any attempt (and after
    /// a planner iteration that met nothing, which makes none).
    #[getter]
    fn last_status(&self) -> PyResult<Option<&'static str>> {
        Ok(self.episode()?.last_attempt().map(|r| r.status.name()))
    }

    /// What ended the last attempt short of convergence, where its status does not say alone
    /// (`"arm_on_table"`, `"covering_on_table"`, ...); `None` otherwise.
    #[getter]
    fn last_cause(&self) -> PyResult<Option<&'static str>> {
        Ok(self
            .episode()?
            .last_attempt()
            .and_then(|r| r.cause.as_ref().map(|c| c.name())))
    }

    /// P(object | readings so far), in the model's object order.
    #[getter]
    fn probabilities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let episode = self.episode()?;
        let p = episode.belief().probabilities();
        array::from_f64(py, p, &[p.len()], "float64")
    }

    /// Converged readings so far (the belief includes each).
    #[getter]
    fn readings(&self) -> PyResult<usize> {
        Ok(self.episode()?.touches())
    }

    /// Reading attempts so far, converged or not.
    #[getter]
    fn attempts(&self) -> PyResult<usize> {
        Ok(self.episode()?.attempts())
    }

    /// The explored object's name (the truth).
    #[getter]
    fn object(&self) -> PyResult<String> {
        Ok(self.episode()?.object_name().to_string())
    }

    /// The explored object's index in the model's objects.
    #[getter]
    fn object_index(&self) -> PyResult<usize> {
        Ok(self.episode()?.object_index())
    }
}
