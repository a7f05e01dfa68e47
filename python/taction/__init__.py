"""taction: a simulated robot arm that recognises objects by touch.

A Python face of the Rust library (Pezzementi et al., *Tactile Object Recognition From Appearance
Information*, IEEE T-RO 2011): objects, the covering sensor, datasets, recognisers and their
posterior, all speaking numpy; and the Gymnasium environments ``taction/ActiveTouch-v1`` (and
``-v0``), registered on import. Importing the package also registers the ``taction.covering`` sensor plugin with stock
``mujoco``, so ``mujoco.MjModel.from_xml_string(taction.scene(obj))`` compiles (unless the plugin
library ``target/release/libtaction_covering.so`` registered it first; either serves).

    import taction
    pawn = taction.objects("chess")[0]
    sensor = taction.Sensor(rows=6, cols=6)
    top_m = pawn.bounds_m[1, 2]   # the pad 0.6 mm into the pawn's top: centre, normal, up
    image = sensor.read(pawn, [0, 0, top_m + 0.0006, 0, 0, -1, 0, 1, 0])   # numpy (6, 6) float32
"""

# The MuJoCo library the extension links is the one the `mujoco` package ships (the extension's
# rpath is `$ORIGIN/../mujoco`); importing `mujoco` first loads it once for both.
# (mujoco ships no type information: the import is untyped.)
import mujoco as _mujoco  # type: ignore[import-untyped, unused-ignore]  # noqa: F401

from taction._taction import (  # noqa: F401
    Dataset,
    Model,
    Object,
    Posterior,
    Sensor,
    TactionError,
    TouchEpisode,
    __version__,
    arm_model,
    collect,
    collect_arm_calibration,
    objects,
    scene,
    train,
    train_for_arm,
)
from taction import _taction


def plugin_path() -> str:
    """The library that holds the ``taction.covering`` MuJoCo sensor plugin: this package's compiled
    module. ``import taction`` has already registered the plugin; ``mujoco.mj_loadPluginLibrary``
    on this path is harmless (the library is loaded once)."""
    return _taction.__file__


def _register_environments() -> None:
    import gymnasium

    if "taction/ActiveTouch-v0" not in gymnasium.registry:
        gymnasium.register(
            id="taction/ActiveTouch-v0",
            entry_point="taction.env:ActiveTouchEnv",
        )
    if "taction/ActiveTouch-v1" not in gymnasium.registry:
        gymnasium.register(
            id="taction/ActiveTouch-v1",
            entry_point="taction.env:GuardedTouchEnv",
        )


_register_environments()

__all__ = [
    "Dataset",
    "Model",
    "Object",
    "Posterior",
    "Sensor",
    "TactionError",
    "TouchEpisode",
    "arm_model",
    "collect",
    "collect_arm_calibration",
    "objects",
    "plugin_path",
    "scene",
    "train",
    "train_for_arm",
]
