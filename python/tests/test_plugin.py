"""Stock `mujoco` with the plugin `import taction` registers; the README's Python block as written."""

import pathlib
import re

import mujoco
import numpy as np

import taction
from conftest import ROOT


def test_stock_mujoco_compiles_and_reads_the_scene(chess):
    taction.Sensor()  # the package is imported: the plugin is registered
    mujoco.mj_loadPluginLibrary(taction.plugin_path())  # loading it again is harmless
    model = mujoco.MjModel.from_xml_string(taction.scene(chess[0]))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    sensor = model.sensor("tactile")
    assert sensor.dim[0] == 36
    image = data.sensordata[sensor.adr[0] : sensor.adr[0] + 36]
    assert np.all((image >= 0) & (image <= 1))


def python_blocks(readme):
    return re.findall(r"```python\n(.*?)```", readme.read_text(), flags=re.S)


def test_the_readme_python_block_runs_as_written(tmp_path, monkeypatch):
    blocks = [b for b in python_blocks(ROOT / "README.md") if b.startswith("import taction")]
    assert blocks, "the README has a Python block beginning with `import taction`"
    monkeypatch.chdir(tmp_path)
    for block in blocks:
        exec(compile(block, "README.md", "exec"), {})
