"""The large-array benchmark: one press per contact of a 28x50 pressure array, the product's
per-frame model against a nearest neighbour and a tuned RBF SVM on the same split.

Run from the repository root, after `cargo build --release`:

    target/parity-venv/bin/python benches/large_array.py --extra-meshes DIR [--out DIR] [...]

`target/parity-venv` is the throwaway venv (numpy + scikit-learn) of `benches/gmm_sklearn.py`:
`python3 -m venv target/parity-venv && target/parity-venv/bin/pip install numpy scikit-learn`.

What it does (every step a `taction` command a user could type):
1. the objects: the 12 shapes (`taction objects export shapes`) and every mesh of `--extra-meshes`
   (at least 10 other meshes), each at a 12 cm diagonal;
2. a simulated 28x50 array (`--rows/--cols`) at a 1.5 mm pitch (`--pitch-m`: a 75 mm x 42 mm pad)
   under a 2 mm covering, 10% noise, pressed once per contact by the training sampler (Sec. V-A3:
   area-weighted random surface points, any roll of the pad): `--train` contacts per object (seed
   `--seed`) and `--test` others (seed `--seed + 1`), so the split is by contact;
3. a few dead (always 0) and saturated (always the range's top) taxels, the same taxels in every
   frame, drawn once from `--seed`, as real arrays have them (`--dead`, `--saturated`);
4. the frames as a user with a real array keeps them, an `.npz` of `frames` and `labels`,
   imported with `taction dataset import --taxel-pitch-m`;
5. the product: `taction train --descriptor shape-index` (its default codebook, the network,
   and `--codebook knn` beside it), `taction recognize --readings 1` (every test frame alone)
   and `--readings 5` (five frames);
6. the baselines on the same standardised frames: 1-nearest-neighbour, and an RBF SVM whose C and
   gamma are chosen by 5-fold cross-validation on the training split (`--grid` sizes it).

Writes `OUT/large_array.csv` (one row per method and frame count, with the 90% Wilson interval)
and `OUT/large_array_per_object.csv` (single-frame accuracy of each method per object), and prints
both. Seeds fixed: the same command gives the same numbers.
"""

import argparse
import csv
import math
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from sklearn.model_selection import GridSearchCV, StratifiedKFold
from sklearn.neighbors import KNeighborsClassifier
from sklearn.preprocessing import StandardScaler
from sklearn.svm import SVC

ROOT = Path(__file__).resolve().parent.parent
TACTION = ROOT / "target" / "release" / "taction"


def taction(*args):
    """Runs a taction command; its standard output."""
    done = subprocess.run([str(TACTION), *map(str, args)], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"taction {' '.join(map(str, args))}: {done.stderr.strip()}")
    return done.stdout


def wilson(right, n, z=1.6449):
    """The 90% Wilson interval of right / n."""
    p = right / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


def objects_folder(out, extra):
    folder = out / "objects"
    if folder.exists():
        shutil.rmtree(folder)
    taction("objects", "export", "shapes", "--out", folder)
    (folder / "manifest.json").unlink()
    meshes = [p for p in sorted(extra.iterdir()) if p.suffix.lower() in (".obj", ".off", ".stl")]
    if len(meshes) < 10:
        sys.exit(f"--extra-meshes {extra}: {len(meshes)} meshes; the benchmark wants at least 10")
    for mesh in meshes:
        target = folder / mesh.name
        if target.exists():
            target = folder / f"extra_{mesh.name}"
        shutil.copy(mesh, target)
    return folder


def frames_of(dataset_csv, npz, defects):
    """The converged frames of a collected dataset with the array's defects, as a user's .npz."""
    export = npz.with_suffix(".export.npz")
    taction("dataset", "export", dataset_csv, "--format", "npz", "--out", export)
    data = np.load(export, allow_pickle=False)
    keep = data["status"] == "converged"
    frames = data["images"][keep].astype(np.float64)
    dead, saturated = defects
    flat = frames.reshape(len(frames), -1)
    flat[:, dead] = 0.0
    flat[:, saturated] = 1.0
    labels = data["object"][keep]
    np.savez(npz, frames=frames, labels=labels)
    return flat.copy(), labels


def imported(out, train_npz, test_npz, pitch_m):
    """The two .npz files as the datasets `taction dataset import` makes of them."""
    datasets = {}
    for name, npz in (("train", train_npz), ("test", test_npz)):
        datasets[name] = out / f"{name}_dataset.csv"
        taction("dataset", "import", npz, "--taxel-pitch-m", pitch_m, "--out", datasets[name])
    return datasets


def product(out, datasets, codebook):
    """The product's accuracy with `codebook` (None: `train`'s default): (frames, right, trials)
    at 1 and 5 frames, and per object at 1."""
    tag = codebook or "default"
    model = out / f"shape_index_{tag}.model.json"
    chosen = ["--codebook", codebook] if codebook else []
    taction("train", "--dataset", datasets["train"], "--descriptor", "shape-index", *chosen,
            "--out", model)
    rows, per_object = [], {}
    for frames in (1, 5):
        folder = out / f"recognize_{tag}_{frames}"
        taction("recognize", "--model", model, "--dataset", datasets["test"], "--readings", frames,
                "--out", folder)
        with open(folder / "accuracy.csv") as f:
            last = list(csv.DictReader(f))[-1]
        rows.append((frames, int(last["correct"]), int(last["trials"])))
        if frames == 1:
            with open(folder / "confusion.csv") as f:
                for row in csv.DictReader(f):
                    true, guess, count = confusion_cell(row)
                    right, n = per_object.get(true, (0, 0))
                    per_object[true] = (right + (count if true == guess else 0), n + count)
    return rows, per_object


