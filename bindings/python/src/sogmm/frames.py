"""Frames and trajectories read by the C library itself.

``read_frame`` decodes the depth PNG and the colour PNG/JPEG with libsogmm's
reader (libpng, libjpeg-turbo with fixed settings), so Python, C, Rust and Go
get the same pixels from the same files, and ``SOGMM.fit_rgbd`` on them the
same model. ``read_trajectory`` / ``write_trajectory`` are the library's
Redwood ``.log`` reader and writer.
"""

from __future__ import annotations

import ctypes
import os
from ctypes import byref, c_void_p

import numpy as np

from . import _ffi
from ._ffi import check, lib
from .errors import InvalidArgumentError


def _pixels(address: int, dtype, count: int) -> np.ndarray:
    """A copy of `count` values at a library-owned address."""
    return np.frombuffer(ctypes.string_at(address, count * np.dtype(dtype).itemsize), dtype=dtype).copy()


def _frame_arrays(handle: c_void_p) -> tuple[np.ndarray, np.ndarray | None]:
    try:
        w, h = lib.sogmm_frame_width(handle), lib.sogmm_frame_height(handle)
        depth = _pixels(lib.sogmm_frame_depth(handle), np.uint16, w * h).reshape(h, w)
        fmt = lib.sogmm_frame_color_format(handle)
        if fmt == 0:
            return depth, None
        channels = 3 if fmt == _ffi.COLOR_RGB8 else 1
        color = _pixels(lib.sogmm_frame_color(handle), np.uint8, w * h * channels)
        return depth, color.reshape((h, w, 3) if channels == 3 else (h, w))
    finally:
        lib.sogmm_frame_free(handle)


def read_frame(depth_path: str | os.PathLike, color_path: str | os.PathLike | None = None
               ) -> tuple[np.ndarray, np.ndarray | None]:
    """Reads an RGB-D frame from image files with the library's decoder.

    Returns ``(depth, color)``: depth a (H, W) uint16 array of raw units (a
    16-bit gray PNG; 8-bit is widened), color a (H, W, 3) uint8 RGB array, a
    (H, W) uint8 gray array, or None when ``color_path`` is None. Pass them to
    ``SOGMM.fit_rgbd`` or ``Map.insert_rgbd``. Raises SogmmIOError (cannot
    read), FormatError (corrupt or truncated image), InvalidDataError (wrong
    channels or bit depth, sizes differ), LimitError (more than 2^26 pixels),
    naming the file."""
    out = c_void_p()
    color = None if color_path is None else os.fsencode(os.fspath(color_path))
    check(lib.sogmm_frame_read(byref(out), os.fsencode(os.fspath(depth_path)), color))
    return _frame_arrays(out)


def decode_frame(depth_bytes: bytes, color_bytes: bytes | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """As :func:`read_frame` from the files' bytes."""
    out = c_void_p()
    d = bytes(depth_bytes)
    c = None if color_bytes is None else bytes(color_bytes)
    check(lib.sogmm_frame_decode(byref(out), d, len(d), c, 0 if c is None else len(c)))
    return _frame_arrays(out)


def read_trajectory(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """Reads a Redwood ``.log`` trajectory: ``(ids, poses)``, ids an (n,) int64
    array (the frame each pose belongs to: the first number of its header
    line), poses (n, 4, 4) float64 camera-to-world rigid transforms, in file
    order. Raises SogmmIOError or InvalidDataError naming the file and line."""
    out = c_void_p()
    check(lib.sogmm_trajectory_read(byref(out), os.fsencode(os.fspath(path))))
    try:
        n = lib.sogmm_trajectory_size(out)
        ids = _pixels(lib.sogmm_trajectory_ids(out), np.int64, n)
        poses = _pixels(lib.sogmm_trajectory_poses(out), np.float64, 16 * n).reshape(n, 4, 4)
        return ids, poses
    finally:
        lib.sogmm_trajectory_free(out)


def write_trajectory(path: str | os.PathLike, poses) -> None:
    """Writes (n, 4, 4) camera-to-world poses as a ``.log`` file (block k with
    the header "k k+1 n"), atomically; read back bitwise. Raises
    InvalidArgumentError for an empty list or a pose that is not rigid."""
    p = np.ascontiguousarray(poses, dtype=np.float64)
    if p.ndim != 3 or p.shape[1:] != (4, 4):
        raise InvalidArgumentError(f"poses must have shape (n, 4, 4), got {p.shape}")
    check(lib.sogmm_trajectory_write(os.fsencode(os.fspath(path)), p.reshape(-1), p.shape[0]))
