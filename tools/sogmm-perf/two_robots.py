#!/usr/bin/env python3
"""Two robots, one map (issue 33): each robot maps half of the synthetic loop
in its own frame and sends its deltas; a third process merges both streams
into one world map, taking robot B's frame from the known relative pose.

1. `sogmm demo --write-frame DIR --loop` (300 frames);
2. robot A maps frames [0, N/2) with their poses, robot B frames [N/2, N)
   with its poses relative to its first frame (its own world), each with
   `sogmm map --deltas`;
3. the merger follows each stream with a receiver (Map.apply_delta: bitwise
   the robot's map) and merges the two into one world model: B's map moved
   by the relative pose (GMM.transform) and merged with A's (GMM.merge:
   weights by support size). (Re-observing each receiver's map from its
   frames' poses into one novelty map was tried first: on a 60-frame loop it
   kept 3x the single map's components, since the renders differ from the
   maps' own frames everywhere.) With --map-merge, the same run also merges
   the two receivers with the core's map-to-map merge (Map.merge_map,
   core/src/map_merge.cpp: where both maps hold a surface the sharper view
   wins instead of both being stacked) and evaluates it beside the plain one;
4. the single-robot map of the whole loop (`sogmm map` over all frames) and
   the merged map are evaluated per pixel on the same frames (`sogmm eval`,
   held-out pixel PSNR), and their components are counted.
Targets (issue 33): merged within 0.5 dB held-out pixel PSNR of the
single-robot map, with at most 1.2x its components.

Usage (from the repository root, after building):
    SOGMM_LIBRARY_PATH=build/capi/libsogmm.so PYTHONPATH=bindings/python/src \\
      python3 tools/sogmm-perf/two_robots.py [--frames 300] [--eval-step 10] [--map-merge] [--robot-alone] [--work /tmp/two_robots]
Prints a table and one JSON line.
"""
import argparse
import json
import os
import shutil
import subprocess

import numpy as np

import sogmm


def run_json(cmd):
    return json.loads(subprocess.run(cmd + ["--json"], check=True, stdout=subprocess.PIPE, text=True).stdout)


def write_log(path, ids, poses):
    with open(path, "w") as f:
        for i, p in zip(ids, poses):
            f.write("%d %d %d\n" % (i, i, i + 1))
            f.write("".join(" ".join("%.17g" % v for v in row) + "\n" for row in p))


