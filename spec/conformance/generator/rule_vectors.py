"""Generates the conformance vectors that pin the rules clarified for issue 15
(FlatBuffers wire rules, zstd frames, symmetric FULL covariances, metadata
values, edge arithmetic, world-frame and merged models).

RUN ONCE, THEN FROZEN, like generate_vectors.cpp: it writes new files into a
scratch folder; copy only the new ones into spec/conformance and append their
manifest entries (printed as manifest_additions.json).

    python3 rule_vectors.py OUT_DIR --batch build/tests/conformance/sogmm_conformance_batch

Files are built here with the `flatbuffers` Python builder (no SOGMM code);
the canonical dump of every valid vector is the C++ reference reader's
(sogmm_conformance_batch), and every vector must get its expected verdict
from both the C++ reader and the independent Python reader before it is
written to the manifest.
"""
import argparse
import json
import math
import pathlib
import struct
import subprocess
import sys

import flatbuffers
import zstandard

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[3] / "tests" / "conformance" / "python_reader"))
from sogmm_reader import crc32c  # noqa: E402  (checked against the CRC-32C check value there)

from fb_tables import array_table, string_vector  # noqa: E402  (this folder; also the memory bench's)

UPPER = [(0, 0), (0, 1), (0, 2), (0, 3), (1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3)]
IDENTITY = [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0]


# ------------------------------------------------------------------ models
def base_model(m=2):
    """M components with weights 1/M, distinct means, diagonal covariances."""
    cov = []
    for k in range(m):
        c = [[0.0] * 4 for _ in range(4)]
        for i in range(4):
            c[i][i] = 0.01 * (k + 1) + 0.001 * i
        c[0][1] = c[1][0] = 0.001
        cov.append(c)
    return {
        "weights": [1.0 / m] * m,
        "means": [[0.1 * k, -0.2, 1.5 + 0.1 * k, 0.5] for k in range(m)],
        "cov": cov,
        "layout": 0,  # UPPER_PACKED
        "dtype": 0,
        "codec": "none",
        "support_size": 1000,
        "fit": None,
        "camera": None,
        "pose": None,
        "axis": True,
        "gray": (0.0, 1.0),
        "key_values": [],
    }


def fit_record(**kw):
    f = {"bandwidth": 0.02, "n_components_requested": 0, "tol": 1e-3, "reg_covar": 1e-6, "max_iter": 100,
         "n_iter": 12, "converged": 1, "log_likelihood": 2.5, "seed": 7}
    f.update(kw)
    return f


def camera_record(**kw):
    c = {"width": 640, "height": 480, "fx": 525.0, "fy": 525.0, "cx": 319.5, "cy": 239.5, "decimation": 5,
         "depth_scale": 1000.0, "depth_min": 0.1, "depth_max": 3.0}
    c.update(kw)
    return c


# ------------------------------------------------------------------ arrays
def array_values(model):
    cov = model["cov"]
    if model["layout"] == 0:
        cv = [c[i][j] for c in cov for i, j in UPPER]
    else:
        cv = [x for c in cov for row in c for x in row]
    return [list(model["weights"]), [x for mu in model["means"] for x in mu], cv]


def encode_array(values, dtype, codec):
    code = "<%d%s" % (len(values), "d" if dtype else "f")
    canonical = struct.pack(code, *values)
    rec = {"dtype": dtype, "order": 0, "filter": 0, "codec": 0, "decoded_length": len(canonical),
           "crc32c": crc32c(canonical), "stored": canonical}
    if codec != "none":
        rec["codec"] = 1
        rec["stored"] = codec(canonical)
    return rec


def zstd_frame(data, content_size=True, checksum=False):
    params = zstandard.ZstdCompressionParameters.from_level(3, write_content_size=content_size,
                                                            write_checksum=checksum)
    if content_size:
        return zstandard.ZstdCompressor(compression_params=params).compress(data)
    # compressobj writes no content size (it does not know it in advance)
    c = zstandard.ZstdCompressor(compression_params=params).compressobj()
    return c.compress(data) + c.flush()


