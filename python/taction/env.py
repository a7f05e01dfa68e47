"""``taction/ActiveTouch-v1`` and ``-v0``: learn where to touch to recognise an unknown object.

Each episode places one object of a set (drawn from the episode's seed; with ``start_pose="random"``
at a pose drawn from it too, turned at most ``start_heading_deg`` about the vertical, 10 for the
raised letters; optionally perturbed after every reading) before the arm. The agent does not see
the object; after every action it sees the last tactile image, where the pad is, how many touches
it has made, the recogniser's belief over the objects, and the K targets the exploration planner
(Sec. III-A of the paper) offers for the next touch. An action either touches toward one of those
targets (one planner iteration: the arm moves toward it and, if the sensor meets the surface, the
controllers of Algorithm 1 settle it and the reading updates the belief) or declares which object
it is, which ends the episode. A right declaration pays ``right_reward``, a wrong one
``wrong_reward``, every touch costs ``touch_cost``; the episode is truncated after ``budget``
touches.

The recogniser is ``model`` (a ``taction.Model`` or a model file), or by default the one
``taction demo`` trains for the arm's touches (``taction.arm_model``: ``training_readings``
sampler readings per object from starts the arm can reach, its posterior calibrated on the arm's
own explorations), trained once per process and set.

``taction/ActiveTouch-v1`` (``GuardedTouchEnv``) makes every touch action a guarded touch: the arm
moves the pad along a ray through the chosen candidate until its covering meets a surface, and the
controllers settle it there, so nearly every action yields a reading; every episode starts the
object at a random pose; the observation adds where the last touch met the surface (``contact``);
the default budget is 30 touches. ``taction/ActiveTouch-v0`` (``ActiveTouchEnv``) is kept as it
was: an action is one planner iteration toward the candidate, and most meet nothing.
"""

from __future__ import annotations

import os
from typing import Any, Optional, Sequence, Union

import gymnasium
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

import taction

#: How far the pad's centre can be from the world origin, metres: the arm (mjcf/arm.xml) has its
#: shoulder 0.30 m above a base at x = -0.35 m and reaches 0.69 m from it, so at most 1.04 m.
PAD_REACH_M = 1.5

#: The raised letters' start headings stay within this many degrees of upright: b/q, d/p, n/u and
#: M/W are one another turned half a circle.
LETTERS_HEADING_DEG = 10.0

#: Models trained by default, per (set, readings, seed): one training per process serves every
#: environment of a vector env.
_DEFAULT_MODELS: dict[tuple[str, int, int, float], taction.Model] = {}


def _objects_of(objects: Union[str, os.PathLike[str], Sequence[taction.Object]]) -> list[taction.Object]:
    if isinstance(objects, (str, os.PathLike)):
        return taction.objects(objects)
    return list(objects)


