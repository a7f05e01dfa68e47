"""Times scikit-learn's GaussianMixture on the features benches/recognize.rs exports, with the same
settings as the Rust benchmark: full covariances, k-means initialisation, reg_covar 1e-6, exactly
100 EM iterations (tol=0), for k = 10, 20, 50.

Usage: python bench_sklearn_gmm.py target/bench-data/gmm_features.csv [repeats]
Prints one line per k: the median and minimum wall time of `fit` over the repeats.
"""

import sys
import time
import warnings

import numpy as np
from sklearn.exceptions import ConvergenceWarning
from sklearn.mixture import GaussianMixture

warnings.filterwarnings("ignore", category=ConvergenceWarning)


def main():
    x = np.loadtxt(sys.argv[1], delimiter=",")
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    for k in (10, 20, 50):
        times = []
        for r in range(repeats):
            g = GaussianMixture(n_components=k, covariance_type="full", max_iter=100, tol=0.0,
                                reg_covar=1e-6, random_state=r)
            t = time.perf_counter()
            g.fit(x)
            times.append(time.perf_counter() - t)
            assert g.n_iter_ == 100
        print(f"sklearn gmm_fit_10x1000x20 k={k}: median {np.median(times):.3f} s, min {min(times):.3f} s "
              f"({repeats} fits, {x.shape[0]}x{x.shape[1]})")


if __name__ == "__main__":
    main()
