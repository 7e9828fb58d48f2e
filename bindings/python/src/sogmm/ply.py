"""Binary PLY output of (x, y, z, gray) points for MeshLab, CloudCompare or Open3D."""

from __future__ import annotations

import os
import tempfile

import numpy as np

from .errors import InvalidArgumentError

__all__ = ["write_ply"]

_VERTEX = np.dtype(
    [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4"), ("red", "u1"), ("green", "u1"), ("blue", "u1")]
)


def write_ply(path: str | os.PathLike, points) -> None:
    """Writes (N, 4) points (x, y, z, gray in [0, 1]) as a binary little-endian PLY.

    Each vertex has float x, y, z, float intensity (the gray value) and uchar
    red = green = blue = round(clip(gray, 0, 1) * 255). The file is written to
    a temporary file in the same folder and renamed into place, so a reader
    never sees a partial file and a failed write leaves any old file intact."""
    p = np.asarray(points)
    if p.dtype.kind not in "biuf" or p.ndim != 2 or p.shape[1] != 4:
        raise InvalidArgumentError(f"points must be a real (N, 4) array (x, y, z, gray), got shape {p.shape} dtype {p.dtype}")
    n = p.shape[0]
    v = np.empty(n, dtype=_VERTEX)
    v["x"], v["y"], v["z"], v["intensity"] = (p[:, i].astype(np.float32) for i in range(4))
    g = np.rint(np.clip(np.nan_to_num(p[:, 3].astype(np.float64), nan=0.0), 0.0, 1.0) * 255.0).astype(np.uint8)
    v["red"] = v["green"] = v["blue"] = g
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment written by sogmm (x, y, z metres; intensity = gray)\n"
        f"element vertex {n}\n"
        "property float x\nproperty float y\nproperty float z\nproperty float intensity\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
    ).encode("ascii")
    target = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(target))
    fd, tmp = tempfile.mkstemp(prefix=".sogmm-ply-", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(header)
            f.write(v.tobytes())
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def read_ply(path: str | os.PathLike) -> np.ndarray:
    """Reads back a PLY written by write_ply as (N, 4) float32 (x, y, z, intensity)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    if header[:2] != ["ply", "format binary_little_endian 1.0"]:
        raise InvalidArgumentError(f"{path}: not a binary little-endian PLY")
    n = next(int(line.split()[2]) for line in header if line.startswith("element vertex"))
    v = np.frombuffer(data, dtype=_VERTEX, count=n, offset=end)
    return np.stack([v["x"], v["y"], v["z"], v["intensity"]], axis=1)
