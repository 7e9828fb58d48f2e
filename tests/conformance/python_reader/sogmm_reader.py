"""An independent reader of .sogmm files, written from spec/format.md only.

It does not use the SOGMM library: only the Python standard library, the
`flatbuffers` runtime (table access) and `zstandard` from PyPI. Its purpose is
to prove that spec/format.md is enough to implement the format.

    read(data, max_decoded_bytes=1 << 30, verify_checksums=True) -> dict

returns the canonical dump (spec/format.md section 10) as a dict, or raises
SogmmError(category, reason, message) with the category and reason that
section 9 assigns to the first failing check.
"""
import math
import struct

import flatbuffers.table
import zstandard

MAGIC = b"\x89SOG\r\n\x1a\n"
END_MAGIC = b"SGMM"
HEADER_SIZE = 32
TRAILER_SIZE = 4
QUANTIZED_FEATURE = 4  # bit 2: quantized components (section 5.7, format 1.4)
MAP_DELTA_FEATURE = 1  # features_required bit 0: a map delta (section 2.5), known to a delta reader only
PACKED_KEY_VALUES_FEATURE = 2  # bit 1: key/values packed in the body (section 2.5.1; format 1.3: any reader)
FRAME_RECORD_FEATURE = 8  # bit 3: a map's frame lines as a binary record (section 2.3.2, format 1.3)
KNOWN_FEATURES = PACKED_KEY_VALUES_FEATURE | QUANTIZED_FEATURE | FRAME_RECORD_FEATURE
PACKED_KEY = "packed_key_values"
FRAME_RECORD_KEY = "map_frame_record"
DEFAULT_MAX_DECODED_BYTES = 1 << 30
MAX_DEPTH = 64
MAX_TABLES = 100000
METADATA_LENGTH_LIMIT = (1 << 31) - 1  # FlatBuffers' maximum buffer size, exclusive


class SogmmError(Exception):
    def __init__(self, category, reason, message):
        super().__init__(f"{reason}: {message}")
        self.category = category
        self.reason = reason


def _fail(category, reason, message):
    raise SogmmError(category, reason, message)


def _format(reason, message):
    _fail("format", reason, message)


# ---------------------------------------------------------------- CRC-32C
def _crc_table():
    table = []
    for i in range(256):
        c = i
        for _ in range(8):
            c = (c >> 1) ^ 0x82F63B78 if c & 1 else c >> 1
        table.append(c)
    return table


_CRC_TABLE = _crc_table()


def crc32c(data):
    c = 0xFFFFFFFF
    t = _CRC_TABLE
    for b in data:
        c = (c >> 8) ^ t[(c ^ b) & 0xFF]
    return c ^ 0xFFFFFFFF


# ---------------------------------------------------------------- FlatBuffers, verified
class _Bad(Exception):
    pass


class _Verifier:
    """Bounds/alignment checks of spec section 4.3 before any access."""

    def __init__(self, buf):
        self.buf = buf
        self.n = len(buf)
        self.tables = 0

    def check(self, pos, size, align=1):
        if pos < 0 or size < 0 or pos + size > self.n or pos % align:
            raise _Bad(f"{size} bytes at {pos} out of bounds or misaligned")

    def u8(self, pos):
        self.check(pos, 1)
        return self.buf[pos]

    def u16(self, pos):
        self.check(pos, 2, 2)
        return struct.unpack_from("<H", self.buf, pos)[0]

    def u32(self, pos):
        self.check(pos, 4, 4)
        return struct.unpack_from("<I", self.buf, pos)[0]

    def follow(self, at):
        """The target of the offset at `at`: non-zero and inside the block."""
        o = self.u32(at)
        if o == 0 or at + o >= self.n:
            raise _Bad(f"offset at {at} is 0 or points outside the block")
        return at + o

    def i32(self, pos):
        self.check(pos, 4, 4)
        return struct.unpack_from("<i", self.buf, pos)[0]


