"""A reference for the direction to the surface that is not dominated by the
depth noise of the clouds (issue 31's gradient line): the nearest point of a
denoised cloud.

The direction from the nearest point of a raw cloud tilts with that point's
depth noise (at the livingroom's 2.78 mm, a few millimetres of tilt over a
query 2 cm away), and the nearest of many noisy points is biased to the ones
that stick out. Here each of the `candidates` cloud points nearest to a query
is first moved onto the plane of its own `k` nearest cloud points (principal
axes, Gaussian weights of scale half the k-th distance): on a plane that
averages the noise of ~k points out. The foot point is the nearest moved
candidate; the direction is query minus foot. Edges stay where the cloud
puts them (a point is only moved along its plane's normal), rounded over
about the neighbourhood's radius (~2.5 cm at k = 256 and 2.9 mm spacing).

k = 256 spans several scan rows even at grazing incidence (at k = 64 the
nearest points are often one row, whose plane is not the surface's).
Projecting a query onto the plane at its nearest point instead (an MLS
projection) runs off the surface beyond edges and clutter: on the
livingroom 41% of such feet ended more than 1 cm from every cloud point.
Validated against the exact gradient of the synthetic room with
livingroom-level noise added: gradient_reference_loop.py.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def plane_projected(tree: cKDTree, p: np.ndarray, k: int = 256, chunk: int = 4096) -> np.ndarray:
    """The rows of p (n, 3) moved onto the weighted PCA plane of their k nearest points of `tree`."""
    cloud, out = tree.data, np.empty((len(p), 3))
    for s0 in range(0, len(p), chunk):
        x = p[s0:s0 + chunk].astype(np.float64)
        dist, nb = tree.query(x, k=k)
        w = np.exp(-(2.0 * dist / dist[:, -1:]) ** 2)
        c = np.einsum("nk,nki->ni", w, cloud[nb]) / w.sum(1, keepdims=True)
        r = cloud[nb] - c[:, None]
        normal = np.linalg.eigh(np.einsum("nk,nki,nkj->nij", w, r, r))[1][:, :, 0]
        out[s0:s0 + chunk] = x - np.einsum("ni,ni->n", x - c, normal)[:, None] * normal
    return out


def denoised_feet(tree: cKDTree, q: np.ndarray, candidates: int = 64, k: int = 256) -> np.ndarray:
    """For each query row of q (n, 3), the nearest of its `candidates` nearest cloud points after plane_projected()."""
    _, cand = tree.query(q, k=candidates)
    ids, where = np.unique(cand, return_inverse=True)
    moved = plane_projected(tree, tree.data[ids], k)[where.reshape(cand.shape)]
    best = np.argmin(np.sum((moved - q[:, None].astype(np.float64)) ** 2, axis=2), axis=1)
    return moved[np.arange(len(q)), best]


def denoised_directions(tree: cKDTree, q: np.ndarray) -> np.ndarray:
    """Unit directions from the denoised foot points to the queries (n, 3)."""
    v = q.astype(np.float64) - denoised_feet(tree, q)
    with np.errstate(invalid="ignore"):
        return v / np.linalg.norm(v, axis=1, keepdims=True)
