"""The sensor from Python reads what the CLI reads, bit for bit; bad input raises TactionError."""

import subprocess

import numpy as np
import pytest

import taction
from conftest import ROOT, taction_cli

# The pad 0.6 mm into the top of the 3 cm sphere (its apex at z = 6 cm): the covering is 1.2 mm.
TOUCH = [0.001, -0.002, 0.0606, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0]


def test_a_reading_equals_taction_sense_bit_for_bit(sphere_path, tmp_path):
    out = tmp_path / "sense.csv"
    taction_cli(
        "sense",
        "--mesh", str(sphere_path),
        "--pad-center", "0.001,-0.002,0.0606",
        "--pad-normal", "0,0,-1",
        "--pad-up", "0,1,0",
        "--out", str(out),
    )
    cli = np.loadtxt(out, delimiter=",", ndmin=2)
    sphere = taction.Object.from_file(sphere_path)
    sensor = taction.Sensor()
    exact = sensor.read(sphere, TOUCH, dtype="float64")
    assert exact.shape == (6, 6)
    assert exact.max() > 0.3, exact  # the apex is felt, off-centre as the pad is
    assert np.array_equal(exact, cli)
    # The default dtype is float32: the same values, rounded once.
    image = sensor.read(sphere, TOUCH)
    assert image.dtype == np.float32
    assert np.array_equal(image, cli.astype(np.float32))


def test_the_sensor_parameters_shape_the_image(sphere_path):
    sphere = taction.Object.from_file(sphere_path)
    big = taction.Sensor(rows=14, cols=10).read(sphere, TOUCH)
    assert big.shape == (14, 10)
    # Lifted clear of the covering, nothing is felt.
    lifted = list(TOUCH)
    lifted[2] += 0.01
    assert taction.Sensor().read(sphere, lifted).max() == 0.0


def test_a_rectangular_pad_reads_what_the_cli_reads(sphere_path, tmp_path):
    out = tmp_path / "sense.csv"
    taction_cli(
        "sense",
        "--mesh", str(sphere_path),
        "--pad-center", "0.001,-0.002,0.0606",
        "--pad-normal", "0,0,-1",
        "--pad-up", "0,1,0",
        "--rows", "5", "--cols", "9", "--pad-width-m", "0.018", "--pad-height-m", "0.01",
        "--out", str(out),
    )
    cli = np.loadtxt(out, delimiter=",", ndmin=2)
    sensor = taction.Sensor(rows=5, cols=9, pad_width_m=0.018, pad_height_m=0.01)
    assert repr(sensor).startswith("Sensor(rows=5, cols=9, pad_width_m=0.018, pad_height_m=0.01, thickness_m=0.001,")
    image = sensor.read(taction.Object.from_file(sphere_path), TOUCH, dtype="float64")
    assert image.shape == (5, 9) and image.max() > 0.3
    assert np.array_equal(image, cli)


# Sensors out of range, as Python keywords (each also given to the CLI as its flags, `--thickness-m`
# for `thickness_m`), with the key the refusal names. The covering at most half the pad is the
# sensor's own rule, which both edges meet through the library.
REFUSED_SENSORS = [
    ({"rows": 0}, "rows"),
    ({"cols": 300}, "cols"),
    ({"pad_m": -0.01}, "pad_width_m"),
    ({"pad_m": 2.0}, "pad_width_m"),
    ({"thickness_m": 0.0}, "thickness_m"),
    ({"thickness_m": 0.007}, "thickness_m"),
    ({"pad_m": 0.004, "thickness_m": 0.0025}, "thickness_m"),
    ({"pad_height_m": 0.0}, "pad_height_m"),
    ({"pad_width_m": 0.004, "thickness_m": 0.0025}, "thickness_m"),
    ({"psf_sigma_m": -0.001}, "psf_sigma_m"),
    ({"rays_per_taxel": 5}, "rays_per_taxel"),
    ({"noise": 2.5}, "noise_fraction"),
]
# The CLI flag that sets each key of the sensor's configuration.
FLAG_OF_KEY = {
    "rows": "--rows",
    "cols": "--cols",
    "pad_width_m": "--pad-m",
    "pad_height_m": "--pad-height-m",
    "thickness_m": "--thickness-m",
    "psf_sigma_m": "--psf-sigma-m",
    "rays_per_taxel": "--rays-per-taxel",
    "noise_fraction": "--noise",
}