class _Table:
    """A table checked by the wire rules of spec section 4.3: soffset aligned
    to 4, vtable (size even, >= 4) and inline bytes (size >= 4) inside the
    block; each known field inside the inline bytes, after the soffset, and
    aligned to its size; every offset non-zero and pointing into the block.
    Each visit of a table counts towards the limit of 100 000."""

    def __init__(self, v, pos, depth):
        if depth > MAX_DEPTH:
            raise _Bad("nesting too deep")
        v.tables += 1
        if v.tables > MAX_TABLES:
            raise _Bad("too many table visits")
        self.v = v
        self.depth = depth
        self.pos = pos
        vt = pos - v.i32(pos)
        v.check(vt, 4, 2)
        self.vt = vt
        self.vt_size = v.u16(vt)
        if self.vt_size < 4 or self.vt_size % 2:
            raise _Bad("bad vtable size")
        v.check(vt, self.vt_size, 2)
        self.inline_size = v.u16(vt + 2)
        if self.inline_size < 4:
            raise _Bad("bad table inline size")
        v.check(pos, self.inline_size, 4)

    def _field(self, fid, size):
        slot = 4 + 2 * fid
        o = self.v.u16(self.vt + slot) if slot + 2 <= self.vt_size else 0
        if o:
            if o < 4 or o + size > self.inline_size:
                raise _Bad(f"field {fid} outside the table's inline bytes")
            self.v.check(self.pos + o, size, size)
        return o

    def scalar(self, fid, fmt, default):
        size = struct.calcsize("<" + fmt)
        o = self._field(fid, size)
        return struct.unpack_from("<" + fmt, self.v.buf, self.pos + o)[0] if o else default

    def _target(self, fid):
        o = self._field(fid, 4)
        return None if not o else self.v.follow(self.pos + o)

    def table(self, fid):
        t = self._target(fid)
        return None if t is None else _Table(self.v, t, self.depth + 1)

    def _vector(self, fid, elem):
        t = self._target(fid)
        if t is None:
            return None
        n = self.v.u32(t)
        self.v.check(t + 4, n * elem, elem)
        return t + 4, n

    def string_at(self, t):
        """The raw bytes of a string (its UTF-8 is checked in step 11)."""
        n = self.v.u32(t)
        self.v.check(t + 4, n + 1)
        if self.v.buf[t + 4 + n] != 0:
            raise _Bad("string not NUL-terminated")
        return bytes(self.v.buf[t + 4:t + 4 + n])

    def string(self, fid):
        t = self._target(fid)
        return None if t is None else self.string_at(t)

    def strings(self, fid):
        vec = self._vector(fid, 4)
        if vec is None:
            return None
        start, n = vec
        return [self.string_at(self.v.follow(start + 4 * i)) for i in range(n)]

    def tables_(self, fid):
        vec = self._vector(fid, 4)
        if vec is None:
            return None
        start, n = vec
        return [_Table(self.v, self.v.follow(start + 4 * i), self.depth + 1) for i in range(n)]

    def doubles(self, fid):
        vec = self._vector(fid, 8)
        if vec is None:
            return None
        start, n = vec
        return list(struct.unpack_from(f"<{n}d", self.v.buf, start))


# ---------------------------------------------------------------- schema
DTYPES = {0: ("f32", 4, "f"), 1: ("f64", 8, "d")}
ORDERS = {0: "component_major", 1: "column_major"}
FILTERS = {0: "none", 1: "byte_stream_split", 2: "quantized"}
CODECS = {0: "none", 1: "zstd"}
LAYOUTS = {0: "upper_packed", 1: "full"}
ARRAY_NAMES = ("weights", "means", "covariances")
FIT_DOUBLES = ("bandwidth", "tol", "reg_covar", "log_likelihood")
CAMERA_DOUBLES = ("fx", "fy", "cx", "cy", "depth_scale", "depth_min", "depth_max")
UPPER = [(0, 0), (0, 1), (0, 2), (0, 3), (1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3)]


def _array_record(t):
    return {
        "dtype": t.scalar(0, "B", 0), "order": t.scalar(1, "B", 0), "filter": t.scalar(2, "B", 0),
        "codec": t.scalar(3, "B", 0), "offset": t.scalar(4, "Q", 0), "stored_length": t.scalar(5, "Q", 0),
        "decoded_length": t.scalar(6, "Q", 0), "crc32c": t.scalar(7, "I", 0),
    }


def _read_all_metadata(root):
    """Touches every known field (so the whole block is verified)."""
    m = {}
    m["n_components"] = root.scalar(0, "Q", 0)
    m["dims"] = root.scalar(1, "I", 4)
    m["support_size"] = root.scalar(2, "Q", 0)
    m["covariance_layout"] = root.scalar(3, "B", 0)
    arrays = []
    for fid in (4, 5, 6):
        t = root.table(fid)
        if t is None:
            raise _Bad(f"required field {ARRAY_NAMES[fid - 4]} missing")
        arrays.append(_array_record(t))
    m["arrays"] = arrays
    m["features_required"] = root.scalar(7, "Q", 0)
    m["features_used"] = root.scalar(8, "Q", 0)
    m["axis_labels"] = root.strings(9)
    m["axis_units"] = root.strings(10)
    m["gray_min"] = root.scalar(11, "d", 0.0)
    m["gray_max"] = root.scalar(12, "d", 1.0)
    f = root.table(13)
    m["fit"] = None if f is None else {
        "bandwidth": f.scalar(0, "d", 0.0), "n_components_requested": f.scalar(1, "Q", 0),
        "tol": f.scalar(2, "d", 0.0), "reg_covar": f.scalar(3, "d", 0.0), "max_iter": f.scalar(4, "i", 0),
        "n_iter": f.scalar(5, "i", 0), "converged": f.scalar(6, "B", 0),
        "log_likelihood": f.scalar(7, "d", 0.0), "seed": f.scalar(8, "Q", 0)}
    c = root.table(14)
    m["camera"] = None if c is None else {
        "width": c.scalar(0, "i", 0), "height": c.scalar(1, "i", 0), "fx": c.scalar(2, "d", 0.0),
        "fy": c.scalar(3, "d", 0.0), "cx": c.scalar(4, "d", 0.0), "cy": c.scalar(5, "d", 0.0),
        "decimation": c.scalar(6, "i", 1), "depth_scale": c.scalar(7, "d", 1000.0),
        "depth_min": c.scalar(8, "d", 0.1), "depth_max": c.scalar(9, "d", 3.0)}
    m["pose"] = root.doubles(15)
    m["producer_name"] = root.string(16) or b""
    m["producer_version"] = root.string(17) or b""
    m["created_unix_ms"] = root.scalar(18, "q", 0)
    kvs = root.tables_(19) or []
    m["key_values"] = [[kv.string(0) or b"", kv.string(1) or b""] for kv in kvs]
    return m


