#!/usr/bin/env python3
"""Peak memory of the .sogmm reader on the worst files we know, against the
bound that spec/format.md section 8 states for it.

Usage:
  format_memory_bound.py --lib build/capi/libsogmm.so \\
      --inspect build/tools/sogmm-inspect/sogmm-inspect [--quick] [--check]

Each file is crafted here (FlatBuffers metadata, zstd frames and CRC-32C
written from the spec, not by the library) and read in a fresh child process
twice: by sogmm_model_load (C API, through ctypes) and by `sogmm-inspect
--verify`. A child's peak RSS (VmHWM / ru_maxrss) minus the peak of the same
child reading a small model (spec/conformance/valid/fitted_livingroom.sogmm)
is compared with the bound

    1 MiB + 2 L + 112 (E + 1) + 84 M + max_i k_i D_i    (k_i = 2 for a float64 array, else 1)

where L is the metadata length, E the key/value pairs, M the components and
D_i the declared decoded size of array i; a value counts only once the reader
has checked it (L after the header check, M and D_i after the size cap). The
default sizes reach the default cap (1 GiB decoded, about 3.5 GB of RSS at
once; 1-2 minutes); --quick uses 1/16 of them (ctest format.memory_bound,
which also passes --check: exit 1 when a peak is over its bound).
"""
import argparse
import ctypes  # noqa: F401  (used by the child code below)
import os
import resource
import struct
import subprocess
import sys
import tempfile

import flatbuffers
import zstandard

GENERATOR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "spec", "conformance", "generator")
sys.path.insert(0, GENERATOR)
from fb_tables import array_table, string_vector  # noqa: E402  (shared with the conformance vector generators)

MIB = 1 << 20
CAP = 1 << 30  # the default cap on decoded bytes
METADATA_LENGTH_LIMIT = (1 << 31) - 1

# ---------------------------------------------------------------- CRC-32C (spec section 6)
POLY = 0x82F63B78
TABLE = []
for _i in range(256):
    _c = _i
    for _ in range(8):
        _c = (_c >> 1) ^ POLY if _c & 1 else _c >> 1
    TABLE.append(_c)


def crc32c(data):
    c = 0xFFFFFFFF
    for b in data:
        c = (c >> 8) ^ TABLE[(c ^ b) & 0xFF]
    return c ^ 0xFFFFFFFF


def _gf2_times(mat, vec):
    s, i = 0, 0
    while vec:
        if vec & 1:
            s ^= mat[i]
        vec >>= 1
        i += 1
    return s


def _gf2_square(mat):
    return [_gf2_times(mat, mat[n]) for n in range(32)]


def crc32c_combine(crc1, crc2, len2):
    """CRC of A + B from CRC(A), CRC(B) and len(B): crc1 is run through len2
    zero bytes (a linear map over GF(2), applied by repeated squaring)."""
    op = [POLY] + [1 << n for n in range(31)]  # one zero bit
    for _ in range(3):
        op = _gf2_square(op)  # one zero byte
    while len2:
        if len2 & 1:
            crc1 = _gf2_times(op, crc1)
        len2 >>= 1
        if len2:
            op = _gf2_square(op)
    return crc1 ^ crc2


def crc32c_repeat(pattern, n):
    """CRC-32C of `pattern` repeated n times, in O(log n)."""
    result, block, blen = 0, crc32c(pattern), len(pattern)
    while n:
        if n & 1:
            result = crc32c_combine(result, block, blen)
        block = crc32c_combine(block, block, blen)
        blen *= 2
        n >>= 1
    return result


