"""Generates the conformance vectors of the rules stated for issue 29 part 4
(spec/format.md sections 2, 3 and 5.4): Block_Maximum_Size, a zero
Number_of_Sequences, RLE literals, windows up to 2^31, the Unused_Bit, an
empty array range at file_length - 4 and a singular matrix that step 19d
accepts.

RUN ONCE, THEN FROZEN, like rule_vectors.py (whose builder and checks it
reuses; its own vectors are not written again):

    python3 zstd_rule_vectors.py OUT_DIR --batch build/tests/conformance/sogmm_conformance_batch

The zstd frames are written byte by byte here (RFC 8878), so that each one
breaks exactly one rule; every vector must get its expected verdict from the
C++ reader and the independent Python reader before it is listed.
"""
import struct

import rule_vectors as rv

MAGIC = b"\x28\xb5\x2f\xfd"


def frame(content, blocks, window_descriptor=None, descriptor_bits=0):
    """A zstd frame declaring len(content) bytes, with a 4-byte
    Frame_Content_Size. window_descriptor None: Single_Segment (Window_Size =
    Frame_Content_Size); else that Window_Descriptor byte."""
    fhd = 0x80 | descriptor_bits  # Frame_Content_Size_Flag 2
    head = MAGIC
    if window_descriptor is None:
        head += bytes([fhd | 0x20])
    else:
        head += bytes([fhd, window_descriptor])
    return head + struct.pack("<I", len(content)) + b"".join(blocks)


def block(kind, size, body, last):
    """Block_Header (Last_Block, Block_Type, Block_Size) and its content."""
    return struct.pack("<I", last | kind << 1 | size << 3)[:3] + body


def raw_block(data, last=True):
    return block(0, len(data), data, last)


def literals_block(data, rle, sequences=b"\x00", last=True):
    """A Compressed_Block holding only literals (raw, or RLE when rle: every
    byte of data the same) with a 2-byte Literals_Section_Header
    (Size_Format 1), followed by the sequence section bytes given."""
    n = len(data)
    assert n < 4096 and (not rle or data == data[:1] * n)
    header = bytes([(1 if rle else 0) | 1 << 2 | (n & 15) << 4, n >> 4])
    body = header + (data[:1] if rle else data) + sequences
    return block(2, len(body), body, last)


def runs(data):
    """data as maximal runs of one byte value."""
    out, i = [], 0
    while i < len(data):
        j = i
        while j < len(data) and data[j] == data[i]:
            j += 1
        out.append(data[i:j])
        i = j
    return out


def with_codec(codec, m=None):
    m = m or rv.base_model(8)
    m["codec"] = codec
    return m


