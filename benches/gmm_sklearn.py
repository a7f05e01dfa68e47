"""scikit-learn's GaussianMixture timed on the data of `benches/recognize.rs`, side by side with ours.

Run from the repository root, after the Rust benchmark (which writes the features, our fits'
iterations and log-likelihoods, and criterion's timings under target/):

    cargo bench --bench recognize
    target/parity-venv/bin/python benches/gmm_sklearn.py [--threads N] [--repeats R]

`target/parity-venv` is the throwaway venv (numpy + scikit-learn) that
`cargo test --test recognize_parity` creates; by hand:
`python3 -m venv target/parity-venv && target/parity-venv/bin/pip install numpy scikit-learn`.

Data: target/bench-data/gmm_features.csv, 10 objects x 1000 readings x 20 dimensions, written by the
benchmark from its fixed seed. Settings, as in `taction::recognize::pipeline::GmmConfig` and the benchmark:
full covariances, reg_covar 1e-6, responsibilities initialised from one k-means run (k-means++
seeding, at most 300 Lloyd iterations, tolerance 1e-4; scikit-learn's `init_params="kmeans"`,
which is KMeans(n_init=1)), k = 10, 20, 50, 100, 200, 400, and two stopping rules:
  gmm_fit_10x1000x20          exactly 100 EM iterations (tol=0): the same work on both sides;
  gmm_fit_10x1000x20_tol1e-3  the default: stop when the mean log-likelihood changes by < 1e-3,
                              at most 100 iterations.
The k-means seeds differ (numpy's RandomState vs our ChaCha streams), so the two fits reach nearby,
not identical, optima; each side repeats one fixed seed, so every repeat does identical work.

Threads: ours uses rayon (all cores unless RAYON_NUM_THREADS is set when the benchmark runs);
scikit-learn uses numpy's BLAS threads, limited here by --threads (threadpoolctl). For a like-for-
like single-thread comparison: `RAYON_NUM_THREADS=1 cargo bench --bench recognize -- gmm_fit` and
`--threads 1` here.

Prints, per group and k: our time (criterion's mean estimate), scikit-learn's (mean of the
repeats), the ratio ours/sklearn, iterations and final mean log-likelihood of each; then the
per-touch posterior update time of the benchmark and touches per second.
"""

import argparse
import glob
import json
import os
import sys
import time
import warnings

import numpy as np
from sklearn.exceptions import ConvergenceWarning
from sklearn.mixture import GaussianMixture
from threadpoolctl import threadpool_limits

GROUPS = {"gmm_fit_10x1000x20": 0.0, "gmm_fit_10x1000x20_tol1e-3": 1e-3}
KS = (10, 20, 50, 100, 200, 400)
MAX_ITER = 100


def criterion_seconds(target, *parts):
    """criterion's mean estimate for one benchmark, seconds (None when it has not been run)."""
    path = os.path.join(target, "criterion", *parts, "new", "estimates.json")
    try:
        with open(path) as f:
            return json.load(f)["mean"]["point_estimate"] * 1e-9
    except (OSError, KeyError, ValueError):
        return None


def sklearn_fit(x, k, tol, repeats):
    times = []
    for _ in range(repeats):
        g = GaussianMixture(n_components=k, covariance_type="full", tol=tol, reg_covar=1e-6,
                            max_iter=MAX_ITER, init_params="kmeans", random_state=0)
        start = time.perf_counter()
        g.fit(x)
        times.append(time.perf_counter() - start)
    return float(np.mean(times)), float(np.min(times)), g.n_iter_, g.converged_, float(g.score(x))


def fmt(v, spec):
    return "-" if v is None else format(v, spec)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--target", default="target", help="cargo's target folder [target]")
    parser.add_argument("--threads", type=int, default=None,
                        help="BLAS/OpenMP threads for scikit-learn [library default]")
    parser.add_argument("--repeats", type=int, default=3, help="fits per k [3]")
    args = parser.parse_args()

    data = os.path.join(args.target, "bench-data", "gmm_features.csv")
    if not os.path.exists(data):
        sys.exit(f"{data} is missing: run `cargo bench --bench recognize -- gmm_fit` first")
    x = np.loadtxt(data, delimiter=",")
    try:
        with open(os.path.join(args.target, "bench-data", "gmm_taction.json")) as f:
            ours = json.load(f)
    except OSError:
        ours = {}
    warnings.filterwarnings("ignore", category=ConvergenceWarning)

    print(f"data {x.shape[0]}x{x.shape[1]}; taction threads {ours.get('threads', '?')}, "
          f"scikit-learn threads {args.threads or 'default'}, {args.repeats} repeats")
    print(f"{'group':<28} {'k':>3} {'taction s':>10} {'sklearn s':>10} {'ratio':>6} "
          f"{'iter t/s':>9} {'mean log-lik taction':>21} {'sklearn':>10}")
    with threadpool_limits(limits=args.threads):
        for group, tol in GROUPS.items():
            for k in KS:
                t_ours = criterion_seconds(args.target, group, "k", str(k))
                fit = ours.get(group, {}).get(str(k), {})
                mean, _, n_iter, _, ll = sklearn_fit(x, k, tol, args.repeats)
                ratio = None if t_ours is None else t_ours / mean
                iters = f"{fit.get('iterations', '-')}/{n_iter}"
                print(f"{group:<28} {k:>3} {fmt(t_ours, '10.3f')} {mean:>10.3f} "
                      f"{fmt(ratio, '6.2f')} {iters:>9} "
                      f"{fmt(fit.get('mean_log_likelihood'), '21.4f')} {ll:>10.4f}")

    for path in sorted(glob.glob(os.path.join(args.target, "criterion", "per_touch", "*"))):
        name = os.path.basename(path)
        if name == "report":
            continue
        t = criterion_seconds(args.target, "per_touch", name)
        if t is not None:
            print(f"per_touch/{name}: {t * 1e6:.1f} us per touch, {1.0 / t:,.0f} touches/s")


if __name__ == "__main__":
    main()
