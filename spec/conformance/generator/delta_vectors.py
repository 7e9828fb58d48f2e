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

Since format 1.2 the library writes deltas with their key/values packed in
the body (spec/format.md 2.5.1), so this script writes the chains as
`points_packed_N` / `rgbd_packed_N` and, from them, the refused packed cases
(a file a delta reader rejects, each with its step-20 reason, or a digest
changed inside the packed bytes). The format 1.1 files (`points_N`,
`rgbd_N` and their refused cases) were written by this script at a67de64
and stay frozen; OUT gets only the new files and `manifest_additions.json`
(the cases to append to deltas/manifest.json).

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
import zstandard

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


def packed_entry(data: bytes) -> str:
    """The metadata entry that locates the packed key/values (read without step 20)."""
    md = sogmm_reader.read(data, delta=True, metadata_only=True)
    return dict((k, v) for k, v in md["key_values"])[sogmm_reader.PACKED_KEY]


def with_entry(data: bytes, codec=None, stored=None, decoded=None, crc=None) -> bytes:
    """`data` with fields of its packed_key_values entry replaced in place
    (each new number as long as the old one)."""
    old = packed_entry(data)
    fields = [int(t) for t in old.split(" ")]
    for i, v in enumerate((codec, stored, decoded, crc)):
        if v is not None:
            fields[i] = v
    new = " ".join(str(v) for v in fields)
    return patched(data, old.encode(), new.encode())


def repacked(data: bytes, edit) -> bytes:
    """`data` with its packed bytes decoded, passed through `edit`, and stored
    again (zstd, content size declared, no checksum), the entry, file length
    and CRC-32Cs updated; the new stored length must have as many digits."""
    codec, stored, decoded, crc = (int(t) for t in packed_entry(data).split(" "))
    assert codec == 1
    end = len(data) - 4
    raw = zstandard.ZstdDecompressor().decompress(data[end - stored:end])
    new = edit(raw)
    z = zstandard.ZstdCompressor(level=19, write_checksum=False, write_content_size=True).compress(new)
    out = bytearray(with_entry(data, stored=len(z), decoded=len(new), crc=sogmm_reader.crc32c(new)))
    out[end - stored:end] = z
    struct.pack_into("<Q", out, 16, len(out))  # file_length
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
    for name, deltas in (("points_packed", points), ("rgbd_packed", rgbd)):
        for i, d in enumerate(deltas):
            assert sogmm_reader.read(d, delta=True)["file"]["format_version"] == "1.2"
            files[f"{name}_{i + 1}.sogmm"] = d
    p2 = points[1]
    codec, stored, decoded, crc = (int(t) for t in packed_entry(p2).split(" "))
    digest = key_value(p2, "delta_digest")
    flipped = digest[:-1] + ("0" if digest[-1] != "0" else "1")
    # Each: (file, data, reason of a delta reader or None when only a receiver refuses it, why).
    refused = [
        ("points_packed_2_wrong_digest.sogmm",
         repacked(p2, lambda raw: raw.replace(digest.encode(), flipped.encode())), None,
         "delta_digest changed by one hex digit inside the packed key/values"),
        ("points_packed_2_packed_crc.sogmm", with_entry(p2, crc=crc ^ 1), "checksum_mismatch",
         "the packed key/values' CRC-32C changed in their entry"),
        ("points_packed_2_packed_codec.sogmm", with_entry(p2, codec=2), "bad_metadata",
         "packed key/values with codec 2 (unknown)"),
        ("points_packed_2_packed_overlap.sogmm", with_entry(p2, stored=stored + 1), "bad_layout",
         "packed key/values one byte longer: they overlap the covariances"),
        ("points_packed_2_packed_length.sogmm", with_entry(p2, decoded=decoded + 1), "decompression_failed",
         "packed key/values declare one decoded byte more than their zstd frame holds"),
        ("points_packed_2_packed_entry_missing.sogmm",
         patched(p2, sogmm_reader.PACKED_KEY.encode(), b"packed_key_valueZ"), "bad_metadata",
         "feature bit 1 set but no packed_key_values entry"),
        ("points_packed_2_packed_odd.sogmm", repacked(p2, lambda raw: raw[:-1]), "bad_metadata",
         "packed key/values whose last value has no NUL"),
        ("points_packed_2_packed_utf8.sogmm", repacked(p2, lambda raw: raw.replace(b"delta_ops", b"delta_op\xff")),
         "bad_metadata", "a packed key that is not UTF-8"),
    ]
    for name, data, reason, _ in refused:
        try:
            sogmm_reader.read(data, delta=True)
            got = None
        except sogmm_reader.SogmmError as e:
            got = e.reason
        assert got == reason, (name, got, reason)
        files[name] = data
    for name, data in files.items():
        with open(os.path.join(a.out, name), "wb") as f:
            f.write(data)

    cases = []
    for name, deltas in (("points_packed", points), ("rgbd_packed", rgbd)):
        with sogmm.Map() as receiver:
            for i, d in enumerate(deltas):
                receiver.apply_delta(d)
                cases.append({"name": f"{name}_after_{i + 1}", "expect": "applied",
                              "apply": [f"{name}_{j + 1}.sogmm" for j in range(i + 1)],
                              "revision": receiver.revision, "n_components": receiver.n_components_,
                              "digest": key_value(d, "delta_digest"),
                              "steps": sorted({line.split(" ")[0] for line in key_value(d, "delta_ops").splitlines()})})
    for name, data, reason, why in refused:
        case = {"name": name[:-len(".sogmm")], "expect": "refused", "apply": ["points_packed_1.sogmm"],
                "then": name, "description": why}
        if reason is not None:
            case["reason"] = reason
        cases.append(case)
    with open(os.path.join(a.out, "manifest_additions.json"), "w") as f:
        json.dump(cases, f, indent=1)
        f.write("\n")
    print("wrote %d files and %d cases to %s" % (len(files), len(cases), a.out))


if __name__ == "__main__":
    main()
