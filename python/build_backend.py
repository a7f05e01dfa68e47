"""The package's build backend: maturin's, after the MuJoCo runtime the Rust crate links against is
in place (`cargo xtask runtime`: the official `mujoco==3.17.0` wheel's library, checked against a
pinned sha256, in `.runtime/mujoco/lib`). A second build finds it and does no network work."""

import os
import subprocess

from maturin import *  # noqa: F401,F403 (the PEP 517 hooks maturin defines)
from maturin import build_editable as _build_editable
from maturin import build_wheel as _build_wheel


def _ensure_mujoco_runtime():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    subprocess.run(
        ["cargo", "run", "--quiet", "--package", "xtask", "--", "runtime"],
        cwd=root,
        check=True,
    )


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    _ensure_mujoco_runtime()
    return _build_wheel(wheel_directory, config_settings, metadata_directory)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    _ensure_mujoco_runtime()
    return _build_editable(wheel_directory, config_settings, metadata_directory)
