// The codec ZSTD of spec/format.md section 5.4: the frame rules a reader
// checks itself before decoding anything (so that the verdict does not depend
// on the zstd decoder), then each frame decoded with fzstd, bounded by its
// declared content size, and its content checksum verified when present.
// Every failure is reason decompression_failed (step 17).
import { Decompress } from 'fzstd';
import { formatError } from './errors.js';
import { xxh64 } from './xxh64.js';

const MAGIC = 0xfd2fb528;
const MAX_BLOCK = 128 << 10;
const MAX_WINDOW = 2 ** 31; // rule 2: ZSTD_WINDOWLOG_MAX of a 64-bit libzstd

function failed(message) {
  formatError('decompression_failed', message);
}

// Little-endian unsigned integer of n <= 8 bytes at pos, as a Number (exact
// up to 2^53; larger content sizes are rejected as more than is left anyway).
function le(st, pos, n) {
  if (pos + n > st.length) failed('zstd frame truncated');
  let v = 0;
  for (let i = n - 1; i >= 0; i--) v = v * 256 + st[pos + i];
  return v;
}

// Rule 5: the literals section and the sequences section header of a
// Compressed_Block at [pos, pos + size), in a frame of Block_Maximum_Size
// blockMax.
function checkCompressedBlock(st, pos, size, blockMax) {
  const b0 = le(st, pos, 1);
  const type = b0 & 3;
  const sizeFormat = (b0 >> 2) & 3;
  let header;
  let content;
  let regenerated;
  if (type < 2) { // Raw or RLE literals: Regenerated_Size only
    header = sizeFormat === 1 ? 2 : sizeFormat === 3 ? 3 : 1;
    regenerated = header === 1 ? b0 >> 3 : (b0 >> 4) + le(st, pos + 1, header - 1) * 16;
    content = type === 0 ? regenerated : 1; // RLE literals: the one byte repeated
  } else { // Compressed or Treeless: Regenerated_Size then Compressed_Size
    header = sizeFormat < 2 ? 3 : sizeFormat === 2 ? 4 : 5;
    const bits = header === 3 ? 10 : header === 4 ? 14 : 18;
    const sizes = Math.floor(le(st, pos, header) / 16);
    content = Math.floor(sizes / 2 ** bits);
    regenerated = sizes % 2 ** bits;
  }
  if (regenerated > blockMax) failed(`literals regenerate ${regenerated} bytes, above Block_Maximum_Size ${blockMax}`);
  if (header + content >= size) failed('literals leave no room for the sequences section');
  const q = pos + header + content;
  const left = size - header - content - 1; // bytes after the first byte of the sequences header
  const n0 = le(st, q, 1);
  const countBytes = n0 < 128 ? 0 : n0 < 255 ? 1 : 2;
  if (left < countBytes) failed('sequences section header beyond the block');
  // 80 00 is the only other spelling of 0 (the 3-byte form is at least 0x7F00);
  // zstd versions read it differently, so it is rejected wherever it is.
  if (n0 === 128 && le(st, q + 1, 1) === 0) failed('Number_of_Sequences of 0 in its 2-byte form');
  if (n0 === 0) {
    if (left !== 0) failed('bytes after an empty sequences section');
    return;
  }
  if (left < countBytes + 1) failed('sequences section header beyond the block');
  if (le(st, q + 1 + countBytes, 1) & 3) failed('reserved bits of Symbol_Compression_Modes');
}

// Rules 1-5 over every frame; returns the frames as {start, end, header,
// windowAt, window, blockMax, contentSize, checksum}.
function frames(st) {
  const out = [];
  let pos = 0;
  while (pos < st.length) {
    const start = pos;
    if (le(st, pos, 4) !== MAGIC) failed('not a zstd frame');
    // Bit 4 (Unused_Bit) is not read: RFC 8878 has a decoder ignore it.
    const fhd = le(st, pos + 4, 1);
    if (fhd & 0x08) failed('reserved bit of the frame header descriptor');
    const single = (fhd >> 5) & 1;
    const fcsFlag = fhd >> 6;
    if (fcsFlag === 0 && !single) failed('frame without content size');
    let p = pos + 5;
    let window = 0;
    const windowAt = single ? -1 : p;
    if (!single) {
      const wd = le(st, p, 1); // Exponent (bits 3-7), Mantissa (bits 0-2)
      const base = 2 ** (10 + (wd >> 3));
      window = base + (base / 8) * (wd & 7);
      p += 1;
    }
    const dictBytes = [0, 1, 2, 4][fhd & 3];
    if (le(st, p, dictBytes) !== 0) failed('frame needs a dictionary');
    p += dictBytes;
    const fcsBytes = [single ? 1 : 0, 2, 4, 8][fcsFlag];
    const contentSize = le(st, p, fcsBytes) + (fcsFlag === 1 ? 256 : 0);
    p += fcsBytes;
    const header = p - start;
    if (single) window = contentSize;
    if (window > MAX_WINDOW) failed(`window of ${window} bytes, above 2^31`);
    const blockMax = Math.min(window, MAX_BLOCK); // Block_Maximum_Size
    let last = 0;
    while (!last) {
      const h = le(st, p, 3);
      p += 3;
      last = h & 1;
      const type = (h >> 1) & 3;
      const size = h >>> 3; // for an RLE block, the bytes it regenerates
      if (type === 3) failed('reserved block type');
      if (size > blockMax) failed(`block of ${size} bytes, above Block_Maximum_Size ${blockMax}`);
      if (type === 2) checkCompressedBlock(st, p, size, blockMax);
      p += type === 1 ? 1 : size;
      if (p > st.length) failed('zstd block beyond the stored bytes');
    }
    const checksum = (fhd >> 2) & 1;
    p += checksum ? 4 : 0;
    if (p > st.length) failed('zstd frame truncated');
    out.push({ start, end: p, header, windowAt, window, blockMax, contentSize, checksum });
    pos = p;
  }
  return out;
}

