#!/usr/bin/env python3
"""Reference values for the core GoogleTest suite (tests/core), from scikit-learn / NumPy.

Regenerate (from the repository root; needs numpy and scikit-learn, tested with
numpy 2.4.6, scikit-learn 1.9.1):

    python3 tests/reference/make_core_fixtures.py

It rewrites the JSON files in tests/data/reference/ (the C++ tests read them at
test time and never need Python). Everything is seeded, so re-running gives the
same files. Fixtures:

  em_sklearn_*.json   4-D points (float32 values), seed indices, and the result of
                      sklearn.mixture.GaussianMixture(covariance_type='full',
                      tol=1e-3, reg_covar=1e-6, max_iter=100) started from
                      one-hot responsibilities on the seed points, passed through
                      sklearn's own GaussianMixture._initialize (what
                      init_params='k-means++' does after choosing the seeds).
  meanshift_sklearn_*.json  2-D points and sklearn.cluster.MeanShift(bin_seeding=True,
                      min_bin_freq=1, cluster_all=True).cluster_centers_ (order as
                      sklearn returns them), plus the number of points within the
                      bandwidth of each centre (computed here with NumPy).
"""
import json
import os
import sys

import numpy as np
import sklearn
from sklearn.cluster import MeanShift
from sklearn.mixture import GaussianMixture

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.normpath(os.path.join(HERE, "..", "data", "reference"))

TOL, REG, MAX_ITER = 1e-3, 1e-6, 100


def f32(a):
    """Round to float32 and back: the C++ side sees exactly these values."""
    return np.asarray(a, dtype=np.float32).astype(np.float64)


def random_spd(rng, scales):
    q, _ = np.linalg.qr(rng.normal(size=(4, 4)))
    return q @ np.diag(np.asarray(scales) ** 2) @ q.T


def mixture_points(rng, means, covs, counts):
    pts = [rng.multivariate_normal(m, c, size=n) for m, c, n in zip(means, covs, counts)]
    x = np.concatenate(pts)
    rng.shuffle(x)
    return f32(x)


def run_sklearn_em(x, seeds):
    """GaussianMixture started exactly as init_params='k-means++' starts it once
    the seeds are chosen: one-hot responsibilities on the seed points passed
    through sklearn's own _initialize (means = seed points, covariances =
    reg_covar I, weights (1 + 10 eps) / N each, i.e. equal but not normalised
    until the first M-step; only the first lower bound sees that)."""
    k = len(seeds)
    resp = np.zeros((len(x), k))
    resp[seeds, np.arange(k)] = 1.0
    gm = GaussianMixture(n_components=k, covariance_type="full", tol=TOL, reg_covar=REG,
                         max_iter=MAX_ITER, random_state=0)
    gm._initialize_parameters = lambda X, random_state, xp=None: gm._initialize(X, resp, xp=xp)
    gm.fit(x)
    return gm


def em_fixture(name, x, seeds, note):
    gm = run_sklearn_em(x, seeds)
    # Robustness of the fixture: the same fit on data perturbed at float32
    # resolution must agree far inside the C++ test tolerances (1e-3 rel, 1e-4 LL).
    rng = np.random.default_rng(1)
    xp = x * (1.0 + rng.uniform(-6e-8, 6e-8, size=x.shape))
    gp = run_sklearn_em(xp, seeds)
    dw = np.max(np.abs(gp.weights_ - gm.weights_) / gm.weights_)
    dm = np.max(np.abs(gp.means_ - gm.means_))
    dc = np.max(np.abs(gp.covariances_ - gm.covariances_))
    dl = abs(gp.lower_bound_ - gm.lower_bound_)
    lbs = list(gm.lower_bounds_)
    changes = np.diff(lbs)
    print(f"{name}: N={len(x)} K={len(seeds)} n_iter={gm.n_iter_} converged={gm.converged_} "
          f"LL={gm.lower_bound_:.6f} last |change|={abs(changes[-1]) if len(changes) else float('nan'):.3e}; "
          f"perturbation: dw={dw:.1e} dmean={dm:.1e} dcov={dc:.1e} dLL={dl:.1e}")
    assert gp.n_iter_ == gm.n_iter_, "fixture too sensitive: iteration count changes"
    # The stopping decision must not be borderline: last |change| well below tol
    # and the one before well above, so float32 rounding cannot change n_iter.
    assert abs(changes[-1]) < 0.8 * TOL and (len(changes) < 2 or abs(changes[-2]) > 1.2 * TOL), \
        f"borderline stopping decision: changes {changes[-3:]}"
    assert dw < 1e-5 and dl < 1e-6, "fixture too sensitive"
    doc = {
        "generator": "tests/reference/make_core_fixtures.py",
        "sklearn_version": sklearn.__version__,
        "numpy_version": np.__version__,
        "note": note,
        "options": {"tol": TOL, "reg_covar": REG, "max_iter": MAX_ITER},
        # shortest float32 decimal: parses back to exactly the same float32
        "points": [[float(str(v)) for v in row] for row in x.astype(np.float32)],
        "seed_indices": [int(s) for s in seeds],
        "weights": gm.weights_.tolist(),
        "means": gm.means_.tolist(),
        "covariances": gm.covariances_.tolist(),
        "lower_bound": float(gm.lower_bound_),
        "lower_bounds": [float(v) for v in lbs],
        "n_iter": int(gm.n_iter_),
        "converged": bool(gm.converged_),
    }
    with open(os.path.join(OUT, name + ".json"), "w") as f:
        json.dump(doc, f, separators=(",", ":"))
        f.write("\n")


