#!/usr/bin/env python3
"""Where a map's per-pixel depth error exceeds a frame's own fit's (issue 29 item 3).

For each frame K: renders the map and K's own fit (`sogmm fit --sequence
--frames K`, written next to the map when absent) from K's pose on eval's
held-out grid (decimation d + 1 minus the d grid), compares each with the
observed depth, and splits the excess of the map's depth MAE over the own
fit's by pixel class:
  - near: a pixel within --edge-px source pixels of a nearer observed surface
    (more than 5 cm in front of this pixel's depth: beside the silhouette of
    a nearer object); far: the rest;
  - front: the render is more than 1 cm in front of the observed depth
    (a ray stopped early); behind: more than 1 cm behind; close: within 1 cm.
For the map's "front" pixels it names the component that stops the ray (the
largest weighted density at the rendered 3-D point): its sigmas, the angle
of its normal (shortest axis) to the ray, the ray's Mahalanobis distance to
its mean, and roughly the insert that created it (the first frame of the
map's CSV, --csv of `sogmm map`, whose component count exceeds its index:
components are appended per flush; a revisit refit renumbers, so this is a
hint, not a record).

Usage (repository root; SOGMM_LIBRARY_PATH=build/capi/libsogmm.so, PYTHONPATH=bindings/python/src):
    python3 tools/sogmm-perf/map_depth_diag.py --sequence L --map M [--frames 54,57,117] [--decimate 5]
        [--bandwidth 0.02] [--sogmm build/tools/sogmm/sogmm] [--edge-px 12] [--surface-sigma 0]
Prints one table row per frame and one JSON line per frame.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np
from PIL import Image

import sogmm


def read_poses(path):
    rows = [list(map(float, line.split())) for line in open(path) if line.strip()]
    return [np.array(rows[5 * i + 1: 5 * i + 5]) for i in range(len(rows) // 5)]


def read_camera(seq):
    j = json.load(open(os.path.join(seq, "intrinsics.json")))
    k = j["intrinsic_matrix"]  # column-major 3x3
    return sogmm.Camera(width=j["width"], height=j["height"], fx=k[0], fy=k[4], cx=k[6], cy=k[7])


def observed_depth(seq, k, depth_min=0.1, depth_max=3.0, scale=1000.0):
    z = np.asarray(Image.open(os.path.join(seq, "depth", "%05d.png" % k)), dtype=np.float64) / scale
    z[(z <= depth_min) | (z > depth_max)] = np.nan
    return z


def nearer_nearby(z, radius, jump=0.05):
    """Per full-resolution pixel: does a pixel within `radius` (Chebyshev) see a
    surface more than `jump` metres in front of this pixel's depth?"""
    zz = np.where(np.isnan(z), np.inf, z)
    h, w = zz.shape
    pad = np.pad(zz, radius, constant_values=np.inf)
    m = np.full_like(zz, np.inf)
    for dv in range(-radius, radius + 1):
        for du in range(-radius, radius + 1):
            m = np.minimum(m, pad[radius + dv: radius + dv + h, radius + du: radius + du + w])
    return m < zz - jump