def vectors():
    v = []

    def add(name, expect, data, description, category=None, reason=None):
        v.append((name, expect, data, description, category, reason))

    # --- 5.4 rule 4: Block_Size <= Block_Maximum_Size = min(Window_Size, 128 KiB)
    def block_over_content(data):
        return frame(data, [literals_block(data, rle=False)])
    add("zstd_block_over_content_size", "invalid", rv.assemble(with_codec(block_over_content)),
        "single-segment frames (Window_Size = Frame_Content_Size) whose one Compressed_Block (raw literals "
        "and no sequences) is 3 bytes larger than the content: above Block_Maximum_Size (zstd 1.5.4 decodes "
        "it, 1.5.7 rejects it; the format rejects it)", "format", "decompression_failed")

    def block_over_window(data):
        return frame(data, [raw_block(data)], window_descriptor=0)  # Window_Size 1 KiB
    add("zstd_block_over_window", "invalid", rv.assemble(with_codec(block_over_window, rv.base_model(128))),
        "frames with a 1 KiB window whose single Raw_Block holds all the content: the means' and "
        "covariances' blocks (2048 and 5120 bytes) are above Block_Maximum_Size", "format", "decompression_failed")

    def rle_over_window(data):
        # Every run but the last as blocks of at most 1 KiB; the last run (a
        # run longer than 1 KiB, made below) in one block: its literals
        # regenerate more than Block_Maximum_Size, its Block_Size is 5.
        rs = runs(data)
        blocks = [literals_block(r, rle=True, last=False) for r in rs[:-1]]
        blocks.append(literals_block(rs[-1], rle=True))
        return frame(data, blocks, window_descriptor=0)
    m = rv.base_model(128)
    m["means"] = [[0.0, 0.0, 0.0, 0.0] for _ in range(128)]  # 2048 zero bytes: one run
    add("zstd_literals_over_window", "invalid", rv.assemble(with_codec(rle_over_window, m)),
        "frames with a 1 KiB window made of Compressed_Blocks of RLE literals: the means' block (5 bytes) "
        "regenerates 2048 literals, above Block_Maximum_Size", "format", "decompression_failed")

    # --- 5.4 rule 5: a zero Number_of_Sequences is the single byte 0, the last of its block
    def zero_sequences(tail):
        def codec(data):
            return frame(data, [literals_block(data, rle=False, sequences=tail)], window_descriptor=0x10)  # 4 KiB
        return codec
    add("zstd_zero_sequences_2byte", "invalid", rv.assemble(with_codec(zero_sequences(b"\x80\x00\x00"))),
        "compressed blocks of raw literals whose Number_of_Sequences is 0 in its 2-byte form (80 00), followed "
        "by a Symbol_Compression_Modes byte (zstd 1.5.4 decodes it, 1.5.7 rejects it; the format rejects it)",
        "format", "decompression_failed")
    add("zstd_zero_sequences_2byte_last", "invalid", rv.assemble(with_codec(zero_sequences(b"\x80\x00"))),
        "compressed blocks of raw literals ending with Number_of_Sequences 0 in its 2-byte form (80 00) "
        "(zstd 1.5.7 decodes it, 1.5.4 rejects it; the format rejects it)", "format", "decompression_failed")

    # --- 5.4 rule 5: RLE literals take their header and 1 byte
    def rle_literals(data):
        rs = runs(data)
        return frame(data, [literals_block(r, rle=len(r) > 1, last=i == len(rs) - 1) for i, r in enumerate(rs)],
                     window_descriptor=0x10)
    m = rv.base_model(8)
    m["means"] = [[0.0, 0.0, 0.0, 0.0] for _ in range(8)]
    add("zstd_rle_literals", "valid", rv.assemble(with_codec(rle_literals, m)),
        "every frame is one Compressed_Block per run of equal bytes, holding RLE literals (header and 1 byte, "
        "Regenerated_Size up to 128) or raw literals, and Number_of_Sequences 0")

    # --- 5.4: windows up to 2^31, the Unused_Bit ignored
    def window(descriptor):
        return lambda data: frame(data, [raw_block(data)], window_descriptor=descriptor)
    add("zstd_window_2_31", "valid", rv.assemble(with_codec(window(21 << 3))),
        "frames whose Window_Descriptor gives Window_Size 2^31 (Exponent 21, Mantissa 0), the largest accepted, "
        "one Raw_Block each")
    add("zstd_window_over_2_31", "invalid", rv.assemble(with_codec(window(21 << 3 | 1))),
        "frames whose Window_Descriptor gives Window_Size 2^31 + 2^28 (Exponent 21, Mantissa 1), above 2^31",
        "format", "decompression_failed")

    def unused_bit(data):
        f = bytearray(rv.zstd_frame(data))
        f[4] |= 0x10
        return bytes(f)
    add("zstd_unused_bit", "valid", rv.assemble(with_codec(unused_bit)),
        "every frame has the Unused_Bit (bit 4 of the Frame_Header_Descriptor) set: a decoder ignores it")

    # --- section 3: an empty range may start at file_length - 4
    def empty_last(arrays):
        arrays[2]["stored"] = b""
    add("zstd_empty_range_at_end", "invalid",
        rv.assemble(with_codec(lambda data: rv.zstd_frame(data)), array_patch=empty_last),
        "covariances: codec ZSTD with stored_length 0 at offset file_length - 4 (an empty range there passes "
        "step 16; no frame decodes to 0 bytes)", "format", "decompression_failed")

    # --- section 2 / step 19d: the Cholesky test defines positive definite
    m = rv.base_model()
    m["cov"][0] = [[118.0, -30.0, 27.0, -39.0], [-30.0, 41.0, 13.0, 26.0],
                   [27.0, 13.0, 34.0, 9.0], [-39.0, 26.0, 9.0, 25.0]]
    add("singular_rounded_pivot", "valid", rv.assemble(m),
        "covariance 0 is an integer matrix B B^T (B 4x3), exactly singular, whose last Cholesky pivot rounds "
        "to 2^-50 = 8.9e-16 > 0 in binary64: step 19d accepts it, and its verdict is the definition")
    return v


if __name__ == "__main__":
    raise SystemExit(rv.main(vectors))
