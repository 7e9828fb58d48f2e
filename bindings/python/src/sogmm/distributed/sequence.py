"""Posed RGB-D sequences as `sogmm fit --sequence` reads them (tools/sogmm/sequence.cpp).

A sequence is DIR/depth/*.png (16-bit) and DIR/color/*.{jpg,jpeg,png}, paired in
name order, with DIR/intrinsics.json (Open3D PinholeCameraIntrinsic) unless a
camera is given, and a Redwood .log trajectory: per frame a header line
"i j n" and four lines of the 4 x 4 camera-to-world pose. The rules (and the
error messages) follow the C++ reader so both front ends accept the same folders.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InvalidArgumentError, InvalidDataError, SogmmIOError
from ..model import GMM

@dataclass(frozen=True)
class Frame:
    """One frame of a sequence: its index in name order, its images and its pose."""

    index: int
    depth: str
    color: str
    pose: tuple  # 16 floats, row-major camera-to-world


def _images(folder: Path, exts: tuple[str, ...]) -> list[str]:
    if not folder.is_dir():
        raise SogmmIOError(f"{folder}: no such folder")
    return sorted(str(p) for p in folder.iterdir() if p.is_file() and p.suffix.lower() in exts)


def list_sequence(directory: str) -> list[tuple[str, str]]:
    """(depth, color) file pairs of a sequence folder, in name order."""
    d = Path(directory)
    if not d.is_dir():
        raise SogmmIOError(f"{directory}: no such folder (expected DIR/depth and DIR/color)")
    depth = _images(d / "depth", (".png",))
    color = _images(d / "color", (".jpg", ".jpeg", ".png"))
    if not depth:
        raise InvalidDataError(f"{directory}/depth: no .png depth image")
    if len(depth) != len(color):
        raise InvalidDataError(f"{directory}: {len(depth)} depth images but {len(color)} color images")
    return list(zip(depth, color))


def _rigid_error(pose: np.ndarray, probe: GMM) -> str:
    """The library's one rigid-pose rule (core/src/pose.cpp), asked through a probe model."""
    try:
        probe.pose = pose
    except InvalidArgumentError as e:
        return str(e)
    return ""


def read_trajectory(path: str) -> list[tuple]:
    """Camera-to-world poses of a Redwood .log file (16 floats each, row-major)."""
    p = Path(path)
    if not p.is_file():
        raise SogmmIOError(f"{path}: cannot open trajectory (no such file)")
    lines = [(n + 1, s) for n, s in enumerate(p.read_text().splitlines()) if s.strip()]
    poses, i = [], 0
    probe = GMM.from_arrays([1.0], np.zeros((1, 4)), np.eye(4)[None])
    while i < len(lines):
        line_no, header = lines[i]
        fields = header.split()
        if len(fields) < 3 or not all(f.lstrip("-").isdigit() for f in fields[:3]):
            raise InvalidDataError(f"{path}:{line_no}: expected a header line 'i j n'")
        if i + 4 >= len(lines):
            raise InvalidDataError(f"{path}:{lines[-1][0]}: truncated 4x4 matrix")
        rows = []
        for line_no, text in lines[i + 1:i + 5]:
            try:
                row = [float(v) for v in text.split()[:4]]
            except ValueError:
                row = []
            if len(row) != 4 or not all(math.isfinite(v) for v in row):
                raise InvalidDataError(f"{path}:{line_no}: expected 4 finite numbers")
            rows.append(row)
        m = np.array(rows, dtype=np.float64)
        problem = _rigid_error(m, probe)
        if problem:
            raise InvalidDataError(f"{path}:{line_no}: pose {len(poses)} is not a rigid transform: {problem}")
        poses.append(tuple(m.ravel().tolist()))
        i += 5
    if not poses:
        raise InvalidDataError(f"{path}: no pose in the trajectory")
    return poses


def parse_frame_range(text: str, count: int) -> list[int]:
    """Frame numbers of "I", "A:B" (B excluded) or "A:B:STEP" among ``count`` frames."""
    def bad(why: str):
        return InvalidArgumentError(f"--frames {text}: {why}")

    parts = text.split(":")
    if not text or len(parts) > 3:
        raise bad("expected I, A:B or A:B:S")

    def number(s: str, fallback: int) -> int:
        if s == "":
            return fallback
        try:
            v = int(s)
        except ValueError:
            raise bad(f"'{s}' is not an integer") from None
        if v < 0:
            raise bad("negative frame numbers are not supported")
        return v

    if len(parts) == 1:
        i = number(parts[0], -1)
        if i >= count:
            raise bad(f"frame {i} does not exist ({count} frames)")
        return [i]
    a, b = number(parts[0], 0), min(number(parts[1], count), count)
    step = number(parts[2], 1) if len(parts) == 3 else 1
    if step < 1:
        raise bad("step must be >= 1")
    out = list(range(a, b, step))
    if not out:
        raise bad(f"selects no frame ({count} frames)")
    return out


def load_frames(directory: str, trajectory: str, frames: str = ":") -> list[Frame]:
    """The selected frames of a sequence with their poses (errors as `sogmm fit --sequence`)."""
    pairs = list_sequence(directory)
    poses = read_trajectory(trajectory)
    selected = parse_frame_range(frames, len(pairs))
    if len(poses) < selected[-1] + 1:
        raise InvalidDataError(f"{trajectory}: has {len(poses)} poses but frame {selected[-1]} is selected")
    return [Frame(i, pairs[i][0], pairs[i][1], poses[i]) for i in selected]
