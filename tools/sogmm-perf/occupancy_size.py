#!/usr/bin/env python3
"""What an occupancy map costs in bytes (issue 31): ROC AUC against file size
for maps of several bandwidths and component precisions, beside OctoMap's
`.bt` built from the same frames, in one run.

Each variant is `sogmm map SEQUENCE --trajectory SEQUENCE/trajectory.log
--frames MAP_FRAMES --bandwidth B --component-precision P` (defaults
otherwise), scored by `sogmm-occupancy-octomap --map` on the rays of
RAY_FRAMES (occupied = the observed depth; free = 20, 50 and 80% of it and
5 cm in front of it); OctoMap is built by the same tool at --resolutions. The
table gives each map's bytes as a share of the finest `.bt`.

Usage (from the repository root; the loop is `sogmm demo --write-frame DIR --loop`):
    python3 tools/sogmm-perf/occupancy_size.py --sequence ../shared/data/rgbd/livingroom
    python3 tools/sogmm-perf/occupancy_size.py --sequence DIR --map-frames 0:300:3 --ray-frames 1:300:30
Prints a markdown table and one JSON line.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile


def json_lines(cmd):
    p = subprocess.run([str(c) for c in cmd], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit("%s failed (%d): %s" % (" ".join(map(str, cmd)), p.returncode, p.stderr.strip()))
    return [json.loads(line) for line in p.stdout.splitlines() if line.startswith("{")]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sequence", required=True)
    ap.add_argument("--map-frames", default="0:2")
    ap.add_argument("--ray-frames", default="2")
    ap.add_argument("--bandwidths", default="0.02,0.03,0.05,0.07,0.1")
    ap.add_argument("--precisions", default="0,0.5")
    ap.add_argument("--resolutions", default="0.02,0.05", help="OctoMap resolutions (m); 'none' skips OctoMap")
    ap.add_argument("--bt-bytes", type=int, help="the finest .bt's bytes from an earlier run (with --resolutions none)")
    ap.add_argument("--build", default="build")
    ap.add_argument("--work", help="folder for the maps (default: a temporary one)")
    a = ap.parse_args()
    if not os.path.isdir(a.sequence):
        print(f"sequence {a.sequence} is absent: nothing to do")
        return
    sogmm = os.path.join(a.build, "tools/sogmm/sogmm")
    bench = os.path.join(a.build, "tools/sogmm-perf/sogmm-occupancy-octomap")
    work = a.work or tempfile.mkdtemp(prefix="sogmm_occ_size_")
    os.makedirs(work, exist_ok=True)
    scored = ["--sequence", a.sequence, "--map-frames", a.map_frames, "--ray-frames", a.ray_frames, "--repeats", "1"]
    rows = []
    if a.resolutions != "none":
        for r in json_lines([bench, *scored, "--resolutions", a.resolutions]):
            if r["model"].startswith("OctoMap"):
                rows.append(dict(model=r["model"], components=None, auc=r["auc"], bytes=r["bytes"]))
    bt = rows[0]["bytes"] if rows else a.bt_bytes  # the first resolution given (the finest by default)
    for b in a.bandwidths.split(","):
        for p in a.precisions.split(","):
            path = os.path.join(work, f"map_b{b}_p{p}.sogmm")
            built = json_lines([sogmm, "map", a.sequence, "--trajectory", os.path.join(a.sequence, "trajectory.log"),
                                "--frames", a.map_frames, "--bandwidth", b, "--component-precision", p,
                                "-o", path, "--json"])[-1]
            r = json_lines([bench, *scored, "--map", path, "--resolutions", "none"])[0]
            rows.append(dict(model=f"SOGMM map, bandwidth {b}, precision {p}", components=built["n_components"],
                             auc=r["auc"], bytes=os.path.getsize(path)))
    print(f"maps from frames {a.map_frames} of {a.sequence}, rays of frames {a.ray_frames}")
    print("| model | components | ROC AUC | file bytes | of the finest .bt |")
    print("|---|---|---|---|---|")
    for r in rows:
        share = f"{100 * r['bytes'] / bt:.1f}%" if bt else "-"
        comps = r["components"] if r["components"] is not None else "-"
        print(f"| {r['model']} | {comps} | {r['auc']:.4f} | {r['bytes']:,} | {share} |")
    print(json.dumps(dict(sequence=a.sequence, map_frames=a.map_frames, ray_frames=a.ray_frames, bt_bytes=bt,
                          rows=rows)))


if __name__ == "__main__":
    main()