def follow(deltas_dir):
    """A receiver that applied every delta of a robot's stream, in order."""
    r = sogmm.Map()
    for name in sorted(os.listdir(deltas_dir)):
        with open(os.path.join(deltas_dir, name), "rb") as f:
            r.apply_delta(f.read())
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sogmm", default="build/tools/sogmm/sogmm")
    ap.add_argument("--frames", type=int, default=300)
    ap.add_argument("--decimate", type=int, default=5)
    ap.add_argument("--eval-step", type=int, default=10)
    ap.add_argument("--work", default="/tmp/two_robots")
    ap.add_argument("--robot-alone", action="store_true",
                    help="also evaluate each robot's map alone (B moved to the world) on the frames of its half")
    ap.add_argument("--map-merge", action="store_true",
                    help="also merge with Map.merge_map and evaluate it beside the plain merge")
    a = ap.parse_args()
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    loop = os.path.join(a.work, "loop")
    subprocess.run([a.sogmm, "demo", "--write-frame", loop, "--loop", "--frames", str(a.frames)], check=True,
                   stdout=subprocess.DEVNULL)
    traj = os.path.join(loop, "trajectory.log")
    ids, poses = sogmm.read_trajectory(traj)
    half = a.frames // 2
    relative = poses[half]  # robot B's frame in the world: the known relative pose
    log_b = os.path.join(a.work, "robot_b.log")
    write_log(log_b, ids[half:], [np.linalg.inv(relative) @ p for p in poses[half:]])
    common = ["--decimate", str(a.decimate), "-q"]
    robots = {}
    for name, log, frames in (("a", traj, "0:%d" % half), ("b", log_b, "%d:%d" % (half, a.frames))):
        deltas = os.path.join(a.work, "deltas_" + name)
        robots[name] = run_json([a.sogmm, "map", loop, "--trajectory", log, "--frames", frames, "-o",
                                 os.path.join(a.work, name + ".sogmm"), "--deltas", deltas] + common)
        robots[name]["delta_bytes"] = sum(os.path.getsize(os.path.join(deltas, n)) for n in os.listdir(deltas))
    single = os.path.join(a.work, "single.sogmm")
    one = run_json([a.sogmm, "map", loop, "--trajectory", traj, "-o", single] + common)

    d = a.decimate
    merged = os.path.join(a.work, "merged.sogmm")
    with follow(os.path.join(a.work, "deltas_a")) as ra, follow(os.path.join(a.work, "deltas_b")) as rb:
        assert ra.n_components_ == robots["a"]["n_components"] and rb.n_components_ == robots["b"]["n_components"]
        world = ra.export().merge(rb.export().transform(relative))
        world.save(merged)
        merged_components = world.n_components_
        if a.map_merge:
            map_merged = os.path.join(a.work, "map_merged.sogmm")
            merge_stats = ra.merge_map(rb, relative)
            ra.save(map_merged)
            map_merged_components = ra.n_components_

    frames = "0:%d:%d" % (a.frames, a.eval_step)
    ev = {m: run_json([a.sogmm, "eval", path, "--sequence", loop, "--trajectory", traj, "--frames", frames,
                       "--decimate", str(d), "--intrinsics", os.path.join(loop, "intrinsics.json")])
          for m, path in (("single", single), ("merged", merged)) + ((("map_merged", map_merged),) if a.map_merge else ())}
    per_frame = [(s["frame"], s["pixel_psnr_heldout"], m["pixel_psnr_heldout"])
                 for s, m in zip(ev["single"]["frames"], ev["merged"]["frames"])]
    worst = min(m - s for _, s, m in per_frame)
    res = {"frames": a.frames, "robot_a_components": robots["a"]["n_components"],
           "robot_b_components": robots["b"]["n_components"],
           "delta_bytes": robots["a"]["delta_bytes"] + robots["b"]["delta_bytes"],
           "single_components": one["n_components"], "merged_components": merged_components,
           "components_ratio": merged_components / one["n_components"],
           "single_pixel_psnr_heldout": ev["single"]["mean"]["pixel_psnr_heldout"],
           "merged_pixel_psnr_heldout": ev["merged"]["mean"]["pixel_psnr_heldout"],
           "worst_frame_psnr_difference": worst}
    print("robots: A %d components, B %d; deltas %d bytes" % (res["robot_a_components"], res["robot_b_components"],
                                                             res["delta_bytes"]))
    print("single-robot map: %d components; merged: %d (%.2fx)" % (one["n_components"], merged_components,
                                                                  res["components_ratio"]))
    print("held-out pixel PSNR, frames %s: single %.2f dB, merged %.2f dB; worst frame merged - single %.2f dB" %
          (frames, res["single_pixel_psnr_heldout"], res["merged_pixel_psnr_heldout"], worst))
    if a.robot_alone:
        # Whether a gap is the merge's or a robot's own: each robot's map on
        # its own half's frames, beside the single-robot map there.
        sogmm.GMM.load(os.path.join(a.work, "b.sogmm")).transform(relative).save(os.path.join(a.work, "b_world.sogmm"))
        alone = {}
        for name, path, first, end in (("a", "a.sogmm", 0, half), ("b", "b_world.sogmm", half, a.frames)):
            r = run_json([a.sogmm, "eval", os.path.join(a.work, path), "--sequence", loop, "--trajectory", traj,
                          "--frames", "%d:%d:%d" % (first, end, a.eval_step), "--decimate", str(d),
                          "--intrinsics", os.path.join(loop, "intrinsics.json")])
            alone[name] = {f["frame"]: f["pixel_psnr_heldout"] for f in r["frames"]}
        res["robot_alone_pixel_psnr_heldout"] = alone
        for name in ("a", "b"):
            print("robot %s alone on its half: " % name.upper() +
                  ", ".join("%d: %.2f (single %.2f)" % (f, v, next(s for g, s, _ in per_frame if g == f))
                            for f, v in sorted(alone[name].items()) if any(g == f for g, _, _ in per_frame)))
    if a.map_merge:
        mm = [f["pixel_psnr_heldout"] for f in ev["map_merged"]["frames"]]
        mm_worst = min(x - s for (_, s, _), x in zip(per_frame, mm))
        res.update({"map_merged_components": map_merged_components,
                    "map_merged_components_ratio": map_merged_components / one["n_components"],
                    "map_merged_pixel_psnr_heldout": ev["map_merged"]["mean"]["pixel_psnr_heldout"],
                    "map_merged_worst_frame_psnr_difference": mm_worst, "map_merge": merge_stats})
        print("map merge (Map.merge_map): %d components (%.2fx; A kept %d, removed %d; B added %d, left out %d); "
              "held-out pixel PSNR %.2f dB; worst frame map-merged - single %.2f dB" %
              (map_merged_components, res["map_merged_components_ratio"], merge_stats["n_kept"],
               merge_stats["n_removed"], merge_stats["n_added"], merge_stats["n_skipped"],
               res["map_merged_pixel_psnr_heldout"], mm_worst))
    for i, (f, s, m) in enumerate(per_frame):
        print("  frame %3d: single %.2f, merged %.2f" % (f, s, m) +
              (", map-merged %.2f" % mm[i] if a.map_merge else ""))
    print(json.dumps(res))


if __name__ == "__main__":
    main()
