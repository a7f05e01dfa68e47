"""Shared inputs of the Python package's tests: small real meshes, a small real dataset and model
(the library's own sampler and trainer, on two chess pieces), and the CLI of the same checkout."""

import math
import pathlib
import subprocess

import numpy as np
import pytest

import taction

ROOT = pathlib.Path(__file__).resolve().parents[2]


def write_sphere_obj(path, radius_m=0.03, rings=24, segments=48):
    """A UV sphere resting on z = 0, faces outward, as an OBJ in metres."""
    centre_z = radius_m
    vertices = [(0.0, 0.0, centre_z + radius_m)]
    for i in range(1, rings):
        theta = math.pi * i / rings
        for j in range(segments):
            phi = 2 * math.pi * j / segments
            vertices.append(
                (
                    radius_m * math.sin(theta) * math.cos(phi),
                    radius_m * math.sin(theta) * math.sin(phi),
                    centre_z + radius_m * math.cos(theta),
                )
            )
    vertices.append((0.0, 0.0, centre_z - radius_m))
    faces = []
    ring = lambda i, j: 2 + (i - 1) * segments + (j % segments)  # 1-based OBJ index
    for j in range(segments):
        faces.append((1, ring(1, j), ring(1, j + 1)))
    for i in range(1, rings - 1):
        for j in range(segments):
            a, b = ring(i, j), ring(i, j + 1)
            c, d = ring(i + 1, j), ring(i + 1, j + 1)
            faces.append((a, c, d))
            faces.append((a, d, b))
    bottom = len(vertices)
    for j in range(segments):
        faces.append((bottom, ring(rings - 1, j + 1), ring(rings - 1, j)))
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in vertices]
    lines += [f"f {a} {b} {c}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")
    return path


def taction_cli(*args):
    """Runs the CLI of this checkout (`cargo run -- ARGS`: the build the test suite already made); returns its stdout."""
    done = subprocess.run(
        ["cargo", "run", "--quiet", "--package", "taction", "--", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.fixture(scope="session")
def sphere_path(tmp_path_factory):
    return write_sphere_obj(tmp_path_factory.mktemp("mesh") / "sphere.obj")


@pytest.fixture(scope="session")
def chess():
    pieces = {o.name: o for o in taction.objects("chess")}
    return [pieces["pawn"], pieces["rook"]]


@pytest.fixture(scope="session")
def small_dataset(chess):
    return taction.collect(chess, mode="sampler", readings=40, seed=5)


@pytest.fixture(scope="session")
def small_model(small_dataset):
    return taction.train(small_dataset, descriptor="mnti", codebook="knn", ks=[5], restarts=1, seed=2)


@pytest.fixture
def rng():
    return np.random.default_rng(0)