def _is_integer(value: Any) -> bool:
    """A Python or numpy integer; not a bool, which Python counts as one."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def default_model(
    objects: Union[str, Sequence[taction.Object]],
    training_readings: int = 1000,
    seed: int = 1,
    start_heading_deg: float = 180.0,
) -> taction.Model:
    """The recogniser ``taction demo`` trains for the arm (``taction.arm_model``: the library's
    recipe, collection, calibration on the arm's own explorations of objects standing within
    ``start_heading_deg`` of upright, and fit, appearance with where each touch landed) on
    ``objects`` (a set name or a list of objects); trained once per process for a set name."""
    key = (objects, training_readings, seed, start_heading_deg) if isinstance(objects, str) else None
    if key is not None and key in _DEFAULT_MODELS:
        return _DEFAULT_MODELS[key]
    model = taction.arm_model(
        _objects_of(objects),
        training_readings=training_readings,
        seed=seed,
        start_heading_deg=start_heading_deg,
    )
    if key is not None:
        _DEFAULT_MODELS[key] = model
    return model


class ActiveTouchEnv(gymnasium.Env):
    """Active tactile recognition as a Gymnasium environment (see the module docs).

    Observation (a Dict):
      - ``image``: Box(0, 1, (rows, cols), float32), the last converged reading (zeros before one);
      - ``pad_pose``: Box((9,), float32), the pad's centre (m), normal and up now;
      - ``touches``: Discrete(budget + 1), touch actions made (converged or not);
      - ``belief``: Box(0, 1, (objects,), float32), P(object | readings so far);
      - ``candidates``: Box((K, 3), float32), the targets the next touch may go toward (m).
    Action: Discrete(K + objects): ``a < K`` touches toward candidate ``a``; ``a >= K`` declares
    object ``a - K`` (``env.unwrapped.objects`` names them).
    ``info`` holds ``converged`` (whether the touch gave a reading), ``reading`` (how the touch's
    reading attempt ended, in the dataset's vocabulary: ``"converged"``, ``"no_contact"``,
    ``"collision"``, ...; ``None`` for a declaration, or a planner iteration that made no attempt),
    ``cause`` (what ended it short, ``"arm_on_table"``, ...; else ``None``), ``attempts``,
    ``readings`` (the converged ones, which the belief includes) and, when the episode ends,
    ``object`` (the truth), ``object_pose`` (where it lies then: position, m, and quaternion w, x,
    y, z) and ``declared``.

    ``free_object=True`` stands the object on a free joint (a solid of ``object_density`` kg/m3,
    1000 by default, with sliding friction ``object_friction``, 0.8), so the arm's presses can
    slide, turn or tip it; ``perturb_by="push"`` (a free object's only) pushes it toward each
    perturbation's draw instead of putting it there. The default is the paper's object, which
    stays where it is put.
    """

    metadata = {"render_modes": []}
    #: Whether the observation carries ``contact`` (``taction/ActiveTouch-v1``).
    _contact_in_observation = False

    def __init__(
        self,
        objects: Union[str, Sequence["taction.Object"]] = "chess",
        model: Union[None, str, os.PathLike, "taction.Model"] = None,
        budget: int = 100,
        candidates: int = 12,
        local_probability: float = 0.5,
        perturb_deg: float = 0.0,
        perturb_frac: float = 0.0,
        start_pose: str = "canonical",
        start_heading_deg: float = 180.0,
        touch_cost: float = 0.01,
        right_reward: float = 1.0,
        wrong_reward: float = -1.0,
        training_readings: int = 1000,
        training_seed: int = 1,
        touch: str = "iteration",
        free_object: bool = False,
        object_density: Optional[float] = None,
        object_friction: Optional[float] = None,
        perturb_by: str = "teleport",
    ) -> None:
        if budget < 1:
            raise taction.TactionError(f"budget: {budget} is not 1 or more")
        if candidates < 1:
            raise taction.TactionError(f"candidates: {candidates} is not 1 or more")
        self._objects = _objects_of(objects)
        names = [o.name for o in self._objects]
        if not names:
            raise taction.TactionError("objects: the set is empty")
        repeated = sorted({name for name in names if names.count(name) > 1})
        if repeated:
            raise taction.TactionError(f"objects: {repeated} more than once")
        if isinstance(model, (str, os.PathLike)):
            model = taction.Model.load(model)
        elif model is None:
            model = default_model(objects if isinstance(objects, str) else self._objects,
                                  training_readings, training_seed, start_heading_deg)
        elif not isinstance(model, taction.Model):
            raise taction.TactionError(
                f"model: {model!r} is neither a taction.Model, a model file nor None (the default recogniser)"
            )
        self.model = model
        by_name = {o.name: o for o in self._objects}
        unknown = [name for name in model.objects if name not in by_name]
        if unknown:
            raise taction.TactionError(f"model: knows objects not in the set: {unknown}")
        # An episode draws its object from the set, and the agent declares among the model's
        # objects: a model that does not know some of the set would quietly shrink the task.
        untrained = [name for name in names if name not in model.objects]
        if untrained:
            raise taction.TactionError(
                f"model: was not trained on {untrained} of the set (it knows {list(model.objects)})"
            )
        self.objects = list(model.objects)
        self._episode_objects = [by_name[name] for name in self.objects]
        self.budget = budget
        self.k = candidates
        self._settings: dict[str, Any] = dict(
            candidates=candidates,
            local_probability=local_probability,
            perturb_deg=perturb_deg,
            perturb_frac=perturb_frac,
            start_pose=start_pose,
            start_heading_deg=start_heading_deg,
            touch=touch,
            free_object=free_object,
            object_density=object_density,
            object_friction=object_friction,
            perturb_by=perturb_by,
        )
        self.touch_cost = touch_cost
        self.right_reward = right_reward
        self.wrong_reward = wrong_reward
        rows, cols = model.sensor_shape
        reach = np.array([PAD_REACH_M] * 3 + [1.0] * 6, dtype=np.float32)
        workspace = taction.TouchEpisode.workspace_m(self._episode_objects).astype(np.float32)
        observed = {
            "image": spaces.Box(0.0, 1.0, (rows, cols), np.float32),
            "pad_pose": spaces.Box(-reach, reach, (9,), np.float32),
            "touches": spaces.Discrete(budget + 1),
            "belief": spaces.Box(0.0, 1.0, (len(self.objects),), np.float32),
            "candidates": spaces.Box(
                np.tile(workspace[0], (candidates, 1)),
                np.tile(workspace[1], (candidates, 1)),
                (candidates, 3),
                np.float32,
            ),
        }
        if self._contact_in_observation:
            observed["contact"] = spaces.Box(-reach[:6], reach[:6], (6,), np.float32)
        self.observation_space = spaces.Dict(observed)
        self.action_space = spaces.Discrete(candidates + len(self.objects))
        self._episode: Optional[taction.TouchEpisode] = None
        self._touches = 0
        self._over = False

    def _current(self, what: str) -> taction.TouchEpisode:
        """The episode under way; before ``reset()``, a refusal naming ``what``."""
        if self._episode is None:
            raise taction.TactionError(f"{what}: call reset() first")
        return self._episode

    @property
    def episode(self) -> taction.TouchEpisode:
        """The episode under way. It knows the truth (``object_index``), so a policy that reads it
        cheats; it is here for tools that measure bounds: ``copy.copy(env.episode)`` replays its
        touches into an episode of its own, the same to the bit, to try a touch on
        (``examples/python/active_touch_baselines.py``'s oracle)."""
        return self._current("episode")

    # The episode's candidates, repeated in order when the planner offered fewer than K.
    def _candidates(self) -> NDArray[np.float64]:
        offered = self._current("candidates").candidates
        return offered[np.arange(self.k) % len(offered)]

    def _observation(self) -> dict[str, Any]:
        e = self._current("observation")
        observation = {
            "image": e.image.astype(np.float32),
            "pad_pose": e.pad_pose.astype(np.float32),
            "touches": self._touches,
            "belief": np.clip(e.probabilities, 0.0, 1.0).astype(np.float32),
            "candidates": self._candidates().astype(np.float32),
        }
        if self._contact_in_observation:
            observation["contact"] = e.contact.astype(np.float32)
        return observation

    def gains(self) -> NDArray[np.float64]:
        """The expected information gain (nats) of a touch toward each of the K candidates: what a
        touch there would teach times the chance it touches at all, judged from the episode's
        earlier touches; what the information-gain policy maximises (``taction.active_touch``)."""
        offered = self._current("gains").gains()
        return offered[np.arange(self.k) % len(offered)]

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        super().reset(seed=seed)
        options = options or {}
        unknown = sorted(set(options) - {"object"})
        if unknown:
            raise taction.TactionError(f"options: {unknown} unknown (the one option is 'object')")
        index = options.get("object")
        if index is None:
            index = int(self.np_random.integers(len(self.objects)))
        elif isinstance(index, str) and index in self.objects:
            index = self.objects.index(index)
        elif _is_integer(index) and 0 <= index < len(self.objects):
            index = int(index)
        else:
            raise taction.TactionError(
                f"options['object']: {index!r} is neither one of {self.objects} nor an index below "
                f"{len(self.objects)}"
            )
        episode_seed = int(self.np_random.integers(2**63 - 1))
        self._episode = taction.TouchEpisode(
            self.model,
            self._episode_objects[index],
            seed=episode_seed,
            workspace=self._episode_objects,
            **self._settings,
        )
        self._touches = 0
        self._over = False
        return self._observation(), {"attempts": 0, "readings": 0}

    def step(self, action: Any) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        if self._episode is None:
            raise taction.TactionError("step: call reset() first")
        if self._over:
            raise taction.TactionError("step: the episode has ended (declared or truncated); call reset()")
        scalar_array = isinstance(action, np.ndarray) and action.shape == () and action.dtype.kind in "iu"
        if not (_is_integer(action) or scalar_array):
            raise taction.TactionError(f"action: {action!r} is not an integer of the action space")
        action = int(action)
        actions = self.k + len(self.objects)  # the action space's n
        if not 0 <= action < actions:
            raise taction.TactionError(f"action: {action} is outside 0..{actions - 1}")
        e = self._episode
        info: dict[str, Any] = {}
        terminated = truncated = False
        if action >= self.k:
            declared = action - self.k
            right = declared == e.object_index
            reward = self.right_reward if right else self.wrong_reward
            terminated = True
            info["declared"] = self.objects[declared]
            info["converged"] = False
            info["reading"] = info["cause"] = None
        else:
            info["converged"] = e.touch(action % len(e.candidates))
            info["reading"] = e.last_status
            info["cause"] = e.last_cause
            self._touches += 1
            reward = -self.touch_cost
            truncated = self._touches >= self.budget
        info["attempts"] = e.attempts
        info["readings"] = e.readings
        if terminated or truncated:
            info["object"] = e.object
            info["object_pose"] = e.object_pose
            self._over = True
        return self._observation(), float(reward), terminated, truncated, info


class GuardedTouchEnv(ActiveTouchEnv):
    """``taction/ActiveTouch-v1``: every action a guarded touch, the object at a random pose.

    As ``ActiveTouchEnv`` (its docs list the observation, the actions and ``info``), with:
      - a touch action moves the pad along a ray through the chosen candidate, descending toward
        the workspace's vertical axis, until the covering meets a surface, where the controllers
        settle it: nearly every action yields a reading, and ``info["reading"]`` says how each
        ended;
      - every episode starts the object at a pose drawn from the episode's seed (any heading; at
        most 10 degrees off upright for the raised letters, whose heading is part of their
        identity, ``start_heading_deg=None``), which neither the agent nor the planner is told;
      - the observation adds ``contact``: Box((6,), float32), where the last converged touch met
        the surface, its point (m) and outward normal (zeros before one);
      - the default budget is 30 touches.
    """

    _contact_in_observation = True

    def __init__(
        self,
        objects: Union[str, Sequence["taction.Object"]] = "chess",
        model: Union[None, str, os.PathLike, "taction.Model"] = None,
        budget: int = 30,
        start_pose: str = "random",
        start_heading_deg: Optional[float] = None,
        touch: str = "guarded",
        **settings: Any,
    ) -> None:
        """``settings``: the other keyword arguments of ``ActiveTouchEnv``, with its defaults."""
        if start_heading_deg is None:
            start_heading_deg = LETTERS_HEADING_DEG if objects == "letters" else 180.0
        super().__init__(
            objects=objects,
            model=model,
            budget=budget,
            start_pose=start_pose,
            start_heading_deg=start_heading_deg,
            touch=touch,
            **settings,
        )
