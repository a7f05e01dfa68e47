"""The cost of one 6x6 reading from Python against the same reading in Rust.

Run from the repository root after the criterion benchmark, which times the Rust call
(`FreePad::read_at`, group `sensor/python_parity`):

    cargo bench --bench sensor -- python_parity
    .venv/bin/python benches/python_reading.py

The Python side is `taction.Sensor().read(pawn, pose)` on the same inputs: the paper's 6x6 sensor,
the free pad 0.6 mm into the top of the chess pawn. It prints both means and their ratio (one run,
one machine), and the cost of the array conversion alone.
"""

import json
import pathlib
import sys
import timeit

import numpy as np

import taction

ROOT = pathlib.Path(__file__).resolve().parents[1]
ESTIMATES = "sensor_python_parity/free_pad_read_at_6x6/new/estimates.json"


def rust_mean_s():
    for base in (ROOT / "target" / "criterion", ROOT / "target" / "bench-data" / "criterion"):
        path = base / ESTIMATES
        if path.exists():
            return json.loads(path.read_text())["mean"]["point_estimate"] * 1e-9
    sys.exit(f"no criterion estimate {ESTIMATES} under target/: run the benchmark first")


def python_mean_s(call, repeats=7, number=2000):
    call()
    times = sorted(timeit.repeat(call, repeat=repeats, number=number))
    return times[len(times) // 2] / number


def main():
    pawn = {o.name: o for o in taction.objects("chess")}["pawn"]
    sensor = taction.Sensor()
    pose = np.array([0.0, 0.0, pawn.bounds_m[1, 2] + 0.0006, 0, 0, -1, 0, 1, 0])
    image = sensor.read(pawn, pose)
    assert image.max() > 0, "the pad should touch the pawn"
    python = python_mean_s(lambda: sensor.read(pawn, pose))
    rust = rust_mean_s()
    print(f"Rust   FreePad::read_at       {rust * 1e6:8.1f} us (criterion mean)")
    print(f"Python taction.Sensor.read    {python * 1e6:8.1f} us (timeit, median of 7 x 2000)")
    print(f"ratio  Python / Rust          {python / rust:8.2f}x")


if __name__ == "__main__":
    main()
