#!/usr/bin/env python3
"""EM convergence at d = 2 (issue 14, item 10): how many seeds converge within max_iter.

Fits livingroom frame 00000 at decimation 2, bandwidth 0.02, default tol and
max_iter, for seeds 0..S-1 with one or more `sogmm` binaries (interleaved seed by
seed, so a loaded machine affects every binary alike) and prints, per binary, a
row per seed (M, EM iterations, converged, final mean log-likelihood) and a
summary: seeds converged, mean log-likelihood, mean iterations, mean EM seconds.

Usage: converge_d2.py [--sogmm build/tools/sogmm/sogmm [--sogmm OTHER ...]]
                      [--seeds 10] [--decimate 2] [--bandwidth 0.02] [--max-iter N] [-- FIT FLAGS...]
Anything after `--` goes to every `sogmm fit` (e.g. -- --dequantise-depth).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sogmm", action="append", help="sogmm binary (repeatable)")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(root), "shared", "data", "rgbd"))
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--decimate", type=int, default=2)
    ap.add_argument("--bandwidth", type=float, default=0.02)
    ap.add_argument("--max-iter", type=int, help="override the default max_iter")
    argv = sys.argv[1:]
    fit_flags = argv[argv.index("--") + 1:] if "--" in argv else []
    a = ap.parse_args(argv[: argv.index("--")] if "--" in argv else argv)
    bins = a.sogmm or [os.path.join(root, "build", "tools", "sogmm", "sogmm")]
    if not os.path.isdir(a.data):
        print("SKIP: %s is absent (the shared RGB-D frames)" % a.data)
        return 0
    d = os.path.join(a.data, "livingroom")
    frame = ["--depth", os.path.join(d, "depth", "00000.png"), "--color", os.path.join(d, "color", "00000.jpg"),
             "--intrinsics", os.path.join(d, "intrinsics.json")]
    results = {b: [] for b in bins}
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(a.seeds):
            for b in bins:
                cmd = [b, "fit"] + frame + ["--decimate", str(a.decimate), "--bandwidth", str(a.bandwidth),
                                            "--seed", str(seed), "--json", "-q", "-o", os.path.join(tmp, "m.sogmm")]
                if a.max_iter:
                    cmd += ["--max-iter", str(a.max_iter)]
                cmd += fit_flags
                p = subprocess.run(cmd, capture_output=True, text=True)
                if p.returncode != 0:
                    sys.exit("converge_d2: %s failed: %s" % (" ".join(cmd), p.stderr.strip()))
                j = json.loads(p.stdout)
                results[b].append(j)
                print("%s seed %d: M %d, %d iterations, converged %s, LL %.5f, EM %.2f s" %
                      (b, seed, j["n_components"], j["em_iterations"], j["converged"], j["log_likelihood"],
                       j["seconds_em"]), file=sys.stderr, flush=True)
    print("d = %d, bandwidth %g, seeds 0..%d%s" % (a.decimate, a.bandwidth, a.seeds - 1,
                                                   ", fit flags " + " ".join(fit_flags) if fit_flags else ""))
    print()
    print("| binary | converged | mean LL | min LL | max LL | mean iterations | max iterations | mean EM s |")
    print("|---|---|---|---|---|---|---|---|")
    for b, rs in results.items():
        ll = [r["log_likelihood"] for r in rs]
        it = [r["em_iterations"] for r in rs]
        print("| %s | %d / %d | %.5f | %.5f | %.5f | %.1f | %d | %.2f |" %
              (b, sum(bool(r["converged"]) for r in rs), len(rs), statistics.mean(ll), min(ll), max(ll),
               statistics.mean(it), max(it), statistics.mean(r["seconds_em"] for r in rs)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
