"""Fitting one posed frame into a leaf partial map: the work of one Ray task.

Pure Python over the package's own library: a Ray worker imports sogmm (and so
opens libsogmm) itself; only file names, numbers and bytes cross processes.
"""

from __future__ import annotations

import dataclasses
import os
import time

import numpy as np

import sogmm
from sogmm import DEFAULTS, SOGMM, Camera, SogmmError

from .partial import leaf, reduce_partials, size_bytes
from .sequence import Frame


@dataclasses.dataclass(frozen=True)
class FitSettings:
    """The fit and depth flags of `sogmm fit --sequence` (same names; the defaults
    are the library's, sogmm.DEFAULTS), except ``threads``: 1, as each Ray task
    holds one CPU."""

    bandwidth: float = DEFAULTS.bandwidth
    n_components: int | None = None
    seed: int = DEFAULTS.seed
    n_init: int = DEFAULTS.n_init
    threads: int = 1
    tol: float = DEFAULTS.tol
    max_iter: int = DEFAULTS.max_iter
    reg_covar: float | str = "auto"  # as sogmm.SOGMM
    truncate: float = DEFAULTS.truncation_nats
    #: ``--dequantise-depth`` / ``--no-dequantise-depth``: the depth-quantisation
    #: floor (SOGMM(dequantise_depth=...)); None = the library's default (on
    #: for frames).
    dequantise_depth: bool | None = None
    decimate: int = DEFAULTS.decimation
    depth_scale: float = DEFAULTS.depth_scale
    depth_min: float = DEFAULTS.depth_min
    depth_max: float = DEFAULTS.depth_max


def read_images(frame: Frame) -> tuple[np.ndarray, np.ndarray]:
    """The frame's depth and colour, decoded by the library (sogmm.read_frame: the
    CLI's decoder, so a worker's frame is byte for byte the CLI's)."""
    return sogmm.read_frame(frame.depth, frame.color)


def test_hold(frame: int) -> None:
    """Test hook (tests/test_distributed.py kills a worker mid-task): with SOGMM_DISTRIBUTED_PID_DIR
    set, a frame listed in the file PID_DIR/hold (comma-separated ids) writes its
    worker's pid to PID_DIR/<frame>.pid on its first attempt and then waits up to
    60 s to be killed; a retry finds the pid file and runs normally."""
    pid_dir = os.environ.get("SOGMM_DISTRIBUTED_PID_DIR")
    if not pid_dir:
        return
    try:
        with open(os.path.join(pid_dir, "hold")) as f:
            held = f.read().split(",")
    except OSError:
        return
    marker = os.path.join(pid_dir, f"{frame}.pid")
    if str(frame) not in held or os.path.exists(marker):
        return
    with open(marker + ".tmp", "w") as f:
        f.write(str(os.getpid()))
    os.replace(marker + ".tmp", marker)
    time.sleep(60)


def fit_frame(frame: Frame, settings: FitSettings, camera: dict) -> tuple[dict, dict | None]:
    """(info, leaf partial map) of one frame; a bad frame gives (info with
    ``error``, None) instead of raising, so Ray retries only worker deaths."""
    test_hold(frame.index)
    start = time.perf_counter()
    info = {"frame": frame.index, "pid": os.getpid(), "error": None}
    try:
        depth, color = read_images(frame)
        model = SOGMM(bandwidth=settings.bandwidth, seed=settings.seed, tol=settings.tol, reg_covar=settings.reg_covar,
                      max_iter=settings.max_iter, n_components=settings.n_components, n_threads=settings.threads,
                      truncation_nats=settings.truncate, n_init=settings.n_init,
                      dequantise_depth=settings.dequantise_depth)
        model.fit_rgbd(depth, color, Camera(**camera), depth_scale=settings.depth_scale, depth_min=settings.depth_min,
                       depth_trunc=settings.depth_max, decimate=settings.decimate)
        part = leaf(frame.index, model.transform(np.asarray(frame.pose).reshape(4, 4)))
    except (SogmmError, OSError, ValueError) as e:
        info.update(error=f"{type(e).__name__}: {e}", seconds=time.perf_counter() - start, bytes=0)
        return info, None
    info.update(seconds=time.perf_counter() - start, bytes=size_bytes(part), n_components=model.n_components_)
    return info, part


def fit_chunk(frames: list[Frame], settings: FitSettings, camera: dict) -> tuple[list[dict], dict | None]:
    """(per-frame infos, the union of their leaf partial maps or None): the
    work of one Ray task over a chunk of frames. Chunking amortises the
    per-task cost of Ray (scheduling, two object-store entries per task, the
    driver's bookkeeping) over several fits; the union is the tree's own
    reduce, so the canonical map does not depend on the chunking. The union's
    time is recorded as ``merge_seconds`` on the last info."""
    infos, leaves = [], []
    for f in sorted(frames, key=lambda f: f.index):
        info, part = fit_frame(f, settings, camera)
        infos.append(info)
        if part is not None:
            leaves.append(part)
    start = time.perf_counter()
    part = reduce_partials(leaves)
    infos[-1]["merge_seconds"] = time.perf_counter() - start
    for info in infos:
        info["bytes"] = 0
    infos[-1]["bytes"] = size_bytes(part)
    return infos, part


def camera_dict(camera: Camera) -> dict:
    """A camera as plain fields (what crosses to the workers)."""
    return dataclasses.asdict(camera)
