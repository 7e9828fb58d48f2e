#!/usr/bin/env python3
"""Fit a SOGMM to one RGB-D frame and write a PLY of samples from the model.

Uses ../shared/data/rgbd/livingroom frame 00000 at decimate 5 when that
folder exists (reading the images needs Pillow), else a synthetic scene made
here with numpy. Prints M, the EM iterations and the mean log-likelihood.

    python3 fit_rgbd.py [--data DIR] [--out samples.ply] [--bandwidth 0.02]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

import sogmm


def find_livingroom(explicit: str | None) -> Path | None:
    candidates = [Path(explicit)] if explicit else []
    env = os.environ.get("SOGMM_DATA_DIR")
    if env:
        candidates.append(Path(env) / "rgbd" / "livingroom")
    here = Path(__file__).resolve()
    # <repo>/bindings/python/examples/fit_rgbd.py -> <repo>/../shared/data
    candidates += [p / "shared" / "data" / "rgbd" / "livingroom" for p in here.parents]
    candidates.append(Path("/work/shared/data/rgbd/livingroom"))
    for c in candidates:
        if (c / "depth" / "00000.png").is_file() and (c / "color" / "00000.jpg").is_file():
            return c
    return None


def synthetic_frame(width: int = 320, height: int = 240):
    """A room corner seen by a pinhole camera: floor, back wall, a box; depth in mm."""
    cam = sogmm.Camera(width, height, 0.8 * width, 0.8 * width, (width - 1) / 2, (height - 1) / 2)
    v, u = np.mgrid[0:height, 0:width].astype(np.float64)
    rx, ry = (u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy
    z = np.full((height, width), 2.5)  # back wall at 2.5 m
    floor = ry > 1e-6
    z_floor = np.where(floor, 0.8 / np.maximum(ry, 1e-6), np.inf)  # floor 0.8 m below the camera
    z = np.minimum(z, z_floor)
    box = (np.abs(rx * 1.6 + 0.2) < 0.25) & (np.abs(ry * 1.6 - 0.3) < 0.25)
    z = np.where(box, 1.6, z)
    gray = np.where(box, 0.85, np.where(z == z_floor, 0.35 + 0.1 * np.sin(8 * rx), 0.6 + 0.2 * ry))
    rng = np.random.default_rng(7)
    depth = np.round((z + rng.normal(0, 0.002, z.shape)) * 1000).astype(np.uint16)
    color = np.clip(np.round(gray * 255), 0, 255).astype(np.uint8)
    return depth, color, cam, 2


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", help="folder with depth/00000.png, color/00000.jpg, intrinsics.json")
    ap.add_argument("--out", default="sogmm_samples.ply", help="PLY file of samples (default %(default)s)")
    ap.add_argument("--bandwidth", type=float, default=0.02)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--samples", type=int, default=200_000)
    ap.add_argument("--synthetic", action="store_true", help="use the synthetic scene even if data exist")
    args = ap.parse_args(argv)

    folder = None if args.synthetic else find_livingroom(args.data)
    frame = None
    if folder is not None:
        try:
            from PIL import Image
        except ImportError:
            print(f"found {folder} but Pillow is not installed (pip install pillow): using the synthetic scene")
        else:
            depth = np.asarray(Image.open(folder / "depth" / "00000.png"))
            color = np.asarray(Image.open(folder / "color" / "00000.jpg").convert("RGB"))
            cam = sogmm.Camera.from_json(folder / "intrinsics.json")
            frame = (depth, color, cam, 5)
            print(f"frame: {folder}/{{depth,color}}/00000 ({cam.width}x{cam.height}), decimate 5")
    if frame is None:
        frame = synthetic_frame()
        print(f"frame: synthetic scene ({frame[2].width}x{frame[2].height}), decimate {frame[3]}")
    depth, color, cam, decimate = frame

    print(f"libsogmm {sogmm.library_version()} from {sogmm.library_path()}")
    points = sogmm.rgbd_to_points(depth, color, cam, decimate=decimate)
    t0 = time.perf_counter()
    model = sogmm.SOGMM(bandwidth=args.bandwidth, seed=args.seed).fit_rgbd(depth, color, cam, decimate=decimate)
    seconds = time.perf_counter() - t0
    print(f"points N          {points.shape[0]}")
    print(f"components M      {model.n_components_}")
    print(f"EM iterations     {model.n_iter_} ({'converged' if model.converged_ else 'not converged'})")
    print(f"log-likelihood    {model.lower_bound_:.4f} (mean per point, fit)")
    print(f"score(points)     {model.score(points):.4f}")
    print(f"fit time          {seconds:.2f} s")
    samples = model.sample(args.samples, seed=args.seed)
    sogmm.write_ply(args.out, samples)
    print(f"wrote {args.samples} samples to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