# ---------------------------------------------------------------- arrays
def stored_array(row, m, dtype, layout):
    """Stored bytes and record of an array of m identical rows `row` (floats).
    layout: "raw" (component-major, no filter, no codec), "one_frame"
    (column-major, byte-stream split, one zstd frame whose window covers all
    its content: the reader must stage the whole array, its worst case) or
    "frame_per_stream" (as the reference writer: one frame per byte stream,
    zstd's default window, which the reader streams through)."""
    code, w = ("<f", 4) if dtype == 0 else ("<d", 8)
    values = [struct.pack(code, v) for v in row]
    canonical_row = b"".join(values)
    rec = {"dtype": dtype, "decoded_length": m * len(canonical_row), "crc32c": crc32c_repeat(canonical_row, m)}
    if layout == "raw":
        rec.update(order=0, filter=0, codec=0)
        return canonical_row * m, rec
    rec.update(order=1, filter=1, codec=1)
    # Column-major, byte k of every element at k * n + i: runs of one byte.
    streams = [[(bytes([v[k]]), m) for v in values] for k in range(w)]
    frames = [sum(streams, [])] if layout == "one_frame" else streams
    out = bytearray()
    for runs in frames:
        size = sum(n for _, n in runs)
        window = {"window_log": max(10, size.bit_length())} if layout == "one_frame" else {}
        params = zstandard.ZstdCompressionParameters.from_level(3, source_size=size, write_content_size=1,
                                                                write_checksum=0, **window)
        cctx = zstandard.ZstdCompressor(compression_params=params)
        obj = cctx.compressobj(size=size)
        for byte, n in runs:
            chunk = byte * min(n, 16 * MIB)
            while n > 0:
                take = min(n, len(chunk))
                out += obj.compress(chunk[:take])
                n -= take
        out += obj.flush()
    return bytes(out), rec


# ---------------------------------------------------------------- metadata (spec section 4)
def metadata(m, records, offsets, key_values, share_strings=False, covariance_layout=0):
    b = flatbuffers.Builder(1024)
    make = b.CreateSharedString if share_strings else b.CreateString

    arrays = [array_table(b, rec, off, rec["stored_length"]) for rec, off in zip(records, offsets)]
    labels, units = string_vector(b, ["x", "y", "z", "gray"]), string_vector(b, ["m", "m", "m", "1"])
    name, version = b.CreateString("format_memory_bound"), b.CreateString("1")
    kv_vector = None
    if key_values:
        tables = []
        for k, v in key_values:
            ko, vo = make(k), make(v)
            b.StartObject(2)
            b.PrependUOffsetTRelativeSlot(0, ko, 0)
            b.PrependUOffsetTRelativeSlot(1, vo, 0)
            tables.append(b.EndObject())
        b.StartVector(4, len(tables), 4)
        for t in reversed(tables):
            b.PrependUOffsetTRelative(t)
        kv_vector = b.EndVector()
    b.StartObject(20)
    b.PrependUint64Slot(0, m, 0)
    b.PrependUint8Slot(3, covariance_layout, 0)
    for i, a in enumerate(arrays):
        b.PrependUOffsetTRelativeSlot(4 + i, a, 0)
    b.PrependUOffsetTRelativeSlot(9, labels, 0)
    b.PrependUOffsetTRelativeSlot(10, units, 0)
    b.PrependUOffsetTRelativeSlot(16, name, 0)
    b.PrependUOffsetTRelativeSlot(17, version, 0)
    if kv_vector is not None:
        b.PrependUOffsetTRelativeSlot(19, kv_vector, 0)
    b.Finish(b.EndObject(), file_identifier=b"SGMM")
    return bytes(b.Output())


def pad8(n):
    return (n + 7) & ~7


def write_model(path, m, dtype, layouts, key_values=(), share_strings=False):
    """A model of m identical components (weights 1/m, covariance diag 1e-3),
    arrays stored with the given layouts. Returns (file bytes, L, E, M, D_max, f64)."""
    rows = [[1.0 / m], [0.0, 0.0, 1.0, 0.5], [1e-3, 0, 0, 0, 1e-3, 0, 0, 1e-3, 0, 1e-3]]
    stored, records = [], []
    for row, layout in zip(rows, layouts):
        data, rec = stored_array(row, m, dtype, layout)
        rec["stored_length"] = len(data)
        stored.append(data)
        records.append(rec)
    meta = metadata(m, records, [1 << 40] * 3, key_values, share_strings)  # offsets: always 8 bytes
    offsets, at = [], 32 + pad8(len(meta))
    for data in stored:
        offsets.append(at)
        at = pad8(at + len(data))
    meta = metadata(m, records, offsets, key_values, share_strings)
    assert 32 + pad8(len(meta)) == offsets[0]
    size = offsets[2] + len(stored[2]) + 4
    with open(path, "wb") as f:
        f.write(b"\x89SOG\r\n\x1a\n" + struct.pack("<HHIQII", 1, 0, 0, size, len(meta), crc32c(meta)))
        f.write(meta)
        for data, off in zip(stored, offsets):
            f.seek(off)
            f.write(data)
        f.write(b"SGMM")
    return {"file": size, "L": len(meta), "E": len(key_values), "M": m,
            "D": sum(r["decoded_length"] for r in records), "D_max": max(r["decoded_length"] for r in records),
            "f64": dtype == 1}


