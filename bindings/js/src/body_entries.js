// Key/values whose bytes are in the body (spec/format.md format 1.3): the
// packed key/values of section 2.5.1 (step 20, feature bit 1) and a map's
// frame record of section 2.3.2 (step 21, feature bit 3), which stands for
// the `map_frames` text.
import { crc32c } from './crc32c.js';
import { fail, formatError } from './errors.js';
import { decodeZstd } from './zstd.js';

export const PACKED_KEY_VALUES = 2n;
export const FRAME_RECORD = 8n;
const UTF8 = new TextDecoder('utf-8', { fatal: true, ignoreBOM: true });

// 20a / 21a: the first entry with `key`, four decimal counts
// "codec stored_length decoded_length crc32c".
function locator(keyValues, key, bit) {
  const at = keyValues.findIndex(([k]) => k === key);
  if (at < 0) formatError('bad_metadata', `feature bit ${bit} is set but there is no entry ${key}`);
  const tokens = keyValues[at][1].split(' ');
  if (tokens.length !== 4 || !tokens.every((t) => /^[0-9]{1,19}$/.test(t))) {
    formatError('bad_metadata', `${key} is not four decimal counts`);
  }
  const [codec, stored, decoded, crc] = tokens.map(BigInt);
  if (codec > 1n || crc >= 1n << 32n) formatError('bad_metadata', `${key}: codec or crc32c out of range`);
  return { at, codec, stored, decoded, crc: Number(crc) };
}

// 20b-e / 21b-e: the cap, the range [end - stored, end) against the body and
// the arrays, the codec and the CRC-32C.
function bodyBytes(data, loc, end, bodyStart, arrays, decodedSoFar, cap, what) {
  if (decodedSoFar + loc.decoded > BigInt(cap)) fail('limit', 'limit', `${what} over the cap`);
  if (loc.stored > end - BigInt(bodyStart)) formatError('bad_layout', `${what} outside the body`);
  const begin = end - loc.stored;
  if (loc.codec === 0n && loc.stored !== loc.decoded) formatError('bad_layout', `${what}: raw, of the wrong length`);
  for (const r of arrays) {
    if (loc.stored > 0n && r.stored_length > 0n && begin < r.offset + r.stored_length && r.offset < end) {
      formatError('bad_layout', `${what} overlaps an array`);
    }
  }
  const stored = data.subarray(Number(begin), Number(end));
  return { begin, raw: loc.codec === 1n ? decodeZstd(stored, Number(loc.decoded)) : stored };
}

function checkCrc(bytes, loc, verifyChecksums, what) {
  if (verifyChecksums && crc32c(bytes) !== loc.crc) formatError('checksum_mismatch', `${what} CRC-32C`);
}

/** Step 20: returns the key/values with the packed ones, and where they begin. */
export function unpackKeyValues(data, keyValues, end, bodyStart, arrays, decodedSoFar, cap, verifyChecksums) {
  const loc = locator(keyValues, 'packed_key_values', 1);
  if (loc.decoded < 2n) formatError('bad_metadata', 'packed_key_values: decoded length below 2');
  const { begin, raw } = bodyBytes(data, loc, end, bodyStart, arrays, decodedSoFar, cap, 'packed key/values');
  checkCrc(raw, loc, verifyChecksums, 'packed key/values');
  let nuls = 0;
  for (const b of raw) nuls += b === 0 ? 1 : 0;
  if (raw[raw.length - 1] !== 0 || nuls % 2 !== 0) formatError('bad_metadata', 'packed key/values are not key NUL value NUL ...');
  const strings = [];
  for (let p = 0; p < raw.length;) {
    const q = raw.indexOf(0, p);
    try {
      strings.push(UTF8.decode(raw.subarray(p, q)));
    } catch {
      formatError('bad_metadata', 'a packed string is not valid UTF-8');
    }
    p = q + 1;
  }
  const rest = keyValues.filter((_, i) => i !== loc.at);
  for (let i = 0; i < strings.length; i += 2) rest.push([strings[i], strings[i + 1]]);
  return { keyValues: rest, begin, decoded: loc.decoded };
}

