#!/usr/bin/env python3
"""Writes the seed programs of fuzz_api into seeds/api/ (layout: fuzz_api.cpp).

Each seed is a short call sequence that reaches deep states (a fitted model
that is merged, moved, saved, reloaded, sampled ...), so that the fuzzer
mutates from there. Run from anywhere: python3 tests/fuzz/make_api_seeds.py.
Deterministic."""
import os
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "seeds", "api")

# Opcodes (LLVMFuzzerTestOneInput's switch, modulo 12).
SET_OPTION, FIT, FROM_ARRAYS, INFO, METADATA, POSE, INFERENCE, MERGE, ROUNDTRIP, LOAD, RGBD, MISC = range(12)


def tame(v):
    """take_double's tame form: (byte - 128) / 16."""
    return bytes([0, max(0, min(255, int(round(v * 16)) + 128))])


def write_seeds(out, seeds):
    """Writes each seed program (name -> bytes) into the folder `out`."""
    os.makedirs(out, exist_ok=True)
    for name, data in seeds.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)
    print(f"wrote {len(seeds)} seeds to {out}")


def fit(slot, n, fixed_k=0):
    how = (1 | (fixed_k << 1)) if fixed_k else 0
    return bytes([FIT, slot, 0, how, n, 0]) + bytes((37 * i + 11) % 256 for i in range(n))


def from_arrays(slot, m):
    out = bytes([FROM_ARRAYS, slot, m - 1, 0])
    for k in range(m):
        out += b"".join(tame(0.25 * k + j * 0.1) for j in range(4))  # mean
        out += b"".join(tame(0.1) for _ in range(4))  # diagonal
        out += bytes([k % 4]) + tame(0.5)  # one off-diagonal pair
    return out + bytes([100])  # support size


def identity_pose_with_translation(t):
    return bytes([0, 128 + 64, 128, 128, 128]) + b"".join(tame(v) for v in t)


def main():
    seeds = {
        "fit_roundtrip_sample": fit(0, 150) + bytes([ROUNDTRIP, 0, 0])
        + bytes([INFERENCE, 0, 0, 100]) + struct.pack("<Q", 7),
        "fixed_k_merge_transform": fit(0, 120, fixed_k=3) + from_arrays(1, 2) + bytes([MERGE, 0, 1, 2])
        + bytes([POSE, 2, 3]) + identity_pose_with_translation((1.0, -2.0, 0.5)) + bytes([ROUNDTRIP, 3, 1]),
        "arrays_regress_score": from_arrays(0, 3) + bytes([INFERENCE, 0, 1, 60, 0]) + bytes(60)
        + bytes([INFERENCE, 0, 2, 60, 0]) + bytes(60),
        "metadata_pose_roundtrip": from_arrays(0, 1) + bytes([METADATA, 0, 3]) + b"key" + bytes([5]) + b"value"
        + bytes([POSE, 0, 0]) + identity_pose_with_translation((0.0, 0.0, 3.0)) + bytes([ROUNDTRIP, 0, 0])
        + bytes([LOAD, 1, 1, 10, 0, 0x40]),
        "rgbd_points_and_fit": bytes([RGBD, 0, 3, 11, 11]) + bytes((i * 7) % 250 + 1 for i in range(144))
        + bytes([RGBD, 1, 0, 11, 11]) + bytes((i * 5) % 250 + 1 for i in range(144)),
        "options_then_fit": bytes([SET_OPTION, 0, 0, 1]) + tame(0.5) + bytes([SET_OPTION, 0, 9, 0, 2])
        + fit(2, 100) + bytes([INFO, 2, 22]),
    }
    write_seeds(OUT, seeds)


if __name__ == "__main__":
    main()