# ------------------------------------------------------------------ metadata
def build_metadata(model, arrays, offsets, extra=None):
    b = flatbuffers.Builder(1024)
    b.ForceDefaults(True)

    arr = [array_table(b, rec, off, len(rec["stored"])) for rec, off in zip(arrays, offsets)]
    labels = string_vector(b, ["x", "y", "z", "gray"]) if model["axis"] else None
    units = string_vector(b, ["m", "m", "m", "1"]) if model["axis"] else None
    fit = camera = pose = kvs = None
    if model["fit"] is not None:
        f = model["fit"]
        b.StartObject(9)
        b.PrependFloat64Slot(0, f["bandwidth"], 0)
        b.PrependUint64Slot(1, f["n_components_requested"], 0)
        b.PrependFloat64Slot(2, f["tol"], 0)
        b.PrependFloat64Slot(3, f["reg_covar"], 0)
        b.PrependInt32Slot(4, f["max_iter"], 0)
        b.PrependInt32Slot(5, f["n_iter"], 0)
        b.PrependUint8Slot(6, f["converged"], 0)  # raw byte: vectors may hold 2
        b.PrependFloat64Slot(7, f["log_likelihood"], 0)
        b.PrependUint64Slot(8, f["seed"], 0)
        fit = b.EndObject()
    if model["camera"] is not None:
        c = model["camera"]
        b.StartObject(10)
        b.PrependInt32Slot(0, c["width"], 0)
        b.PrependInt32Slot(1, c["height"], 0)
        for slot, name in ((2, "fx"), (3, "fy"), (4, "cx"), (5, "cy")):
            b.PrependFloat64Slot(slot, c[name], 0)
        b.PrependInt32Slot(6, c["decimation"], 1)
        b.PrependFloat64Slot(7, c["depth_scale"], 1000.0)
        b.PrependFloat64Slot(8, c["depth_min"], 0.1)
        b.PrependFloat64Slot(9, c["depth_max"], 3.0)
        camera = b.EndObject()
    if model["pose"] is not None:
        b.StartVector(8, 16, 8)
        for x in reversed(model["pose"]):
            b.PrependFloat64(x)
        pose = b.EndVector()
    name = b.CreateString("rule_vectors.py")
    version = b.CreateString("1")
    if model["key_values"]:
        items = []
        shared = {}
        for k, v in model["key_values"]:
            if (k, v) in shared and model.get("share_tables"):
                items.append(shared[(k, v)])
                continue
            ko, vo = b.CreateString(k), b.CreateString(v)
            b.StartObject(2)
            b.PrependUOffsetTRelativeSlot(0, ko, 0)
            b.PrependUOffsetTRelativeSlot(1, vo, 0)
            shared[(k, v)] = b.EndObject()
            items.append(shared[(k, v)])
        b.StartVector(4, len(items), 4)
        for o in reversed(items):
            b.PrependUOffsetTRelative(o)
        kvs = b.EndVector()
    b.StartObject(21 if model.get("unknown_field") else 20)
    m = len(model["weights"])
    b.PrependUint64Slot(0, m, 0)
    b.PrependUint32Slot(1, 4, 4)
    b.PrependUint64Slot(2, model["support_size"], 0)
    b.PrependUint8Slot(3, model["layout"], 0)
    for slot, a in zip((4, 5, 6), arr):
        b.PrependUOffsetTRelativeSlot(slot, a, 0)
    b.PrependUint64Slot(7, 0, 0)
    b.PrependUint64Slot(8, 0, 0)
    if labels is not None:
        b.PrependUOffsetTRelativeSlot(9, labels, 0)
        b.PrependUOffsetTRelativeSlot(10, units, 0)
    b.PrependFloat64Slot(11, model["gray"][0], 0.0)
    b.PrependFloat64Slot(12, model["gray"][1], 1.0)
    for slot, o in ((13, fit), (14, camera), (15, pose)):
        if o is not None:
            b.PrependUOffsetTRelativeSlot(slot, o, 0)
    b.PrependUOffsetTRelativeSlot(16, name, 0)
    b.PrependUOffsetTRelativeSlot(17, version, 0)
    b.PrependInt64Slot(18, 1700000000000, 0)
    if kvs is not None:
        b.PrependUOffsetTRelativeSlot(19, kvs, 0)
    if model.get("unknown_field"):
        b.PrependUint64Slot(20, 0x1122334455667788, 0)
    root = b.EndObject()
    b.Finish(root, file_identifier=b"SGMM")
    return bytearray(b.Output())