def _decode_strings(md, block_length):
    """Step 11, strings (spec section 4.4): valid UTF-8 without NUL, and no
    more bytes in total (a shared string once per use) than the block."""
    raw = [md["producer_name"], md["producer_version"]] + [b for kv in md["key_values"] for b in kv]
    if sum(len(b) for b in raw) > block_length:
        _format("bad_metadata", "strings total more bytes than the metadata block")
    for b in raw:
        if b"\0" in b:
            _format("bad_metadata", "a string contains NUL")
        try:
            b.decode("utf-8")  # strict: no overlong forms, surrogates or code points above U+10FFFF
        except UnicodeDecodeError as e:
            _format("bad_metadata", f"a string is not valid UTF-8: {e}")
    md["producer_name"] = md["producer_name"].decode("utf-8")
    md["producer_version"] = md["producer_version"].decode("utf-8")
    md["key_values"] = [[k.decode("utf-8"), v.decode("utf-8")] for k, v in md["key_values"]]


def _round_f32(x):
    """Nearest binary32 value of a binary64 value (ties to even), as spec
    section 5.6 defines the values of F64 arrays; beyond the range: infinity."""
    try:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)


# ---------------------------------------------------------------- checks and decoding
def _check_pose(p):
    if not all(math.isfinite(x) for x in p):
        _fail("invalid_data", "bad_pose", "pose has a non-finite entry")
    if p[12:16] != [0.0, 0.0, 0.0, 1.0]:
        _fail("invalid_data", "bad_pose", "last row is not 0 0 0 1")
    for i in range(3):
        for j in range(3):
            dot = sum(p[k * 4 + i] * p[k * 4 + j] for k in range(3))
            if abs(dot - (1.0 if i == j else 0.0)) > 1e-3:
                _fail("invalid_data", "bad_pose", "rotation not orthonormal")
    det = (p[0] * (p[5] * p[10] - p[6] * p[9]) - p[1] * (p[4] * p[10] - p[6] * p[8])
           + p[2] * (p[4] * p[9] - p[5] * p[8]))
    if not det > 0:
        _fail("invalid_data", "bad_pose", "rotation is a reflection")


MAX_WINDOW = 1 << 31  # section 5.4: larger windows are rejected


def _zstd_structure(st):
    """The frame structure section 5.4 has a reader check itself (RFC 8878
    field names): header descriptor reserved bit clear (the unused bit is
    ignored), content size present, a window of at most 2^31 bytes, no
    reserved block type, blocks and literals of at most Block_Maximum_Size,
    and in compressed blocks the literals inside the block, a zero sequence
    count only as the single last byte, and the reserved bits of
    Symbol_Compression_Modes clear."""
    def need(pos, n):
        if pos + n > len(st):
            _format("decompression_failed", "zstd frame truncated")

    def le(pos, n):
        need(pos, n)
        return int.from_bytes(st[pos:pos + n], "little")

    pos = 0
    while pos < len(st):
        if le(pos, 4) != 0xFD2FB528:
            _format("decompression_failed", "not a zstd frame")
        fhd = le(pos + 4, 1)
        if fhd & 0x08:
            _format("decompression_failed", "reserved bit of the frame header descriptor")
        single = fhd >> 5 & 1
        fcs_flag = fhd >> 6
        if fcs_flag == 0 and not single:
            _format("decompression_failed", "frame without content size")
        pos += 5
        if not single:
            wd = le(pos, 1)
            window = (1 << (10 + (wd >> 3))) * (8 + (wd & 7)) // 8
            pos += 1
        pos += (0, 1, 2, 4)[fhd & 3]
        n = (1, 2, 4, 8)[fcs_flag]
        content_size = le(pos, n) + (256 if fcs_flag == 1 else 0)
        pos += n
        if single:
            window = content_size
        if window > MAX_WINDOW:
            _format("decompression_failed", "window above 2^31 bytes")
        block_max = min(window, 128 << 10)
        last = False
        while not last:
            h = le(pos, 3)
            pos += 3
            last, kind, size = h & 1, h >> 1 & 3, h >> 3
            if kind == 3:
                _format("decompression_failed", "reserved block type")
            if size > block_max:
                _format("decompression_failed", "block larger than Block_Maximum_Size")
            if kind == 2:
                _compressed_block(st, pos, size, le, block_max)
            pos += 1 if kind == 1 else size
            need(pos, 0)
        pos += 4 if fhd >> 2 & 1 else 0
        need(pos, 0)


