"""Reference results from scikit-learn for taction's recognition parity test (tests/recognize_parity.rs).

Usage: python sklearn_parity.py DIR

DIR holds, written by the Rust test:
  features_*.csv   raw features, one per line (comma-separated)
  task.json        {"pca": [{"file", "variance_kept"}], "gmm": [{"file", "variance_kept", "k",
                    "rust_parameters": {"weights", "means", "covariances"}, "rust_reduced": file}]}
Prints one JSON object with, per task, scikit-learn's explained variance (ratios and the number of
components PCA(n_components=variance_kept) keeps), the mean log-likelihood of its own
GaussianMixture fit, and its evaluation of the Rust mixture on the Rust-reduced data.
"""

import json
import sys

import numpy as np
from sklearn.decomposition import PCA
from sklearn.mixture import GaussianMixture


def load(path):
    return np.loadtxt(path, delimiter=",", ndmin=2)


def pca_report(x, variance_kept):
    full = PCA(svd_solver="full").fit(x)
    ratio = full.explained_variance_ratio_
    # The fewest components whose cumulative ratio reaches the fraction (taction's rule; sklearn's
    # own float n_components asks for strictly more).
    kept = int(np.searchsorted(np.cumsum(ratio), variance_kept, side="left") + 1)
    return {
        "explained_variance": full.explained_variance_.tolist(),
        "explained_variance_ratio": ratio.tolist(),
        "components_kept": min(kept, len(ratio)),
    }, PCA(n_components=min(kept, len(ratio)), svd_solver="full").fit(x)


def rust_mixture_score(params, x):
    k = len(params["weights"])
    d = len(params["means"][0])
    g = GaussianMixture(n_components=k, covariance_type="full")
    g.weights_ = np.array(params["weights"])
    g.means_ = np.array(params["means"])
    g.covariances_ = np.array(params["covariances"]).reshape(k, d, d)
    g.precisions_cholesky_ = np.array(
        [np.linalg.inv(np.linalg.cholesky(c)).T for c in g.covariances_]
    )
    return float(g.score(x))


def main():
    root = sys.argv[1]
    with open(f"{root}/task.json") as f:
        task = json.load(f)
    out = {"pca": [], "gmm": []}
    for t in task["pca"]:
        report, _ = pca_report(load(f"{root}/{t['file']}"), t["variance_kept"])
        out["pca"].append(report)
    for t in task["gmm"]:
        x = load(f"{root}/{t['file']}")
        report, pca = pca_report(x, t["variance_kept"])
        reduced = pca.transform(x)
        fits = [
            GaussianMixture(n_components=t["k"], covariance_type="full", random_state=seed).fit(reduced)
            for seed in range(3)
        ]
        report["sklearn_mean_log_likelihood"] = max(float(g.score(reduced)) for g in fits)
        report["rust_model_mean_log_likelihood"] = rust_mixture_score(
            t["rust_parameters"], load(f"{root}/{t['rust_reduced']}")
        )
        out["gmm"].append(report)
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
