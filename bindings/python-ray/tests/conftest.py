"""Fixtures of the sogmm_ray tests (a local Ray with 2 CPUs, started and
stopped here). Run as the ctest python_distributed. The test modules that need
Ray skip without it (test_without_ray.py runs either way)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

# Without installed packages (a plain checkout): the checkout's sogmm and sogmm_ray.
BINDINGS = Path(__file__).resolve().parents[2]
for src in (BINDINGS / "python" / "src", BINDINGS / "python-ray" / "src"):
    if str(src) not in sys.path:
        sys.path.append(str(src))
import sogmm  # noqa: E402

NO_RAY = "Ray is not installed (pip install 'sogmm[ray]')"

N_FRAMES = 12
BAD_FRAME = 7  # all depth invalid: the fit has no point


def _orbit_pose(i: int) -> np.ndarray:
    """Camera i of an orbit: 30 degrees apart about the vertical (y) axis,
    0.3 m from the origin (so the frames fall into several 0.5 m tiles)."""
    a = np.deg2rad(30.0 * i)
    c, s = np.cos(a), np.sin(a)
    p = np.eye(4)
    p[:3, :3] = [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    p[:3, 3] = [0.3 * s, 0.02 * i, -0.3 * c]
    return p


def _frame(i: int, width=96, height=72):
    """A room corner (back wall, floor, a box that moves with i), depth in mm, gray."""
    fx = 0.8 * width
    v, u = np.mgrid[0:height, 0:width].astype(np.float64)
    rx, ry = (u - (width - 1) / 2) / fx, (v - (height - 1) / 2) / fx
    z = np.full((height, width), 2.0 + 0.05 * i)
    z = np.minimum(z, np.where(ry > 1e-6, 0.7 / np.maximum(ry, 1e-6), np.inf))
    box = (np.abs(rx * 1.6 + 0.2 - 0.03 * i) < 0.25) & (np.abs(ry * 1.6 - 0.3) < 0.25)
    z = np.where(box, 1.4, z)
    gray = np.where(box, 0.85, 0.4 + 0.2 * np.sin(6 * rx + i) * (ry + 0.5))
    rng = np.random.default_rng(100 + i)
    depth = np.round((z + rng.normal(0, 0.002, z.shape)) * 1000).astype(np.uint16)
    if i == BAD_FRAME:
        depth[:] = 0
    return depth, np.clip(np.round(gray * 255), 0, 255).astype(np.uint8), sogmm.Camera(width, height, fx, fx,
                                                                                         (width - 1) / 2,
                                                                                         (height - 1) / 2)


def write_sequence(folder: Path, n: int = N_FRAMES) -> Path:
    Image = pytest.importorskip("PIL.Image", reason="Pillow is not installed")
    (folder / "depth").mkdir(parents=True)
    (folder / "color").mkdir()
    log = []
    for i in range(n):
        depth, gray, cam = _frame(i)
        Image.fromarray(depth).save(folder / "depth" / f"{i:05d}.png")
        Image.fromarray(gray).save(folder / "color" / f"{i:05d}.png")
        log.append(f"{i} {i + 1} {n}")
        log += [" ".join(f"{x:.17g}" for x in row) for row in _orbit_pose(i)]
    (folder / "intrinsics.json").write_text(cam.to_json())
    (folder / "trajectory.log").write_text("\n".join(log) + "\n")
    return folder


@pytest.fixture(scope="session")
def sequence(tmp_path_factory) -> Path:
    return write_sequence(tmp_path_factory.mktemp("seq"))


@pytest.fixture(scope="session")
def pid_dir(tmp_path_factory) -> Path:
    """Side channel of the worker-kill test; set before Ray starts so workers inherit it."""
    d = tmp_path_factory.mktemp("pids")
    os.environ["SOGMM_DISTRIBUTED_PID_DIR"] = str(d)
    return d


@pytest.fixture(scope="session")
def local_ray(pid_dir):
    """A local Ray with 2 CPUs for the whole session, always shut down."""
    ray = pytest.importorskip("ray", reason=NO_RAY)
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        yield ray
    finally:
        ray.shutdown()