def _compressed_block(st, pos, size, le, block_max):
    b0 = le(pos, 1)
    kind, fmt = b0 & 3, b0 >> 2 & 3
    if kind < 2:
        header = 2 if fmt == 1 else 3 if fmt == 3 else 1
        regenerated = b0 >> 3 if header == 1 else (b0 >> 4) + (le(pos + 1, header - 1) << 4)
        content = regenerated if kind == 0 else 1
    else:
        header = 3 if fmt < 2 else 4 if fmt == 2 else 5
        bits = 10 if header == 3 else 14 if header == 4 else 18
        sizes = le(pos, header) >> 4
        content, regenerated = sizes >> bits, sizes & ((1 << bits) - 1)
    if regenerated > block_max:
        _format("decompression_failed", "literals larger than Block_Maximum_Size")
    if header + content >= size:
        _format("decompression_failed", "literals leave no room for the sequences section")
    q = pos + header + content
    left = size - header - content - 1
    n0 = le(q, 1)
    count_bytes = 0 if n0 < 128 else 1 if n0 < 255 else 2
    if left < count_bytes:
        _format("decompression_failed", "sequences section header beyond the block")
    if n0 == 128 and le(q + 1, 1) == 0:
        _format("decompression_failed", "Number_of_Sequences of 0 in its 2-byte form")
    if n0 == 0:
        if left:
            _format("decompression_failed", "bytes after an empty sequences section")
        return
    if left < count_bytes + 1:
        _format("decompression_failed", "sequences section header beyond the block")
    if le(q + 1 + count_bytes, 1) & 3:
        _format("decompression_failed", "reserved bits of Symbol_Compression_Modes")


def _zstd_frames(stored, expected):
    """Section 5.4: frames back to back, each declaring its content size and
    no dictionary; its content checksum, if present, is verified (by zstd)."""
    out = bytearray()
    pos = 0
    while pos < len(stored):
        if stored[pos:pos + 4] != b"\x28\xb5\x2f\xfd":
            _format("decompression_failed", "not a zstd frame")
        try:
            params = zstandard.get_frame_parameters(stored[pos:pos + 18])
        except zstandard.ZstdError as e:
            _format("decompression_failed", f"frame header: {e}")
        if params.content_size == zstandard.CONTENTSIZE_UNKNOWN:
            _format("decompression_failed", "frame without content size")
        if params.dict_id:
            _format("decompression_failed", "frame needs a dictionary")
        if params.content_size > expected - len(out):
            _format("decompression_failed", "frame declares more than is left")
        start = len(out)
        # Any window up to 2^31 (checked above): the content size bounds the output.
        d = zstandard.ZstdDecompressor(max_window_size=MAX_WINDOW).decompressobj()
        consumed = None
        try:
            # Small input chunks keep every output burst bounded (bomb-safe).
            for i in range(pos, len(stored), 256):
                chunk = stored[i:i + 256]
                out += d.decompress(chunk)
                if len(out) - start > params.content_size:
                    _format("decompression_failed", "frame decodes to more than its content size")
                if d.eof:
                    consumed = i + len(chunk) - len(d.unused_data)
                    break
        except zstandard.ZstdError as e:
            _format("decompression_failed", str(e))
        if consumed is None:
            _format("decompression_failed", "incomplete zstd frame")
        if len(out) - start != params.content_size:
            _format("decompression_failed", "frame decodes to less than its content size")
        pos = consumed
    if len(out) != expected:
        _format("decompression_failed", f"decodes to {len(out)} bytes, {expected} declared")
    return bytes(out)


def _decode(stored, rec, rows, cols, width=None):
    w = width or DTYPES[rec["dtype"]][1]
    n = rows * cols
    if rec["codec"] == 1:
        _zstd_structure(stored)
    data = _zstd_frames(stored, n * w) if rec["codec"] == 1 else bytes(stored)
    if rec["filter"] in (1, 2):  # byte k of element i is at k * n + i
        joined = bytearray(n * w)
        for k in range(w):
            joined[k::w] = data[k * n:(k + 1) * n]
        data = bytes(joined)
    if rec["order"] == 1:  # column-major -> component-major
        comp = bytearray(n * w)
        for c in range(cols):
            for r in range(rows):
                src = (c * rows + r) * w
                dst = (r * cols + c) * w
                comp[dst:dst + w] = data[src:src + w]
        data = bytes(comp)
    return data


# ---------------------------------------------------------------- quantized components (section 5.7)
CODE_COLUMNS = (1, 5, 14)


def _bad_code(k, what):
    _fail("invalid_data", "bad_quantization", f"component {k}: {what}")


def _mf(c, f):
    """(F + (c mod F)) 2^(floor(c / F) - f) and its exponent floor(c / F)."""
    big = 1 << f
    e = c // big
    return math.ldexp(float(big + c % big), e - f), e


