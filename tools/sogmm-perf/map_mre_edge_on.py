#!/usr/bin/env python3
"""How much of a map's MRE excess at a frame comes from surfaces that frame sees edge-on (issue 18).

MRE (sogmm eval) is the mean distance from model samples the camera could see
(in its frustum, not more than 5 cm behind its depth) to the frame's points.
A world map also holds surfaces that other frames observed and that this
frame sees edge-on: a flat component whose plane passes near the camera. Its
samples, a millimetre thick, spread along the grazing rays over centimetres,
in front of what the pixel sees, and far from the frame's points, which hold
almost nothing of that surface. This script recomputes the MRE of the map and
of the frame's own fit with the eval's rule, once with every component and
once without the flat components (smallest standard deviation below a tenth
of the middle one) whose normal is within asin(--edge-on) of perpendicular to
the ray to their mean, and prints both.

    python3 tools/sogmm-perf/map_mre_edge_on.py --map MAP --frames 63,66,252

The own fits are made with `sogmm fit --sequence` of the one frame
(--bandwidth, --decimate as map_loop.py). Samples are drawn per component
with a fixed seed, so the figures repeat; they differ from `sogmm eval`'s by
the sampling only (a few tenths of a millimetre).
"""

import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np


def load_poses(path):
    rows = open(path).read().split("\n")
    poses = []
    for b in range(0, len(rows) - 4, 5):
        if not rows[b].strip():
            break
        poses.append(np.array([[float(x) for x in rows[b + r].split()] for r in range(1, 5)]))
    return poses


def frame_points(seq, k, d, fx, fy, cx, cy, scale):
    from PIL import Image
    names = sorted(os.listdir(os.path.join(seq, "depth")))
    depth = np.asarray(Image.open(os.path.join(seq, "depth", names[k]))).astype(float) / scale
    dd = depth[::d, ::d]
    v, u = np.nonzero(dd > 0)
    z = dd[v, u]
    pts = np.stack([(u * d - cx) * z / fx, (v * d - cy) * z / fy, z], 1)
    return dd, pts


def mre(model, world_to_camera, dd, tree, cam, rng, n, edge_on):
    mu = np.asarray(model.means_, float)
    cov = np.asarray(model.covariances_, float)
    w = np.asarray(model.weights_, float)
    counts = rng.multinomial(n, w / w.sum())
    fx, fy, cx, cy, d, zmax = cam
    h, wd = dd.shape
    dists = []
    for j in np.nonzero(counts)[0]:
        sxx = cov[j][:3, :3]
        ev, evec = np.linalg.eigh(sxx)
        rot = world_to_camera[:3, :3]
        m_cam = rot @ mu[j][:3] + world_to_camera[:3, 3]
        normal = rot @ evec[:, 0]
        flat = ev[0] < 0.01 * ev[1]  # sigma ratio below 1/10
        if edge_on > 0 and flat and abs(normal @ m_cam) / np.linalg.norm(m_cam) < edge_on:
            continue
        s = mu[j][:3] + rng.standard_normal((counts[j], 3)) @ np.linalg.cholesky(sxx).T
        c = s @ rot.T + world_to_camera[:3, 3]
        z = c[:, 2]
        ok = z > 0.1
        zs = np.where(ok, z, 1.0)
        u = np.round(fx / d * c[:, 0] / zs + cx / d).astype(int)
        v = np.round(fy / d * c[:, 1] / zs + cy / d).astype(int)
        ok &= (u >= 0) & (v >= 0) & (u < wd) & (v < h) & (z <= zmax)
        obs = np.full(len(s), np.inf)
        obs[ok] = dd[v[ok], u[ok]]
        obs[obs == 0] = np.inf
        ok &= ~(z > obs + 0.05)  # the eval's first-surface rule
        if ok.any():
            dists.append(tree.query(c[ok])[0])
    return 1000.0 * np.concatenate(dists).mean()


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--map", required=True, help="world-frame map (.sogmm) of the sequence")
    ap.add_argument("--frames", required=True, help="comma-separated frame indices")
    ap.add_argument("--sequence", default=os.path.join(tempfile.gettempdir(), "sogmm_room_loop"))
    ap.add_argument("--sogmm", default=os.path.join(root, "build", "tools", "sogmm", "sogmm"))
    ap.add_argument("--decimate", type=int, default=5)
    ap.add_argument("--bandwidth", type=float, default=0.02)
    ap.add_argument("--edge-on", type=float, default=0.1,
                    help="|cos| between a flat component's normal and the ray below which it is edge-on")
    ap.add_argument("--samples", type=int, default=200000)
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(root, "bindings", "python", "src"))
    os.environ.setdefault("SOGMM_LIBRARY_PATH", os.path.join(root, "build", "capi", "libsogmm.so.2"))
    import json

    import sogmm
    from scipy.spatial import cKDTree
    intr = json.load(open(os.path.join(a.sequence, "intrinsics.json")))
    k3 = intr["intrinsic_matrix"]  # column-major 3 x 3 (Open3D)
    fx, fy, cx, cy = k3[0], k3[4], k3[6], k3[7]
    traj = os.path.join(a.sequence, "trajectory.log")
    poses = load_poses(traj)
    the_map = sogmm.GMM.load(a.map)
    print("| frame | MRE map / own fit, mm | + mm | without edge-on flat components (|cos| < %g) | + mm |" % a.edge_on)
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="sogmm_edge_on_") as work:
        for k in [int(x) for x in a.frames.split(",")]:
            own_path = os.path.join(work, "own_%05d.sogmm" % k)
            subprocess.run([a.sogmm, "fit", "--sequence", a.sequence, "-o", own_path, "--trajectory", traj,
                            "--frames", str(k), "--decimate", str(a.decimate), "--bandwidth", str(a.bandwidth),
                            "--json"], check=True, stdout=subprocess.DEVNULL)
            own = sogmm.GMM.load(own_path)
            dd, pts = frame_points(a.sequence, k, a.decimate, fx, fy, cx, cy, 1000.0)
            tree = cKDTree(pts)
            to_cam = np.linalg.inv(poses[k])
            cam = (fx, fy, cx, cy, a.decimate, 3.0)
            r = {}
            for name, model in (("map", the_map), ("own", own)):
                for e in (0.0, a.edge_on):
                    r[name, e] = mre(model, to_cam, dd, tree, cam, np.random.default_rng(1), a.samples, e)
            print("| %d | %.2f / %.2f | %+.2f | %.2f / %.2f | %+.2f |" % (
                k, r["map", 0.0], r["own", 0.0], r["map", 0.0] - r["own", 0.0], r["map", a.edge_on],
                r["own", a.edge_on], r["map", a.edge_on] - r["own", a.edge_on]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