def sklearn_bin_seeds_count(x, h):
    # sklearn falls back to all points as seeds when every point has its own
    # bin; the fixtures must avoid that case.
    bins = {tuple(b) for b in np.round(x / h)}
    return len(bins)


def meanshift_fixture(name, x, h, note, anchor="zero"):
    if anchor == "zero":
        assert sklearn_bin_seeds_count(x, h) < len(x)
        ms = MeanShift(bandwidth=h, bin_seeding=True, min_bin_freq=1, cluster_all=True)
    else:
        # The authors' grid (anchored at the per-axis data minimum), fed to
        # sklearn's mean-shift engine as explicit seeds.
        lo = x.min(axis=0)
        cells = np.unique(np.floor((x - lo) / h + 0.5), axis=0)
        seeds = lo + cells * h
        ms = MeanShift(bandwidth=h, seeds=seeds, cluster_all=True)
    ms.fit(x)
    c = ms.cluster_centers_
    d = np.linalg.norm(x[None, :, :] - c[:, None, :], axis=2)
    strengths = (d <= h).sum(axis=1)
    # Distance between distinct kept centres: must be clear of h for a robust test.
    dc = np.linalg.norm(c[None] - c[:, None], axis=2) + np.eye(len(c)) * 1e9
    print(f"{name}: N={len(x)} h={h} anchor={anchor} K={len(c)} strengths={strengths.tolist()} "
          f"min centre gap/h={dc.min() / h:.3f}")
    doc = {
        "generator": "tests/reference/make_core_fixtures.py",
        "sklearn_version": sklearn.__version__,
        "note": note,
        "anchor": anchor,
        "bandwidth": h,
        "points": x.tolist(),
        "centers": c.tolist(),
        "strengths": strengths.tolist(),
    }
    with open(os.path.join(OUT, name + ".json"), "w") as f:
        json.dump(doc, f)
        f.write("\n")


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = np.random.default_rng(20230401)

    # --- EM A: 4 well-separated components, one seed in each cluster.
    means = np.array([[0.0, 0.0, 1.0, 0.2], [0.8, 0.1, 1.5, 0.7],
                      [-0.5, 0.6, 2.0, 0.4], [0.3, -0.7, 2.5, 0.9]])
    covs = [random_spd(rng, s) for s in ([0.08, 0.05, 0.04, 0.03], [0.1, 0.06, 0.05, 0.02],
                                          [0.07, 0.07, 0.03, 0.05], [0.09, 0.04, 0.04, 0.04])]
    counts = [260, 200, 180, 160]
    x = mixture_points(rng, means, covs, counts)
    # one seed per true cluster: the point nearest to each true mean
    seeds = [int(np.argmin(np.linalg.norm(x - m, axis=1))) for m in means]
    em_fixture("em_sklearn_separated", x, seeds,
               "4 separated 4-D Gaussians (800 points), one seed point per cluster")

    # --- EM B: overlapping mixture, K = 6 random seeds (several per cluster): more iterations.
    means = np.array([[0.0, 0.0, 1.0, 0.3], [0.25, 0.1, 1.2, 0.6], [-0.2, 0.3, 1.1, 0.5]])
    covs = [random_spd(rng, s) for s in ([0.1, 0.07, 0.05, 0.1], [0.08, 0.08, 0.06, 0.08],
                                          [0.12, 0.05, 0.05, 0.06])]
    x = mixture_points(rng, means, covs, [400, 300, 300])
    seeds = [348, 366, 399, 735, 779, 881]  # fixed: gives a clear-cut stopping decision
    em_fixture("em_sklearn_overlap", x, seeds,
               "3 overlapping 4-D Gaussians (1000 points), 6 random seed points")

    # --- Mean shift: blobs plus uniform background in 2-D (range, gray)-like scale.
    blobs = [([1.0, 0.2], 0.05, 120), ([1.3, 0.6], 0.08, 100), ([2.1, 0.4], 0.06, 90),
             ([1.7, 0.9], 0.04, 60)]
    pts = [rng.normal(c, s, size=(n, 2)) for c, s, n in blobs]
    pts.append(rng.uniform([0.8, 0.0], [2.4, 1.0], size=(80, 2)))
    x = np.concatenate(pts)
    rng.shuffle(x)
    meanshift_fixture("meanshift_sklearn_zero", x, 0.1,
                      "4 blobs + uniform background (450 points); sklearn's grid (anchored at 0)")
    meanshift_fixture("meanshift_sklearn_datamin", x, 0.1,
                      "same points; authors' grid (anchored at data min) given to sklearn as seeds",
                      anchor="datamin")
    x2 = rng.normal([0.5, 0.5], [0.3, 0.2], size=(300, 2))
    meanshift_fixture("meanshift_sklearn_gauss_small_h", x2, 0.07,
                      "one broad 2-D Gaussian (300 points), small bandwidth: many modes")


if __name__ == "__main__":
    sys.exit(main())