def _dequantize(codes, m):
    """Section 5.7: the float32 weights, means and packed covariances of the codes."""
    cw, cm, cc = codes
    omega = []
    for k in range(m):
        o, e = _mf(cw[k], 3)
        if not -126 <= e <= 0:
            _bad_code(k, "weight code out of range")
        omega.append(o)
    total = 0.0
    for o in omega:
        total += o
    weights = [_round_f32(o / total) for o in omega]
    means, cov = [], []
    for k in range(m):
        f, c0, c1, c2, cv, r, u, Y, Z, T, sb, B0, B1, B2 = cc[14 * k:14 * k + 14]
        if not 0 <= f <= 16:
            _bad_code(k, "f out of range")
        lam = []
        for c in (c0, c1, c2, cv):
            val, e = _mf(c, f)
            if not -126 <= e <= 127:
                _bad_code(k, "variance code out of range")
            lam.append(val)
        v = lam.pop()
        if not 0 <= r <= 24:
            _bad_code(k, "r out of range")
        if not 0 <= u <= 24:
            _bad_code(k, "u out of range")
        if Y * Y + Z * Z > 4 ** r:
            _bad_code(k, "tilt codes of norm above 1")
        if not -(1 << u) <= T <= 1 << u:
            _bad_code(k, "turn code out of range")
        if not 0 <= sb <= 40:
            _bad_code(k, "s out of range")
        y, z, t = math.ldexp(float(Y), -r), math.ldexp(float(Z), -r), math.ldexp(float(T), -u)
        w = math.sqrt(1 - (y * y + z * z))
        a0, a1, a2, a3 = w, w * t, y + z * t, z - y * t
        n = ((a0 * a0 + a1 * a1) + a2 * a2) + a3 * a3
        q = 2 / n
        R = [[1 - q * (a2 * a2 + a3 * a3), q * (a1 * a2 - a0 * a3), q * (a1 * a3 + a0 * a2)],
             [q * (a1 * a2 + a0 * a3), 1 - q * (a1 * a1 + a3 * a3), q * (a2 * a3 - a0 * a1)],
             [q * (a1 * a3 - a0 * a2), q * (a2 * a3 + a0 * a1), 1 - q * (a1 * a1 + a2 * a2)]]
        beta = [math.ldexp(float(B), -sb) for B in (B0, B1, B2)]
        S = [[0.0] * 4 for _ in range(4)]
        for a in range(3):
            for b in range(a, 3):
                S[a][b] = ((lam[0] * R[a][0]) * R[b][0] + (lam[1] * R[a][1]) * R[b][1]) + (lam[2] * R[a][2]) * R[b][2]
        tau = [math.sqrt(lam[i]) * beta[i] for i in range(3)]
        for a in range(3):
            S[a][3] = math.sqrt(v) * ((R[a][0] * tau[0] + R[a][1] * tau[1]) + R[a][2] * tau[2])
        S[3][3] = v * (1 + ((beta[0] * beta[0] + beta[1] * beta[1]) + beta[2] * beta[2]))
        cov.extend(_round_f32(S[i][j]) for i, j in UPPER)
        e, U0, U1, U2, G = cm[5 * k:5 * k + 5]
        if not 0 <= e <= 40:
            _bad_code(k, "e out of range")
        h = math.ldexp(1.0, -e)
        yt = [math.sqrt(lam[i]) * (U * h) for i, U in enumerate((U0, U1, U2))]
        means.extend(_round_f32((R[a][0] * yt[0] + R[a][1] * yt[1]) + R[a][2] * yt[2]) for a in range(3))
        means.append(_round_f32(math.sqrt(v) * (G * h)))
    return [weights, means, cov]


def _cholesky_ok(a):
    l = [[0.0] * 4 for _ in range(4)]
    for j in range(4):
        d = a[j][j]
        for k in range(j):
            d -= l[j][k] * l[j][k]
        if not d > 0.0:
            return False
        l[j][j] = math.sqrt(d)
        for i in range(j + 1, 4):
            s = a[i][j]
            for k in range(j):
                s -= l[i][k] * l[j][k]
            l[i][j] = s / l[j][j]
    return True