def stopping_component(gmm, point):
    """The component of largest weighted 3-D density at `point` (world)."""
    mu, cov, w = gmm.means_[:, :3], gmm.covariances_[:, :3, :3].astype(np.float64), gmm.weights_
    d = point[None, :] - mu
    inv = np.linalg.inv(cov)
    m2 = np.einsum("ki,kij,kj->k", d, inv, d)
    logp = np.log(np.maximum(w, 1e-300)) - 0.5 * m2 - 0.5 * np.log(np.linalg.det(cov))
    return int(np.argmax(logp)), m2


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sequence", required=True)
    ap.add_argument("--map", required=True)
    ap.add_argument("--csv", help="the map's per-frame CSV (sogmm map --csv): names the insert of a component")
    ap.add_argument("--frames", default="54,57,117")
    ap.add_argument("--decimate", type=int, default=5)
    ap.add_argument("--bandwidth", type=float, default=0.02)
    ap.add_argument("--sogmm", default="build/tools/sogmm/sogmm")
    ap.add_argument("--edge-px", type=int, default=12, help="full-resolution pixels: the 'near a silhouette' radius")
    ap.add_argument("--surface-sigma", type=float, default=0.0)
    ap.add_argument("--own-dir", default=None, help="where own fits are read or written (default: next to --map)")
    ap.add_argument("--worst", type=int, default=5, help="print this many of the worst map pixels")
    a = ap.parse_args()
    seq, d = a.sequence, a.decimate
    poses = read_poses(os.path.join(seq, "trajectory.log"))
    cam = read_camera(seq)
    e = d + 1
    dc = sogmm.Camera(width=cam.width // e, height=cam.height // e, fx=cam.fx / e, fy=cam.fy / e, cx=cam.cx / e,
                      cy=cam.cy / e)
    the_map = sogmm.load(a.map)
    created = None
    if a.csv:
        import csv
        created = [(int(r["frame"]), int(r["components"])) for r in csv.DictReader(open(a.csv))]
    own_dir = a.own_dir or os.path.dirname(os.path.abspath(a.map))
    for k in [int(x) for x in a.frames.split(",")]:
        own_path = os.path.join(own_dir, "own_%d.sogmm" % k)
        if not os.path.exists(own_path):
            subprocess.run([a.sogmm, "fit", "--sequence", seq, "--trajectory", os.path.join(seq, "trajectory.log"),
                            "--frames", str(k), "--decimate", str(d), "--bandwidth", str(a.bandwidth), "-o", own_path,
                            "--json"], check=True, stdout=subprocess.DEVNULL)
        own = sogmm.load(own_path)
        pose = poses[k]
        z_full = observed_depth(seq, k)
        near_full = nearer_nearby(z_full, a.edge_px)
        zo = z_full[::e, ::e][: dc.height, : dc.width]
        near = near_full[::e, ::e][: dc.height, : dc.width]
        vv, uu = np.mgrid[0: dc.height, 0: dc.width]
        heldout = ~(((uu * e) % d == 0) & ((vv * e) % d == 0))
        zm = the_map.render(dc, pose, surface_sigma=a.surface_sigma)[0].astype(np.float64)
        zw = own.render(dc, pose, surface_sigma=a.surface_sigma)[0].astype(np.float64)
        ok = heldout & ~np.isnan(zo)
        okm, okw = ok & ~np.isnan(zm), ok & ~np.isnan(zw)
        em, ew = np.abs(zm - zo), np.abs(zw - zo)
        mae_m, mae_w = em[okm].mean(), ew[okw].mean()
        both = okm & okw
        n = both.sum()

        def cls(z):
            return np.where(z < zo - 0.01, "front", np.where(z > zo + 0.01, "behind", "close"))

        cm, cw = cls(zm), cls(zw)
        # The excess on the pixels both show, in mm of the mean, by (near/far, map class).
        split = {}
        for nn, nname in ((True, "near"), (False, "far")):
            for c in ("front", "behind", "close"):
                sel = both & (near == nn) & (cm == c)
                split["%s_%s" % (nname, c)] = {
                    "pixels": int(sel.sum()),
                    "excess_mm": float(1000 * (em[sel] - ew[sel]).sum() / n),
                    "map_mm": float(1000 * em[sel].sum() / n), "own_mm": float(1000 * ew[sel].sum() / n)}
        # The components that stop the map's rays early, and where they come from.
        idx = np.argwhere(both & (cm == "front"))
        r_cam = pose[:3, :3]
        stops = []
        for (v, u) in idx:
            ray = np.array([(u - dc.cx) / dc.fx, (v - dc.cy) / dc.fy, 1.0])
            p_world = r_cam @ (ray * zm[v, u]) + pose[:3, 3]
            kk, m2 = stopping_component(the_map, p_world)
            cov = the_map.covariances_[kk, :3, :3].astype(np.float64)
            val, vec = np.linalg.eigh(cov)
            dirw = r_cam @ (ray / np.linalg.norm(ray))
            cosn = abs(float(vec[:, 0] @ dirw))
            # Mahalanobis distance of the ray (a line) to the component's mean.
            inv = np.linalg.inv(cov)
            c0 = pose[:3, 3] - the_map.means_[kk, :3]
            aa = dirw @ inv @ dirw
            bb = dirw @ inv @ c0
            rr = c0 @ inv @ c0 - bb * bb / aa
            birth = None
            if created:
                birth = next((f for f, c in created if c > kk), None)
            stops.append({"pixel": [int(u), int(v)], "near": bool(near[v, u]), "err_mm": 1000 * float(em[v, u]),
                          "own_err_mm": 1000 * float(ew[v, u]), "component": kk,
                          "sigmas_mm": [1000 * float(np.sqrt(x)) for x in val],
                          "normal_to_ray_deg": float(np.degrees(np.arccos(min(1.0, cosn)))),
                          "ray_sigma": float(np.sqrt(max(rr, 0))), "created_by_frame_csv": birth})
        stops.sort(key=lambda s: -s["err_mm"] + s["own_err_mm"])
        comps = {}
        for s in stops:
            c = comps.setdefault(s["component"], {"pixels": 0, "excess_mm": 0.0, "sigmas_mm": s["sigmas_mm"],
                                                  "ray_sigma": [], "created": s["created_by_frame_csv"],
                                                  "normal_to_ray_deg": []})
            c["pixels"] += 1
            c["excess_mm"] += (s["err_mm"] - s["own_err_mm"]) / n
            c["ray_sigma"].append(s["ray_sigma"])
            c["normal_to_ray_deg"].append(s["normal_to_ray_deg"])
        top = sorted(comps.items(), key=lambda kv: -kv[1]["excess_mm"])[:8]
        print("frame %d: depth MAE map %.2f mm, own %.2f mm (+%.2f); on the %d pixels both show %.2f vs %.2f" % (
            k, 1000 * mae_m, 1000 * mae_w, 1000 * (mae_m - mae_w), n, 1000 * em[both].mean(), 1000 * ew[both].mean()))
        for key, s in split.items():
            if s["pixels"]:
                print("  %-12s %5d px  map %6.2f  own %6.2f  excess %+6.2f mm" % (key, s["pixels"], s["map_mm"],
                                                                                 s["own_mm"], s["excess_mm"]))
        ray_sig = np.array([s["ray_sigma"] for s in stops]) if stops else np.zeros(0)
        ang = np.array([s["normal_to_ray_deg"] for s in stops]) if stops else np.zeros(0)
        if len(stops):
            print("  map 'front' pixels: ray at %.2f sigma (median; %.0f%% beyond 2), normal-to-ray median %.0f deg" % (
                np.median(ray_sig), 100 * np.mean(ray_sig > 2), np.median(ang)))
        for kk, c in top:
            print("    component %d: %d px, excess %+.2f mm, sigmas %s mm, ray at %.2f-%.2f sigma, normal-to-ray %.0f deg, "
                  "created at frame %s" % (kk, c["pixels"], c["excess_mm"], "/".join("%.1f" % x for x in c["sigmas_mm"]),
                                           min(c["ray_sigma"]), max(c["ray_sigma"]),
                                           np.median(c["normal_to_ray_deg"]), c["created"]))
        for s in stops[: a.worst]:
            print("    pixel %s: map %.1f mm off, own %.1f mm" % (s["pixel"], s["err_mm"], s["own_err_mm"]))
        print(json.dumps({"frame": k, "depth_mae_map_mm": 1000 * mae_m, "depth_mae_own_mm": 1000 * mae_w,
                          "split": split, "top_components": [{"id": kk, **{x: (y if not isinstance(y, list) or x ==
                                                                               "sigmas_mm" else float(np.median(y)))
                                                                           for x, y in c.items()}} for kk, c in top]}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
