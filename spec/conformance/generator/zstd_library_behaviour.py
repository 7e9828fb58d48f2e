"""Why section 5.4's rules are checked by the reader itself: decodes, with
libzstd's one-shot and streaming calls, a frame that breaks each rule (built
as zstd_rule_vectors.py builds them) with two zstd versions, a system
libzstd given by --lib (loaded with ctypes) and the one bundled in the
`zstandard` module, and prints what each accepts. A record, not a test.

    python3 zstd_library_behaviour.py --lib /usr/lib/x86_64-linux-gnu/libzstd.so.1.5.4
"""
import argparse
import ctypes
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import zstandard  # noqa: E402

import rule_vectors as rv  # noqa: E402
import zstd_rule_vectors as z  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument('--lib', required=True, help='a libzstd shared library')
lib = ctypes.CDLL(ap.parse_args().lib)
lib.ZSTD_versionString.restype = ctypes.c_char_p
OTHER = 'zstandard ' + '.'.join(map(str, zstandard.ZSTD_VERSION))
THIS = 'libzstd ' + lib.ZSTD_versionString().decode()
lib.ZSTD_decompress.restype = ctypes.c_size_t
lib.ZSTD_isError.restype = ctypes.c_uint
lib.ZSTD_getErrorName.restype = ctypes.c_char_p
lib.ZSTD_decompress.argtypes=[ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t]
lib.ZSTD_isError.argtypes=[ctypes.c_size_t]; lib.ZSTD_getErrorName.argtypes=[ctypes.c_size_t]
class IB(ctypes.Structure): _fields_=[('src',ctypes.c_void_p),('size',ctypes.c_size_t),('pos',ctypes.c_size_t)]
class OB(ctypes.Structure): _fields_=[('dst',ctypes.c_void_p),('size',ctypes.c_size_t),('pos',ctypes.c_size_t)]
lib.ZSTD_createDStream.restype=ctypes.c_void_p
lib.ZSTD_decompressStream.restype=ctypes.c_size_t
lib.ZSTD_decompressStream.argtypes=[ctypes.c_void_p, ctypes.POINTER(OB), ctypes.POINTER(IB)]
lib.ZSTD_DCtx_setParameter.argtypes=[ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
def lib_oneshot(f, n):
    dst = ctypes.create_string_buffer(n + 16); src = ctypes.create_string_buffer(f, len(f))
    r = lib.ZSTD_decompress(dst, n+16, src, len(f))
    return lib.ZSTD_getErrorName(r).decode() if lib.ZSTD_isError(r) else f"ok {r}"
def lib_stream(f, n, chunk=7):
    d = lib.ZSTD_createDStream(); lib.ZSTD_DCtx_setParameter(d, 100, 31)  # ZSTD_d_windowLogMax
    dst = ctypes.create_string_buffer(1<<17); src = ctypes.create_string_buffer(f, len(f)); out=0
    for i in range(0, len(f), chunk):
        ib = IB(ctypes.addressof(src)+i, min(chunk, len(f)-i), 0)
        while ib.pos < ib.size:
            ob = OB(ctypes.addressof(dst), 1<<17, 0)
            r = lib.ZSTD_decompressStream(d, ctypes.byref(ob), ctypes.byref(ib))
            if lib.ZSTD_isError(r): return lib.ZSTD_getErrorName(r).decode()
            out += ob.pos
            if r == 0 and ib.pos == ib.size: break
    return f"ok {out}"
def bundled_oneshot(f, n):
    try: return "ok %d" % len(zstandard.ZstdDecompressor(max_window_size=1<<31).decompress(f))
    except zstandard.ZstdError as e: return str(e)
def bundled_stream(f, n, chunk=7):
    d = zstandard.ZstdDecompressor(max_window_size=1<<31).decompressobj(); out=0
    try:
        for i in range(0, len(f), chunk): out += len(d.decompress(f[i:i+chunk]))
    except zstandard.ZstdError as e: return str(e)
    return f"ok {out}"
def unused_bit(f):
    return f[:4] + bytes([f[4] | 0x10]) + f[5:]


data = bytes(range(200)) * 10  # 2000 bytes, no runs
small = bytes(range(40))
zeros = b"\0" * 2048
cases = {
 "block_over_content": z.frame(small, [z.literals_block(small, rle=False)]),
 "block_over_window(raw)": z.frame(data, [z.raw_block(data)], window_descriptor=0),
 "literals_over_window(rle)": z.frame(zeros, [z.literals_block(zeros, rle=True)], window_descriptor=0),
 "zero_seq_2byte+modes": z.frame(small, [z.literals_block(small, rle=False, sequences=b"\x80\x00\x00")], window_descriptor=0x10),
 "zero_seq_2byte_last": z.frame(small, [z.literals_block(small, rle=False, sequences=b"\x80\x00")], window_descriptor=0x10),
 "window_over_2_31": z.frame(small, [z.raw_block(small)], window_descriptor=21<<3|1),
 "window_2_31": z.frame(small, [z.raw_block(small)], window_descriptor=21<<3),
 "unused_bit": unused_bit(rv.zstd_frame(data)),
}
n_of = {"literals_over_window(rle)": 2048, "block_over_window(raw)": 2000, "unused_bit": 2000}
for k, f in cases.items():
    n = n_of.get(k, 40)
    print(f"{k:28s} {THIS} one-shot: {lib_oneshot(f,n):40s} stream: {lib_stream(f,n):40s}")
    print(f"{'':28s} {OTHER} one-shot: {bundled_oneshot(f,n)[:40]:40s} stream: {bundled_stream(f,n)[:60]}")