# ---------------------------------------------------------------- the procedure of section 9
def read(data, max_decoded_bytes=DEFAULT_MAX_DECODED_BYTES, verify_checksums=True, metadata_only=False,
         delta=False):
    """Section 9's procedure; with delta=True a map delta reader's (section 2.5):
    bit 0 known and required, M = 0 allowed, weights only >= 0, FULL
    covariances returned as stored."""
    data = bytes(data)
    size = len(data)
    # 1-2
    k = min(size, 8)
    if data[:k] != MAGIC[:k]:
        _format("bad_magic", "wrong signature")
    if size < HEADER_SIZE + TRAILER_SIZE:
        _format("truncated", "shorter than header + trailer")
    major, minor, flags, file_length, meta_len, meta_crc = struct.unpack_from("<HHIQII", data, 8)
    # 3-7
    if major != 1:
        _format("unsupported_version", f"major version {major}")
    if flags != 0:
        _format("bad_header", "reserved flags set")
    if file_length > size:
        _format("truncated", "file shorter than declared")
    if file_length < size:
        _format("bad_header", "trailing data")
    if data[-4:] != END_MAGIC:
        _format("bad_trailer", "end marker missing")
    body_start = HEADER_SIZE + (meta_len + 7) // 8 * 8
    if meta_len < 8 or meta_len >= METADATA_LENGTH_LIMIT or body_start + TRAILER_SIZE > file_length:
        _format("bad_header", "metadata length out of range")
    meta = data[HEADER_SIZE:HEADER_SIZE + meta_len]
    # 8
    if verify_checksums and crc32c(meta) != meta_crc:
        _format("checksum_mismatch", "metadata CRC-32C")
    # 9
    if meta[4:8] != b"SGMM":
        _format("bad_metadata", "file identifier")
    try:
        v = _Verifier(meta)
        root = _Table(v, v.follow(0), 1)
        md = _read_all_metadata(root)
    except (_Bad, struct.error) as e:
        _format("bad_metadata", f"FlatBuffers verification failed: {e}")
    # 10
    known = KNOWN_FEATURES | (MAP_DELTA_FEATURE if delta else 0)
    if md["features_required"] & ~known:
        _format("unsupported_feature", hex(md["features_required"]))
    if delta and not md["features_required"] & MAP_DELTA_FEATURE:
        _format("not_a_delta", "features_required bit 0 is not set")
    if delta and md["features_required"] & (QUANTIZED_FEATURE | FRAME_RECORD_FEATURE):
        _format("unsupported_feature", "a map delta with bit 2 or 3 (section 7: model features only)")
    # 11
    if md["dims"] != 4:
        _format("bad_metadata", "dims != 4")
    if md["axis_labels"] is not None and md["axis_labels"] != [b"x", b"y", b"z", b"gray"]:
        _format("bad_metadata", "axis labels")
    if md["axis_units"] is not None and md["axis_units"] != [b"m", b"m", b"m", b"1"]:
        _format("bad_metadata", "axis units")
    if md["gray_min"] != 0.0 or md["gray_max"] != 1.0:
        _format("bad_metadata", "gray range")
    if md["fit"] is not None:
        if md["fit"]["converged"] > 1:
            _format("bad_metadata", "a bool that is neither 0 nor 1")
        md["fit"]["converged"] = md["fit"]["converged"] == 1
    for table, names in (("fit", FIT_DOUBLES), ("camera", CAMERA_DOUBLES)):
        if md[table] is not None and not all(math.isfinite(md[table][k]) for k in names):
            _format("bad_metadata", f"a {table} double is not finite")
    _decode_strings(md, meta_len)
    if md["pose"] is not None:
        if len(md["pose"]) != 16:
            _format("bad_metadata", "pose length")
        _check_pose(md["pose"])
    # 12
    if md["covariance_layout"] not in LAYOUTS:
        _format("unsupported_encoding", "covariance layout")
    for rec in md["arrays"]:
        if (rec["dtype"] not in DTYPES or rec["order"] not in ORDERS or rec["filter"] not in FILTERS
                or rec["codec"] not in CODECS):
            _format("unsupported_encoding", "unknown enum value")
    quantized = bool(md["features_required"] & QUANTIZED_FEATURE)
    for rec in md["arrays"]:
        if (rec["filter"] == 2) != quantized:
            _format("unsupported_encoding", "filter QUANTIZED and feature bit 2 disagree")
        if quantized and (rec["dtype"] != 0 or md["covariance_layout"] != 0):
            _format("unsupported_encoding", "quantized components decode to float32, packed")
    # 13
    m = md["n_components"]
    if m == 0 and not delta:
        _fail("invalid_data", "empty", "M = 0")
    # 14-15
    packed = md["covariance_layout"] == 0
    cols = (1, 4, 10 if packed else 16)
    total = 0
    for rec, c in zip(md["arrays"], cols):
        expected = m * c * DTYPES[rec["dtype"]][1]
        if rec["decoded_length"] != expected or expected >= 1 << 64:
            _fail("invalid_data", "length_mismatch", "decoded length disagrees with M")
        total += expected
    if total > max_decoded_bytes:
        _fail("limit", "limit", f"{total} decoded bytes declared")
    # 16
    body_end = file_length - TRAILER_SIZE
    for i, rec in enumerate(md["arrays"]):
        off, n = rec["offset"], rec["stored_length"]
        if off % 8 or off < body_start or off + n > body_end:
            _format("bad_layout", "array outside the body or misaligned")
        filtered = m * CODE_COLUMNS[i] * 4 if quantized else rec["decoded_length"]
        if rec["codec"] == 0 and n != filtered:
            _format("bad_layout", "raw array length")
        for other in md["arrays"][:i]:
            if n and other["stored_length"] and off < other["offset"] + other["stored_length"] \
                    and other["offset"] < off + n:
                _format("bad_layout", "arrays overlap")
    out = {
        "file": {
            "format_version": f"{major}.{minor}", "file_length": file_length, "metadata_length": meta_len,
            "features_required": md["features_required"], "features_used": md["features_used"],
            "covariance_layout": LAYOUTS[md["covariance_layout"]],
        },
    }
    for name, rec in zip(ARRAY_NAMES, md["arrays"]):
        out["file"][name] = {
            "dtype": DTYPES[rec["dtype"]][0], "order": ORDERS[rec["order"]], "filter": FILTERS[rec["filter"]],
            "codec": CODECS[rec["codec"]], "offset": rec["offset"], "stored_length": rec["stored_length"],
            "decoded_length": rec["decoded_length"], "crc32c": rec["crc32c"]}
    out.update({
        "n_components": m, "support_size": md["support_size"],
        "axis_labels": ["x", "y", "z", "gray"], "axis_units": ["m", "m", "m", "1"],
        "fit": md["fit"], "camera": md["camera"], "pose": md["pose"],
        "producer_name": md["producer_name"], "producer_version": md["producer_version"],
        "created_unix_ms": md["created_unix_ms"], "key_values": md["key_values"],
    })
    if metadata_only:
        return out
    # 17-18
    values = []
    if quantized:  # 17, 17b, then 18 over the decoded float32 values (section 5.7)
        codes = []
        for rec, kc in zip(md["arrays"], CODE_COLUMNS):
            raw = _decode(data[rec["offset"]:rec["offset"] + rec["stored_length"]], rec, m, kc, 4)
            zz = struct.unpack(f"<{m * kc}I", raw)
            codes.append([z >> 1 if z % 2 == 0 else -((z + 1) >> 1) for z in zz])
        values = _dequantize(codes, m)
        for name, rec, v in zip(ARRAY_NAMES, md["arrays"], values):
            if verify_checksums and crc32c(struct.pack(f"<{len(v)}f", *v)) != rec["crc32c"]:
                _format("checksum_mismatch", f"{name} CRC-32C")
    for name, rec, c in zip(ARRAY_NAMES, md["arrays"], cols) if not quantized else ():
        raw = _decode(data[rec["offset"]:rec["offset"] + rec["stored_length"]], rec, m, c)
        if verify_checksums and crc32c(raw) != rec["crc32c"]:
            _format("checksum_mismatch", f"{name} CRC-32C")
        _, w, code = DTYPES[rec["dtype"]]
        v = struct.unpack(f"<{m * c}{code}", raw)
        values.append([_round_f32(x) for x in v] if code == "d" else list(v))
    weights, means, cov = values
    # 19 (on the values as float32, section 5.6)
    if not all(math.isfinite(x) for arr in values for x in arr):
        _fail("numeric", "non_finite", "NaN or infinity in the arrays")
    if any(x < 0 for x in weights):
        _fail("numeric", "bad_weights", "negative weight")
    s = 0.0
    for x in weights:
        s += x
    if abs(s - 1.0) > 1e-4 and not delta:
        _fail("numeric", "bad_weights", f"weights sum to {s}")
    mats = []
    for k in range(m):
        if packed:
            a = [[0.0] * 4 for _ in range(4)]
            for t, (i, j) in enumerate(UPPER):
                a[i][j] = a[j][i] = cov[10 * k + t]
        else:
            a = [cov[16 * k + 4 * i:16 * k + 4 * i + 4] for i in range(4)]
            scale = max(abs(x) for row in a for x in row)
            asym = max(abs(a[i][j] - a[j][i]) for i in range(4) for j in range(4))
            if asym > 1e-5 * scale:
                _fail("numeric", "not_symmetric", f"component {k}")
            # Section 5.1: a reader returns (and tests) the symmetric part;
            # a delta's receiver must reproduce the sender's bits (2.5).
            sym = [[_round_f32((a[i][j] + a[j][i]) / 2) for j in range(4)] for i in range(4)]
            if not _cholesky_ok(sym):
                _fail("numeric", "not_spd", f"component {k}")
            if not delta:
                a = sym
            mats.append([list(row) for row in a])
            continue
        if not _cholesky_ok(a):
            _fail("numeric", "not_spd", f"component {k}")
        mats.append(a)
    out["weights"] = weights
    out["means"] = [means[4 * k:4 * k + 4] for k in range(m)]
    out["covariances"] = mats
    total = sum(rec["decoded_length"] for rec in md["arrays"])
    packed_begin = file_length - TRAILER_SIZE
    if md["features_required"] & PACKED_KEY_VALUES_FEATURE:
        out["key_values"], stored, decoded = _unpack_key_values(
            data, file_length, body_start, md["arrays"], total, max_decoded_bytes, verify_checksums, out["key_values"])
        packed_begin -= stored
        total += decoded
    if md["features_required"] & FRAME_RECORD_FEATURE:
        out["key_values"] = _unpack_frame_record(data, packed_begin, body_start, md["arrays"], total,
                                                 max_decoded_bytes, verify_checksums, out["key_values"])
    return out