// C's "%.17g" of a finite double (correctly rounded, ties to even), from its
// exact binary value: 17 significant digits, exponent form when the decimal
// exponent is below -4 or above 16, trailing zeros removed.
export function formatG17(x) {
  if (x === 0) return Object.is(x, -0) ? '-0' : '0';
  const sign = x < 0 ? '-' : '';
  const dv = new DataView(new ArrayBuffer(8));
  dv.setFloat64(0, Math.abs(x));
  const hi = dv.getUint32(0);
  let mant = (BigInt(hi & 0xfffff) << 32n) | BigInt(dv.getUint32(4));
  let e2 = (hi >>> 20) & 0x7ff;
  if (e2 === 0) e2 = 1; else mant |= 1n << 52n;
  e2 -= 1075; // |x| = mant 2^e2 exactly
  const num = e2 >= 0 ? mant << BigInt(e2) : mant;
  const den = e2 >= 0 ? 1n : 1n << BigInt(-e2);
  let d = Math.floor(Math.log10(Math.abs(x)));
  const pow = (k) => 10n ** BigInt(k);
  const atLeast = (k) => (k >= 0 ? num >= den * pow(k) : num * pow(-k) >= den); // |x| >= 10^k
  while (!atLeast(d)) d -= 1;
  while (atLeast(d + 1)) d += 1;
  const s = 16 - d; // q = round(|x| 10^s), 17 digits
  const n2 = s >= 0 ? num * pow(s) : num;
  const d2 = s >= 0 ? den : den * pow(-s);
  let q = n2 / d2;
  const r2 = 2n * (n2 % d2);
  if (r2 > d2 || (r2 === d2 && q % 2n === 1n)) q += 1n;
  if (q === pow(17)) {
    q = pow(16);
    d += 1;
  }
  const digits = q.toString();
  if (d < -4 || d >= 17) {
    const frac = digits.slice(1).replace(/0+$/, '');
    const exp = `${d < 0 ? '-' : '+'}${String(Math.abs(d)).padStart(2, '0')}`;
    return `${sign}${digits[0]}${frac ? `.${frac}` : ''}e${exp}`;
  }
  const whole = d >= 0 ? digits.slice(0, d + 1) : '0';
  const frac = (d >= 0 ? digits.slice(d + 1) : '0'.repeat(-d - 1) + digits).replace(/0+$/, '');
  return `${sign}${whole}${frac ? `.${frac}` : ''}`;
}

/** Step 21: the key/values with the frame record's entry replaced by `map_frames`. */
export function unpackFrameRecord(data, keyValues, end, bodyStart, arrays, decodedSoFar, cap, verifyChecksums) {
  const loc = locator(keyValues, 'map_frame_record', 3);
  if (loc.decoded === 0n || loc.decoded % 120n !== 0n) formatError('bad_metadata', 'map_frame_record: decoded length not a positive multiple of 120');
  const { raw } = bodyBytes(data, loc, end, bodyStart, arrays, decodedSoFar, cap, 'frame record');
  // Column-major, byte-stream split binary64: byte k of element (r, c) at k n + c rows + r.
  const rows = Number(loc.decoded) / 120;
  const n = rows * 15;
  const canonical = new Uint8Array(8 * n);
  for (let c = 0; c < 15; c++) {
    for (let r = 0; r < rows; r++) {
      for (let k = 0; k < 8; k++) canonical[8 * (15 * r + c) + k] = raw[k * n + c * rows + r];
    }
  }
  checkCrc(canonical, loc, verifyChecksums, 'frame record');
  const dv = new DataView(canonical.buffer);
  let text = '';
  for (let r = 0; r < rows; r++) {
    const fields = [String(r)];
    for (let c = 0; c < 15; c++) {
      const x = dv.getFloat64(8 * (15 * r + c), true);
      const count = c < 2 || c === 14;
      if (count ? !(x >= 0 && x <= 2 ** 53 && Math.floor(x) === x) : !Number.isFinite(x)) {
        formatError('bad_metadata', `frame record: frame ${r} column ${c} is ${count ? 'not a count' : 'not finite'}`);
      }
      fields.push(count ? String(x + 0) : formatG17(x)); // x + 0: -0 as 0
    }
    text += `${fields.join(' ')}\n`;
  }
  return keyValues.map((kv, i) => (i === loc.at ? ['map_frames', text] : kv));
}
