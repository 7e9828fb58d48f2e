#!/usr/bin/env python3
"""Writes the seed inputs of fuzz_fit into seeds/fit/ (layout: fuzz_fit.cpp).

Run from anywhere: python3 tests/fuzz/make_fit_seeds.py. Deterministic."""
import os
import random
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "seeds", "fit")


def header(flags, k, bw, tol=1e-3, reg=1e-6, iters=4, seed=1):
    return struct.pack("<BHdddBI", flags, k, bw, tol, reg, iters, seed)


def clusters(n, rng, scale=1.0):
    centres = [(0.1, 0.2, 1.0, 0.2), (-0.3, 0.1, 1.5, 0.7), (0.4, -0.2, 2.2, 0.5)]
    out = b""
    for i in range(n):
        c = centres[i % 3]
        p = [scale * (c[j] + rng.gauss(0, 0.03)) for j in range(3)] + [min(1, max(0, c[3] + rng.gauss(0, 0.05)))]
        out += struct.pack("<4f", *p)
    return out


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = random.Random(7)
    seeds = {
        "self_organizing_flat": header(0, 0, 0.3) + clusters(120, rng),
        "fixed_k3": header(1, 3, 0.0) + clusters(90, rng),
        "blurring": header(2, 0, 0.5) + clusters(60, rng),
        "raw_options": header(4 | 8 | 16, 0, 0.05, 1e-4, 1e-3) + clusters(60, rng),
        "identical_points": header(1, 2, 0.0) + struct.pack("<4f", 1, 1, 1, 0.5) * 40,
        "kilometres": header(0, 0, 0.9) + clusters(60, rng, 1000.0),
        "empty": header(0, 0, 0.3),
    }
    for name, data in seeds.items():
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
