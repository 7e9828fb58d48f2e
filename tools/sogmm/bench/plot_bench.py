#!/usr/bin/env python3
"""Plots of `sogmm bench` results like the paper's Fig. 4: PSNR, MRE and model
memory per method, one panel each (one bar group per frame).

Usage: plot_bench.py RESULTS.csv OUT_DIR
Writes OUT_DIR/bench_psnr.png, bench_mre.png, bench_memory.png and
bench_summary.png (the three panels stacked). Exit code 3 when matplotlib is
not installed (the bench then reports that plots were skipped), 2 for usage
errors, 1 for other failures.
"""
import csv
import math
import os
import sys


def main(argv):
    if len(argv) != 3:
        print("usage: plot_bench.py RESULTS.csv OUT_DIR", file=sys.stderr)
        return 2
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plot_bench.py: matplotlib is not installed; no plots", file=sys.stderr)
        return 3

    csv_path, out_dir = argv[1], argv[2]
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        print("plot_bench.py: no rows in " + csv_path, file=sys.stderr)
        return 1

    frames, methods = [], []
    for r in rows:
        if r["frame"] not in frames:
            frames.append(r["frame"])
        if r["method"] not in methods:
            methods.append(r["method"])
    table = {(r["frame"], r["method"]): r for r in rows}

    def value(r, key, scale=1.0):
        v = r.get(key, "")
        if v in ("", "nan"):
            return math.nan
        if v == "inf":
            return math.inf
        return float(v) * scale

    panels = [
        ("psnr", "psnr", 1.0, "PSNR (dB, honest)\nhigher is better", False),
        ("mre", "mre", 1.0, "MRE (m)\nlower is better", False),
        ("memory", "memory_bytes", 1e-6, "Model size (MB)\nlower is better", True),
    ]
    colors = {"octomap": "#4c72b0", "ndt": "#dd8452", "fc": "#55a868", "sogmm": "#c44e52"}
    family = {r["method"]: r["family"] for r in rows}

    def draw(ax, key, scale, label, logy):
        n = max(1, len(frames))
        width = 0.8 / n
        finite = [value(table[(fr, m)], key, scale) for fr in frames for m in methods if (fr, m) in table]
        finite = [v for v in finite if math.isfinite(v)]
        cap = max(finite) * 1.1 if finite else 1.0
        for i, fr in enumerate(frames):
            xs, hs, cs = [], [], []
            for j, m in enumerate(methods):
                if (fr, m) not in table:
                    continue
                v = value(table[(fr, m)], key, scale)
                if math.isnan(v):
                    continue
                xs.append(j - 0.4 + width * (i + 0.5))
                hs.append(min(v, cap))  # infinite PSNR drawn at the top
                cs.append(colors.get(family[m], "gray"))
            ax.bar(xs, hs, width=width * 0.95, color=cs, alpha=1.0 - 0.5 * i / n,
                   label=fr if len(frames) > 1 else None, edgecolor="black", linewidth=0.4)
        ax.set_xticks(range(len(methods)))
        ax.set_xticklabels(methods, rotation=30, ha="right", fontsize=8)
        ax.set_ylabel(label, fontsize=9)
        if logy:
            ax.set_yscale("log")
        ax.grid(axis="y", alpha=0.3)
        if len(frames) > 1 and len(frames) <= 8:
            ax.legend(fontsize=7, title="frame", title_fontsize=7)

    os.makedirs(out_dir, exist_ok=True)
    for name, key, scale, label, logy in panels:
        fig, ax = plt.subplots(figsize=(7, 3))
        draw(ax, key, scale, label, logy)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, "bench_%s.png" % name), dpi=120)
        plt.close(fig)
    fig, axes = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    for ax, (name, key, scale, label, logy) in zip(axes, panels):
        draw(ax, key, scale, label, logy)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "bench_summary.png"), dpi=120)
    plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
