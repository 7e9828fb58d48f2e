#!/usr/bin/env python3
"""Writes the map delta vectors (spec/format.md section 2.5) into OUT
(spec/conformance/deltas/ once; they are then frozen like the other vectors).

Two chains made by the library through its Python binding:
- `points`: a map of points with novelty off and Hellinger fusion, the same
  two clouds inserted in turn (steps merge, set, drop);
- `rgbd`: two RGB-D frames of the synthetic loop (`sogmm demo --write-frame
  DIR --loop`), the second refitting what the first holds (steps merge,
  remove).
Refused cases apply a delta to a receiver holding a chain's first deltas: a
gap, a duplicate, another map's delta, a digest or a position changed in
place (the metadata CRC-32C fixed, so only section 2.5's rules refuse them),
and a model file. The library (Map.apply_delta) and the independent receiver
(tests/conformance/python_reader/delta_receiver.py) must agree on every case.

Usage (from the repository root, after building):
    SOGMM_LIBRARY_PATH=build/capi/libsogmm.so \\
      PYTHONPATH=bindings/python/src:bindings/python/tests:tests/conformance/python_reader \\
      python3 spec/conformance/generator/delta_vectors.py OUT --sogmm build/tools/sogmm/sogmm
"""
import argparse
import json
import os
import struct
import subprocess
import tempfile

import numpy as np

import sogmm
import sogmm_reader
from conftest import blobs  # the binding tests' seeded point clouds

META_CRC_OFFSET = 28  # header: magic 8, major 2, minor 2, flags 4, file_length 8, metadata_length 4, crc 4


def patched(data: bytes, old: bytes, new: bytes) -> bytes:
    """`data` with the one occurrence of `old` in its metadata block replaced
    by `new` (same length) and the block's CRC-32C recomputed."""
    assert len(old) == len(new)
    meta_len = struct.unpack_from("<I", data, 24)[0]
    meta = data[32:32 + meta_len]
    assert meta.count(old) == 1, old
    meta = meta.replace(old, new)
    out = bytearray(data)
    out[32:32 + meta_len] = meta
    struct.pack_into("<I", out, META_CRC_OFFSET, sogmm_reader.crc32c(meta))
    return bytes(out)


def key_value(data: bytes, key: str) -> str:
    return dict((k, v) for k, v in sogmm_reader.read(data, delta=True)["key_values"])[key]


def chain(make_map, inserts):
    """The deltas of each insert, and the sender's digest after each."""
    deltas = []
    with make_map() as m:
        for insert in inserts:
            since = m.revision
            insert(m)
            deltas.append(m.export_delta(since))
    return deltas


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--sogmm", default="build/tools/sogmm/sogmm")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)

    points = chain(lambda: sogmm.Map(novelty=False, fusion="hellinger", fusion_threshold=0.3, bandwidth=0.08,
                                     seed=3, n_threads=1),
                   [lambda m, k=k: m.insert_points(blobs(n_per=200, seed=k % 2), np.eye(4)) for k in range(3)])
    with tempfile.TemporaryDirectory() as tmp:
        loop = os.path.join(tmp, "loop")
        subprocess.run([a.sogmm, "demo", "--write-frame", loop, "--loop"], check=True,
                       stdout=subprocess.DEVNULL)
        cam = sogmm.Camera.from_json(os.path.join(loop, "intrinsics.json"))
        _, poses = sogmm.read_trajectory(os.path.join(loop, "trajectory.log"))
        frames = [sogmm.read_frame(os.path.join(loop, "depth", "%05d.png" % k),
                                   os.path.join(loop, "color", "%05d.png" % k)) for k in (0, 3)]
        rgbd = chain(lambda: sogmm.Map(batch_size=2000, n_threads=1),
                     [lambda m, i=i, k=k: m.insert_rgbd(*frames[i], cam, poses[k]) for i, k in enumerate((0, 3))])

    files = {}
    for name, deltas in (("points", points), ("rgbd", rgbd)):
        for i, d in enumerate(deltas):
            files[f"{name}_{i + 1}.sogmm"] = d
    digest = key_value(points[1], "delta_digest")
    flipped = digest[:-1] + ("0" if digest[-1] != "0" else "1")
    files["points_2_wrong_digest.sogmm"] = patched(points[1], digest.encode(), flipped.encode())
    ops = key_value(points[1], "delta_ops")
    assert "drop 4 5 6 7\n" in ops, ops
    files["points_2_position_beyond.sogmm"] = patched(points[1], b"drop 4 5 6 7\n", b"drop 4 5 6 9\n")
    for name, data in files.items():
        with open(os.path.join(a.out, name), "wb") as f:
            f.write(data)

    cases = []
    for name, deltas in (("points", points), ("rgbd", rgbd)):
        with sogmm.Map() as receiver:
            for i, d in enumerate(deltas):
                receiver.apply_delta(d)
                cases.append({"name": f"{name}_after_{i + 1}", "expect": "applied",
                              "apply": [f"{name}_{j + 1}.sogmm" for j in range(i + 1)],
                              "revision": receiver.revision, "n_components": receiver.n_components_,
                              "digest": key_value(d, "delta_digest"),
                              "steps": sorted({line.split(" ")[0] for line in key_value(d, "delta_ops").splitlines()})})
    refused = [
        ("gap", ["points_1.sogmm"], "points_3.sogmm", "starts at revision 2, the receiver is at 1"),
        ("duplicate", ["points_1.sogmm", "points_2.sogmm"], "points_2.sogmm", "starts at revision 1, already applied"),
        ("another_map", ["points_1.sogmm"], "rgbd_2.sogmm", "another map's delta at the right revision"),
        ("wrong_digest", ["points_1.sogmm"], "points_2_wrong_digest.sogmm", "delta_digest changed by one hex digit"),
        ("position_beyond", ["points_1.sogmm"], "points_2_position_beyond.sogmm",
         "drop names position 9 of a map of 8"),
        ("model_file", [], "../valid/one_component.sogmm", "a model, not a delta: not_a_delta"),
    ]
    for name, before, delta, why in refused:
        cases.append({"name": name, "expect": "refused", "apply": before, "then": delta, "description": why})
    with open(os.path.join(a.out, "manifest.json"), "w") as f:
        json.dump({"format": "sogmm map delta vectors 1", "cases": cases}, f, indent=1)
        f.write("\n")
    print("wrote %d files and %d cases to %s" % (len(files), len(cases), a.out))


if __name__ == "__main__":
    main()
