#!/usr/bin/env python3
"""Benchmark of sogmm_ray (issue 19): throughput of 1 and 2 Ray workers,
Ray's overhead per frame against the fit time (with the default chunking of
several frames per task, and with one frame per task as before), bytes moved
per frame, the map-building reduce, and the per-frame fit and per-component
merge costs that the paper estimate in bindings/python-ray/README.md is computed
from.

    SOGMM_LIBRARY_PATH=build/capi/libsogmm.so PYTHONPATH=bindings/python/src:bindings/python-ray/src \\
      python3 tools/sogmm-perf/ray_bench.py --sogmm build/tools/sogmm/sogmm [--frames 200] [--repeats 1]

The sequence is the first --frames frames of the 300-frame synthetic room loop
(`sogmm demo --write-frame DIR --loop`, 640 x 480, fitted at d = 5). Runs are
interleaved (in-process sequential, Ray 1 worker with one frame per task and
with the default chunking, Ray 2 workers, the map reduce in process and on 2
workers; repeated) and medians are reported with the load average, since the
machine is shared. Every Ray map is checked bitwise against its sequential
build.
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

# As in a Ray worker (Ray sets OMP_NUM_THREADS to the task's CPUs): without it
# the in-process baseline's one-thread fits ran ~1.8x slower on a loaded machine.
os.environ.setdefault("OMP_NUM_THREADS", "1")

import sogmm  # noqa: E402
from sogmm_ray import (FitSettings, MapSettings, build_map, fit_frame, load_frames,  # noqa: E402
                       reduce_partials, sequential_build)
from sogmm_ray.frame_fit import camera_dict  # noqa: E402
from sogmm_ray.partial import finalize  # noqa: E402


LOOP_FRAMES = 300  # `sogmm demo --loop`'s default length


def write_sequence(sogmm_cli: str, folder: Path, n: int) -> Path:
    """The synthetic room loop (max(n, 300) frames: the loop's path depends on its length)."""
    loop = folder / "loop"
    subprocess.run([sogmm_cli, "demo", "--write-frame", str(loop), "--loop", "--frames", str(max(n, LOOP_FRAMES))],
                   check=True, stdout=subprocess.DEVNULL)
    return loop


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
    ap.add_argument("--tile-size", type=float, default=2.0, help="metres (the loop's 4 quadrants at 2)")
    ap.add_argument("--no-map", action="store_true", help="skip the map-reduce runs")
    ap.add_argument("--json", help="also write the numbers to this JSON file")
    a = ap.parse_args(argv)
    import ray

    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    tmp = Path(tempfile.mkdtemp(prefix="sogmm_ray_bench_"))
    try:
        seq = write_sequence(a.sogmm, tmp, a.frames)
        frames = load_frames(str(seq), str(seq / "trajectory.log"), f"0:{a.frames}")
        cam = sogmm.Camera.from_json(seq / "intrinsics.json")
        settings = FitSettings(decimate=a.decimate)
        map_settings = MapSettings()
        load = [os.getloadavg()]
        # (name, workers, frames per task (None = auto), map settings or None)
        ray_runs = [("ray1_1pertask", 1, 1, None), ("ray1", 1, None, None), ("ray2", 2, None, None)]
        if not a.no_map:
            ray_runs.append(("ray2_map", 2, None, map_settings))
        runs = {k: [] for k in ["sequential", "sequential_map"] + [r[0] for r in ray_runs]}
        startup = []
        ref = {}
        for _ in range(a.repeats):
            runs["sequential"].append(sequential_build(frames, settings, cam))
            if not a.no_map:
                runs["sequential_map"].append(sequential_build(frames, settings, cam, map=map_settings,
                                                               tile_size=a.tile_size))
            ref = ref or {None: runs["sequential"][0].model,
                          "map": runs["sequential_map"][0].model if not a.no_map else None}
            for name, w, per_task, ms in ray_runs:
                ray.init(num_cpus=w, include_dashboard=False, log_to_driver=False)
                try:
                    startup.append(_warm(ray, w))
                    r = build_map(frames, settings, cam, fan_in=a.fan_in, progress=False, frames_per_task=per_task,
                                  map=ms, tile_size=a.tile_size)
                finally:
                    ray.shutdown()
                runs[name].append(r)
                want = ref["map" if ms else None]
                same = all(getattr(r.model, k).tobytes() == getattr(want, k).tobytes()
                           for k in ("weights_", "means_", "covariances_")) and r.model.metadata == want.metadata
                if not same:
                    print(f"ERROR: the {name} map differs from the sequential one", file=sys.stderr)
                    return 1
            load.append(os.getloadavg())
        med = {k: statistics.median(x.seconds_wall for x in v) for k, v in runs.items() if v}
        n = len(frames)

        def per_frame(name: str, fn) -> float:
            return statistics.median(fn(x) for x in runs[name]) / n

        fit_per_frame = per_frame("ray1", lambda x: x.seconds_fit)
        # Ray's overhead: the 1-worker job's wall time beyond the work it did
        # (fits, and merges: in-task unions and merge tasks, all timed inside
        # the tasks), per frame, with the workers already started (_warm).
        overhead = per_frame("ray1", lambda x: x.seconds_wall - x.seconds_fit - x.seconds_merge)
        overhead_1 = per_frame("ray1_1pertask", lambda x: x.seconds_wall - x.seconds_fit - x.seconds_merge)
        r1 = runs["ray1"][0]
        ref = ref[None]
        leaves = [fit_frame(f, settings, camera_dict(cam))[1] for f in frames[:8]]
        c_merge, c_final, m_merge = merge_cost(leaves, a.fan_in)
        out = {
            "frames": n, "decimate": a.decimate, "components_per_frame": ref.n_components_ / n,
            "map_components": ref.n_components_,
            **{f"seconds_{k}": v for k, v in med.items()},
            "throughput_ratio_2_over_1": med["ray1"] / med["ray2"],
            "frames_per_task_ray1": -(-n // r1.tasks), "frames_per_task_ray2": -(-n // runs["ray2"][0].tasks),
            "fit_seconds_per_frame": fit_per_frame,  # inside the 1-worker job's tasks
            "ray_overhead_seconds_per_frame": overhead, "ray_overhead_over_fit": overhead / fit_per_frame,
            # The same with one frame per task (the previous scheduling), in this run.
            "ray_overhead_seconds_per_frame_1pertask": overhead_1,
            "ray_overhead_over_fit_1pertask": overhead_1 / per_frame("ray1_1pertask", lambda x: x.seconds_fit),
            # Wall beyond the fits alone (merges counted as overhead too).
            "ray_overhead_incl_merge_over_fit": per_frame("ray1", lambda x: x.seconds_wall - x.seconds_fit)
            / fit_per_frame,
            "ray_startup_seconds_median": statistics.median(startup),  # workers + import, once per job
            "ray1_over_sequential": med["ray1"] / med["sequential"],
            # Fit time per frame inside the tasks: when it grows from 1 to 2
            # workers, the two workers were not given two idle cores.
            "fit_seconds_per_frame_ray1": statistics.median(x.seconds_fit for x in runs["ray1"]) / n,
            "fit_seconds_per_frame_ray2": statistics.median(x.seconds_fit for x in runs["ray2"]) / n,
            "bytes_moved_per_frame": r1.bytes_moved / n, "merge_tasks": r1.merges,
            "bytes_moved_per_frame_1pertask": runs["ray1_1pertask"][0].bytes_moved / n,
            **({} if a.no_map else {
                "map_reduce_components": runs["ray2_map"][0].model.n_components_,
                "map_reduce_tasks": runs["ray2_map"][0].tasks,
                "map_reduce_2_workers_over_sequential": med["ray2_map"] / med["sequential_map"]}),
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
        for p, e in out.get("estimate_2870_frames", {}).items():  # the rows of bindings/python/README.md's table
            print(f"| {p} | {2 * p} | {e['fit_s']:.0f} s | {e['merge_s']:.1f} s | {e['finalize_s']:.1f} s | "
                  + (f"{e['total_s']:.0f} s |" if e["total_s"] < 120 else f"{e['total_s'] / 60:.1f} min |"))
        if a.json:
            Path(a.json).write_text(json.dumps(out, indent=1))
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