// The frame as fzstd decodes it, with a window of max(128 KiB, the content
// size rounded up to a power of two). A larger declared window is lowered:
// the content size bounds the history a frame can refer to, and a hostile
// descriptor must not make the decoder allocate up to 2 GiB for a few bytes.
// A smaller one is raised, and a single-segment frame (window = content
// size) gets a window descriptor too: fzstd sizes a block's buffer by the
// window (at most 128 KiB) and drops output beyond it without an error, so
// with a full 128 KiB buffer a block larger than the frame's
// Block_Maximum_Size reaches the checks of decodeFrame instead (libzstd
// rejects such a frame when it streams it). The frame's own history is all
// a match can refer to either way, as in libzstd's whole-frame decoding.
function withWindow(frame, f) {
  let log = 17;
  while (2 ** log < f.contentSize) log++;
  const descriptor = (log - 10) << 3;
  if (f.windowAt >= 0) {
    if (2 ** log === f.window) return frame;
    const copy = frame.slice();
    copy[f.windowAt - f.start] = descriptor;
    return copy;
  }
  const fhd = frame[4];
  const dictBytes = [0, 1, 2, 4][fhd & 3];
  const wide = f.contentSize >= 2 ** 32;
  const head = [0x28, 0xb5, 0x2f, 0xfd, (fhd & 0x17) | ((wide ? 3 : 2) << 6), descriptor];
  for (let i = 0; i < dictBytes; i++) head.push(frame[5 + i]);
  let size = f.contentSize;
  for (let i = 0; i < (wide ? 8 : 4); i++) { head.push(size % 256); size = Math.floor(size / 256); }
  const out = new Uint8Array(head.length + frame.length - f.header);
  out.set(head);
  out.set(frame.subarray(f.header), head.length);
  return out;
}

// One frame's content, exactly contentSize bytes, or a rejection.
function decodeFrame(st, f) {
  const bytes = withWindow(st.subarray(f.start, f.end), f);
  const out = new Uint8Array(f.contentSize);
  let n = 0;
  // fzstd hands over each block's output as one chunk: a block that decodes
  // to more than Block_Maximum_Size breaks RFC 8878 (section 5.4: readers
  // SHOULD reject it; it only shows once decoded).
  const d = new Decompress((chunk) => {
    if (chunk.length > f.blockMax) failed(`a block decodes to ${chunk.length} bytes, above Block_Maximum_Size ${f.blockMax}`);
    if (n + chunk.length > f.contentSize) failed('frame decodes to more than its content size');
    out.set(chunk, n);
    n += chunk.length;
  });
  try {
    d.push(bytes, true);
  } catch (e) {
    if (e && e.reason) throw e;
    failed(`zstd: ${e && e.message}`);
  }
  if (n !== f.contentSize) failed('frame decodes to less than its content size');
  if (f.checksum) {
    const stored = new DataView(st.buffer, st.byteOffset + f.end - 4, 4).getUint32(0, true);
    if (Number(xxh64(out) & 0xffffffffn) !== stored) failed('zstd content checksum mismatch');
  }
  return out;
}

/** The decoded bytes of an array stored as zstd frames: exactly `expected` bytes. */
export function decodeZstd(stored, expected) {
  const list = frames(stored);
  const out = new Uint8Array(expected);
  let n = 0;
  for (const f of list) {
    if (f.contentSize > expected - n) failed('frame declares more than is left of decoded_length');
    out.set(decodeFrame(stored, f), n);
    n += f.contentSize;
  }
  if (n !== expected) failed(`decodes to ${n} bytes, ${expected} declared`);
  return out;
}