def confusion_cell(row):
    """(true object, guessed object, count) of a confusion.csv row."""
    return row["object_true"], row["object_guess"], int(row["count"])


def baselines(train, test, grid, seed):
    (x_train, y_train), (x_test, y_test) = train, test
    scaler = StandardScaler().fit(x_train)
    a, b = scaler.transform(x_train), scaler.transform(x_test)
    guesses = {"1-NN pixels": KNeighborsClassifier(1).fit(a, y_train).predict(b)}
    d = a.shape[1]
    search = GridSearchCV(
        SVC(kernel="rbf"),
        {"C": grid["C"], "gamma": [g / d for g in grid["gamma_times_d"]]},
        cv=StratifiedKFold(5, shuffle=True, random_state=seed),
        n_jobs=-1,
    ).fit(a, y_train)
    best = search.best_params_
    name = f"RBF SVM pixels (C={best['C']:g}, gamma={best['gamma'] * d:g}/d)"
    guesses[name] = search.predict(b)
    return guesses


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--extra-meshes", type=Path, required=True,
                        help="a folder of at least 10 OBJ/OFF/STL meshes besides the 12 shapes")
    parser.add_argument("--out", type=Path, default=ROOT / "target" / "large-array")
    parser.add_argument("--rows", type=int, default=28)
    parser.add_argument("--cols", type=int, default=50)
    parser.add_argument("--pitch-m", type=float, default=0.0015)
    parser.add_argument("--thickness-m", type=float, default=0.002)
    parser.add_argument("--noise", type=float, default=0.1)
    parser.add_argument("--train", type=int, default=200, help="training contacts per object")
    parser.add_argument("--test", type=int, default=100, help="test contacts per object")
    parser.add_argument("--dead", type=int, default=3)
    parser.add_argument("--saturated", type=int, default=2)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--grid", choices=["small", "full"], default="full",
                        help="the SVM's search: full C in {1, 10, 100, 1000} x gamma in {0.1, 0.3, 1, 3} / d")
    args = parser.parse_args()
    if not TACTION.exists():
        sys.exit(f"{TACTION}: build it first (cargo build --release)")
    args.out.mkdir(parents=True, exist_ok=True)
    started = time.time()
    objects = objects_folder(args.out, args.extra_meshes)
    sensor = ["--rows", args.rows, "--cols", args.cols, "--pad-width-m", args.pitch_m * args.cols,
              "--pad-height-m", args.pitch_m * args.rows, "--thickness-m", args.thickness_m,
              "--noise", args.noise]
    rng = np.random.default_rng(args.seed)
    chosen = rng.choice(args.rows * args.cols, args.dead + args.saturated, replace=False)
    defects = (chosen[:args.dead], chosen[args.dead:])
    split = {}
    for name, readings, seed in (("train", args.train, args.seed), ("test", args.test, args.seed + 1)):
        collected = args.out / f"{name}_collected.csv"
        taction("collect", "--objects", objects, "--object-size-m", 0.12, "--mode", "sampler",
                "--readings", readings, "--seed", seed, *sensor, "--out", collected)
        split[name] = frames_of(collected, args.out / f"{name}_frames.npz", defects)
    print(f"collected in {time.time() - started:.0f} s: {len(split['train'][1])} training and "
          f"{len(split['test'][1])} test frames of {args.rows}x{args.cols} taxels, "
          f"{len(set(split['train'][1]))} objects; dead taxels {sorted(defects[0].tolist())}, "
          f"saturated {sorted(defects[1].tolist())}", flush=True)
    datasets = imported(args.out, args.out / "train_frames.npz", args.out / "test_frames.npz",
                        args.pitch_m)
    # The product's default for the shape index (the network), and the neighbour codebook beside it.
    products = {name: product(args.out, datasets, codebook) for name, codebook in
                (("taction shape-index (default: mlp)", None), ("taction shape-index (knn)", "knn"))}
    grid = {"small": {"C": [10, 100], "gamma_times_d": [1, 3]},
            "full": {"C": [1, 10, 100, 1000], "gamma_times_d": [0.1, 0.3, 1, 3]}}[args.grid]
    guesses = baselines(split["train"], split["test"], grid, args.seed)
    y_test = split["test"][1]
    table = [(name, frames, right, n) for name, (rows, _) in products.items()
             for frames, right, n in rows]
    for name, guess in guesses.items():
        table.append((name, 1, int((guess == y_test).sum()), len(y_test)))
    with open(args.out / "large_array.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["method", "frames", "right", "trials", "accuracy", "low90", "high90"])
        for name, frames, right, n in table:
            low, high = wilson(right, n)
            w.writerow([name, frames, right, n, right / n, low, high])
            print(f"{name:<44} {frames} frame(s): {right:>5}/{n:<5} = {right / n:.3f} [{low:.3f}, {high:.3f}]")
    with open(args.out / "large_array_per_object.csv", "w", newline="") as f:
        w = csv.writer(f)
        names = [*products, *guesses]
        w.writerow(["object", *names])
        for obj in sorted(set(y_test.tolist())):
            mask = y_test == obj
            cells = [per[obj][0] / per[obj][1] for _, per in products.values()]
            cells += [float((guess[mask] == obj).mean()) for guess in guesses.values()]
            w.writerow([obj, *[f"{c:.3f}" for c in cells]])
            print(f"  {obj:<18} " + " ".join(f"{c:.2f}" for c in cells))
    print(f"wrote {args.out / 'large_array.csv'} and large_array_per_object.csv in {time.time() - started:.0f} s")


if __name__ == "__main__":
    main()
