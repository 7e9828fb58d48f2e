"""SOGMM: Self-Organizing Gaussian Mixture Models for RGB-D frames.

A pure-Python (ctypes) binding of the C library libsogmm. Quick start::

    import sogmm
    cam = sogmm.Camera.from_json("intrinsics.json")
    model = sogmm.SOGMM(bandwidth=0.02).fit_rgbd(depth, color, cam, decimate=5)
    print(model.n_components_, model.lower_bound_)
    sogmm.write_ply("samples.ply", model.sample(100_000, seed=0))
"""

from __future__ import annotations

from . import _ffi
from ._ffi import DEFAULTS, option_info
from .camera import Camera, rgbd_to_points
from .errors import (
    BufferTooSmallError,
    CancelledError,
    FormatError,
    InternalError,
    InvalidArgumentError,
    InvalidDataError,
    LimitError,
    MapBusyError,
    NotFittedError,
    NotFoundError,
    NullArgumentError,
    NumericError,
    SogmmError,
    SogmmIOError,
    SogmmMemoryError,
)
from .frames import decode_frame, read_frame, read_trajectory, write_trajectory
from .map import Map
from .metrics import PSNR, psnr_images
from .model import GMM, SOGMM, from_bytes, load
from .ply import read_ply, write_ply
from .registration import register

__version__ = "0.1.0"

#: States of Map.occupancy(points, return_state=True).
OCCUPANCY_FREE = _ffi.OCCUPANCY_FREE
OCCUPANCY_OCCUPIED = _ffi.OCCUPANCY_OCCUPIED
OCCUPANCY_UNKNOWN = _ffi.OCCUPANCY_UNKNOWN

#: ABI version this package expects (checked against the loaded library on import).
ABI_VERSION = _ffi.ABI_VERSION


def library_version() -> str:
    """Version string of the loaded libsogmm ("MAJOR.MINOR.PATCH")."""
    return _ffi.lib.sogmm_version_string().decode("ascii")


def library_path() -> str:
    """File the C library was loaded from."""
    return str(_ffi.library_path)


__all__ = [
    "DEFAULTS",
    "option_info",
    "decode_frame",
    "read_frame",
    "read_trajectory",
    "write_trajectory",
    "ABI_VERSION",
    "BufferTooSmallError",
    "CancelledError",
    "MapBusyError",
    "Camera",
    "FormatError",
    "GMM",
    "InternalError",
    "InvalidArgumentError",
    "InvalidDataError",
    "LimitError",
    "Map",
    "NotFittedError",
    "NotFoundError",
    "NullArgumentError",
    "OCCUPANCY_FREE",
    "OCCUPANCY_OCCUPIED",
    "OCCUPANCY_UNKNOWN",
    "NumericError",
    "PSNR",
    "SOGMM",
    "SogmmError",
    "SogmmIOError",
    "SogmmMemoryError",
    "from_bytes",
    "library_path",
    "library_version",
    "load",
    "psnr_images",
    "read_ply",
    "register",
    "rgbd_to_points",
    "write_ply",
]
