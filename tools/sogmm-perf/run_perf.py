#!/usr/bin/env python3
"""Performance benchmark of SOGMM (issue 8), with scikit-learn as a fixed peer.

Runs `sogmm-perf` on livingroom frame 00000 for the issue's cases, several
times each, and prints a markdown table of medians: N, M, ms per stage, EM
iterations, ms per EM iteration, GFLOP/s of the EM passes, peak RSS, the EM
scaling from 1 to 2 threads, and scikit-learn's GaussianMixture time per EM
iteration on the same points and the same initial responsibilities (one-hot
on our k-means++ seeds), with the ratio.

Usage (from the repository root, after tools/setup.sh):
    python3 tools/sogmm-perf/run_perf.py [--runs 5] [--cases d5s02,d5s01,d4s02,d2s02,d1s02]
        [--sklearn-iters 3] [--no-sklearn] [--perf BEFORE --perf AFTER]

With several --perf binaries every run of a case goes through each binary in
turn (interleaved, so a loaded machine slows them alike) and a second table
gives, per case, each binary's median EM and total fit time and its ratio to
the first binary's.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "..", "shared", "data", "rgbd", "livingroom")
BIN = os.path.join(ROOT, "build", "tools", "sogmm-perf", "sogmm-perf")
CASES = {  # name: (decimation, bandwidth)
    "d5s02": (5, 0.02), "d5s01": (5, 0.01), "d4s02": (4, 0.02), "d2s02": (2, 0.02), "d1s02": (1, 0.02)}
TARGET_S = {"d5s02": 0.5, "d5s01": 1.5, "d2s02": 4.0, "d1s02": 12.0}


def run_case(d, bw, threads, dump=None, binary=BIN):
    cmd = [binary, "--depth", os.path.join(DATA, "depth", "00000.png"), "--color",
           os.path.join(DATA, "color", "00000.jpg"), "--intrinsics", os.path.join(DATA, "intrinsics.json"),
           "--decimate", str(d), "--bandwidth", str(bw), "--threads", str(threads)]
    if dump:
        cmd += ["--dump-points", dump]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def sklearn_ms_per_iter(dump, iters):
    import numpy as np
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.mixture import GaussianMixture
    with open(dump, "rb") as f:
        n, m = np.frombuffer(f.read(16), dtype=np.uint64)
        x = np.frombuffer(f.read(int(n) * 16), dtype=np.float32).reshape(int(n), 4).astype(np.float64)
        seeds = np.frombuffer(f.read(int(m) * 8), dtype=np.uint64).astype(np.int64)
    k = len(seeds)
    # One-hot responsibilities on the seeds give means = seed points,
    # covariances = reg_covar I and equal weights: the same start as our EM.
    gm = GaussianMixture(k, covariance_type="full", tol=0.0, reg_covar=1e-6, max_iter=iters,
                         weights_init=np.full(k, 1.0 / k), means_init=x[seeds],
                         precisions_init=np.repeat(np.eye(4)[None] / 1e-6, k, axis=0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        t = time.perf_counter()
        gm.fit(x)
        return 1000.0 * (time.perf_counter() - t) / gm.n_iter_


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--sklearn-iters", type=int, default=3)
    ap.add_argument("--no-sklearn", action="store_true")
    ap.add_argument("--perf", action="append", help="sogmm-perf binary (repeatable; interleaved)")
    a = ap.parse_args()
    if a.perf:
        return compare(a)
    if not os.path.isdir(DATA):
        sys.exit(f"run_perf: {DATA} not found (the real frames live in ../shared/data)")
    if not os.path.exists(BIN):
        sys.exit(f"run_perf: {BIN} not built (run tools/setup.sh)")
    rows = []
    for name in a.cases.split(","):
        d, bw = CASES[name]
        runs2 = [run_case(d, bw, 2) for _ in range(a.runs)]
        runs1 = [run_case(d, bw, 1) for _ in range(max(1, a.runs // 2))]
        med = {k: statistics.median(r[k] for r in runs2) for k in runs2[0] if isinstance(runs2[0][k], (int, float))}
        em1 = statistics.median(r["ms_per_iteration"] for r in runs1)
        sk = None
        if not a.no_sklearn:
            with tempfile.TemporaryDirectory() as tmp:
                dump = os.path.join(tmp, "points.bin")
                run_case(d, bw, 2, dump)
                sk = sklearn_ms_per_iter(dump, a.sklearn_iters)
        rows.append((name, d, bw, med, em1, sk))
        print(f"{name}: done", file=sys.stderr)
    print("| case | N | M | mode count ms | seeding ms | EM ms | EM iters | ms/iter | GFLOP/s | "
          "regress ms | sample ms | metrics ms | total fit s (target) | peak RSS MiB | EM 1->2 threads | "
          "sklearn ms/iter | speed-up vs sklearn (per iter) |")
    print("|" + "---|" * 17)
    for name, d, bw, m, em1, sk in rows:
        target = TARGET_S.get(name)
        target_txt = f" (<= {target})" if target else ""
        sk_txt = "" if sk is None else f"{sk:.0f}"
        ratio_txt = "" if sk is None else f"{sk / m['ms_per_iteration']:.0f}x"
        print(f"| d={d}, bw {bw} | {int(m['n'])} | {int(m['m'])} | {1000*m['s_mode_count']:.1f} | "
              f"{1000*m['s_seeding']:.1f} | {1000*m['s_em']:.0f} | {int(m['em_iterations'])} | "
              f"{m['ms_per_iteration']:.2f} | {m['gflops']:.1f} | {1000*m['s_regress']:.1f} | "
              f"{1000*m['s_sample']:.1f} | {1000*m['s_metrics']:.1f} | {m['s_total_fit']:.3f}{target_txt} | "
              f"{m['peak_rss_mib']:.0f} | {em1 / m['ms_per_iteration']:.2f}x | {sk_txt} | {ratio_txt} |")

def compare(a):
    """Median EM and total fit seconds per case for each binary, runs interleaved."""
    print("| case | binary | N | M | EM iters | EM ms | ms/iter | total fit s | EM ratio | total ratio |")
    print("|" + "---|" * 10)
    for name in a.cases.split(","):
        d, bw = CASES[name]
        runs = {b: [] for b in a.perf}
        for _ in range(a.runs):
            for b in a.perf:
                runs[b].append(run_case(d, bw, 2, binary=b))
        med = {b: {k: statistics.median(r[k] for r in rs) for k in ("n", "m", "em_iterations", "s_em",
                                                                    "ms_per_iteration", "s_total_fit")}
               for b, rs in runs.items()}
        base = med[a.perf[0]]
        for b in a.perf:
            m = med[b]
            print(f"| d={d}, bw {bw} | {b} | {int(m['n'])} | {int(m['m'])} | {m['em_iterations']:.0f} | "
                  f"{1000*m['s_em']:.0f} | {m['ms_per_iteration']:.2f} | {m['s_total_fit']:.3f} | "
                  f"{m['s_em']/base['s_em']:.2f} | {m['s_total_fit']/base['s_total_fit']:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    main()
