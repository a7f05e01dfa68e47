//! One active-touch episode (beyond the paper; its Sec. VI): the arm explores an unknown object one
//! touch at a time toward a target the caller picks among the planner's candidates, and the
//! recogniser's belief follows every converged reading. `taction/ActiveTouch-v1` (and `-v0`)
//! step it.

use std::sync::{Arc, Mutex, MutexGuard};

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyTuple};
use taction::active_touch::{EpisodeConfig, TouchAction};
use taction::explore::PlannerConfig;
use taction::sim::{FreeBody, ObjectSpec};
use taction::valid::Valid;

use crate::args::{self, Whole, start_pose};
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
/// perturbed after every reading within `perturb_deg` / `perturb_frac` (put there, or with
/// `perturb_by="push"` pushed there, a free object's only). `free_object=True` stands the object on
/// a free joint, a solid of `object_density` kg/m3 (1000) with sliding friction `object_friction`
/// (0.8), so the arm's presses can move it, as `taction.collect`'s does. A touch is `touch`:
/// `"guarded"` (the pad moved along a ray through the candidate until it meets a surface, then
/// settled: a reading attempt every touch, two when the first met the object and failed) or
/// `"iteration"` (one planner iteration toward it).
///
/// Its touches release the GIL; one episode is used by one thread at a time (a lock). It pickles
/// as its arguments and the touches made so far, which the unpickled episode makes again: the
/// library is deterministic for a seed, so it is the same episode, bit for bit.
#[pyclass(module = "taction")]
pub struct TouchEpisode {
    made: Made,
    inner: Mutex<taction::active_touch::TouchEpisode>,
    /// The candidate index of every touch made so far, in order (locked after `inner`).
    touched: Mutex<Vec<usize>>,
}

/// The arguments an episode was made with, as a pickle carries them.
struct Made {
    model: Py<Model>,
    object: Py<Object>,
    seed: u64,
    candidates: usize,
    local_probability: f64,
    perturb_deg: f64,
    perturb_frac: f64,
    workspace: Option<Vec<Py<Object>>>,
    start_pose: String,
    start_heading_deg: f64,
    touch: String,
    free_object: bool,
    object_density: Option<f64>,
    object_friction: Option<f64>,
    perturb_by: String,
}

impl Made {
    /// The constructor's positional arguments, in its signature's order: a tuple built item by
    /// item, since they are more than a Rust tuple converts.
    fn args<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let workspace: Option<Vec<Py<Object>>> = self
            .workspace
            .as_ref()
            .map(|w| w.iter().map(|o| o.clone_ref(py)).collect());
        let items = [
            self.model.clone_ref(py).into_bound(py).into_any(),
            self.object.clone_ref(py).into_bound(py).into_any(),
            self.seed.into_pyobject(py)?.into_any(),
            self.candidates.into_pyobject(py)?.into_any(),
            self.local_probability.into_pyobject(py)?.into_any(),
            self.perturb_deg.into_pyobject(py)?.into_any(),
            self.perturb_frac.into_pyobject(py)?.into_any(),
            workspace.into_pyobject(py)?.into_any(),
            self.start_pose.as_str().into_pyobject(py)?.into_any(),
            self.start_heading_deg.into_pyobject(py)?.into_any(),
            self.touch.as_str().into_pyobject(py)?.into_any(),
            PyBool::new(py, self.free_object).to_owned().into_any(),
            self.object_density.into_pyobject(py)?.into_any(),
            self.object_friction.into_pyobject(py)?.into_any(),
            self.perturb_by.as_str().into_pyobject(py)?.into_any(),
        ];
        PyTuple::new(py, items)
    }

    /// The episode's configuration, its arguments checked.
    fn config(&self) -> PyResult<Valid<EpisodeConfig>> {
        let start_pose = start_pose(&self.start_pose, self.start_heading_deg)?;
        let touch = TouchAction::parse(&self.touch).ok_or_else(|| {
            bad_argument(
                "touch",
                format!("'{}' is none of {}", self.touch, TouchAction::NAMES.join(", ")),
            )
        })?;
        let planner = PlannerConfig::exploring(&self.fitted_to()?, self.local_probability);
        let free_object = FreeBody::requested(self.free_object, self.object_density, self.object_friction)
            .map_err(refused)?;
        let config = EpisodeConfig {
            planner: Valid::new(planner).map_err(refused)?,
            perturbation: args::perturbation(self.perturb_deg, self.perturb_frac, &self.perturb_by)?,
            start_pose,
            candidates: self.candidates,
            touch,
            free_object,
            ..EpisodeConfig::new(*self.model.get().inner.sensor())
        };
        Valid::new(config).map_err(refused)
    }

    /// The objects the planner's box is fitted to: `workspace`, which must include the episode's
    /// object, or that object alone.
    fn fitted_to(&self) -> PyResult<Vec<ObjectSpec>> {
        let object = self.object.get();
        let Some(objects) = &self.workspace else {
            return Ok(vec![object.spec()]);
        };
        if !objects.iter().any(|o| o.get().inner.name == object.inner.name) {
            let names: Vec<&str> = objects.iter().map(|o| o.get().inner.name.as_str()).collect();
            return Err(bad_argument(
                "workspace",
                format!(
                    "{names:?} does not include the episode's object '{}'",
                    object.inner.name
                ),
            ));
        }
        Ok(objects.iter().map(|o| o.get().spec()).collect())
    }

    /// The episode, before any touch.
    fn start(&self, py: Python<'_>) -> PyResult<taction::active_touch::TouchEpisode> {
        let config = self.config()?;
        let spec = self.object.get().spec();
        let recognizer = Arc::clone(&self.model.get().inner);
        let seed = self.seed;
        py.detach(|| taction::active_touch::TouchEpisode::new(recognizer, &spec, &config, seed))
            .map_err(refused)
    }
}

