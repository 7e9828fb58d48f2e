// CRC-32C (Castagnoli), spec/format.md section 6: reflected polynomial
// 0x82F63B78, initial value and final XOR 0xFFFFFFFF. Slicing-by-8 tables so
// that a 50,000-component map (about 3 MB of arrays) checks in milliseconds.
const TABLES = (() => {
  const t = new Uint32Array(8 * 256);
  for (let i = 0; i < 256; i++) {
    let c = i;
    for (let k = 0; k < 8; k++) c = c & 1 ? (c >>> 1) ^ 0x82f63b78 : c >>> 1;
    t[i] = c >>> 0;
  }
  for (let i = 0; i < 256; i++) {
    for (let s = 1; s < 8; s++) {
      const prev = t[(s - 1) * 256 + i];
      t[s * 256 + i] = (prev >>> 8) ^ t[prev & 0xff];
    }
  }
  return t;
})();

const LITTLE_ENDIAN = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

// The CRC register c after the 8-byte groups of bytes[0, 8 * groups): two
// aligned 32-bit loads per group instead of eight byte loads (the page runs
// this once, cold, over a few megabytes). A function of its own with one
// loop, so that V8 optimises it where it runs (on-stack replacement).
function aligned8(t, words, groups, c) {
  for (let w = 0; w < 2 * groups; w += 2) {
    const a = c ^ words[w];
    const b = words[w + 1];
    c = t[7 * 256 + (a & 0xff)] ^ t[6 * 256 + ((a >>> 8) & 0xff)] ^ t[5 * 256 + ((a >>> 16) & 0xff)] ^
        t[4 * 256 + (a >>> 24)] ^ t[3 * 256 + (b & 0xff)] ^ t[2 * 256 + ((b >>> 8) & 0xff)] ^
        t[256 + ((b >>> 16) & 0xff)] ^ t[b >>> 24];
  }
  return c;
}

/** CRC-32C of the bytes (a Uint8Array), as an unsigned 32-bit number. */
export function crc32c(bytes) {
  const t = TABLES;
  let c = 0xffffffff;
  let i = 0;
  const n = bytes.length;
  if (LITTLE_ENDIAN && bytes.byteOffset % 4 === 0) {
    const groups = n >>> 3;
    c = aligned8(t, new Uint32Array(bytes.buffer, bytes.byteOffset, 2 * groups), groups, c);
    i = 8 * groups;
  } else {
    for (; i + 8 <= n; i += 8) {
      const a = c ^ (bytes[i] | (bytes[i + 1] << 8) | (bytes[i + 2] << 16) | (bytes[i + 3] << 24));
      c = t[7 * 256 + (a & 0xff)] ^ t[6 * 256 + ((a >>> 8) & 0xff)] ^ t[5 * 256 + ((a >>> 16) & 0xff)] ^
          t[4 * 256 + (a >>> 24)] ^ t[3 * 256 + bytes[i + 4]] ^ t[2 * 256 + bytes[i + 5]] ^
          t[256 + bytes[i + 6]] ^ t[bytes[i + 7]];
    }
  }
  for (; i < n; i++) c = (c >>> 8) ^ t[(c ^ bytes[i]) & 0xff];
  return (c ^ 0xffffffff) >>> 0;
}
