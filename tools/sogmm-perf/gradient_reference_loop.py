#!/usr/bin/env python3
"""Validates the gradient references of issue 31 where the truth is exact:
the synthetic room of `sogmm demo --write-frame DIR --loop` with seeded
Gaussian depth noise of the livingroom's level added to its frames (default
2.78 mm, then rounded to the millimetre like the sensor's PNGs). Same protocol
as occupancy_eval.py: a map from frames 0-1 (decimation 5), the points of
frame 2's rays (its noisy depth; 20/50/80% of it and 5 cm in front), the
reference cloud the union of frames 0-2's noisy full-resolution clouds.

The truth is the gradient of the unsigned distance to the room's analytic
surfaces (walls, floor, ceiling, spheres, boxes: tools/sogmm/synthetic_room.cpp),
scored for points 2-30 cm from them whose exact foot point the frames saw
(within 1 cm of frames 0-2's noise-free clouds; a reference built from the
clouds cannot know a surface no frame saw). Prints, within 10 degrees of the
exact direction (2-30 / 2-5 / 5-30 cm):

- the nearest-noisy-point reference (occupancy_eval.py's), and the same
  without noise;
- the denoised reference (surface_reference.py), the one accepted where it
  scores >= 0.97 at 2-30 cm;
- the map built from the noisy frames: its gradient against the exact truth
  and against both references, and its distance's median |error| against the
  exact distance.

    SOGMM_LIBRARY_PATH=build/capi/libsogmm.so PYTHONPATH=bindings/python/src \\
      python3 tools/sogmm-perf/gradient_reference_loop.py --loop-dir /tmp/loop [--noise 0.00278]
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

import occupancy_eval as oe
import sogmm
from gradient_reference_eval import scores, unit
from surface_reference import denoised_directions

# The room of tools/sogmm/synthetic_room.{hpp,cpp} (y points down).
WALL, FLOOR, CEILING = 2.0, 1.0, -1.5
SPHERES = (((0.8, 0.7, 1.4), 0.3), ((-1.3, 0.6, -1.2), 0.4))
BOXES = (((1.2, 0.3, -0.7), (1.8, 1.0, 0.1)), ((-1.8, -0.4, 0.4), (-1.3, 1.0, 1.2)))


def room_distance(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unsigned distance of points inside the room to its surfaces, and its unit gradient."""
    d, g = [], []
    for axis, plane in ((0, WALL), (0, -WALL), (2, WALL), (2, -WALL), (1, FLOOR), (1, CEILING)):
        d.append(np.abs(x[:, axis] - plane))
        g.append(np.zeros_like(x))
        g[-1][:, axis] = np.sign(x[:, axis] - plane)
    for c, r in SPHERES:
        v = x - np.array(c)
        length = np.linalg.norm(v, axis=1)
        d.append(np.abs(length - r))
        g.append(v / length[:, None] * np.sign(length - r)[:, None])
    for lo, hi in BOXES:  # points outside the box: the offset from its nearest point
        lo, hi = np.array(lo), np.array(hi)
        p = x - (lo + hi) / 2
        out = np.maximum(np.abs(p) - (hi - lo) / 2, 0.0) * np.sign(p)
        length = np.linalg.norm(out, axis=1)
        d.append(length)
        g.append(out / np.maximum(length, 1e-300)[:, None])
    k = np.argmin(np.stack(d), axis=0)
    rows = np.arange(len(x))
    return np.stack(d)[k, rows], np.stack(g)[k, rows]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--loop-dir", required=True, help="frames of `sogmm demo --write-frame DIR --loop`")
    ap.add_argument("--noise", type=float, default=0.00278, help="depth noise sigma (m), livingroom's level")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--decimate", type=int, default=5)
    a = ap.parse_args()
    data = Path(a.loop_dir)
    cam = sogmm.Camera.from_json(data / "intrinsics.json")
    poses = oe.read_trajectory(data / "trajectory.log")
    rng = np.random.default_rng(a.seed)
    clean, noisy = {}, {}
    for i in (0, 1, 2):
        depth, color = oe.frame(data, i)
        z = depth.astype(np.float64)
        seen = z > 0
        z[seen] += 1000.0 * a.noise * rng.standard_normal(int(seen.sum()))
        noisy[i] = (np.where(seen, np.clip(np.round(z), 1, 65535), 0).astype(np.uint16), color)
        clean[i] = oe.world_points(depth / 1000.0, cam, poses[i], 1, [1.0])[0].astype(np.float64)
    cloud = np.concatenate([oe.world_points(noisy[i][0] / 1000.0, cam, poses[i], 1, [1.0])[0] for i in (0, 1, 2)])
    cloud = cloud.astype(np.float64)
    occ, *free = oe.world_points(noisy[2][0] / 1000.0, cam, poses[2], a.decimate, [1.0, 0.2, 0.5, 0.8, "m5cm"])
    pts = np.concatenate([occ] + free).astype(np.float64)
    truth, exact = room_distance(pts)
    keep = truth <= 0.5
    q, truth, exact = pts[keep], truth[keep], exact[keep]
    clean_tree = cKDTree(np.concatenate(list(clean.values())), compact_nodes=False)
    seen = clean_tree.query(q - truth[:, None] * exact)[0] <= 0.01
    off = room_distance(cloud[::50])[0]
    print(f"noise {1e3 * a.noise:.2f} mm (seed {a.seed}): the noisy clouds' RMS distance to the room "
          f"{1e3 * np.sqrt(np.mean(off ** 2)):.2f} mm; {len(q)} points of frame 2's rays within 0.5 m, "
          f"{seen.mean():.3f} of them with an observed exact foot point (scored)")
    tree = cKDTree(cloud, compact_nodes=False)
    nearest = unit(q - cloud[tree.query(q)[1]])
    print(f"nearest-noisy-point reference vs exact: {scores(nearest, exact, truth, seen)}")
    print(f"nearest-point reference without noise vs exact: "
          f"{scores(unit(q - clean_tree.data[clean_tree.query(q)[1]]), exact, truth, seen)}")
    denoised = denoised_directions(tree, q)
    print(f"denoised reference (k 256, 64 candidates) vs exact: {scores(denoised, exact, truth, seen)}")

    m = sogmm.Map(decimate=a.decimate, seed=0)
    for i in (0, 1):
        m.insert_rgbd(*noisy[i], cam, poses[i])
    m.flush()
    dist, grad = m.surface_distance(q, gradient=True, n_threads=2)
    print(f"map from frames 0-1 with that noise ({m.n_components_} components): distance median |error| against the "
          f"exact distance {1e3 * np.median(np.abs(dist - truth)):.2f} mm")
    print(f"  gradient vs exact: {scores(grad, exact, truth, seen)}")
    print(f"  gradient vs the nearest-noisy-point reference: {scores(grad, nearest, truth, seen)}")
    print(f"  gradient vs the denoised reference: {scores(grad, denoised, truth, seen)}")


if __name__ == "__main__":
    main()
