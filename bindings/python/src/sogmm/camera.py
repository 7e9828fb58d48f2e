"""Pinhole camera intrinsics and RGB-D back-projection.

:func:`rgbd_to_points` returns the points the C library fits for a frame
(``sogmm_frame_to_points_f32``: decimated pixel (u, v) is source pixel
(d u, d v), intrinsics divided by the factor, valid depth in (depth_min, depth_trunc], gray from
uint8 gray, uint8 RGB or float gray).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass

import numpy as np

from contextlib import contextmanager
from ctypes import byref, c_size_t, c_void_p

from . import _ffi
from ._input_file import read_input_file
from .errors import FormatError, InvalidArgumentError

# The library's option defaults (sogmm_option_get_info): keyword defaults read, never copied.
_D = _ffi.DEFAULTS

__all__ = ["Camera", "rgbd_to_points"]


@dataclass(frozen=True)
class Camera:
    """Pinhole intrinsics of full-size images (Open3D PinholeCameraIntrinsic names).

    Pixel (u, v) at depth z back-projects to x = (u - cx) z / fx,
    y = (v - cy) z / fy.
    """

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    def __post_init__(self):
        for name in ("width", "height"):
            v = getattr(self, name)
            if isinstance(v, bool) or int(v) != v or not (1 <= int(v) <= 2**31 - 1):
                raise InvalidArgumentError(f"Camera.{name} must be an integer in [1, 2^31-1], got {v!r}")
            object.__setattr__(self, name, int(v))
        for name in ("fx", "fy", "cx", "cy"):
            try:
                v = float(getattr(self, name))
            except (TypeError, ValueError):
                raise InvalidArgumentError(f"Camera.{name} must be a number, got {getattr(self, name)!r}") from None
            if not math.isfinite(v) or (name in ("fx", "fy") and not v > 0):
                what = "finite and > 0" if name in ("fx", "fy") else "finite"
                raise InvalidArgumentError(f"Camera.{name} = {v} is invalid (must be {what})")
            object.__setattr__(self, name, v)

    @property
    def intrinsic_matrix(self) -> np.ndarray:
        """The 3 x 3 matrix K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @classmethod
    def from_json(cls, path: str | os.PathLike) -> "Camera":
        """Reads Open3D's PinholeCameraIntrinsic JSON: {"width", "height",
        "intrinsic_matrix": 9 numbers, column-major}.

        A missing file raises FileNotFoundError (an OSError), a FIFO or any
        other file that is not regular SogmmIOError (also an OSError) at
        once; a malformed one raises FormatError naming the field."""
        text = read_input_file(path, "intrinsics file")
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as e:
            raise FormatError(f"{path}: not valid JSON ({e})") from None
        if not isinstance(doc, dict):
            raise FormatError(f"{path}: expected a JSON object")
        for field in ("width", "height", "intrinsic_matrix"):
            if field not in doc:
                raise FormatError(f"{path}: missing field '{field}'")
        k = doc["intrinsic_matrix"]
        if not isinstance(k, list) or len(k) != 9 or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in k):
            raise FormatError(f"{path}: 'intrinsic_matrix' must be a list of 9 numbers (column-major)")
        for field in ("width", "height"):
            if not isinstance(doc[field], int) or isinstance(doc[field], bool):
                raise FormatError(f"{path}: '{field}' must be an integer")
        # Column-major: [fx, 0, 0, 0, fy, 0, cx, cy, 1].
        try:
            return cls(doc["width"], doc["height"], k[0], k[4], k[6], k[7])
        except InvalidArgumentError as e:
            raise FormatError(f"{path}: {e}") from None

    def to_json(self) -> str:
        """Open3D PinholeCameraIntrinsic JSON text."""
        k = [self.fx, 0.0, 0.0, 0.0, self.fy, 0.0, self.cx, self.cy, 1.0]
        return json.dumps({"width": self.width, "height": self.height, "intrinsic_matrix": k}, indent=1)


def _as_camera(camera) -> Camera:
    if isinstance(camera, Camera):
        return camera
    raise InvalidArgumentError(f"camera must be a sogmm.Camera, got {type(camera).__name__}")


def prepare_depth(depth, camera: Camera) -> np.ndarray:
    """(H, W) raw depth as C-contiguous uint16 (no copy when it already is)."""
    d = np.asarray(depth)
    if d.ndim != 2:
        raise InvalidArgumentError(f"depth must be a 2-D (height, width) array, got shape {d.shape}")
    if d.shape != (camera.height, camera.width):
        raise InvalidArgumentError(
            f"depth has shape {d.shape} but the camera is {camera.width} x {camera.height} "
            f"(expected shape ({camera.height}, {camera.width}))"
        )
    if d.dtype == np.uint16:
        return np.ascontiguousarray(d)
    if d.dtype.kind in "iu":
        if d.size and (d.min() < 0 or d.max() > 65535):
            raise InvalidArgumentError("depth values must fit in uint16 (0..65535 raw units)")
        return np.ascontiguousarray(d, dtype=np.uint16)
    raise InvalidArgumentError(
        f"depth must hold raw integer units (uint16, depth_scale per metre), got dtype {d.dtype}; "
        "for metric float depth pass (depth_m * depth_scale).astype(np.uint16)"
    )


