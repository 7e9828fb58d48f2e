#!/usr/bin/env python3
"""How much of issue 31's gradient line ("within 10 degrees of the true
direction for 90% of points 2-30 cm from the surface") a map can meet against
occupancy_eval.py's reference, the direction from the nearest point of the
frames' raw clouds. Same map (frames 0-1), query points (frame 2's rays) and
reference as occupancy_eval.py; prints, per band 2-30, 2-5 and 5-30 cm:

- the map's gradient (nearest disc) against the reference, and the misses by
  how far the nearest disc point lies from the nearest cloud point; the
  map's gradient against the denoised reference (surface_reference.py, validated
  on the noisy synthetic room by gradient_reference_loop.py), and the
  nearest-point reference against it;
- the reference against itself: the direction from frame 0's cloud against
  the one from frame 1's, for points both clouds put at the same distance;
- the cloud's noise (off-plane RMS of 5x5-pixel patches of frame 0) and the
  score an exact gradient gets against a nearest-point reference of a cloud
  with that noise: points sampled on the map's own discs at the clouds'
  spacing, moved along the disc normal by N(0, sigma^2), scored with the
  map's gradient (exact for that surface);
- a smoother gradient: the soft-min of the disc distances,
  d_tau = -tau log sum_i exp(-d_i / tau), whose gradient is the average of the
  discs' unit directions weighted by exp(-(d_i - d_min) / tau); with the
  median |distance error| of d_tau (the issue asks <= 1 cm).

    SOGMM_LIBRARY_PATH=build/capi/libsogmm.so PYTHONPATH=bindings/python/src \\
      python3 tools/sogmm-perf/gradient_reference_eval.py [--data /work/shared/data/rgbd/livingroom]
"""
from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

import occupancy_eval as oe
import sogmm
from surface_reference import denoised_directions

BANDS = ((0.02, 0.30), (0.02, 0.05), (0.05, 0.30))


def unit(v: np.ndarray) -> np.ndarray:
    """Rows scaled to length 1 (NaN for a zero row: a point on the cloud, in no band)."""
    with np.errstate(invalid="ignore"):
        return v / np.linalg.norm(v, axis=1, keepdims=True)


def scores(g: np.ndarray, ref: np.ndarray, dist: np.ndarray, mask=True) -> str:
    """Share within 10 degrees and median angle per band (bands by `dist`)."""
    out = []
    for lo, hi in BANDS:
        b = (dist >= lo) & (dist <= hi) & mask
        ang = np.degrees(np.arccos(np.clip(np.sum(g[b] * ref[b], axis=1), -1, 1)))
        out.append(f"{100 * lo:.0f}-{100 * hi:.0f} cm {np.mean(ang <= 10):.3f} (median {np.median(ang):.1f} deg, "
                   f"n {b.sum()})")
    return "; ".join(out)


def discs(gmm: sogmm.GMM, k: float) -> dict:
    """The components' discs as core/src/surface_discs.cpp builds them."""
    lam, vec = np.linalg.eigh(np.asarray(gmm.covariances_, dtype=np.float64)[:, :3, :3])
    return dict(mu=np.asarray(gmm.means_, dtype=np.float64)[:, :3], n=vec[:, :, 0], e2=vec[:, :, 1],
                e1=vec[:, :, 2], a=k * np.sqrt(lam[:, 2]), b=k * np.sqrt(lam[:, 1]))


