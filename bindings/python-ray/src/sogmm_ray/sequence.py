"""Posed RGB-D sequences as `sogmm fit --sequence` reads them (tools/sogmm/sequence.cpp).

A sequence is DIR/depth/*.png (16-bit) and DIR/color/*.{jpg,jpeg,png}, sorted by
name, with DIR/intrinsics.json (Open3D PinholeCameraIntrinsic) unless a camera
is given, and a Redwood .log trajectory: per frame a header line "i j n" and
four lines of the 4 x 4 camera-to-world pose. Images and poses are paired by
frame number (00012.png, 00012.jpg and the pose "12 ..."), not by order, unless
asked (``pair_by_order``). The rules (and the error messages) follow the C++
reader so both front ends accept the same folders.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

import sogmm
from sogmm import InvalidDataError

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


_ORDER_HINT = " (give --pair-by-order to pair files by order)"


def _frame_number(path: str) -> int:
    """The frame number of an image name (00012.png: 12), -1 when the name without extension is not a number."""
    stem = Path(path).stem
    return int(stem) if 0 < len(stem) <= 18 and stem.isascii() and stem.isdigit() else -1


def _numbered(path: str) -> int:
    n = _frame_number(path)
    if n < 0:
        raise InvalidDataError(f"{path}: the name is not a frame number (as 00012.png), so it cannot be paired by "
                               f"number{_ORDER_HINT}")
    return n


def list_sequence(directory: str, pair_by_order: bool = False) -> list[tuple[str, str, int]]:
    """(depth, color, frame number) of a sequence folder, in depth-name order.

    By default a depth and a color image are paired by the frame number of
    their names; with ``pair_by_order`` the k-th depth goes with the k-th
    color and the number is -1 (the rules of tools/sogmm/sequence.cpp)."""
    d = Path(directory)
    if not d.is_dir():
        raise SogmmIOError(f"{directory}: no such folder (expected DIR/depth and DIR/color)")
    depth = _images(d / "depth", (".png",))
    color = _images(d / "color", (".jpg", ".jpeg", ".png"))
    if not depth:
        raise InvalidDataError(f"{directory}/depth: no .png depth image")
    if len(depth) != len(color):
        raise InvalidDataError(f"{directory}: {len(depth)} depth images but {len(color)} color images")
    if pair_by_order:
        return [(a, b, -1) for a, b in zip(depth, color)]
    color_of = {}
    for c in color:
        n = _numbered(c)
        if n in color_of:
            raise InvalidDataError(f"{c}: a second color image of frame {n}")
        color_of[n] = c
    out, seen = [], set()
    for a in depth:
        n = _numbered(a)
        if n in seen:
            raise InvalidDataError(f"{a}: a second depth image of frame {n}")
        seen.add(n)
        if n not in color_of:
            raise InvalidDataError(f"{a}: no color image of frame {n} in {directory}/color{_ORDER_HINT}")
        out.append((a, color_of[n], n))
    return out


def read_trajectory(path: str) -> list[tuple]:
    """Camera-to-world poses of a Redwood .log file (16 floats each, row-major), in file order."""
    return read_trajectory_log(path)[0]


def read_trajectory_log(path: str) -> tuple[list[tuple], list[int]]:
    """(poses in file order, the frame number of each: the first field of its header line "i j n"),
    read by the library's reader (sogmm.read_trajectory: the CLI's rules and messages)."""
    ids, poses = sogmm.read_trajectory(path)
    return [tuple(p.ravel().tolist()) for p in poses], [int(i) for i in ids]


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


def load_frames(directory: str, trajectory: str, frames: str = ":", pair_by_order: bool = False) -> list[Frame]:
    """The selected frames of a sequence with their poses (errors as `sogmm fit --sequence`).

    ``frames`` selects by position in name order. Each frame gets the pose
    whose header number is the frame number of its image names (00012.png:
    the pose "12 ..."); a frame without its pose, or a number two poses claim,
    is refused (InvalidDataError) unless ``pair_by_order``: then the k-th
    image goes with the k-th pose, as before."""
    files = list_sequence(directory, pair_by_order)
    poses, ids = read_trajectory_log(trajectory)
    selected = parse_frame_range(frames, len(files))
    if pair_by_order:
        if len(poses) < selected[-1] + 1:
            raise InvalidDataError(f"{trajectory}: has {len(poses)} poses but frame {selected[-1]} is selected")
        return [Frame(i, files[i][0], files[i][1], poses[i]) for i in selected]
    block_of = {}
    for k, n in enumerate(ids):
        if n in block_of:
            raise InvalidDataError(f"{trajectory}: two poses of frame {n}{_ORDER_HINT}")
        block_of[n] = k
    out = []
    for i in selected:
        depth, color, n = files[i]
        if n not in block_of:
            raise InvalidDataError(f"{trajectory}: no pose of frame {n} ({depth}){_ORDER_HINT}")
        out.append(Frame(i, depth, color, poses[block_of[n]]))
    return out
