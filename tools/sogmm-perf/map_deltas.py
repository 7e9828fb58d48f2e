#!/usr/bin/env python3
"""Bytes of map deltas on the synthetic room loop (issue 33).

1. `sogmm demo --write-frame DIR --loop --frames N` (the loop);
2. `sogmm map DIR --trajectory ... --deltas DELTAS` (one delta per insert
   that fitted, and one at the end);
3. reports, per frame and per delta, the bytes of the deltas against
   - the raw decimated cloud: 16 bytes per point (x, y, z, gray float32);
   - the whole map sent at every delta: the map file's bytes per component
     times the components the map had at each delta (from the per-frame
     CSV), an estimate that ignores the fixed header (~1 KB per file);
4. checks `sogmm apply-deltas` rebuilds the same number of components;
5. with --draco-step K (needs DracoPy from PyPI and the Python binding:
   SOGMM_LIBRARY_PATH, PYTHONPATH=bindings/python/src): every K-th frame's
   decimated cloud (x, y, z and gray as one 8-bit attribute) compressed with
   Draco at the quantisation steps of DRACO_STEPS_M (1 cm and coarser), each
   with its F-score at 1 cm against the cloud it came from, beside the map's F-score at 1 cm (`sogmm eval`, mass-weighted)
   on the same frames. "Equal F-score" compares the deltas with the coarsest
   Draco step whose F-score is still at least the map's.
6. with --compare-sogmm PATH (another build, e.g. of an older commit): the
   same map with that binary in the same run, its deltas' bytes beside
   these (the format 1.1 deltas of a67de64 against the packed 1.2 ones).
Each delta's bytes are split into its header and metadata block (32 +
pad8(metadata length)) and its body (arrays, packed key/values, end marker).
MCAP is not measured here.

Usage (from the repository root):
    python3 tools/sogmm-perf/map_deltas.py [--sogmm build/tools/sogmm/sogmm] [--frames 100]
        [--decimate 5] [--bandwidth 0.02] [--work /tmp/sogmm_deltas] [--draco-step K]
        [--compare-sogmm OTHER/sogmm] [-- MAP FLAGS...]
Prints a table and one JSON line.
"""
import argparse
import csv
import json
import os
import shutil
import subprocess

# Draco quantisation steps (metres): 1 cm is the issue's; coarser ones find
# the Draco cloud whose F-score at 1 cm matches the map's.
DRACO_STEPS_M = (0.01, 0.02, 0.03, 0.04, 0.06)
F_THRESHOLD_M = 0.01


def run_json(cmd):
    out = subprocess.run(cmd + ["--json"], check=True, stdout=subprocess.PIPE, text=True).stdout
    return json.loads(out)


def f_score(truth, estimate, threshold=F_THRESHOLD_M):
    """F-score of two point sets at `threshold` (precision: estimate points
    within it of the truth; recall: truth points within it of the estimate)."""
    from scipy.spatial import cKDTree
    precision = float((cKDTree(truth).query(estimate)[0] <= threshold).mean())
    recall = float((cKDTree(estimate).query(truth)[0] <= threshold).mean())
    return 0.0 if precision + recall == 0 else 2 * precision * recall / (precision + recall)


