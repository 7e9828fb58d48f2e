#!/usr/bin/env python3
"""Map deltas over a thin link (issue 33): replays the deltas that
`sogmm map SEQ --trajectory ... --deltas DIR` wrote through a first-in
first-out link of a fixed rate, with one keyframe (one inserted frame) per
second, and prints what the mean per keyframe hides: the deltas come in bursts
(one per fit), so the link queues them.

Which frame a delta follows: `sogmm map` writes one delta after every insert
whose row in the map's CSV says flushed=1, in frame order, and one at the end
for the final flush and the frames since (tools/sogmm/command_map.cpp); the
files are named by revision, so sorted names are in that order. The k-th delta
is created when the k-th flushed row's frame is inserted, the last extra one
when the last frame is (the time of the fit itself is not counted: a robot
that fits slower than one frame a second only delays the queue further).

Keyframe i (the i-th row of the CSV) is taken at i / fps seconds. The link
sends bytes in order at `rate` bit/s. Printed: bytes per keyframe (total over
keyframes), per delta mean and max, the link's load (mean bytes per second over
its capacity), the largest queue (bytes created but not yet sent, just after a
delta is created), the largest latency from a delta's creation to its last byte
arriving, and how many deltas found the link still busy. The queue is bounded
(drains) when the load is below 1: then every burst drains before the stream
ends unless one backlog carries into the next.

Usage (from the repository root):
    python3 tools/sogmm-perf/delta_link.py DELTAS_DIR MAP_CSV [--rate 32000] [--fps 1] [--json]
"""
import argparse
import csv
import json
import os
import sys


def delta_times(deltas_dir, csv_path, fps):
    """(creation time in s, bytes) of each delta, in order, and the number of
    keyframes. Refuses a directory whose count does not match the CSV."""
    if not os.path.isdir(deltas_dir):
        sys.exit("%s: not a folder of deltas" % deltas_dir)
    names = sorted(n for n in os.listdir(deltas_dir) if n.startswith("delta-") and n.endswith(".sogmm"))
    if not names:
        sys.exit("%s holds no delta-*.sogmm file" % deltas_dir)
    sizes = [os.path.getsize(os.path.join(deltas_dir, n)) for n in names]
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit("%s: no frames" % csv_path)
    flushed = [i for i, r in enumerate(rows) if r["flushed"] == "1"]
    if len(sizes) not in (len(flushed), len(flushed) + 1):
        sys.exit("%s holds %d deltas but %s has %d flushed frames (expected that many, or one more for the "
                 "final flush): not the same run?" % (deltas_dir, len(sizes), csv_path, len(flushed)))
    rows_of = flushed + [len(rows) - 1] * (len(sizes) - len(flushed))
    return [(i / fps, b) for i, b in zip(rows_of, sizes)], len(rows)


def simulate(deltas, rate_bytes):
    """FIFO link: each delta starts once it exists and the previous one has
    left. Returns the largest queue (bytes), the largest latency (s), the
    number of deltas that found the link busy, and when the last byte left."""
    free_at = 0.0  # when the link has sent everything queued so far
    max_queue = max_latency = 0.0
    waited = 0
    for created, size in deltas:
        backlog = max(0.0, free_at - created) * rate_bytes
        waited += backlog > 0
        max_queue = max(max_queue, backlog + size)
        free_at = max(free_at, created) + size / rate_bytes
        max_latency = max(max_latency, free_at - created)
    return max_queue, max_latency, waited, free_at


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("deltas")
    ap.add_argument("csv")
    ap.add_argument("--rate", type=float, default=32000.0, help="link rate, bit/s (default 32000)")
    ap.add_argument("--fps", type=float, default=1.0, help="keyframes per second (default 1)")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    if not (a.rate > 0 and a.fps > 0):
        sys.exit("--rate and --fps must be > 0")
    deltas, n_frames = delta_times(a.deltas, a.csv, a.fps)
    rate_bytes = a.rate / 8
    total = sum(b for _, b in deltas)
    duration = n_frames / a.fps
    max_queue, max_latency, waited, done = simulate(deltas, rate_bytes)
    res = {"keyframes": n_frames, "deltas": len(deltas), "bytes": total,
           "bytes_per_keyframe": round(total / n_frames, 1),
           "bytes_per_delta_mean": round(total / len(deltas), 1), "bytes_per_delta_max": max(b for _, b in deltas),
           "link_load": round(total / (duration * rate_bytes), 3), "max_queue_bytes": round(max_queue),
           "max_latency_s": round(max_latency, 2), "deltas_that_waited": waited,
           "last_byte_after_last_keyframe_s": round(done - (n_frames - 1) / a.fps, 2),
           "bounded": total / duration < rate_bytes}
    if a.json:
        print(json.dumps(res))
        return
    print("%d keyframes at %g/s, %d deltas, %d bytes: %.1f bytes per keyframe; per delta mean %.1f, max %d" %
          (n_frames, a.fps, len(deltas), total, res["bytes_per_keyframe"], res["bytes_per_delta_mean"],
           res["bytes_per_delta_max"]))
    print("link %g bit/s (%g bytes/s): load %.3f; largest queue %d bytes; largest latency %.2f s (creation to "
          "last byte); %d of %d deltas found the link busy; last byte %.2f s after the last keyframe; queue %s" %
          (a.rate, rate_bytes, res["link_load"], res["max_queue_bytes"], res["max_latency_s"], waited,
           len(deltas), res["last_byte_after_last_keyframe_s"],
           "bounded (load < 1: every burst drains)" if res["bounded"] else "UNBOUNDED (load >= 1)"))


if __name__ == "__main__":
    main()
