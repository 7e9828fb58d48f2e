#!/usr/bin/env python3
"""Writes the seed programs of fuzz_map into seeds/map/ (layout: fuzz_map.cpp).

Each seed is a short map session that reaches a deep state (a flushed map that
is saved, reloaded and queried; a map of RGB-D frames asked for occupancy; a
pose far away, a fixed K above the points, a cancelled fit ...), so that the
fuzzer mutates from there. Run from anywhere: python3 tests/fuzz/make_map_seeds.py.
Deterministic."""
import os
import struct

from make_api_seeds import tame, write_seeds  # the same reader layouts (fuzz_inputs.hpp)

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "seeds", "map")

# Opcodes (LLVMFuzzerTestOneInput's step table, modulo 15).
(SET_OPTION, CREATE, INSERT_POINTS, FRAME, INSERT_FRAME, FLUSH, DISCARD, PROGRESS, SAVE_LOAD, LOAD_BYTES, QUERY,
 MISC, ORIGIN, TRACK, DELTA) = range(15)
# Query kinds (step_query: what % 8).
EXPORT, SCORE, REGRESS, SAMPLE, RENDER, OCCUPANCY, SURFACE, COLLISION = range(8)
# Indices into take_special's table.
SPECIAL = {1e-30: 1, 5e5: 5, 1e10: 9, 1e39: 11}


def pose(tx=0.0, ty=0.0, special_x=None):
    """take_map_pose, form 1: identity rotation, a translation (x maybe special)."""
    how = 1 | (4 if special_x is not None else 0)
    x = bytes([SPECIAL[special_x]]) if special_x is not None else tame(tx)
    return bytes([how]) + x + tame(ty) + tame(0.0)


def create(slot, defaults=False):
    return bytes([CREATE, slot, 1 if defaults else 0])


def insert_points(slot, n, p=None, salt=11):
    return bytes([INSERT_POINTS, slot, n, 0]) + bytes((37 * i + salt) % 256 for i in range(n)) + (p or pose())


def set_map_i64(key, value):
    """A map-options i64 set by raw key (the registry index byte 0xff is past every key)."""
    return bytes([SET_OPTION, 4, 0xFF]) + struct.pack("<iq", key, value)


def frame(w, h, f, salt=0, gray=True, special_f=None):
    what = (2 if gray else 0) | (0x20 if special_f is not None else 0)
    out = bytes([FRAME, what, w - 1, h - 1]) + bytes((7 * i + salt) % 250 + 1 for i in range(w * h))
    return out + (bytes([SPECIAL[special_f]]) if special_f is not None else bytes([f - 4]))


def origin(slot, x, y, z):
    """step_origin: each axis a double (flag byte 0, then the value)."""
    return bytes([ORIGIN, slot]) + b"".join(bytes([0]) + tame(v) for v in (x, y, z))


def track(slot, guess=None):
    """step_track: the full info struct; the constant-velocity guess, or `guess`."""
    return bytes([TRACK, slot, 3 if guess is not None else 2]) + (guess or pose())


def delta(sender, receiver, since_first=True):
    """step_delta: the sender's delta since its first (or last) revision, applied to the receiver."""
    return bytes([DELTA, sender | (receiver << 1), 0 if since_first else 0x80])


def query(slot, kind, n, extra=b"", flags=0):
    return bytes([QUERY, slot, kind | flags, n]) + extra


def points_bytes(n, salt=3):
    return bytes([0]) + bytes((11 * i + salt) % 256 for i in range(n))


MAP_BATCH_SIZE, N_COMPONENTS = 602, 101


def main():
    seeds = {
        "points_flush_save_query": create(0) + insert_points(0, 150) + bytes([FLUSH, 0]) + bytes([SAVE_LOAD, 0, 2])
        + query(0, SCORE, 40, points_bytes(40)) + query(1, SAMPLE, 30, struct.pack("<Q", 5))
        + query(0, REGRESS, 20, points_bytes(20)) + query(1, EXPORT, 0, tame(-1) * 3 + tame(2) * 3),
        "frames_occupancy_render": create(0) + frame(10, 10, 10) + bytes([INSERT_FRAME, 0]) + pose()
        + bytes([INSERT_FRAME, 0]) + pose(0.05, 0.0) + bytes([FLUSH, 0]) + query(0, OCCUPANCY, 30, points_bytes(30))
        + query(0, RENDER, 0, bytes([9, 9]) + pose()) + query(0, SURFACE, 20, points_bytes(20))
        + query(0, COLLISION, 3, (tame(0.3) * 3 + tame(0.1)) * 3),
        "far_poses_then_discard": create(0) + insert_points(0, 120) + insert_points(0, 60, pose(special_x=1e10))
        + insert_points(0, 60, pose(special_x=1e39)) + insert_points(0, 60, pose(special_x=5e5))
        + bytes([FLUSH, 0, DISCARD, 0, 0, SAVE_LOAD, 0, 0]),
        "cancelled_fits": set_map_i64(MAP_BATCH_SIZE, 64) + create(1) + bytes([PROGRESS, 1, 2])
        + insert_points(1, 100) + bytes([PROGRESS, 1, 0]) + insert_points(1, 100, salt=5) + bytes([FLUSH, 1])
        + query(1, SCORE, 20, points_bytes(20), flags=8 | 0x10),
        "saved_then_mutated": create(0) + insert_points(0, 100) + bytes([FLUSH, 0, SAVE_LOAD, 0, 0])
        + bytes([LOAD_BYTES, 1, 1]) + struct.pack("<HB", 40, 0x10) + bytes([LOAD_BYTES, 0, 0, 8]) + b"\x89SOG\r\n\x1a\n",
        "fixed_k_above_pending": set_map_i64(N_COMPONENTS, 8) + create(0) + insert_points(0, 5) + bytes([FLUSH, 0])
        + insert_points(0, 40, salt=9),
        "origin_track_then_delta": create(0) + origin(0, 5e5, 0.0, 0.0) + frame(10, 10, 10) + track(0, pose(5e5))
        + track(0) + track(0, pose(5e5 + 0.02)) + bytes([FLUSH, 0]) + create(1) + delta(0, 1) + delta(0, 1, False)
        + query(1, SCORE, 20, points_bytes(20)),
        "first_frame_tiny_focal": create(0) + frame(8, 8, 0, special_f=1e-30) + bytes([INSERT_FRAME, 0]) + pose()
        + frame(8, 8, 10, salt=3) + bytes([INSERT_FRAME, 0]) + pose() + bytes([FLUSH, 0]),
    }
    write_seeds(OUT, seeds)


if __name__ == "__main__":
    main()