def draco_clouds(loop, frames, decimate, step):
    """Per Draco step: total bytes and mean F-score at 1 cm over every
    `step`-th frame's decimated cloud, and the frames used."""
    import DracoPy
    import numpy as np
    import sogmm
    cam = sogmm.Camera.from_json(os.path.join(loop, "intrinsics.json"))
    used = list(range(0, frames, step))
    out = {q: {"bytes": 0, "fscore": 0.0} for q in DRACO_STEPS_M}
    for k in used:
        name = "%05d.png" % k
        depth, color = sogmm.read_frame(os.path.join(loop, "depth", name), os.path.join(loop, "color", name))
        p = sogmm.rgbd_to_points(depth, color, cam, decimate=decimate)
        xyz = np.ascontiguousarray(p[:, :3], dtype=np.float32)
        gray = np.clip(np.round(p[:, 3] * 255), 0, 255).astype(np.uint8)[:, None].copy()
        lo = xyz.min(axis=0)
        extent = float((xyz.max(axis=0) - lo).max())
        for q in DRACO_STEPS_M:
            bits = max(1, int(np.ceil(np.log2(extent / q + 1))))
            blob = DracoPy.encode(xyz, quantization_bits=bits, quantization_range=extent, quantization_origin=lo,
                                  compression_level=10, colors=gray)
            back = np.asarray(DracoPy.decode(blob).points, dtype=np.float64)
            out[q]["bytes"] += len(blob)
            out[q]["fscore"] += f_score(xyz.astype(np.float64), back) / len(used)
    return out, used