def _locator(key, value):
    """The four counts "codec stored_length decoded_length crc32c" of a locating entry (20a, 21a)."""
    tokens = value.split(" ")
    if len(tokens) != 4 or not all(t and len(t) <= 19 and t.isascii() and t.isdigit() for t in tokens):
        _format("bad_metadata", f"{key} is not four decimal counts")
    codec, stored, decoded, crc = (int(t) for t in tokens)
    if codec > 1 or crc >= 1 << 32:
        _format("bad_metadata", f"{key}: codec or crc32c out of range")
    return codec, stored, decoded, crc


def _body_range(end, codec, stored, decoded, body_start, arrays, decoded_so_far, cap, what):
    """Steps 20b-c / 21b-c: the cap, and the stored range [end - stored, end)
    inside the body, of the decoded length when raw, overlapping no array."""
    if decoded_so_far + decoded > cap:
        _fail("limit", "limit", f"arrays and {what} over the cap")
    if stored > end - body_start:
        _format("bad_layout", f"{what} outside the body")
    begin = end - stored
    if codec == 0 and stored != decoded:
        _format("bad_layout", f"raw {what} length")
    for rec in arrays:
        if stored and rec["stored_length"] and begin < rec["offset"] + rec["stored_length"] and rec["offset"] < end:
            _format("bad_layout", f"{what} overlaps an array")
    return begin


