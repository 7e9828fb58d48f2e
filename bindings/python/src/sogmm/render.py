"""Rendering a model or map from a pinhole camera (``sogmm_model_render_f32``,
``sogmm_map_render_f32``): :meth:`GMM.render` and :meth:`Map.render` call
:func:`render_images`."""

from __future__ import annotations

import numpy as np

from . import _ffi
from ._ffi import check
from .camera import Camera
from .errors import InvalidArgumentError, LimitError
from .progress import ProgressArg, call_with_progress

#: SOGMM_MAX_RENDER_PIXELS of sogmm.h: the largest width * height a render takes.
MAX_RENDER_PIXELS = 1 << 26


def render_images(fn, handle, camera: Camera, pose, depth_min: float, depth_trunc: float, n_threads: int,
                  progress: ProgressArg) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Runs ``fn`` (one of the two C functions) on ``handle``; returns depth,
    gray and variance as float32 (height, width) arrays, NaN where the model
    shows nothing."""
    from .model import _pose  # model imports nothing from here: no cycle at import time

    if not isinstance(camera, Camera):
        raise InvalidArgumentError(f"camera must be a sogmm.Camera, got {type(camera).__name__}")
    p = np.eye(4) if pose is None else _pose(pose)
    if camera.width * camera.height > MAX_RENDER_PIXELS:  # before allocating the images
        raise LimitError(f"render: {camera.width} x {camera.height} pixels exceed {MAX_RENDER_PIXELS}")
    shape = (camera.height, camera.width)
    depth = np.empty(shape, dtype=np.float32)
    gray = np.empty(shape, dtype=np.float32)
    var = np.empty(shape, dtype=np.float32)
    with _ffi.Options(f64={_ffi.OPT_DEPTH_MIN: depth_min, _ffi.OPT_DEPTH_MAX: depth_trunc},
                      i64={_ffi.OPT_THREADS: n_threads}) as o:
        call_with_progress(o, progress, lambda: fn(handle, camera.width, camera.height, camera.fx, camera.fy,
                                                   camera.cx, camera.cy, p, o.ptr, depth, gray, var))
    return depth, gray, var


__all__ = ["render_images"]