def prepare_color(color, camera: Camera) -> tuple[str, np.ndarray]:
    """Classifies the color image.

    Returns ("gray8", uint8 (H, W)), ("rgb8", uint8 (H, W, 3)) or
    ("grayf", float32 (H, W) in [0, 1]); C-contiguous, copied only if needed.
    RGBA uint8 drops alpha."""
    c = np.asarray(color)
    hw = (camera.height, camera.width)
    if c.shape[:2] != hw:
        raise InvalidArgumentError(f"color has shape {c.shape}, expected ({camera.height}, {camera.width}[, 3])")
    if c.ndim == 2:
        if c.dtype == np.uint8:
            return "gray8", np.ascontiguousarray(c)
        if c.dtype.kind == "f":
            return "grayf", np.ascontiguousarray(c, dtype=np.float32)
        raise InvalidArgumentError(f"a gray image must be uint8 (0..255) or float (0..1), got dtype {c.dtype}")
    if c.ndim == 3 and c.shape[2] in (3, 4):
        if c.dtype != np.uint8:
            raise InvalidArgumentError(f"an RGB image must be uint8, got dtype {c.dtype}")
        return "rgb8", np.ascontiguousarray(c[:, :, :3])
    raise InvalidArgumentError(f"color must be (H, W) gray or (H, W, 3) RGB, got shape {c.shape}")


def check_depth_options(depth_scale, depth_min, depth_trunc, decimate) -> tuple[float, float, float, int]:
    """Only what the C call cannot see: ``decimate`` must be an integer (``int()``
    would round 1.5 and turn True into 1 before C sees it). The ranges and the
    rules between the values (depth_trunc > depth_min, decimate at most the
    image's width and height) are the library's option registry's, checked when
    the options are set and at the call (InvalidArgumentError naming the value)."""
    try:
        whole = not isinstance(decimate, (bool, str)) and int(decimate) == decimate
    except (TypeError, ValueError, OverflowError):
        whole = False
    if not whole:
        raise InvalidArgumentError(f"decimate = {decimate!r} must be an integer")
    return float(depth_scale), float(depth_min), float(depth_trunc), int(decimate)


def rgbd_to_points(
    depth,
    color,
    camera: Camera,
    depth_scale: float = _D.depth_scale,
    depth_min: float = _D.depth_min,
    depth_trunc: float = _D.depth_max,
    decimate: int = _D.decimation,
) -> np.ndarray:
    """Back-projects the valid pixels of an RGB-D frame to (N, 4) float32 rows (x, y, z, gray).

    Args:
        depth: (H, W) raw depth, integer dtype (uint16), ``depth_scale`` units
            per metre, 0 = no reading.
        color: registered image: (H, W) gray uint8 or float in [0, 1], or
            (H, W, 3) RGB uint8.
        camera: intrinsics of the full-size images.
        depth_min, depth_trunc: a pixel is valid when depth_min < z <= depth_trunc (metres).
        decimate: integer factor; (W // d, H // d) pixels, pixel (u, v) read from
            source pixel (d u, d v), intrinsics divided by d, as the C library does.

    Points are in the camera frame (x right, y down, z forward), ordered row
    by row, identical to what ``SOGMM.fit_rgbd`` fits.
    """
    f = prepare_frame(depth, color, camera, depth_scale, depth_min, depth_trunc, decimate)
    n = c_size_t(0)
    # The options handle checks the values first (the registry's ranges).
    with _ffi.Options(f64=f.f64, i64=f.i64) as o, f.handle() as frame:
        d = f.i64[_ffi.OPT_DECIMATION]
        capacity = 4 * (f.camera.width // d) * (f.camera.height // d)  # every decimated pixel valid
        out = np.empty(capacity, dtype=np.float32)
        _ffi.check(_ffi.lib.sogmm_frame_to_points_f32(out, capacity, byref(n), frame, o.ptr))
    return out[: 4 * n.value].reshape(n.value, 4).copy()


_COLOR_FORMATS = {"gray8": _ffi.COLOR_GRAY8, "rgb8": _ffi.COLOR_RGB8, "grayf": _ffi.COLOR_GRAY_F32}


@dataclass(frozen=True)
class PreparedFrame:
    """An RGB-D frame checked and laid out as sogmm_frame_from_arrays takes it."""

    camera: Camera
    depth: np.ndarray  # (H, W) C-contiguous uint16
    color: np.ndarray  # the color image's bytes, flat
    color_format: int  # SOGMM_COLOR_*
    f64: dict  # back-projection options (depth scale and range)
    i64: dict  # (decimation)

    @contextmanager
    def handle(self):
        """The frame as a C ``sogmm_frame`` (sogmm_frame_from_arrays with the
        camera's intrinsics), freed when the block ends."""
        c = self.camera
        h = c_void_p()
        _ffi.check(_ffi.lib.sogmm_frame_from_arrays(byref(h), c.width, c.height, self.depth,
                                                    self.color.ctypes.data, self.color_format))
        try:
            _ffi.check(_ffi.lib.sogmm_frame_set_intrinsics(h, c.fx, c.fy, c.cx, c.cy))
            yield h
        finally:
            _ffi.lib.sogmm_frame_free(h)


def prepare_frame(depth, color, camera, depth_scale, depth_min, depth_trunc, decimate) -> PreparedFrame:
    """Checks a frame and its back-projection options (InvalidArgumentError)."""
    camera = _as_camera(camera)
    d = prepare_depth(depth, camera)
    kind, c = prepare_color(color, camera)
    depth_scale, depth_min, depth_trunc, dec = check_depth_options(depth_scale, depth_min, depth_trunc, decimate)
    return PreparedFrame(
        camera=camera,
        depth=d,
        color=c.reshape(-1).view(np.uint8),
        color_format=_COLOR_FORMATS[kind],
        f64={_ffi.OPT_DEPTH_SCALE: depth_scale, _ffi.OPT_DEPTH_MIN: depth_min, _ffi.OPT_DEPTH_MAX: depth_trunc},
        i64={_ffi.OPT_DECIMATION: dec},
    )
