#!/usr/bin/env python3
"""World-frame queries on a map (issue 18): Map.score_samples / regress_gray
through sogmm_map_*_f32 against the previous path, export() then the GMM
query (a copy of every component per call), and the same with a progress
callback (chunked). All give the same bits (checked here). Builds a synthetic map (novelty off, fixed K per frame), then times
the two paths interleaved in the same process and prints medians and ratios:

  SOGMM_LIBRARY_PATH=build/capi/libsogmm.so python3 tools/sogmm-perf/map_queries.py
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
try:
    import sogmm
except ImportError:
    sys.path.insert(0, str(ROOT / "bindings" / "python" / "src"))
    import sogmm


def build_map(frames: int, k: int, points: int) -> sogmm.Map:
    rng = np.random.default_rng(0)
    m = sogmm.Map(novelty=False, n_components=k, seed=1, n_threads=2, max_iter=20)
    for f in range(frames):
        centres = rng.uniform(-1, 1, size=(k, 4)).astype(np.float32)
        pts = centres[rng.integers(0, k, points)] + rng.normal(0, 0.02, (points, 4)).astype(np.float32)
        pose = np.eye(4)
        pose[0, 3] = 2.5 * f
        m.insert_points(pts, pose)
    return m


def timed(fn) -> tuple[float, object]:
    t0 = time.perf_counter()
    r = fn()
    return time.perf_counter() - t0, r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--k", type=int, default=50, help="components per frame")
    ap.add_argument("--points", type=int, default=2000, help="points per frame")
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    m = build_map(args.frames, args.k, args.points)
    print(f"map: {m.n_components_} components")
    rng = np.random.default_rng(5)
    for n in (100, 10000):
        q = np.column_stack([rng.uniform(0, 2.5 * args.frames, n), rng.uniform(-1, 1, (n, 2))]).astype(np.float32)
        quiet = lambda *_: None  # noqa: E731 - a progress callback that never cancels
        for name, old, new, with_progress in (
            ("score_samples", lambda: m.export().score_samples(q), lambda: m.score_samples(q),
             lambda: m.score_samples(q, progress=quiet)),
            ("regress_gray", lambda: m.export().regress_gray(q)[0], lambda: m.regress_gray(q)[0],
             lambda: m.regress_gray(q, progress=quiet)[0]),
        ):
            t_old, t_new, t_prog = [], [], []
            for _ in range(args.repeats):  # interleaved: the same load on all three
                a, ra = timed(old)
                b, rb = timed(new)
                c, rc = timed(with_progress)
                t_old.append(a)
                t_new.append(b)
                t_prog.append(c)
                assert np.array_equal(ra, rb) and np.array_equal(ra, rc), "the map query differs from export + query"
            mo, mn, mp = (statistics.median(t) for t in (t_old, t_new, t_prog))
            print(f"{name:14s} n={n:6d}: export+query {1e3 * mo:8.2f} ms, map query {1e3 * mn:8.2f} ms "
                  f"(ratio {mo / mn:4.2f}x), with progress {1e3 * mp:8.2f} ms (ratio {mp / mn:4.2f}x) "
                  f"(medians of {args.repeats})")


if __name__ == "__main__":
    main()