def disc_offsets(d: dict, k: np.ndarray, x: np.ndarray) -> np.ndarray:
    """x minus its nearest point on disc k (row by row), as core/src/surface_discs.cpp."""
    r = x - d["mu"][k]
    e1, e2, n, a, b = d["e1"][k], d["e2"][k], d["n"][k], d["a"][k], d["b"][k]
    s, t, c = (r * e1).sum(1), (r * e2).sum(1), (r * n).sum(1)
    S, T, tau = np.abs(s), np.abs(t), np.zeros(len(x))
    for _ in range(64):  # Newton on the ellipse's secular equation, from below
        p, q = a * S / (tau + a * a), b * T / (tau + b * b)
        f = p * p + q * q - 1.0
        step = f / (2.0 * (p * p / (tau + a * a) + q * q / (tau + b * b)))
        tau = np.where(f > 1e-15, np.maximum(tau + step, tau), tau)
    inside = (s / a) ** 2 + (t / b) ** 2 <= 1.0
    ds, dt = np.where(inside, 0.0, S - a * a * S / (tau + a * a)), np.where(inside, 0.0, T - b * b * T / (tau + b * b))
    return np.copysign(ds, s)[:, None] * e1 + np.copysign(dt, t)[:, None] * e2 + c[:, None] * n


