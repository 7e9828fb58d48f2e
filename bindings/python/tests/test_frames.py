"""sogmm.read_frame / decode_frame and the .log trajectory reader and writer
(the C library's, so every language reads the same pixels)."""

from __future__ import annotations

import os
import struct
import zlib

import numpy as np
import pytest

import sogmm
from conftest import data_dir


def png_bytes(pixels: np.ndarray, bit_depth: int, color_type: int) -> bytes:
    """A PNG built here, byte by byte (filter 0 on every row): the test's own truth."""
    h, w = pixels.shape[:2]
    raw = pixels.astype(">u2" if bit_depth == 16 else "u1").reshape(h, -1).tobytes()
    row = len(raw) // h
    body = b"".join(b"\0" + raw[i * row:(i + 1) * row] for i in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", w, h, bit_depth, color_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(body)) + chunk(b"IEND", b"")


def test_decode_frame_gives_the_pixels_of_the_files():
    rng = np.random.default_rng(3)
    depth = rng.integers(0, 65536, size=(5, 7), dtype=np.uint16)
    rgb = rng.integers(0, 256, size=(5, 7, 3), dtype=np.uint8)
    d, c = sogmm.decode_frame(png_bytes(depth, 16, 0), png_bytes(rgb, 8, 2))
    assert d.dtype == np.uint16 and np.array_equal(d, depth)
    assert c.dtype == np.uint8 and np.array_equal(c, rgb)
    d, c = sogmm.decode_frame(png_bytes(depth, 16, 0))
    assert c is None and np.array_equal(d, depth)
    gray = rng.integers(0, 256, size=(5, 7), dtype=np.uint8)
    _, c = sogmm.decode_frame(png_bytes(depth, 16, 0), png_bytes(gray, 8, 0))
    assert c.shape == (5, 7) and np.array_equal(c, gray)


def test_hostile_frames_raise_the_documented_errors(tmp_path):
    depth = np.arange(35, dtype=np.uint16).reshape(5, 7)
    good = png_bytes(depth, 16, 0)
    with pytest.raises(sogmm.FormatError, match="truncated"):
        sogmm.decode_frame(good[:-20])
    with pytest.raises(sogmm.InvalidDataError, match="one channel"):
        sogmm.decode_frame(png_bytes(np.zeros((5, 7, 3), np.uint8), 8, 2))
    with pytest.raises(sogmm.InvalidDataError, match="different sizes"):
        sogmm.decode_frame(good, png_bytes(np.zeros((4, 7), np.uint8), 8, 0))
    with pytest.raises(sogmm.SogmmIOError, match="missing.png"):
        sogmm.read_frame(tmp_path / "missing.png")
    fifo = tmp_path / "fifo.png"
    os.mkfifo(fifo)
    with pytest.raises(sogmm.SogmmIOError, match="FIFO"):
        sogmm.read_frame(fifo)


def test_trajectory_round_trip_is_bitwise(tmp_path):
    a, b = 0.3, -1.1
    poses = np.array([np.eye(4), [[np.cos(a), -np.sin(a), 0, 1 / 3], [np.sin(a), np.cos(a), 0, -2], [0, 0, 1, 1e-9],
                                  [0, 0, 0, 1]],
                      [[1, 0, 0, 0], [0, np.cos(b), -np.sin(b), 5], [0, np.sin(b), np.cos(b), 6], [0, 0, 0, 1]]])
    path = tmp_path / "t.log"
    sogmm.write_trajectory(path, poses)
    ids, back = sogmm.read_trajectory(path)
    assert ids.tolist() == [0, 1, 2]
    assert back.tobytes() == poses.tobytes()
    path.write_text("0 0 1\n2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    with pytest.raises(sogmm.InvalidDataError, match="t.log:5: pose 0 is not a rigid"):
        sogmm.read_trajectory(path)
    with pytest.raises(sogmm.InvalidArgumentError, match="pose 0: last row"):
        sogmm.write_trajectory(tmp_path / "u.log", 2 * poses)
    assert not (tmp_path / "u.log").exists()


def test_livingroom_frame_read_and_fitted():
    room = data_dir() / "rgbd" / "livingroom"
    if not room.is_dir():
        pytest.skip(f"{room} is absent (the real frames live in ../shared/data)")
    depth, color = sogmm.read_frame(room / "depth" / "00000.png", room / "color" / "00000.jpg")
    assert depth.shape == (480, 640) and color.shape == (480, 640, 3)
    ids, poses = sogmm.read_trajectory(room / "trajectory.log")
    assert ids.tolist() == list(range(len(ids))) and poses.shape == (len(ids), 4, 4)
    # PNG is lossless: Pillow, an independent decoder, gives the same depth.
    image = pytest.importorskip("PIL.Image")
    with image.open(room / "depth" / "00000.png") as im:
        assert np.array_equal(np.asarray(im).astype(np.uint16), depth)
    with image.open(room / "color" / "00000.jpg") as im:
        pil = np.asarray(im.convert("RGB")).astype(int)
    # JPEG decoders may round differently (the reason the library decodes for
    # every language), but only by a few levels.
    assert np.abs(pil - color).max() <= 4
