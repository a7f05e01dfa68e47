"""Stock `mujoco` with the plugin `import taction` registers; the README's Python block as written."""

import pathlib
import re
import subprocess
import sys

import mujoco
import numpy as np
import pytest

import taction
from conftest import ROOT


def test_stock_mujoco_reads_what_the_free_pad_reads(chess):
    """The object (a mocap body) is put under the arm's pad, its top 0.6 mm into the covering:
    stock mujoco's sensordata equals taction's free-pad reading at the same relative pose."""
    pawn = chess[0]
    sensor = taction.Sensor()
    mujoco.mj_loadPluginLibrary(taction.plugin_path())  # loading it again is harmless
    model = mujoco.MjModel.from_xml_string(taction.scene(pawn))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    site = data.site("pad")
    x_s, y_s, n = site.xmat.reshape(3, 3).T  # the site's axes: right, up, normal
    top = pawn.bounds_m[1, 2]
    depth = 0.0012 - 0.0006
    # The object's +z along -normal, +y along the pad's up: its top meets the covering.
    rotation = np.column_stack([-x_s, y_s, -n])
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, rotation.flatten())
    mocap = model.body_mocapid[model.body("object").id]
    assert mocap >= 0
    data.mocap_pos[mocap] = site.xpos + n * (top + depth)
    data.mocap_quat[mocap] = quat
    mujoco.mj_forward(model, data)
    tactile = model.sensor("tactile")
    assert tactile.dim[0] == 36
    image = data.sensordata[tactile.adr[0] : tactile.adr[0] + 36].reshape(6, 6)
    expected = sensor.read(pawn, [0, 0, top + depth, 0, 0, -1, 0, 1, 0], dtype="float64")
    assert expected.max() > 0.2
    assert np.allclose(image, expected, atol=1e-6), (image, expected)


def python_blocks(readme):
    return re.findall(r"```python\n(.*?)```", readme.read_text(), flags=re.S)


@pytest.mark.parametrize("document", ["README.md", "docs/python.md"])
def test_the_python_blocks_run_as_written(document, tmp_path, monkeypatch):
    blocks = [b for b in python_blocks(ROOT / document) if b.startswith("import taction")]
    assert blocks, f"{document} has a Python block beginning with `import taction`"
    monkeypatch.chdir(tmp_path)
    for block in blocks:
        exec(compile(block, document, "exec"), {})


# The README's "In MuJoCo" block, then `import taction`, or the other way round: one process, two
# copies of the plugin's code (the plugin library and the package's module).
BOTH_ORDERS = """
import sys
import mujoco
first = sys.argv[1]
if first == "package":
    import taction
mujoco.mj_loadPluginLibrary("target/release/libtaction_covering.so")
if first == "library":
    import taction
m = mujoco.MjModel.from_xml_path("mjcf/scene.xml")
d = mujoco.MjData(m)
mujoco.mj_resetDataKeyframe(m, d, m.key("touch").id)
mujoco.mj_forward(m, d)
adr = m.sensor("tactile").adr[0]
print(max(d.sensordata[adr:adr + 36]))
"""


@pytest.mark.parametrize("first", ["library", "package"])
def test_the_plugin_library_and_the_package_share_one_process(first):
    """MuJoCo ends the process when a second plugin of one name registers: the copy that comes
    second must leave the first's registration alone, and the sensor must still read."""
    assert (ROOT / "target/release/libtaction_covering.so").exists(), "cargo xtask setup builds it"
    done = subprocess.run(
        [sys.executable, "-c", BOTH_ORDERS, first], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr + done.stdout
    assert float(done.stdout.strip()) > 0.2