def _frame_line(index, row):
    """A `map_frames` line from a record row (section 2.3.2): counts in decimal, pose entries as C's %.17g."""
    counts = [int(row[0]), int(row[1])]
    return " ".join([str(index), *map(str, counts), *("%.17g" % x for x in row[2:14]), str(int(row[14]))]) + "\n"


def _unpack_frame_record(data, packed_begin, body_start, arrays, decoded_so_far, cap, verify_checksums, key_values):
    """Step 21 (section 2.3.2): the frame record, right before the packed
    key/values, replaces the first entry `map_frame_record` by `map_frames`."""
    # 21a
    at = next((i for i, (k, _) in enumerate(key_values) if k == FRAME_RECORD_KEY), None)
    if at is None:
        _format("bad_metadata", "bit 3 set, no map_frame_record entry")
    codec, stored, decoded, crc = _locator(FRAME_RECORD_KEY, key_values[at][1])
    if decoded == 0 or decoded % 120:
        _format("bad_metadata", "map_frame_record: decoded length not a positive multiple of 120")
    begin = _body_range(packed_begin, codec, stored, decoded, body_start, arrays, decoded_so_far, cap,
                        "frame record")  # 21b-c
    # 21d-e: the array pipeline, column-major and byte-stream split
    rows = decoded // 120
    raw = _decode(data[begin:packed_begin], {"dtype": 1, "codec": codec, "filter": 1, "order": 1}, rows, 15)
    if verify_checksums and crc32c(raw) != crc:
        _format("checksum_mismatch", "frame record CRC-32C")
    # 21f
    values = struct.unpack(f"<{rows * 15}d", raw)
    lines = []
    for r in range(rows):
        row = values[15 * r:15 * r + 15]
        for c, x in enumerate(row):
            if c in (0, 1, 14):
                if not (0 <= x <= 2.0 ** 53 and math.floor(x) == x):
                    _format("bad_metadata", f"frame record: frame {r} column {c} is not a count")
            elif not math.isfinite(x):
                _format("bad_metadata", f"frame record: frame {r} column {c} is not finite")
        lines.append(_frame_line(r, row))
    return key_values[:at] + [["map_frames", "".join(lines)]] + key_values[at + 1:]


def _unpack_key_values(data, file_length, body_start, arrays, arrays_decoded, cap, verify_checksums, key_values):
    """Step 20 (section 2.5.1): the key/values packed at the end of the body,
    located by the first entry `packed_key_values`, which they replace."""
    # 20a
    at = next((i for i, (k, _) in enumerate(key_values) if k == PACKED_KEY), None)
    if at is None:
        _format("bad_metadata", "bit 1 set, no packed_key_values entry")
    codec, stored, decoded, crc = _locator(PACKED_KEY, key_values[at][1])
    if decoded < 2:
        _format("bad_metadata", "packed_key_values: decoded length out of range")
    end = file_length - TRAILER_SIZE
    begin = _body_range(end, codec, stored, decoded, body_start, arrays, arrays_decoded, cap,
                        "packed key/values")  # 20b-c
    # 20d-e
    raw = data[begin:end]
    if codec == 1:
        _zstd_structure(raw)
        raw = _zstd_frames(raw, decoded)
    if verify_checksums and crc32c(raw) != crc:
        _format("checksum_mismatch", "packed key/values CRC-32C")
    # 20f
    if raw[-1:] != b"\0" or raw.count(0) % 2:
        _format("bad_metadata", "packed key/values are not key NUL value NUL ...")
    strings = raw[:-1].split(b"\0")
    try:
        text = [b.decode("utf-8") for b in strings]
    except UnicodeDecodeError:
        _format("bad_metadata", "packed key/values: not UTF-8")
    rest = key_values[:at] + key_values[at + 1:]
    return rest + [[text[i], text[i + 1]] for i in range(0, len(text), 2)], stored, decoded
