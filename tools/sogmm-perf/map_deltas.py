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
4. checks `sogmm apply-deltas` rebuilds the same number of components.
Draco (1 cm quantisation) and MCAP are not measured here (later sessions).

Usage (from the repository root):
    python3 tools/sogmm-perf/map_deltas.py [--sogmm build/tools/sogmm/sogmm] [--frames 100]
        [--decimate 5] [--bandwidth 0.02] [--work /tmp/sogmm_deltas] [-- MAP FLAGS...]
Prints a table and one JSON line.
"""
import argparse
import csv
import json
import os
import shutil
import subprocess


def run_json(cmd):
    out = subprocess.run(cmd + ["--json"], check=True, stdout=subprocess.PIPE, text=True).stdout
    return json.loads(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sogmm", default="build/tools/sogmm/sogmm")
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--decimate", type=int, default=5)
    ap.add_argument("--bandwidth", type=float, default=0.02)
    ap.add_argument("--work", default="/tmp/sogmm_deltas")
    ap.add_argument("map_flags", nargs="*")
    a = ap.parse_args()
    loop, deltas = os.path.join(a.work, "loop"), os.path.join(a.work, "deltas")
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    subprocess.run([a.sogmm, "demo", "--write-frame", loop, "--loop", "--frames", str(a.frames)], check=True,
                   stdout=subprocess.DEVNULL)
    out = os.path.join(a.work, "loop.sogmm")
    s = run_json([a.sogmm, "map", loop, "--trajectory", os.path.join(loop, "trajectory.log"), "--decimate",
                  str(a.decimate), "--bandwidth", str(a.bandwidth), "-o", out, "--deltas", deltas, "-q"] + a.map_flags)
    sizes = [os.path.getsize(os.path.join(deltas, n)) for n in sorted(os.listdir(deltas))]
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
    print("frames %d, points %d, map %d components (%d bytes)" % (res["frames"], res["points"], res["components"],
                                                                  res["map_file_bytes"]))
    print("deltas: %d, total %d bytes, mean %.0f, max %d, per frame %.0f" %
          (len(sizes), total, res["delta_bytes_mean"], res["delta_bytes_max"], res["delta_bytes_per_frame"]))
    print("raw decimated clouds: %d bytes (%.1fx the deltas)" % (raw, res["raw_over_deltas"]))
    print("whole map at every delta (estimate): %d bytes (%.1fx the deltas)" % (whole, res["whole_over_deltas"]))
    print(json.dumps(res))


if __name__ == "__main__":
    main()
