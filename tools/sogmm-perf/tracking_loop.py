#!/usr/bin/env python3
"""Mapping without a trajectory (issue 32): `sogmm map DIR` tracks each frame
against the map (core tracking, sogmm/map_tracking.hpp) and writes the poses
it used (--trajectory-out); this script compares them with the sequence's own
trajectory.log.

ATE: the RMSE of the camera positions after aligning the estimate's first
frame with the truth's (x_truth_k ~ T_truth_0 T_est_0^-1 x_est_k; no
best-fit alignment, so drift is not hidden), each estimate paired with its
frame number (from the map's CSV, so that skipped frames and slices such as
--frames 78:96 pair right). Also prints the skipped frames,
the worst frame, the first frame off by more than 1 cm and the wall time.

Usage (from the repository root; the synthetic loop is written if missing):
    python3 tools/sogmm-perf/tracking_loop.py [--sogmm build/tools/sogmm/sogmm] [--loop-dir /tmp/sogmm_track]
        [--frames 0:300] [-- MAP FLAGS...]   (e.g. -- --no-registration-gray)
Prints a one-line summary and one JSON line.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np


def read_log(path):
    """Redwood .log: a header line 'id id n' then 4 rows of the 4 x 4 pose, per frame."""
    lines = [line for line in open(path).read().splitlines() if line.strip()]
    poses = {}
    for i in range(0, len(lines), 5):
        frame = int(lines[i].split()[0])
        poses[frame] = np.array([[float(x) for x in lines[i + j].split()] for j in range(1, 5)])
    return poses


def ate(estimate, truth):
    """Per-frame position errors (metres) after the first-frame alignment."""
    first = min(estimate)
    align = truth[first] @ np.linalg.inv(estimate[first])
    return {k: float(np.linalg.norm((align @ estimate[k])[:3, 3] - truth[k][:3, 3])) for k in sorted(estimate)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sogmm", default="build/tools/sogmm/sogmm")
    ap.add_argument("--loop-dir", default="/tmp/sogmm_track")
    ap.add_argument("--frames", default="0:300")
    ap.add_argument("map_flags", nargs="*")
    a = ap.parse_args()
    if not os.path.isfile(os.path.join(a.loop_dir, "trajectory.log")):
        subprocess.run([a.sogmm, "demo", "--write-frame", a.loop_dir, "--loop"], check=True,
                       stdout=subprocess.DEVNULL)
    out = os.path.join(a.loop_dir, "tracked")
    t0 = time.monotonic()
    run = subprocess.run([a.sogmm, "map", a.loop_dir, "--frames", a.frames, "-o", out + ".sogmm",
                          "--trajectory-out", out + ".log", "--quiet", "--json"] + a.map_flags,
                         capture_output=True, text=True)
    seconds = time.monotonic() - t0
    if run.returncode != 0:
        sys.exit("sogmm map failed: " + run.stderr.strip().splitlines()[-1])
    summary = json.loads(run.stdout)
    # --trajectory-out numbers the inserted frames 0, 1, ...; the CSV's rows
    # (inserted frames only, in order) hold their frame numbers.
    rows = [line.split(",")[0] for line in open(out + ".csv").read().splitlines()[1:] if line]
    estimate = {int(rows[k]): pose for k, pose in read_log(out + ".log").items()}
    errors = ate(estimate, read_log(os.path.join(a.loop_dir, "trajectory.log")))
    e = np.array(list(errors.values()))
    worst = max(errors, key=errors.get)
    first_off = next((k for k, v in errors.items() if v > 0.01), None)
    result = {"frames": a.frames, "flags": a.map_flags, "inserted": len(errors),
              "skipped": summary["n_skipped"], "ate_rmse_cm": round(float(np.sqrt((e ** 2).mean())) * 100, 3),
              "max_cm": round(errors[worst] * 100, 3), "worst_frame": worst, "first_frame_over_1cm": first_off,
              "odometry": summary.get("n_odometry", 0), "components": summary["n_components"],
              "flushes": summary["n_flushes"], "seconds": round(seconds, 1)}
    print(f"{a.frames} {' '.join(a.map_flags)}: {result['inserted']} inserted, {result['skipped']} skipped, {result['odometry']} by odometry; "
          f"ATE RMSE {result['ate_rmse_cm']} cm (max {result['max_cm']} cm at frame {worst}; first over 1 cm: "
          f"{first_off}); {result['components']} components, {result['flushes']} fits, {seconds:.0f} s")
    print(json.dumps(result))


if __name__ == "__main__":
    main()