def write_sparse_header(path, size, metadata_length):
    with open(path, "wb") as f:
        f.write(b"\x89SOG\r\n\x1a\n" + struct.pack("<HHIQII", 1, 0, 0, size, metadata_length, 0))
        f.truncate(size)
        f.seek(size - 4)
        f.write(b"SGMM")
    return {"file": size, "L": metadata_length, "E": 0, "M": 0, "D": 0, "D_max": 0, "f64": False}


def bound(f):
    """spec/format.md section 8, with the values the reader has checked."""
    length = f["L"] if 8 <= f["L"] < METADATA_LENGTH_LIMIT and 32 + pad8(f["L"]) + 4 <= f["file"] else 0
    m, d_max = (f["M"], f["D_max"]) if f["D"] <= CAP else (0, 0)
    return MIB + 2 * length + 112 * (f["E"] + 1) + 84 * m + (2 if f["f64"] else 1) * d_max  # one dtype per file


# ---------------------------------------------------------------- measuring
LOAD_CHILD = r"""
import ctypes, sys
lib = ctypes.CDLL(sys.argv[1])
lib.sogmm_model_load.argtypes = [ctypes.POINTER(ctypes.c_void_p), ctypes.c_char_p, ctypes.c_void_p]
lib.sogmm_last_error.restype = ctypes.c_char_p
h = ctypes.c_void_p()
status = lib.sogmm_model_load(ctypes.byref(h), sys.argv[2].encode(), None)
hwm = [l for l in open("/proc/self/status") if l.startswith("VmHWM:")][0].split()[1]
msg = lib.sogmm_last_error().decode("utf-8", "replace").split(":")[0] if status else "ok"
print(status, hwm, msg)
"""


def peak_of_load(lib, path):
    """(peak RSS in bytes, verdict) of a fresh process calling sogmm_model_load."""
    out = subprocess.run([sys.executable, "-c", LOAD_CHILD, lib, path], capture_output=True, text=True, timeout=600)
    status, hwm_kib, msg = out.stdout.split(maxsplit=2)
    return int(hwm_kib) * 1024, ("ok" if status == "0" else msg.strip())


# A child's ru_maxrss also counts what it inherited at fork (this script is
# large after crafting a file), so sogmm-inspect is started by GNU time, a
# small program whose own fork costs less than sogmm-inspect's baseline.
TIME = "/usr/bin/time"


def peak_of_inspect(inspect, path):
    """(peak RSS in bytes, verdict) of `sogmm-inspect --verify`."""
    out = subprocess.run([TIME, "-f", "maxrss %M", inspect, "--verify", path], capture_output=True, text=True,
                         timeout=600)
    peak_kib = [l for l in out.stderr.splitlines() if l.startswith("maxrss ")][-1].split()[1]
    said = out.stdout.strip()
    verdict = "ok" if said == "ok" else said.replace("invalid: ", "").split(":")[0]
    return int(peak_kib) * 1024, verdict


