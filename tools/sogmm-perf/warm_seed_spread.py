#!/usr/bin/env python3
"""Warm-started next frame against its cold fit, over seeds (issue 35's warm line).

One seed compares one cold fit with one warm fit, and both move with the
k-means++ seed by more than they differ (livingroom 00001 at d = 5, bandwidth
0.02: cold PSNR 30.03-30.81 dB over seeds 0-9). So this runs
`sogmm-bench-warm` (frame B fitted cold, and warm from frame A's fit of the
same seed moved by the relative pose, EM limited by the core's default warm
pass limit or --warm-max-iter) for seeds 0..S-1 on each pair and prints, per
pair, the cold and warm mean log-likelihood and PSNR (mean and range over the
seeds), how many seeds the warm fit is at least as good on, and the warm/cold
time ratio (median and largest). --sweep-max-iter adds one row per pass limit
(the same cold fits; one warm fit each) and --bench-args passes the warm fit's
other settings (e.g. --min-mass, --warm-tol-standard-errors,
--warm-em-acceleration 1).

Usage (from the repository root):
    python3 tools/sogmm-perf/warm_seed_spread.py [--bench build/tools/sogmm-perf/sogmm-bench-warm]
        [--data ../shared/data/rgbd/livingroom] [--pairs 0:1,1:2] [--seeds 10] [--warm-max-iter 8]
        [--threads 1] [--sweep-max-iter 6,8,10] [--bench-args "--min-mass 0.5"]
Prints a markdown table and one JSON line.
"""
import argparse
import json
import os
import statistics
import subprocess


def run(bench, data, a, b, seed, warm_max_iter, threads, extra):
    cap = [] if warm_max_iter is None else ["--warm-max-iter", str(warm_max_iter)]
    out = subprocess.run(
        [bench, "--sequence", data, "--trajectory", os.path.join(data, "trajectory.log"), "--from", str(a), "--to",
         str(b), "--decimate", "5", "--bandwidth", "0.02", "--threads", str(threads), "--repeat", "1", "--seed",
         str(seed)] + cap + extra,
        check=True, capture_output=True, text=True).stdout
    lines = [json.loads(line) for line in out.strip().splitlines() if line.startswith("{")]
    lines[-1]["sweep"] = lines[:-1]
    return lines[-1]


def spread(values):
    return {"mean": statistics.mean(values), "min": min(values), "max": max(values)}


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bench", default=os.path.join(root, "build", "tools", "sogmm-perf", "sogmm-bench-warm"))
    ap.add_argument("--data", default=os.path.join(os.path.dirname(root), "shared", "data", "rgbd", "livingroom"))
    ap.add_argument("--pairs", default="0:1,1:2", help="A:B pairs, comma separated (B warm-started from A)")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--warm-max-iter", type=int, default=None,
                    help="EM passes of the warm fit (0: as the cold fit); default: the bench's (the core's default)")
    ap.add_argument("--sweep-max-iter", default="",
                    help="pass caps, comma separated: per pair one more row each (warm LL and PSNR: mean, mean and "
                         "smallest difference to the cold fit [min], seeds warm >= cold; M; median time ratio of one "
                         "untimed-repeat fit)")
    ap.add_argument("--bench-args", default="",
                    help="more sogmm-bench-warm flags for the warm fit, e.g. '--min-mass 0.5 --warm-squarem'")
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    if not os.path.isdir(args.data):
        print(f"data folder {args.data} is absent: nothing to do")
        return
    extra = args.bench_args.split()
    sweep = [int(v) for v in args.sweep_max_iter.split(",")] if args.sweep_max_iter else []
    if sweep:
        extra += ["--sweep-max-iter", args.sweep_max_iter]
    rows = []
    cap = "the default cap" if args.warm_max_iter is None else f"{args.warm_max_iter}"
    print(f"warm EM: passes {cap}, flags '{args.bench_args}'; seeds 0-{args.seeds - 1}, d = 5, bandwidth 0.02, "
          f"{args.threads} thread(s), load average {os.getloadavg()[0]:.1f}")
    if sweep:
        print("cap rows: | pair | cap P | warm LL: mean, mean warm - cold [smallest], seeds warm >= cold | "
              "the same for PSNR | warm M | median warm / cold time |")
    print("| pair | figure | cold: mean [min, max] | warm: mean [min, max] | seeds warm >= cold |")
    print("|---|---|---|---|---|")
    for pair in args.pairs.split(","):
        a, b = (int(v) for v in pair.split(":"))
        runs = [run(args.bench, args.data, a, b, s, args.warm_max_iter, args.threads, extra) for s in range(args.seeds)]
        row = {"pair": f"{a}->{b}", "seeds": args.seeds}
        for name, key in (("log-likelihood", "ll"), ("PSNR (dB)", "psnr")):
            cold = spread([r[f"{key}_cold"] for r in runs])
            warm = spread([r[f"{key}_warm"] for r in runs])
            wins = sum(r[f"{key}_warm"] >= r[f"{key}_cold"] for r in runs)
            row[key] = {"cold": cold, "warm": warm, "warm_at_least_cold": wins}
            print(f"| {a}->{b} | {name} | {cold['mean']:.3f} [{cold['min']:.3f}, {cold['max']:.3f}] | "
                  f"{warm['mean']:.3f} [{warm['min']:.3f}, {warm['max']:.3f}] | {wins} of {args.seeds} |")
        ratios = [r["s_warm"] / r["s_cold"] for r in runs]
        row["per_seed"] = [{k: r[k] for k in ("ll_cold", "ll_warm", "psnr_cold", "psnr_warm", "m_cold", "m_warm",
                                              "iter_cold", "iter_warm")} for r in runs]
        row["time_ratio"] = {"median": statistics.median(ratios), "max": max(ratios)}
        print(f"| {a}->{b} | warm / cold time | | median {row['time_ratio']['median']:.2f}, "
              f"largest {row['time_ratio']['max']:.2f} | |")
        for i, cap in enumerate(sweep):
            fits = [r["sweep"][i] for r in runs]
            cells = []
            for key in ("ll", "psnr"):
                delta = [f[f"{key}_warm"] - r[f"{key}_cold"] for f, r in zip(fits, runs)]
                cells.append(f"{statistics.mean(f[f'{key}_warm'] for f in fits):.3f}, "
                             f"{statistics.mean(delta):+.3f} [{min(delta):+.3f}], {sum(d >= 0 for d in delta)}")
            ratio = statistics.median(f["s_warm"] / r["s_cold"] for f, r in zip(fits, runs))
            print(f"| {a}->{b} | cap {cap} | {cells[0]} | {cells[1]} | "
                  f"{statistics.mean(f['m_warm'] for f in fits):.0f} | {ratio:.2f} |")
            row.setdefault("sweep", []).append(fits)
        rows.append(row)
    print(json.dumps({"warm_max_iter": args.warm_max_iter, "bench_args": args.bench_args, "threads": args.threads, "rows": rows}))


if __name__ == "__main__":
    main()