def near_pairs(d: dict, x: np.ndarray, bound: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(point, disc) pairs whose lower bound |x - mu| - a is at most `bound` of the point."""
    rows, cols = [], []
    for s0 in range(0, len(x), 512):
        lb = np.linalg.norm(x[s0:s0 + 512, None] - d["mu"][None], axis=2) - d["a"][None]
        i, k = np.nonzero(lb <= bound[s0:s0 + 512, None])
        rows.append(i + s0)
        cols.append(k)
    return np.concatenate(rows), np.concatenate(cols)


def patch_noise(depth_m: np.ndarray, cam: sogmm.Camera, rng: np.random.Generator, w: int = 5) -> float:
    """Median off-plane RMS of random w x w pixel patches (valid depth only), metres."""
    v, u = np.mgrid[0:depth_m.shape[0], 0:depth_m.shape[1]]
    xyz = np.stack([(u - cam.cx) / cam.fx * depth_m, (v - cam.cy) / cam.fy * depth_m, depth_m], -1)
    res = []
    for _ in range(4000):
        r0, c0 = rng.integers(0, depth_m.shape[0] - w), rng.integers(0, depth_m.shape[1] - w)
        z = depth_m[r0:r0 + w, c0:c0 + w]
        if (z > 0.1).all() and (z <= 3.0).all():
            p = xyz[r0:r0 + w, c0:c0 + w].reshape(-1, 3)
            p = p - p.mean(0)
            res.append(np.sqrt(max(np.linalg.eigvalsh(p.T @ p / len(p))[0], 0.0)))
    return float(np.median(res))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default=os.environ.get("SOGMM_DATA_DIR", "/work/shared/data") + "/rgbd/livingroom")
    ap.add_argument("--decimate", type=int, default=5)
    ap.add_argument("--noise", type=float, nargs="+", default=[0.0, 0.001, 0.002, 0.003], help="sigmas (m)")
    ap.add_argument("--tau", type=float, nargs="+", default=[0.002, 0.005, 0.01, 0.02], help="soft-min tau (m)")
    a = ap.parse_args()
    data = Path(a.data)
    cam = sogmm.Camera.from_json(data / "intrinsics.json")
    poses = oe.read_trajectory(data / "trajectory.log")
    m = sogmm.Map(decimate=a.decimate, seed=0)
    for i in (0, 1):
        m.insert_rgbd(*oe.frame(data, i), cam, poses[i])
    m.flush()
    depth2 = oe.frame(data, 2)[0].astype(np.float64) / 1000.0
    occ, *free = oe.world_points(depth2, cam, poses[2], a.decimate, [1.0, 0.2, 0.5, 0.8, "m5cm"])
    pts = np.concatenate([occ] + free)
    clouds = [oe.world_points(oe.frame(data, i)[0].astype(np.float64) / 1000.0, cam, poses[i], 1, [1.0])[0]
              .astype(np.float64) for i in (0, 1, 2)]
    tree = cKDTree(np.concatenate(clouds), compact_nodes=False)  # see occupancy_eval.py
    truth, nearest = tree.query(pts)
    keep = truth <= 0.5
    q, truth, near = pts[keep].astype(np.float64), truth[keep], tree.data[nearest[keep]]
    dist, grad = m.surface_distance(q, gradient=True, n_threads=2)
    ref = unit(q - near)
    print(f"map: frames 0-1, {m.n_components_} components; {len(q)} points of frame 2's rays within 0.5 m")
    print(f"map gradient vs the reference: {scores(grad, ref, truth)}; distance median |error| "
          f"{1e3 * np.median(np.abs(dist - truth)):.2f} mm")
    denoised = denoised_directions(tree, q)
    print(f"map gradient vs the denoised reference (surface_reference.py): {scores(grad, denoised, truth)}")
    print(f"nearest-point reference vs the denoised reference: {scores(ref, denoised, truth)}")
    gap = np.linalg.norm(q - grad * dist[:, None] - near, axis=1)  # nearest disc point to nearest cloud point
    for lo, hi in ((0, 0.01), (0.01, 0.02), (0.02, 0.05), (0.05, np.inf)):
        print(f"  nearest disc point {100 * lo:.0f}-{100 * hi:.0f} cm from the nearest cloud point: "
              f"{scores(grad, ref, truth, (gap >= lo) & (gap < hi))}")

    own = [cKDTree(c, compact_nodes=False).query(q) for c in clouds[:2]]
    same = np.abs(own[0][0] - own[1][0]) < 0.01
    print(f"reference vs itself (frame 0's cloud vs frame 1's, both distances within 1 cm): "
          f"{scores(unit(q - clouds[0][own[0][1]]), unit(q - clouds[1][own[1][1]]), truth, same)}")

    rng = np.random.default_rng(0)
    spacing = float(np.median(tree.query(tree.data[::997], k=2)[0][:, 1]))
    print(f"cloud noise: off-plane RMS of 5x5-pixel patches of frame 0, median "
          f"{1e3 * patch_noise(oe.frame(data, 0)[0] / 1000.0, cam, rng):.2f} mm; spacing of the 3 clouds "
          f"{1e3 * spacing:.2f} mm")
    d = discs(m.export(), float(sogmm._ffi.DEFAULTS.surface_disc_sigmas))
    count = np.maximum(1, np.round(np.pi * d["a"] * d["b"] / spacing ** 2)).astype(int)
    k = np.repeat(np.arange(len(count)), count)
    rad, ang = np.sqrt(rng.uniform(0, 1, len(k))), rng.uniform(0, 2 * np.pi, len(k))
    on_disc = d["mu"][k] + (rad * np.cos(ang) * d["a"][k])[:, None] * d["e1"][k] + \
        (rad * np.sin(ang) * d["b"][k])[:, None] * d["e2"][k]
    eps = rng.standard_normal(len(k))
    for sigma in a.noise:
        cloud = on_disc + (sigma * eps)[:, None] * d["n"][k]
        _, j = cKDTree(cloud, compact_nodes=False).query(q)
        print(f"exact gradient vs a nearest-point reference, {len(cloud)} points on the discs, noise "
              f"{1e3 * sigma:.1f} mm: {scores(grad, unit(q - cloud[j]), dist)}")

    for tau in a.tau:
        i, kk = near_pairs(d, q, dist + 8 * tau)
        off = disc_offsets(d, kk, q[i])
        di = np.linalg.norm(off, axis=1)
        w = np.exp(-(di - dist[i]) / tau)
        g = np.zeros_like(q)
        np.add.at(g, i, w[:, None] * off / np.maximum(di, 1e-300)[:, None])
        soft = dist - tau * np.log(np.bincount(i, w, minlength=len(q)))
        nearest_disc = np.full(len(q), np.inf)
        np.minimum.at(nearest_disc, i, di)  # this file's discs must be the library's
        assert np.max(np.abs(nearest_disc - dist)) < 1e-6, "numpy discs differ from the library's"
        print(f"soft-min tau {1e3 * tau:.0f} mm: {scores(unit(g), ref, truth)}; distance median |error| "
              f"{1e3 * np.median(np.abs(soft - truth)):.2f} mm")


if __name__ == "__main__":
    main()