impl TouchEpisode {
    fn episode(&self) -> PyResult<MutexGuard<'_, taction::active_touch::TouchEpisode>> {
        self.inner
            .lock()
            .map_err(|_| refused("the episode was poisoned by an earlier failure"))
    }

    fn touched(&self) -> PyResult<MutexGuard<'_, Vec<usize>>> {
        self.touched
            .lock()
            .map_err(|_| refused("the episode was poisoned by an earlier failure"))
    }
}

#[pymethods]
impl TouchEpisode {
    #[new]
    #[pyo3(signature = (model, object, seed=Whole(1), candidates=Whole(12), local_probability=0.5, perturb_deg=0.0, perturb_frac=0.0, workspace=None, start_pose="canonical", start_heading_deg=180.0, touch="guarded", free_object=false, object_density=None, object_friction=None, perturb_by="teleport"), text_signature = "(model, object, seed=1, candidates=12, local_probability=0.5, perturb_deg=0.0, perturb_frac=0.0, workspace=None, start_pose='canonical', start_heading_deg=180.0, touch='guarded', free_object=False, object_density=None, object_friction=None, perturb_by='teleport')")]
    #[allow(clippy::too_many_arguments)] // Python keyword arguments, each an episode parameter
    fn new(
        py: Python<'_>,
        model: Py<Model>,
        object: Py<Object>,
        seed: Whole<u64>,
        candidates: Whole<usize>,
        local_probability: f64,
        perturb_deg: f64,
        perturb_frac: f64,
        workspace: Option<Vec<Py<Object>>>,
        start_pose: &str,
        start_heading_deg: f64,
        touch: &str,
        free_object: bool,
        object_density: Option<f64>,
        object_friction: Option<f64>,
        perturb_by: &str,
    ) -> PyResult<Self> {
        let made = Made {
            model,
            object,
            seed: seed.0,
            candidates: candidates.0,
            local_probability,
            perturb_deg,
            perturb_frac,
            workspace,
            start_pose: start_pose.to_string(),
            start_heading_deg,
            touch: touch.to_string(),
            free_object,
            object_density,
            object_friction,
            perturb_by: perturb_by.to_string(),
        };
        let inner = made.start(py)?;
        Ok(Self {
            made,
            inner: Mutex::new(inner),
            touched: Mutex::new(Vec::new()),
        })
    }

    /// Pickled as its arguments, and as its state the touches made so far (`__setstate__`).
    #[allow(clippy::type_complexity)] // pickle's (callable, arguments, state)
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>, Vec<usize>)> {
        let _episode = self.episode()?;
        let touched = self.touched()?.clone();
        Ok((py.get_type::<Self>().into_any(), self.made.args(py)?, touched))
    }

    /// Makes the touches `touched` (candidate indices, in order) of a pickled episode again; only
    /// on an episode not touched yet.
    fn __setstate__(&self, py: Python<'_>, touched: Vec<Whole<usize>>) -> PyResult<()> {
        let mut episode = self.episode()?;
        let mut done = self.touched()?;
        if !done.is_empty() {
            return Err(bad_argument(
                "state",
                format!("the episode was touched {} times already", done.len()),
            ));
        }
        let episode = &mut *episode;
        for Whole(index) in touched {
            py.detach(|| episode.touch(index))
                .map_err(|e| bad_argument("state", format!("replaying touch {index}: {e}")))?;
            done.push(index);
        }
        Ok(())
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
        let touch = py.detach(move || episode.touch(index)).map_err(refused)?;
        // Only touches that succeeded are made again when unpickled (a refused index touches
        // nothing).
        self.touched()?.push(index);
        Ok(touch.is_some())
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

    /// Where the explored object lies now (the truth, as `object` is): `(7,)` float64, its
    /// position (m) and orientation quaternion (w, x, y, z); a free object's moves as the arm
    /// presses it.
    #[getter]
    fn object_pose<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pose = self
            .episode()?
            .scene()
            .object_pose()
            .ok_or_else(|| refused("the episode's scene has no object"))?;
        let q = pose.rotation;
        let values = [pose.position_m.to_array().to_vec(), vec![q.w, q.x, q.y, q.z]].concat();
        array::from_f64(py, &values, &[7], "float64")
    }

    /// The explored object's index in the model's objects.
    #[getter]
    fn object_index(&self) -> PyResult<usize> {
        Ok(self.episode()?.object_index())
    }
}
