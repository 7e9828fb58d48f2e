#!/usr/bin/env python3
"""scikit-learn reference for the large-geometry EM property test (issue 14).

Regenerate (from the repository root; numpy 2.4.6, scikit-learn 1.9.1 as pinned in
tools/requirements-dev.txt):

    python3 tests/reference/make_em_scale_fixture.py

Writes tests/data/reference/em_large_geometry.json: for each case (a 30 m plane,
a 100 m line, a 1 km plane with 1 cm and with 5 cm noise, each under its own
seeded random rotation and offset, gray uniform in [0.2, 0.8]) the float32 points
and the best mean log-likelihood per point (GaussianMixture.score, float64) of
sklearn's GaussianMixture(covariance_type='full', K = 10, reg_covar = 1e-6,
tol = 1e-3, max_iter = 1000, init_params='k-means++', n_init = 8, random_state = 0)
fitted to exactly those float32 values. The C++ test (tests/core/test_em_properties.cpp)
fits the same points with sogmm and compares the score of the stored float32 model.

Each case also has "auto": the automatic reg_covar floors, computed here by an
independent implementation of the rule in core/include/sogmm/reg_covar.hpp
(spatial 1e-6 x 100^k, 10^k the power of ten nearest the median distance of the
points from their coordinate-wise lower median; gray 1e-6 x 100^k, 10^k the
smallest power of ten not below the gray range, less 1e-6 of it), and sklearn's best score with
those floors. sklearn adds one scalar reg_covar, so it fits the points with gray
multiplied by c = sqrt(spatial / gray) and reg_covar = spatial (the same EM in
other units); the score in the original units is that score + log c.
Everything is seeded, so re-running gives the same file.
"""
import json
import os
import warnings

import numpy as np
from sklearn.exceptions import ConvergenceWarning
from sklearn.mixture import GaussianMixture

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.normpath(os.path.join(HERE, "..", "data", "reference", "em_large_geometry.json"))
N, K, REG = 1000, 10, 1e-6


def rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q @ np.diag(np.sign(np.diag(r)))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def best_score(x, reg):
    gm = GaussianMixture(K, covariance_type="full", reg_covar=reg, tol=1e-3, max_iter=1000,
                         init_params="k-means++", n_init=8, random_state=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        gm.fit(x)
    return float(gm.score(x))


def lower_median(v):
    return np.sort(v)[(len(v) - 1) // 2]


def auto_floors(x):
    """The automatic reg_covar floors of float64 points x (N x 4)."""
    centre = np.array([lower_median(x[:, j]) for j in range(3)])
    size = lower_median(np.sqrt(((x[:, :3] - centre) ** 2).sum(axis=1)))
    k = int(np.round(np.log10(size)))
    rng = (x[:, 3].max() - x[:, 3].min()) * (1 - 1e-6)  # float rounding above a power of ten counts as it
    kg = int(np.ceil(np.log10(rng)))
    while 10.0 ** kg < rng:
        kg += 1
    while 10.0 ** (kg - 1) >= rng:
        kg -= 1
    return float(f"1e{2 * k - 6}"), float(f"1e{2 * kg - 6}")


def case(name, seed, half_u, half_v, noise):
    """Points on a box [-half_u, half_u] x [-half_v, half_v] x noise, rotated and moved."""
    rng = np.random.default_rng(seed)
    local = np.stack([rng.uniform(-half_u, half_u, N), rng.uniform(-half_v, half_v, N) if half_v > 0
                      else rng.normal(0.0, noise, N), rng.normal(0.0, noise, N)], axis=1)
    xyz = local @ rotation(rng).T + rng.uniform(-5.0, 5.0, 3)
    gray = rng.uniform(0.2, 0.8, N)
    pts = np.concatenate([xyz, gray[:, None]], axis=1).astype(np.float32)
    x = pts.astype(np.float64)
    spatial, gray_floor = auto_floors(x)
    c = np.sqrt(spatial / gray_floor)
    xs = x.copy()
    xs[:, 3] *= c
    auto = {"reg_covar_spatial": spatial, "reg_covar_gray": gray_floor,
            "sklearn_score": best_score(xs, spatial) + float(np.log(c))}
    return {"name": name, "n_components": K, "reg_covar": REG, "sklearn_score": best_score(x, REG), "auto": auto,
            "points": [[float(v) for v in p] for p in pts]}


def main():
    cases = [case("plane_30m_1cm", 1, 15.0, 15.0, 0.01), case("line_100m_1cm", 2, 50.0, 0.0, 0.01),
             case("plane_1km_1cm", 3, 500.0, 500.0, 0.01), case("plane_1km_5cm", 4, 500.0, 500.0, 0.05)]
    with open(OUT, "w") as f:
        json.dump({"generator": "tests/reference/make_em_scale_fixture.py", "cases": cases}, f)
    for c in cases:
        print(c["name"], c["sklearn_score"], c["auto"])


if __name__ == "__main__":
    main()
