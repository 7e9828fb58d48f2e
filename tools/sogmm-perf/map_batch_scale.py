#!/usr/bin/env python3
"""Map batch bandwidth rules side by side (issue 29 item 3): components and
per-pixel held-out accuracy of `sogmm map` variants against each frame's own fit.

For one sequence and frame range, builds each variant's map (`sogmm map` with
that variant's flags), the append-everything map (`--no-novelty`) and the own
fit of every checked frame (`sogmm fit --sequence` of that frame alone), then
scores each model with `sogmm eval --json` on the checked frames: the fields
pixel_psnr_heldout and depth_mae_heldout (eval's held-out grid: decimation
d + 1 minus the pixels of the d grid). Targets: every frame's held-out pixel
PSNR at most 0.5 dB below its own fit's, depth MAE at most 1 mm above it.

Usage (from the repository root):
    python3 tools/sogmm-perf/map_batch_scale.py --sequence DIR --frames 0:3 --check 0:3 \\
        --variant "default=" --variant "scale 0.9=--novelty-bandwidth-scale 0.9" [--sogmm S] [--work W]
A variant is NAME=FLAGS (FLAGS split on spaces, given to `sogmm map`; leading
VAR=VALUE words set that build's environment, e.g. SOGMM_ISA=sse2).
Prints a markdown table and one JSON line.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile


def run_json(cmd, env=None):
    p = subprocess.run([str(c) for c in cmd] + ["--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       env=dict(os.environ, **(env or {})))
    if p.returncode != 0:
        sys.exit("%s failed (%d): %s" % (" ".join(map(str, cmd)), p.returncode, p.stderr.strip()))
    return json.loads(p.stdout)


def cached(path, cmd):
    """run_json(cmd), which writes `path`, unless `path` and its answer are already there."""
    answer = path + ".json"
    if os.path.isfile(path) and os.path.isfile(answer):
        return json.load(open(answer))
    out = run_json(cmd)
    with open(answer, "w") as f:
        json.dump(out, f)
    return out


def per_frame(sogmm, model, seq, traj, check, decimate):
    ev = run_json([sogmm, "eval", model, "--sequence", seq, "--trajectory", traj, "--frames", check,
                   "--decimate", decimate])
    return {f["frame"]: (f["pixel_psnr_heldout"], 1000.0 * f["depth_mae_heldout"]) for f in ev["frames"]}


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sogmm", default=os.path.join(root, "build", "tools", "sogmm", "sogmm"))
    ap.add_argument("--sequence", required=True)
    ap.add_argument("--frames", required=True, help="frames mapped (sogmm --frames syntax)")
    ap.add_argument("--check", required=True, help="frames scored (sogmm --frames syntax)")
    ap.add_argument("--decimate", type=int, default=5)
    ap.add_argument("--bandwidth", type=float, default=0.02)
    ap.add_argument("--variant", action="append", required=True, help="NAME=FLAGS for sogmm map")
    ap.add_argument("--work", default=None, help="keep the models here (default: a temporary folder)")
    a = ap.parse_args()
    traj = os.path.join(a.sequence, "trajectory.log")
    common = ["--trajectory", traj, "--decimate", a.decimate, "--bandwidth", a.bandwidth]
    work = a.work or tempfile.mkdtemp(prefix="sogmm_batch_scale_")
    os.makedirs(work, exist_ok=True)
    append = os.path.join(work, "append.sogmm")
    # Append-everything and the own fits do not depend on the variants: kept
    # in --work, a second run reuses them.
    n_append = cached(append, [a.sogmm, "map", a.sequence, "--frames", a.frames, "-o", append, "--quiet",
                               "--no-novelty"] + common)["n_components"]
    rows = []
    for v in a.variant:
        name, _, flags = v.partition("=")
        words = flags.split()
        # Leading VAR=VALUE words set the environment of that build (as in a shell).
        env = dict(w.split("=", 1) for w in words if "=" in w and not w.startswith("-"))
        words = [w for w in words if not ("=" in w and not w.startswith("-"))]
        out = os.path.join(work, "map_%d.sogmm" % len(rows))
        m = run_json([a.sogmm, "map", a.sequence, "--frames", a.frames, "-o", out, "--quiet"] + common + words, env)
        rows.append({"variant": name, "flags": flags, "components": m["n_components"],
                     "share_of_append": m["n_components"] / n_append,
                     "frames": per_frame(a.sogmm, out, a.sequence, traj, a.check, a.decimate)})
    # Own fits: one per checked frame (the frames the first variant's eval
    # scored: append-everything's own eval, over tens of thousands of
    # components, would only list them), scored on that frame.
    own = {}
    own_components = {}
    frames = sorted(rows[0]["frames"])
    for k in frames:
        path = os.path.join(work, "own_%05d.sogmm" % k)
        own_components[k] = cached(path, [a.sogmm, "fit", "--sequence", a.sequence, "--frames", k, "-o", path] +
                                   common)["n_components"]
        own[k] = per_frame(a.sogmm, path, a.sequence, traj, k, a.decimate)[k]
    print("append-everything: %d components; own fits: %s" % (n_append, own_components))
    print("| model | components (%% of %d) | %s | worst PSNR loss dB (<= 0.5) | worst depth MAE +mm (<= 1) |" % (
        n_append, " | ".join("frame %d: PSNR dB / MAE mm" % k for k in frames)))
    print("|---|---|%s---|---|" % ("---|" * len(frames)))
    print("| own fits | %s | %s | | |" % (" / ".join(str(own_components[k]) for k in frames),
                                         " | ".join("%.2f / %.2f" % own[k] for k in frames)))
    for r in rows:
        f = r["frames"]
        r["worst_psnr_loss_db"] = max(own[k][0] - f[k][0] for k in frames)
        r["worst_depth_mae_increase_mm"] = max(f[k][1] - own[k][1] for k in frames)
        print("| %s | %d (%.1f%%) | %s | %.2f | %.2f |" % (
            r["variant"], r["components"], 100 * r["share_of_append"],
            " | ".join("%.2f / %.2f" % f[k] for k in frames), r["worst_psnr_loss_db"],
            r["worst_depth_mae_increase_mm"]))
    print(json.dumps({"sequence": a.sequence, "frames": a.frames, "append": n_append,
                      "own": {str(k): own[k] for k in frames}, "variants": rows}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
