#!/usr/bin/env python3
"""Benchmark of sogmm.distributed (issue 19): throughput of 1 and 2 Ray workers,
Ray's overhead per frame against the fit time, bytes moved per frame, and the
per-frame fit and per-component merge costs that the paper estimate in
bindings/python/README.md is computed from.

    SOGMM_LIBRARY_PATH=build/capi/libsogmm.so PYTHONPATH=bindings/python/src \\
      python3 tools/sogmm-perf/ray_bench.py --sogmm build/tools/sogmm/sogmm [--frames 200] [--repeats 1]

The sequence is `sogmm demo --write-frame` (640 x 480, fitted at d = 5). The demo
writes at most 100 frames, so a longer sequence repeats them (frame i + 100 is
frame i's images with the next poses of the same camera path). Runs are
interleaved (in-process sequential, Ray 1 worker, Ray 2 workers, repeated) and
medians are reported with the load average, since the machine is shared.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

# As in a Ray worker (Ray sets OMP_NUM_THREADS to the task's CPUs): without it
# the in-process baseline's one-thread fits ran ~1.8x slower on a loaded machine.
os.environ.setdefault("OMP_NUM_THREADS", "1")

import sogmm  # noqa: E402
from sogmm.distributed import (FitSettings, build_map, fit_frame, load_frames,  # noqa: E402
                               reduce_partials, sequential_build)
from sogmm.distributed.frame_fit import camera_dict  # noqa: E402
from sogmm.distributed.partial import finalize  # noqa: E402


def write_sequence(sogmm_cli: str, folder: Path, n: int) -> Path:
    """n demo frames; beyond the demo's 100, frames repeat with poses continued."""
    demo = folder / "demo"
    made = min(n, 100)
    subprocess.run([sogmm_cli, "demo", "--write-frame", str(demo), "--frames", str(made)], check=True,
                   stdout=subprocess.DEVNULL)
    if n == made:
        return demo
    seq = folder / "seq"
    (seq / "depth").mkdir(parents=True)
    (seq / "color").mkdir()
    poses = [np.array(p).reshape(4, 4) for p in _poses(demo / "trajectory.log")]
    step = np.linalg.inv(poses[0]) @ poses[-1]  # the camera path of frames 0..99, continued
    log = []
    for i in range(n):
        src = i % made
        for kind in ("depth", "color"):
            os.symlink(demo / kind / f"{src:05d}.png", seq / kind / f"{i:05d}.png")
        pose = poses[src]
        for _ in range(i // made):
            pose = pose @ step
        log.append(f"{i} {i + 1} {n}")
        log += [" ".join(f"{x:.17g}" for x in row) for row in pose]
    (seq / "trajectory.log").write_text("\n".join(log) + "\n")
    shutil.copy(demo / "intrinsics.json", seq / "intrinsics.json")
    return seq


def _poses(log: Path):
    from sogmm.distributed.sequence import read_trajectory
    return read_trajectory(str(log))


def merge_cost(leaves: list, fan_in: int, target: int = 60_000) -> tuple[float, float, int]:
    """Seconds per component of a merge task (bytes in, merge, bytes out) on a
    partial of about ``target`` components plus fan_in - 1 leaves, and of
    finalize on the merged leaves (medians of 3)."""
    root = leaves[0]
    for p in leaves[1:]:
        root = reduce_partials([root, p])
    big = root
    while sogmm.from_bytes(big["model"]).n_components_ < target:
        big = reduce_partials([big, big])  # repeated frames: only for timing (finalize rejects them)
    m = sogmm.from_bytes(big["model"]).n_components_ + sum(
        sogmm.from_bytes(p["model"]).n_components_ for p in leaves[:fan_in - 1])

    def timed(fn) -> float:
        t = []
        for _ in range(3):
            s = time.perf_counter()
            fn()
            t.append(time.perf_counter() - s)
        return statistics.median(t)

    c_merge = timed(lambda: reduce_partials([big] + leaves[:fan_in - 1])) / m
    c_final = timed(lambda: finalize(root)) / sogmm.from_bytes(root["model"]).n_components_
    return c_merge, c_final, m


def real_frame_cost(settings: FitSettings) -> dict:
    """Fit time and components of the shared livingroom frames 0-2 (if present)."""
    d = Path(os.environ.get("SOGMM_DATA_DIR", "/work/shared/data")) / "rgbd" / "livingroom"
    if not (d / "trajectory.log").is_file():
        return {}
    frames = load_frames(str(d), str(d / "trajectory.log"), "0:3")
    cam = camera_dict(sogmm.Camera.from_json(d / "intrinsics.json"))
    infos = [fit_frame(f, settings, cam)[0] for f in frames]
    return {"livingroom_fit_seconds_per_frame": statistics.median(i["seconds"] for i in infos),
            "livingroom_components_per_frame": statistics.median(i["n_components"] for i in infos)}


def paper_estimate(t_fit: float, overhead: float, m: float, c_merge: float, c_final: float, n: int = 2870,
                   fan_in: int = 8, cores_per_node: int = 2, nodes=(1, 8, 64)) -> dict:
    """Wall time of an n-frame job on P nodes (bindings/python/README.md):
    T(P) = n (t_fit + o) / W + sum over tree levels l = 1..L of
    max(n m c_merge / W, min(F^l, n) m c_merge) + n m c_final, with W = P x cores
    worker slots and L = ceil(log_F n); the fit phase is spread evenly, every
    merge level touches all n m components once, and a level cannot finish
    before its largest task (the root merges the whole map)."""
    import math
    levels = max(1, math.ceil(math.log(n) / math.log(fan_in)))
    out = {}
    for p in nodes:
        w = p * cores_per_node
        fit = n * (t_fit + overhead) / w
        merge = sum(max(n * m * c_merge / w, min(fan_in ** l, n) * m * c_merge) for l in range(1, levels + 1))
        final = n * m * c_final
        out[p] = {"fit_s": fit, "merge_s": merge, "finalize_s": final, "total_s": fit + merge + final}
    return out


def _warm(ray, workers: int) -> float:
    """Starts the workers and imports sogmm in each (a one-time cost, reported
    apart from the per-frame overhead); returns its seconds."""
    def warm():
        import sogmm  # noqa: F401
        time.sleep(0.5)  # keeps each task busy so that every worker starts
    start = time.perf_counter()
    ray.get([ray.remote(warm).options(num_cpus=1).remote() for _ in range(workers)])
    return time.perf_counter() - start - 0.5


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sogmm", default="build/tools/sogmm/sogmm", help="the sogmm CLI (for demo --write-frame)")
    ap.add_argument("--frames", type=int, default=200)
    ap.add_argument("--decimate", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=1, help="interleaved rounds (medians over them)")
    ap.add_argument("--fan-in", type=int, default=8)
    ap.add_argument("--json", help="also write the numbers to this JSON file")
    a = ap.parse_args(argv)
    import ray

    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    tmp = Path(tempfile.mkdtemp(prefix="sogmm_ray_bench_"))
    try:
        seq = write_sequence(a.sogmm, tmp, a.frames)
        frames = load_frames(str(seq), str(seq / "trajectory.log"))
        cam = sogmm.Camera.from_json(seq / "intrinsics.json")
        settings = FitSettings(decimate=a.decimate)
        load = [os.getloadavg()]
        runs = {"sequential": [], "ray1": [], "ray2": []}
        startup = []
        ref = None
        for _ in range(a.repeats):
            r = sequential_build(frames, settings, cam)
            runs["sequential"].append(r)
            ref = ref or r.model
            for w in (1, 2):
                ray.init(num_cpus=w, include_dashboard=False, log_to_driver=False)
                try:
                    startup.append(_warm(ray, w))
                    r = build_map(frames, settings, cam, fan_in=a.fan_in, progress=False)
                finally:
                    ray.shutdown()
                runs[f"ray{w}"].append(r)
                same = all(getattr(r.model, k).tobytes() == getattr(ref, k).tobytes()
                           for k in ("weights_", "means_", "covariances_")) and r.model.metadata == ref.metadata
                if not same:
                    print(f"ERROR: the {w}-worker map differs from the sequential one", file=sys.stderr)
                    return 1
            load.append(os.getloadavg())
        med = {k: statistics.median(x.seconds_wall for x in v) for k, v in runs.items()}
        n = len(frames)
        fit_per_frame = statistics.median(x.seconds_fit for x in runs["ray1"]) / n
        r1 = runs["ray1"][0]
        # Ray's overhead: the 1-worker job's wall time beyond the work it did
        # (fit and merge tasks, timed inside the tasks), per frame, with the
        # workers already started (_warm).
        overhead = statistics.median(x.seconds_wall - x.seconds_fit - x.seconds_merge for x in runs["ray1"]) / n
        leaves = [fit_frame(f, settings, camera_dict(cam))[1] for f in frames[:8]]
        c_merge, c_final, m_merge = merge_cost(leaves, a.fan_in)
        out = {
            "frames": n, "decimate": a.decimate, "components_per_frame": ref.n_components_ / n,
            "map_components": ref.n_components_,
            "seconds_sequential": med["sequential"], "seconds_ray1": med["ray1"], "seconds_ray2": med["ray2"],
            "throughput_ratio_2_over_1": med["ray1"] / med["ray2"],
            "fit_seconds_per_frame": fit_per_frame,  # inside the 1-worker job's tasks
            "ray_overhead_seconds_per_frame": overhead, "ray_overhead_over_fit": overhead / fit_per_frame,
            "ray_startup_seconds_median": statistics.median(startup),  # workers + import, once per job
            "ray1_over_sequential": med["ray1"] / med["sequential"],
            # Fit time per frame inside the tasks: when it grows from 1 to 2
            # workers, the two workers were not given two idle cores.
            "fit_seconds_per_frame_ray1": statistics.median(x.seconds_fit for x in runs["ray1"]) / n,
            "fit_seconds_per_frame_ray2": statistics.median(x.seconds_fit for x in runs["ray2"]) / n,
            "bytes_moved_per_frame": r1.bytes_moved / n, "merge_tasks": r1.merges,
            "merge_seconds_per_component": c_merge, "merge_timed_components": m_merge,
            "finalize_seconds_per_component": c_final, **real_frame_cost(settings),
            "loadavg_1min": [round(l[0], 2) for l in load], "cpus": os.cpu_count(),
        }
        if "livingroom_fit_seconds_per_frame" in out:
            est = paper_estimate(out["livingroom_fit_seconds_per_frame"], overhead,
                                 out["livingroom_components_per_frame"], c_merge, c_final, fan_in=a.fan_in)
            out["estimate_2870_frames"] = est
        for k, v in out.items():
            print(f"{k:34s} {v:.6g}" if isinstance(v, float) else f"{k:34s} {v}")
        if a.json:
            Path(a.json).write_text(json.dumps(out, indent=1))
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
