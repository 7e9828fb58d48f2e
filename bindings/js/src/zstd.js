// The codec ZSTD of spec/format.md section 5.4: the frame rules a reader
// checks itself before decoding anything (so that the verdict does not depend
// on the zstd decoder), then the frames decoded by libzstd compiled to
// WebAssembly (zstddec; fzstd, in JavaScript, took 0.3-0.6 s of a page's
// first parse of a 50,000-component map, its code not yet optimised).
// Every failure is reason decompression_failed (step 17).
import { ZSTDDecoder } from 'zstddec';
import { formatError } from './errors.js';

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

// The Window_Descriptor for a window of max(128 KiB, the content size rounded
// up to a power of two): the content size bounds the history a frame can
// refer to, and libzstd built for 32 bits (WebAssembly) refuses windows above
// 2^30 that the 64-bit one decodes. Block_Maximum_Size stays 128 KiB.
function contentWindowDescriptor(contentSize) {
  let log = 17;
  while (2 ** log < contentSize) log++;
  return (log - 10) << 3;
}

// Rules 1-5 over every frame; returns each frame's declared content size and,
// for a frame whose window is larger than its content needs, where its
// Window_Descriptor is and the smaller one to decode it with.
function frames(st) {
  const out = [];
  let pos = 0;
  while (pos < st.length) {
    if (le(st, pos, 4) !== MAGIC) failed('not a zstd frame');
    // Bit 4 (Unused_Bit) is not read: RFC 8878 has a decoder ignore it.
    const fhd = le(st, pos + 4, 1);
    if (fhd & 0x08) failed('reserved bit of the frame header descriptor');
    const single = (fhd >> 5) & 1;
    const fcsFlag = fhd >> 6;
    if (fcsFlag === 0 && !single) failed('frame without content size');
    let p = pos + 5;
    let window = 0;
    const windowAt = p;
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
    p += (fhd >> 2) & 1 ? 4 : 0; // the content checksum, verified by libzstd
    if (p > st.length) failed('zstd frame truncated');
    const lowered = single ? -1 : contentWindowDescriptor(contentSize);
    out.push({ contentSize, windowAt, descriptor: lowered >= 0 && window > 2 ** (10 + (lowered >> 3)) ? lowered : -1 });
    pos = p;
  }
  return out;
}

// libzstd's ZSTD_decompress (zstddec, WebAssembly) returns an error code
// where the wrapper expects a length, and the wrapper then returns fewer
// bytes than asked for (none); an empty frame would look decoded either way.
// So one raw frame of one known byte is decoded after the array's frames: the
// whole decoded, exactly `expected` bytes then this byte, or a rejection.
// libzstd checks each frame against its declared content size and verifies
// the content checksums; it rejects a block that decodes to more than the
// frame's Block_Maximum_Size (RFC 8878 section 5.4: readers SHOULD).
const SENTINEL_BYTE = 0x5a;
const SENTINEL = [0x28, 0xb5, 0x2f, 0xfd, 0x20, 0x01, 0x09, 0x00, 0x00, SENTINEL_BYTE];

const decoder = new ZSTDDecoder();
let decoderReady = false;

/** Compiles the WebAssembly zstd decoder; read() needs it done for zstd arrays. */
export function zstdReady() {
  return decoder.init().then(() => { decoderReady = true; });
}

/** The decoded bytes of an array stored as zstd frames: exactly `expected` bytes. */
export function decodeZstd(stored, expected) {
  let total = 0;
  const list = frames(stored);
  for (const { contentSize } of list) {
    if (contentSize > expected - total) failed('frame declares more than is left of decoded_length');
    total += contentSize;
  }
  if (total !== expected) failed(`decodes to ${total} bytes, ${expected} declared`);
  if (!decoderReady) throw new Error('the zstd decoder is not compiled yet: await zstdReady() before read()');
  const input = new Uint8Array(stored.length + SENTINEL.length);
  input.set(stored);
  input.set(SENTINEL, stored.length);
  for (const f of list) if (f.descriptor >= 0) input[f.windowAt] = f.descriptor;
  let out;
  try {
    out = decoder.decode(input, expected + 1);
  } catch (e) {
    failed(`zstd: ${e && e.message}`);
  }
  if (out.length !== expected + 1 || out[expected] !== SENTINEL_BYTE) {
    failed('the frames do not decode (corrupt data, a wrong content size or checksum, or a block above Block_Maximum_Size)');
  }
  return out.subarray(0, expected);
}
