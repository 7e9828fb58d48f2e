#!/usr/bin/env python3
"""Cancel latency of a d = 1 fit through the Python binding (issue 16).

Each run starts a full-resolution fit (the shared livingroom frame 00000 when
present, else a synthetic 640 x 480 tilted plane with gray bands), sends
SIGINT to this process about 1 s in (from a timer thread, as Ctrl-C would)
and measures the time from the signal to the KeyboardInterrupt raised by
fit(). Prints every run and the median. With --dump FILE it instead writes the
frame's points as raw float32 (n x 4), the input of the Rust and Go
counterparts:

  python3 tools/sogmm-perf/cancel_latency.py --runs 5
  python3 tools/sogmm-perf/cancel_latency.py --dump /tmp/frame.f32
  SOGMM_LIB_DIR=build/capi cargo run --release --example cancel_latency -- /tmp/frame.f32 5
  go run ./cmd/sogmm-cancel-latency /tmp/frame.f32 5      (in bindings/go, CGO_LDFLAGS as go_test_race)
"""
from __future__ import annotations

import argparse
import os
import signal
import statistics
import sys
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
try:
    import sogmm
except ImportError:
    sys.path.insert(0, str(ROOT / "bindings" / "python" / "src"))
    import sogmm


def frame_points() -> tuple[np.ndarray, str]:
    folder = Path(os.environ.get("SOGMM_DATA_DIR", ROOT.parent / "shared" / "data")) / "rgbd" / "livingroom"
    if (folder / "depth" / "00000.png").is_file():
        from PIL import Image

        depth = np.asarray(Image.open(folder / "depth" / "00000.png"))
        color = np.asarray(Image.open(folder / "color" / "00000.jpg").convert("RGB"))
        cam = sogmm.Camera.from_json(folder / "intrinsics.json")
        return sogmm.rgbd_to_points(depth, color, cam), "livingroom 00000"
    w, h = 640, 480
    v, u = np.mgrid[0:h, 0:w]
    depth = (1000 + 0.8 * u + 0.4 * v).astype(np.uint16)
    gray = (30 + 100 * ((u * 3) // w)).astype(np.uint8)
    cam = sogmm.Camera(w, h, 525.0, 525.0, 319.5, 239.5)
    return sogmm.rgbd_to_points(depth, gray, cam), "synthetic 640x480 plane"


def one_run(points: np.ndarray, delay: float) -> float:
    sent = {}

    def interrupt():
        sent["t"] = time.perf_counter()
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(delay, interrupt)
    timer.start()
    try:
        sogmm.SOGMM(bandwidth=0.02, seed=0).fit(points)
    except KeyboardInterrupt:
        return time.perf_counter() - sent["t"]
    finally:
        timer.cancel()
    raise SystemExit("the fit ended before the interrupt: use a larger frame or a shorter --delay")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--delay", type=float, default=1.0, help="seconds from the start of the fit to SIGINT")
    ap.add_argument("--dump", help="write the frame's points (raw float32, n x 4) here and exit")
    args = ap.parse_args()
    points, what = frame_points()
    if args.dump:
        np.ascontiguousarray(points, dtype=np.float32).tofile(args.dump)
        print(f"{args.dump}: {points.shape[0]} points of {what}")
        return 0
    print(f"python: d = 1 fit of {what} ({points.shape[0]} points), SIGINT after {args.delay} s; "
          f"load average {os.getloadavg()[0]:.1f}")
    lat = []
    for r in range(args.runs):
        lat.append(one_run(points, args.delay))
        print(f"  run {r + 1}: {1000 * lat[-1]:.1f} ms")
    print(f"python cancel latency: median {1000 * statistics.median(lat):.1f} ms, max {1000 * max(lat):.1f} ms "
          f"over {args.runs} runs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