# ---------------------------------------------------------------- the cases
def cases(tmp, scale):
    """(name, path, facts) of every worst case; scale 1 = full size, 16 = --quick."""
    def path(name):
        return os.path.join(tmp, name + ".sogmm")

    m32 = CAP // 60 // scale  # float32, packed: 60 decoded bytes per component
    m64 = CAP // 120 // scale
    out = []
    p = path("bomb_f32_one_frame")
    out.append(("zstd bomb f32, one frame per array, full window", p, write_model(p, m32, 0, ["one_frame"] * 3)))
    p = path("bomb_f32_per_stream")
    out.append(("zstd bomb f32, frame per byte stream", p, write_model(p, m32, 0, ["frame_per_stream"] * 3)))
    p = path("bomb_f64_one_frame")
    out.append(("zstd bomb f64, one frame per array, full window", p, write_model(p, m64, 1, ["one_frame"] * 3)))
    p = path("bomb_f64_per_stream")
    out.append(("zstd bomb f64, frame per byte stream", p, write_model(p, m64, 1, ["frame_per_stream"] * 3)))
    p = path("raw_f32")
    out.append(("uncompressed f32", p, write_model(p, CAP // 4 // 60 // scale, 0, ["raw"] * 3)))
    # The files of the issue: many pairs pointing at one string (now rejected).
    for pairs, value in ((14500, 58000), (51600, 206000)):
        pairs, value = pairs // scale, value // scale
        p = path(f"shared_{pairs}")
        facts = write_model(p, 1, 0, ["raw"] * 3, [("k", "v" * value)] * pairs, share_strings=True)
        out.append((f"shared strings, {pairs} x {value} B", p, facts))
    n = 99990 // scale  # the FlatBuffers verifier allows 100 000 tables
    p = path("many_entries")
    out.append((f"{n} distinct key/value pairs", p,
                write_model(p, 1, 0, ["raw"] * 3, [(f"key{i:06d}", f"value{i:06d}") for i in range(n)])))
    p = path("large_metadata")
    out.append((f"one {256 // scale} MiB value", p,
                write_model(p, 1, 0, ["raw"] * 3, [("blob", "x" * (256 * MIB // scale))])))
    p = path("sparse_4gib_header")
    length = 0xFFFFFFF9
    out.append(("sparse 4 GiB, metadata_length 0xFFFFFFF9", p, write_sparse_header(p, 32 + pad8(length) + 4, length)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lib", required=True, help="libsogmm.so")
    ap.add_argument("--inspect", required=True, help="sogmm-inspect")
    ap.add_argument("--quick", action="store_true", help="1/16 of the sizes (seconds instead of minutes)")
    ap.add_argument("--check", action="store_true", help="exit 1 when a peak is over its bound")
    ap.add_argument("--vectors", default=os.path.join(os.path.dirname(__file__), "..", "..", "spec", "conformance"))
    a = ap.parse_args()
    assert crc32c_repeat(b"abc", 5) == crc32c(b"abc" * 5) and crc32c(b"123456789") == 0xE3069283

    # Baseline: a small compressed file (so the decoder's code is paged in too).
    small = os.path.join(a.vectors, "valid", "fitted_livingroom.sogmm")
    readers = [("load", lambda p: peak_of_load(a.lib, p))]
    if os.access(TIME, os.X_OK):
        readers.append(("inspect", lambda p: peak_of_inspect(a.inspect, p)))
    else:
        print(f"{TIME} (Debian package 'time') is missing: sogmm-inspect is not measured")
    base = {name: measure(small)[0] for name, measure in readers}
    print(f"baseline peak RSS ({os.path.basename(small)}): " +
          ", ".join(f"{name} {b / MIB:.1f} MiB" for name, b in base.items()) + "; below: peak minus baseline")
    head = (f"{'case':48} {'reader':8} {'file B':>11} {'decoded B':>11} {'entries':>7} {'verdict':>16} "
            f"{'peak MiB':>9} {'allowed':>9} {'ratio':>6}")
    print(head)
    print("-" * len(head))
    worst = 0.0
    with tempfile.TemporaryDirectory(prefix="sogmm-memory-bound-") as tmp:
        for name, path, facts in cases(tmp, 16 if a.quick else 1):
            allowed = bound(facts)
            for reader, measure in readers:
                peak, verdict = measure(path)
                used = max(0, peak - base[reader])
                ratio = used / allowed
                worst = max(worst, ratio)
                print(f"{name:48} {reader:8} {facts['file']:>11} {facts['D']:>11} {facts['E']:>7} {verdict:>16} "
                      f"{used / MIB:>9.1f} {allowed / MIB:>9.1f} {ratio:>6.3f}", flush=True)
            os.unlink(path)
    print(f"largest measured/allowed: {worst:.3f}")
    return 1 if a.check and worst > 1.0 else 0


if __name__ == "__main__":
    sys.exit(main())