@pytest.mark.parametrize(
    "bad,key", REFUSED_SENSORS, ids=[",".join(f"{k}={v}" for k, v in bad.items()) for bad, _ in REFUSED_SENSORS]
)
def test_python_refuses_every_sensor_the_cli_refuses_for_the_same_reason(sphere_path, tmp_path, bad, key):
    flags = []
    for name, value in bad.items():
        flags += ["--" + name.replace("_", "-"), str(value)]
    cli = subprocess.run(
        ["cargo", "run", "--quiet", "--package", "taction", "--", "sense", "--mesh", str(sphere_path),
         "--pad-center", "0,0,0.0606", "--pad-normal", "0,0,-1", "--out", str(tmp_path / "r.csv"), *flags],
        cwd=ROOT, capture_output=True, text=True,
    )
    assert cli.returncode == 2 and not (tmp_path / "r.csv").exists(), cli.stderr
    with pytest.raises(taction.TactionError, match=f" {key}=") as python:
        taction.Sensor(**bad)
    reason = str(python.value).split("want ", 1)[1]
    assert f"{FLAG_OF_KEY[key]}: " in cli.stderr and f"want {reason}" in cli.stderr, (str(python.value), cli.stderr)


def test_noise_is_seeded(sphere_path):
    sphere = taction.Object.from_file(sphere_path)
    a = taction.Sensor(noise=0.4, seed=3).read(sphere, TOUCH)
    b = taction.Sensor(noise=0.4, seed=3).read(sphere, TOUCH)
    c = taction.Sensor(noise=0.4, seed=4).read(sphere, TOUCH)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_a_broken_mesh_raises_an_error_naming_the_file(tmp_path):
    broken = tmp_path / "broken_cup.obj"
    broken.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(taction.TactionError, match="broken_cup.obj"):
        taction.Object.from_file(broken)
    missing = tmp_path / "nowhere.stl"
    with pytest.raises(taction.TactionError, match="nowhere.stl"):
        taction.Object.from_file(missing)


def test_out_of_range_parameters_name_the_field(sphere_path):
    with pytest.raises(taction.TactionError, match="rows"):
        taction.Sensor(rows=0)
    for bad in [dict(rows=-1), dict(seed=-1), dict(rays_per_taxel=2.5)]:
        with pytest.raises(taction.TactionError, match="whole number"):
            taction.Sensor(**bad)
    with pytest.raises(taction.TactionError, match="noise"):
        taction.Sensor(noise=-0.1)
    sphere = taction.Object.from_file(sphere_path)
    with pytest.raises(taction.TactionError, match="pad_pose"):
        taction.Sensor().read(sphere, [0, 0, 0.06, 0, 0, -1])
    with pytest.raises(taction.TactionError, match="pad_pose"):
        taction.Sensor().read(sphere, [0, 0, 0.06, 0, 0, -1, 0, 0, -1])


def test_a_reading_comes_as_floats_only(sphere_path):
    sphere = taction.Object.from_file(sphere_path)
    pose = TOUCH
    single = taction.Sensor().read(sphere, pose)
    double = taction.Sensor().read(sphere, pose, dtype=np.float64)
    assert single.dtype == np.float32 and double.dtype == np.float64
    assert single.max() > 0.2 and np.array_equal(single, double.astype(np.float32))
    for bad in ["uint8", np.int32, "nonsense"]:
        with pytest.raises(taction.TactionError, match="dtype"):
            taction.Sensor().read(sphere, pose, dtype=bad)


def test_size_m_rescales_a_folder_and_built_in_sets_refuse_it(sphere_path):
    folder = sphere_path.parent
    (resized,) = [o for o in taction.objects(folder, size_m=0.08) if o.name == sphere_path.stem]
    assert abs(resized.size_m - 0.08) < 1e-9
    for bad in [-1.0, float("nan"), 0.0]:
        with pytest.raises(taction.TactionError, match="size_m"):
            taction.objects(folder, size_m=bad)
        with pytest.raises(taction.TactionError, match="size_m"):
            taction.Object.from_file(sphere_path, size_m=bad)
    with pytest.raises(taction.TactionError, match="size_m"):
        taction.objects("chess", size_m=0.05)