def assemble(model, patch=None, array_patch=None):
    """A whole file. patch(meta) edits the metadata block in place (same
    length); array_patch(arrays) edits the array records before layout."""
    m = model
    arrays = [encode_array(v, m["dtype"], m["codec"]) for v in array_values(m)]
    if array_patch:
        array_patch(arrays)
    meta = build_metadata(m, arrays, [0, 0, 0])
    for _ in range(2):  # offsets depend on the block length, which does not depend on them
        body = 32 + (len(meta) + 7) // 8 * 8
        offsets, at = [], body
        for rec in arrays:
            offsets.append(at)
            at = (at + len(rec["stored"]) + 7) // 8 * 8
        meta = build_metadata(m, arrays, offsets)
    if patch:
        patch(meta)
    body = 32 + (len(meta) + 7) // 8 * 8
    out = bytearray(body)
    out[32:32 + len(meta)] = meta
    for rec, off in zip(arrays, offsets):
        out += bytes(off - len(out))
        out += rec["stored"]
    out += b"SGMM"
    out[0:8] = b"\x89SOG\r\n\x1a\n"
    struct.pack_into("<HHIQII", out, 8, 1, 0, 0, len(out), len(meta), crc32c(meta))
    return bytes(out)


# ------------------------------------------------------------------ locating bytes in a block
def u16(b, p):
    return struct.unpack_from("<H", b, p)[0]


def u32(b, p):
    return struct.unpack_from("<I", b, p)[0]


def root(meta):
    return u32(meta, 0)


def vtable(meta, table):
    return table - struct.unpack_from("<i", meta, table)[0]


def field(meta, table, fid):
    """Position of field fid of the table (0 if absent)."""
    vt = vtable(meta, table)
    fo = u16(meta, vt + 4 + 2 * fid) if 4 + 2 * fid + 2 <= u16(meta, vt) else 0
    return table + fo if fo else 0


def follow(meta, pos):
    return pos + u32(meta, pos)


def sub_table(meta, fid):
    return follow(meta, field(meta, root(meta), fid))