def delta_sizes(sogmm, loop, decimate, bandwidth, out, deltas, map_flags):
    """Maps the loop with `sogmm --deltas`; the map summary and, per delta
    file in order, (bytes, header + metadata bytes)."""
    s = run_json([sogmm, "map", loop, "--trajectory", os.path.join(loop, "trajectory.log"), "--decimate",
                  str(decimate), "--bandwidth", str(bandwidth), "-o", out, "--deltas", deltas, "-q"] + map_flags)
    sizes = []
    for n in sorted(os.listdir(deltas)):
        with open(os.path.join(deltas, n), "rb") as f:
            head = f.read(32)
        meta = int.from_bytes(head[24:28], "little")
        sizes.append((os.path.getsize(os.path.join(deltas, n)), 32 + (meta + 7) // 8 * 8))
    return s, sizes


def summary(sizes, n_frames):
    total = sum(b for b, _ in sizes)
    meta = sum(m for _, m in sizes)
    return {"deltas": len(sizes), "delta_bytes_total": total, "delta_bytes_mean": total / len(sizes),
            "delta_bytes_max": max(b for b, _ in sizes), "delta_bytes_per_frame": total / n_frames,
            "metadata_bytes_mean": meta / len(sizes), "body_bytes_mean": (total - meta) / len(sizes)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sogmm", default="build/tools/sogmm/sogmm")
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--decimate", type=int, default=5)
    ap.add_argument("--bandwidth", type=float, default=0.02)
    ap.add_argument("--work", default="/tmp/sogmm_deltas")
    ap.add_argument("--draco-step", type=int, default=0, help="compare with Draco on every K-th frame (0: off)")
    ap.add_argument("--compare-sogmm", help="also map with this binary and report its deltas beside these")
    ap.add_argument("map_flags", nargs="*")
    a = ap.parse_args()
    loop, deltas = os.path.join(a.work, "loop"), os.path.join(a.work, "deltas")
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    subprocess.run([a.sogmm, "demo", "--write-frame", loop, "--loop", "--frames", str(a.frames)], check=True,
                   stdout=subprocess.DEVNULL)
    out = os.path.join(a.work, "loop.sogmm")
    s, split = delta_sizes(a.sogmm, loop, a.decimate, a.bandwidth, out, deltas, a.map_flags)
    sizes = [b for b, _ in split]
    with open(os.path.join(a.work, "loop.csv")) as f:
        rows = list(csv.DictReader(f))
    flushed_components = [int(r["components"]) for r in rows if r["flushed"] == "1"]
    flushed_components.append(s["n_components"])  # the final delta
    per_component = s["file_bytes"] / max(1, s["n_components"])
    whole = sum(per_component * c for c in flushed_components[: len(sizes)])
    raw = 16 * s["n_points"]
    total = sum(sizes)
    r = run_json([a.sogmm, "apply-deltas", deltas, "-o", os.path.join(a.work, "rebuilt.sogmm")])
    res = {
        "frames": s["n_frames"], "points": s["n_points"], "components": s["n_components"], "deltas": len(sizes),
        "delta_bytes_total": total, "delta_bytes_mean": total / len(sizes), "delta_bytes_max": max(sizes),
        "delta_bytes_per_frame": total / s["n_frames"], "raw_cloud_bytes": raw, "raw_over_deltas": raw / total,
        "whole_map_every_delta_bytes": round(whole), "whole_over_deltas": whole / total,
        "map_file_bytes": s["file_bytes"], "rebuilt_components": r["n_components"],
    }
    res.update({k: v for k, v in summary(split, s["n_frames"]).items() if k.startswith(("metadata", "body"))})
    print("frames %d, points %d, map %d components (%d bytes)" % (res["frames"], res["points"], res["components"],
                                                                  res["map_file_bytes"]))
    print("deltas: %d, total %d bytes, mean %.0f, max %d, per frame %.0f" %
          (len(sizes), total, res["delta_bytes_mean"], res["delta_bytes_max"], res["delta_bytes_per_frame"]))
    print("  per delta: header and metadata %.0f bytes, body (arrays, packed key/values) %.0f" %
          (res["metadata_bytes_mean"], res["body_bytes_mean"]))
    if a.compare_sogmm:
        cs, csplit = delta_sizes(a.compare_sogmm, loop, a.decimate, a.bandwidth, os.path.join(a.work, "compare.sogmm"),
                                 os.path.join(a.work, "deltas-compare"), a.map_flags)
        c = summary(csplit, cs["n_frames"])
        c["components"] = cs["n_components"]
        res["compare"] = c
        print("compare (%s): %d deltas, total %d bytes, mean %.0f, max %d, per frame %.0f; header and metadata %.0f, "
              "body %.0f per delta; %d components" % (a.compare_sogmm, c["deltas"], c["delta_bytes_total"],
                                                     c["delta_bytes_mean"], c["delta_bytes_max"],
                                                     c["delta_bytes_per_frame"], c["metadata_bytes_mean"],
                                                     c["body_bytes_mean"], c["components"]))
    print("raw decimated clouds: %d bytes (%.1fx the deltas)" % (raw, res["raw_over_deltas"]))
    print("whole map at every delta (estimate): %d bytes (%.1fx the deltas)" % (whole, res["whole_over_deltas"]))
    if a.draco_step > 0:
        draco, used = draco_clouds(loop, s["n_frames"], a.decimate, a.draco_step)
        frames_arg = "0:%d:%d" % (s["n_frames"], a.draco_step)
        ev = run_json([a.sogmm, "eval", out, "--sequence", loop, "--trajectory", os.path.join(loop, "trajectory.log"),
                       "--frames", frames_arg, "--decimate", str(a.decimate)])
        map_f = ev["mean"]["fscore"]
        scale = s["n_frames"] / len(used)  # Draco bytes of every frame, from the frames compressed
        res["map_fscore_1cm"] = map_f
        res["draco"] = {"%g" % q: {"bytes_all_frames": round(v["bytes"] * scale), "fscore_1cm": v["fscore"],
                                   "over_deltas": v["bytes"] * scale / total} for q, v in draco.items()}
        print("map F-score at 1 cm (mass-weighted, frames %s): %.3f" % (frames_arg, map_f))
        for q, v in draco.items():
            print("Draco at %.0f mm steps: %d bytes for all frames (%.1fx the deltas), F-score at 1 cm %.3f" %
                  (1000 * q, v["bytes"] * scale, v["bytes"] * scale / total, v["fscore"]))
        at_least = [q for q, v in draco.items() if v["fscore"] >= map_f]
        if at_least:
            q = max(at_least)
            res["draco_equal_fscore_step_m"] = q
            print("coarsest Draco step with F-score >= the map's: %.0f mm, %.1fx the deltas" %
                  (1000 * q, res["draco"]["%g" % q]["over_deltas"]))
    print(json.dumps(res))


if __name__ == "__main__":
    main()
