#!/usr/bin/env python3
"""Converts one RGB-D frame to the raw inputs of generate_vectors (run once).

Usage: frame_to_raw.py DEPTH.png COLOR.jpg OUT_PREFIX
Writes OUT_PREFIX.depth.u16 (uint16 LE, row-major) and OUT_PREFIX.gray.f32
(float32 LE, gray = (0.299 R + 0.587 G + 0.114 B) / 255), and prints W H.
Needs numpy and Pillow.
"""
import sys

import numpy as np
from PIL import Image


def main() -> int:
    depth_png, color_jpg, prefix = sys.argv[1:4]
    depth = np.array(Image.open(depth_png)).astype("<u2")
    rgb = np.array(Image.open(color_jpg).convert("RGB")).astype(np.float64)
    gray = ((0.299 * rgb[..., 0] + 0.587 * rgb[..., 1] + 0.114 * rgb[..., 2]) / 255.0).astype("<f4")
    assert depth.shape == gray.shape
    depth.tofile(prefix + ".depth.u16")
    gray.tofile(prefix + ".gray.f32")
    print(depth.shape[1], depth.shape[0])
    return 0


if __name__ == "__main__":
    sys.exit(main())