# ------------------------------------------------------------------ the vectors
def vectors():
    v = []

    def add(name, expect, data, description, category=None, reason=None):
        v.append((name, expect, data, description, category, reason))

    def with_fit_camera():
        m = base_model()
        m["fit"] = fit_record()
        m["camera"] = camera_record()
        return m

    # --- section 4.3, FlatBuffers wire rules
    def vt_size(size, fid):
        def p(meta):
            struct.pack_into("<H", meta, vtable(meta, sub_table(meta, fid)), size)
        return p

    add("vtable_size_2", "invalid", assemble(with_fit_camera(), vt_size(2, 13)),
        "the fit table's vtable has size 2 (below 4): FlatBuffers would read every fit field as its default",
        "format", "bad_metadata")
    add("vtable_size_0", "invalid", assemble(with_fit_camera(), vt_size(0, 14)),
        "the camera table's vtable has size 0", "format", "bad_metadata")

    def inline_size(meta):
        struct.pack_into("<H", meta, vtable(meta, sub_table(meta, 14)) + 2, 8)
    add("field_outside_inline_size", "invalid", assemble(with_fit_camera(), inline_size),
        "the camera table's inline size is 8, its fields lie beyond it (inside the block)", "format", "bad_metadata")

    def misalign(meta):
        cam = sub_table(meta, 14)
        vt = vtable(meta, cam)
        # fx (id 2, a double) moved to a position that is 4 mod 8, inside the inline bytes
        fo = u16(meta, vt + 4 + 2 * 2)
        for delta in (4, -4):
            if (cam + fo + delta) % 8 == 4 and 4 <= fo + delta and fo + delta + 8 <= u16(meta, vt + 2):
                struct.pack_into("<H", meta, vt + 8, fo + delta)
                return
        raise RuntimeError("no misaligned slot")
    add("field_misaligned", "invalid", assemble(with_fit_camera(), misalign),
        "camera.fx (a double) at a block position that is 4 mod 8", "format", "bad_metadata")

    def zero_field_offset(meta):
        struct.pack_into("<I", meta, field(meta, root(meta), 16), 0)
    add("field_offset_zero", "invalid", assemble(base_model(), zero_field_offset),
        "the offset stored in producer_name is 0", "format", "bad_metadata")

    def zero_element_offset(meta):
        vec = follow(meta, field(meta, root(meta), 10))
        struct.pack_into("<I", meta, vec + 4, 0)
    add("element_offset_zero", "invalid", assemble(base_model(), zero_element_offset),
        "element 0 of axis_units is the offset 0", "format", "bad_metadata")

    def garbage_unknown(meta):
        vt = vtable(meta, root(meta))
        struct.pack_into("<H", meta, vt + 4 + 2 * 20, 0xFFF8)
    m = base_model()
    m["unknown_field"] = True
    add("unknown_field_unchecked", "valid", assemble(m, garbage_unknown),
        "root field 20 (unknown to a 1.0 reader) has a vtable entry pointing far outside the table and the "
        "block: unknown fields are not read, so not checked")
    m = base_model()
    m["key_values"] = [("frame", "a"), ("frame", "a")]
    m["share_tables"] = True
    add("table_visited_twice", "valid", assemble(m),
        "both key_values elements point at one KeyValue table: two visits, two entries (section 4.3)")
    m = base_model(1)
    m["key_values"] = [("", "")] * 99997
    m["share_tables"] = True
    add("table_visits_over_limit", "invalid", assemble(m),
        "99 997 key_values elements share one KeyValue table: 100 001 table visits (root, 3 arrays and the "
        "elements), over 100 000, with only 5 distinct tables", "format", "bad_metadata")

    # --- section 4.2 values
    m = with_fit_camera()
    m["fit"]["converged"] = 2
    add("bool_2", "invalid", assemble(m), "fit.converged is the byte 2 (a bool is 0 or 1)", "format", "bad_metadata")
    m = with_fit_camera()
    m["fit"]["log_likelihood"] = math.nan
    add("fit_nan", "invalid", assemble(m), "fit.log_likelihood is NaN", "format", "bad_metadata")
    m = with_fit_camera()
    m["camera"]["depth_max"] = math.inf
    add("camera_inf", "invalid", assemble(m), "camera.depth_max is +Inf", "format", "bad_metadata")
    m = base_model()
    m["axis"] = False
    add("no_axis_labels", "valid", assemble(m),
        "axis_labels and axis_units absent: read as the fixed lists, which the dump shows")
    m = with_fit_camera()
    m["weights"] = [1.0, -0.0]
    m["means"][0][0] = -0.0
    m["gray"] = (-0.0, 1.0)
    m["fit"]["log_likelihood"] = -0.0
    m["pose"] = [1.0, -0.0, 0.0, -0.0, 0.0, 1.0, -0.0, 0.0, -0.0, 0.0, 1.0, 0.0, -0.0, -0.0, -0.0, 1.0]
    add("negative_zero", "valid", assemble(m),
        "-0.0 as a weight, a mean, gray_min, a fit double and pose entries (last row too): equal to 0 in "
        "every check; the dump keeps the sign")

    # --- section 5.1, FULL covariances
    m = base_model()
    m["layout"] = 1
    m["cov"][1][0][1] = 0.001
    m["cov"][1][1][0] = 0.0010000003967434168  # float32 0.001 plus 3 ulps: symmetric within 1e-5
    add("full_nearly_symmetric", "valid", assemble(m),
        "FULL covariance 1 with (1,0) 3 float32 ulps above (0,1): the reader returns the symmetric part, "
        "(a01 + a10) / 2 (1.5 ulps above, a tie) rounded to float32 (to even), in both places")
    m = base_model()
    m["cov"][0] = [[1.0, 1.0, 0, 0], [1.0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]
    add("not_spd_zero_pivot", "invalid", assemble(m),
        "covariance 0 is positive semidefinite, its second Cholesky pivot exactly 0 (the test is d > 0)",
        "numeric", "not_spd")

    # --- section 9, edge arithmetic
    m = base_model(4)
    m["weights"] = [0.25, 0.25, 0.25, 0.25009]  # float32 sum 1 + 9.0e-5 (within 1e-4)
    add("weights_sum_within_tolerance", "valid", assemble(m),
        "weights summing to 1.0000900030136108 in binary64 (float32 values): within 1e-4")

    def pose_diag(a):
        p = list(IDENTITY)
        p[0] = a
        return p
    m = base_model()
    m["pose"] = pose_diag(math.sqrt(1.000999))
    add("pose_within_tolerance", "valid", assemble(m),
        "pose rotation diag(sqrt(1.000999), 1, 1): (R^T R)[0][0] - 1 = 0.000999, within 1e-3")
    m = base_model()
    m["pose"] = pose_diag(math.sqrt(1.0011))
    add("pose_beyond_tolerance", "invalid", assemble(m),
        "pose rotation diag(sqrt(1.0011), 1, 1): (R^T R)[0][0] - 1 = 0.0011, beyond 1e-3", "invalid_data", "bad_pose")
    m = base_model()
    m["pose"] = pose_diag(-1.0)
    add("pose_reflection", "invalid", assemble(m),
        "pose rotation diag(-1, 1, 1): orthonormal, det(R) = -1", "invalid_data", "bad_pose")

    # --- section 5.4, zstd frames
    def zstd_model(**kw):
        m = base_model(8)
        m["codec"] = lambda data: zstd_frame(data, **kw)
        return m
    add("zstd_content_checksum", "valid", assemble(zstd_model(checksum=True)),
        "every frame carries a content checksum, which is correct (and verified)")

    def bad_checksum(arrays):
        s = bytearray(arrays[2]["stored"])
        s[-1] ^= 0xFF
        arrays[2]["stored"] = bytes(s)
    add("zstd_checksum_mismatch", "invalid", assemble(zstd_model(checksum=True), array_patch=bad_checksum),
        "the covariances' zstd content checksum is wrong (the content is intact)", "format", "decompression_failed")
    add("zstd_no_content_size", "invalid", assemble(zstd_model(content_size=False)),
        "zstd frames without the frame content size", "format", "decompression_failed")

    def empty_stored(arrays):
        arrays[1]["stored"] = b""
    add("zstd_stored_length_0", "invalid", assemble(zstd_model(), array_patch=empty_stored),
        "means: codec ZSTD with stored_length 0 (no frame: decodes to 0 bytes)", "format", "decompression_failed")

    def reserved_modes(arrays):
        s = bytearray(arrays[2]["stored"])
        at = modes_byte(s)
        s[at] |= 1
        arrays[2]["stored"] = bytes(s)
    m = base_model(64)  # enough repetition for zstd to emit sequences
    m["codec"] = lambda data: zstd_frame(data)
    add("zstd_reserved_bits", "invalid", assemble(m, array_patch=reserved_modes),
        "a reserved bit of a compressed block's Symbol_Compression_Modes is set (zstd 1.5.4 ignores it, 1.5.7 "
        "rejects it; the format rejects it)", "format", "decompression_failed")

    # --- section 2, world-frame and merged models
    m = with_fit_camera()
    m["fit"].update(n_iter=169, max_iter=100, converged=0, log_likelihood=2.25)
    m["key_values"] = [("coordinate_frame", "world"), ("merged_fits", "3")]
    add("world_merged", "valid", assemble(m),
        "a model merged in the world frame from 3 fits: coordinate_frame = world, merged_fits = 3, "
        "n_iter the total (169 > max_iter 100), converged false as one fit did not converge, log_likelihood "
        "the support-weighted mean of the fits'")
    return v


def modes_byte(s):
    """Position of Symbol_Compression_Modes of the first compressed block with sequences."""
    fhd = s[4]
    single = fhd >> 5 & 1
    pos = 5 + (0 if single else 1) + (0, 1, 2, 4)[fhd & 3] + (1, 2, 4, 8)[fhd >> 6]
    while True:
        h = int.from_bytes(s[pos:pos + 3], "little")
        pos += 3
        kind, size = h >> 1 & 3, h >> 3
        if kind == 2:
            b0 = s[pos]
            lt, fmt = b0 & 3, b0 >> 2 & 3
            if lt < 2:
                hl = 2 if fmt == 1 else 3 if fmt == 3 else 1
                rs = b0 >> 3 if hl == 1 else (b0 >> 4) + (int.from_bytes(s[pos + 1:pos + hl], "little") << 4)
                content = rs if lt == 0 else 1
            else:
                hl = 3 if fmt < 2 else 4 if fmt == 2 else 5
                content = int.from_bytes(s[pos:pos + hl], "little") >> 4 >> (10 if hl == 3 else 14 if hl == 4 else 18)
            q = pos + hl + content
            if s[q] != 0:
                return q + (1 if s[q] < 128 else 2 if s[q] < 255 else 3)
        if h & 1:
            raise RuntimeError("no compressed block with sequences")
        pos += 1 if kind == 1 else size


def main(make_vectors=vectors):
    """Writes make_vectors()'s vectors (this file's, or a later generator's
    that imports this one) and checks them with both readers."""
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--batch", required=True)
    a = ap.parse_args()
    import sogmm_reader
    out = pathlib.Path(a.out)
    (out / "valid").mkdir(parents=True, exist_ok=True)
    (out / "invalid").mkdir(parents=True, exist_ok=True)
    entries = []
    paths = []
    vs = make_vectors()
    for name, expect, data, description, category, reason in vs:
        rel = f"{expect}/{name}.sogmm"
        (out / rel).write_bytes(data)
        paths.append(str(out / rel))
    (out / "list").write_text("\n".join(paths) + "\n")
    lines = subprocess.run([a.batch, str(out / "list")], check=True, capture_output=True, text=True).stdout.splitlines()
    failures = 0
    for (name, expect, data, description, category, reason), line in zip(vs, lines):
        rel = f"{expect}/{name}.sogmm"
        try:
            py = ("accept", sogmm_reader.read(data))
        except sogmm_reader.SogmmError as e:
            py = ("reject", f"{e.category} {e.reason}")
        verdict, _, rest = line.partition(" ")
        entry = {"file": rel, "expect": expect}
        if expect == "valid":
            ok = verdict == "accept" and py[0] == "accept" and json.loads(rest) == py[1]
            (out / f"valid/{name}.json").write_text(rest + "\n")
            entry["json"] = f"valid/{name}.json"
        else:
            ok = rest == f"{category} {reason}" and py == ("reject", rest)
            entry.update(category=category, reason=reason)
        entry["description"] = description
        if not ok:
            failures += 1
            print(f"FAIL {rel}: C++ {line[:200]} / Python {str(py)[:200]}")
        entries.append(entry)
    (out / "manifest_additions.json").write_text(json.dumps(entries, indent=2) + "\n")
    print(f"{len(vs) - failures}/{len(vs)} vectors as expected")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
