#!/usr/bin/env python3
"""The depth-quantisation floor judged on held-out pixels (issue 29, item 1).

For each shared frame (livingroom 00000, tum), decimation and seed, fits the
frame with the floor (the library's default for frames) and without it
(dequantise_depth=False), and prints per seed: components, EM iterations,
converged, training mean log-likelihood and two held-out mean
log-likelihoods: on the held-out points as the sensor reported them, and on
the same points with each depth spread uniformly over its quantisation bin
(seeded; x and y move along the pixel's ray). The sensor's depth levels are
the frame's distinct depths (livingroom: 191 levels, 4 mm apart at 1 m); a
bin runs between the midpoints to the neighbouring levels. The first figure
is the likelihood of the quantised readings, which a model with spikes on the
levels also scores well on; the second is that of the surface the readings
stand for.

Held-out pixels: the pixels of the decimation d + 1 grid that are not on the
fitting grid d (pixel (u, v) is on grid g when g divides u and v). They are
found by the library's own back-projection: the fitting grid's pixels are
given depth 0 (no reading) and the frame is back-projected at d + 1, so the
held-out points are exactly what sogmm_rgbd_to_points returns there.

Usage: dequantise_heldout.py [--seeds 10] [--decimate 2 5] [--bandwidth 0.02]
                             [--max-iter 100] [--tol 1e-3]
Needs the Python package on PYTHONPATH and SOGMM_LIBRARY_PATH (as ctest sets
them), Pillow, and ../shared/data/rgbd next to the checkout (else it skips).
"""
import argparse
import json
import os
import statistics
import sys

import numpy as np


def load(folder, depth_name, color_name):
    from PIL import Image
    depth = np.asarray(Image.open(os.path.join(folder, depth_name)))
    color = np.asarray(Image.open(os.path.join(folder, color_name)).convert("RGB"))
    with open(os.path.join(folder, "intrinsics.json")) as f:
        j = json.load(f)
    k = j["intrinsic_matrix"]  # column-major
    return depth, color, (j["width"], j["height"], k[0], k[4], k[6], k[7])


def held_out_points(sogmm, depth, color, cam, d, depth_scale):
    masked = depth.copy()
    masked[::d, ::d] = 0  # the fitting grid: no reading there
    return sogmm.rgbd_to_points(masked, color, cam, depth_scale=depth_scale, decimate=d + 1)


def spread_within_bins(points, depth, depth_scale, seed=0):
    """The points with each depth moved uniformly within its quantisation bin."""
    levels = np.unique(depth[depth > 0]).astype(np.float64) / depth_scale
    mids = (levels[1:] + levels[:-1]) / 2
    lo = np.concatenate([[levels[0] - (mids[0] - levels[0])], mids])
    hi = np.concatenate([mids, [levels[-1] + (levels[-1] - mids[-1])]])
    z = points[:, 2].astype(np.float64)
    i = np.clip(np.searchsorted(levels, z), 0, len(levels) - 1)
    i = np.where((i > 0) & (np.abs(levels[i - 1] - z) < np.abs(levels[i] - z)), i - 1, i)
    znew = np.random.default_rng(seed).uniform(lo[i], hi[i])
    out = points.astype(np.float64).copy()
    out[:, :3] *= (znew / z)[:, None]
    return out.astype(np.float32)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))
    ap.add_argument("--data", default=os.path.join(os.path.dirname(root), "shared", "data", "rgbd"))
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--decimate", type=int, nargs="+", default=[2, 5])
    ap.add_argument("--bandwidth", type=float, default=0.02)
    ap.add_argument("--max-iter", type=int, default=100)
    ap.add_argument("--tol", type=float, default=1e-3)
    ap.add_argument("--threads", type=int, default=0)
    a = ap.parse_args()
    if not os.path.isdir(a.data):
        print("SKIP: %s is absent (the shared RGB-D frames)" % a.data)
        return 0
    import sogmm
    frames = [("livingroom 00000", os.path.join(a.data, "livingroom"), "depth/00000.png", "color/00000.jpg", 1000.0),
              ("tum", os.path.join(a.data, "tum"), "depth.png", "color.png", 5000.0)]
    failures = []
    for name, folder, dn, cn, scale in frames:
        depth, color, c = load(folder, dn, cn)
        cam = sogmm.Camera(*c)
        for d in a.decimate:
            held = held_out_points(sogmm, depth, color, cam, d, scale)
            spread = spread_within_bins(held, depth, scale)
            rows = {}
            for floor in (True, False):
                rows[floor] = []
                for seed in range(a.seeds):
                    est = sogmm.SOGMM(bandwidth=a.bandwidth, seed=seed, max_iter=a.max_iter, tol=a.tol,
                                      n_threads=a.threads, dequantise_depth=floor)
                    est.fit_rgbd(depth, color, cam, depth_scale=scale, decimate=d)
                    rows[floor].append((est.n_components_, est.n_iter_, est.converged_, est.lower_bound_,
                                        float(np.mean(est.score_samples(held))),
                                        float(np.mean(est.score_samples(spread)))))
            print(f"\n{name}, d = {d}, bandwidth {a.bandwidth}, max_iter {a.max_iter}, tol {a.tol}: "
                  f"{len(held)} held-out points")
            print("| floor | seed | M | iterations | converged | train LL | held-out LL | held-out LL, spread in bins |")
            print("|---|---|---|---|---|---|---|---|")
            for floor in (True, False):
                for seed, r in enumerate(rows[floor]):
                    print(f"| {'on' if floor else 'off'} | {seed} | {r[0]} | {r[1]} | {r[2]} | {r[3]:.4f} | {r[4]:.4f} "
                          f"| {r[5]:.4f} |")
            for floor in (True, False):
                rr = rows[floor]
                print(f"floor {'on ' if floor else 'off'}: {sum(r[2] for r in rr)}/{len(rr)} converged, "
                      f"mean iterations {statistics.mean(r[1] for r in rr):.1f}, "
                      f"mean train LL {statistics.mean(r[3] for r in rr):.4f}, "
                      f"mean held-out LL {statistics.mean(r[4] for r in rr):.4f}, "
                      f"spread in bins {statistics.mean(r[5] for r in rr):.4f}", flush=True)
            for col, what in ((4, "held-out LL"), (5, "held-out LL spread in bins")):
                on = statistics.mean(r[col] for r in rows[True])
                off = statistics.mean(r[col] for r in rows[False])
                if on < off:
                    failures.append(f"{name} d = {d}: {what} with the floor {on:.4f} < without {off:.4f}")
            if d == 2 and sum(r[2] for r in rows[True]) < 0.9 * a.seeds:
                failures.append(f"{name} d = 2: fewer than 9 in 10 seeds converge with the floor")
    print("\n" + ("\n".join("NOT MET: " + f for f in failures) if failures else "all criteria met"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
