#!/usr/bin/env python3
"""Seconds from the start of a d = 1 fit to the start of each stage, read from
the progress reports, for one or more builds of libsogmm, interleaved run by
run in fresh processes (so that load drifts hit every build alike). Prints
the median per build and stage and the ratio of each build to the first.

  python3 tools/sogmm-perf/stage_times.py --lib OLD/libsogmm.so --lib build/capi/libsogmm.so --runs 5

The frame is the one tools/sogmm-perf/cancel_latency.py uses. The fit stops
(is cancelled) at the start of EM, so a run costs the mode count and seeding.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
CHILD = """
import json, sys, time
sys.path.insert(0, %r)
sys.path.insert(0, %r)
import sogmm
from cancel_latency import frame_points
from sogmm.progress import STAGE_NAMES, STAGE_EM
points, _ = frame_points()
starts = {}
t0 = time.perf_counter()
def sink(stage, step, total, ll):
    name = STAGE_NAMES.get(stage, str(stage))
    if name == "mode count" and total > 0:
        name = "mean shift"  # the seeds are binned: the mode count's set-up is done
    starts.setdefault(name, time.perf_counter() - t0)
    return stage == STAGE_EM
try:
    sogmm.SOGMM(bandwidth=0.02, seed=0).fit(points, progress=sink)
except sogmm.CancelledError:
    pass
print(json.dumps(starts))
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lib", action="append", required=True, help="a libsogmm.so (repeat)")
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    src = str(HERE.parents[1] / "bindings" / "python" / "src")
    code = CHILD % (src, str(HERE))
    times: dict[str, dict[str, list[float]]] = {lib: {} for lib in args.lib}
    for _ in range(args.runs):
        for lib in args.lib:
            env = dict(os.environ, SOGMM_LIBRARY_PATH=lib)
            out = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True)
            for stage, t in json.loads(out.stdout).items():
                times[lib].setdefault(stage, []).append(t)
    base = {s: statistics.median(v) for s, v in times[args.lib[0]].items()}
    print(f"load average {os.getloadavg()[0]:.1f}; median seconds to the start of each stage over {args.runs} runs")
    for lib in args.lib:
        row = ", ".join(f"{s} {statistics.median(v):.3f} s (x{statistics.median(v) / base[s]:.2f})"
                        for s, v in times[lib].items())
        print(f"{lib}: {row}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
