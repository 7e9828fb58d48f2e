// An independent reader of .sogmm files, written from spec/format.md alone
// (no SOGMM library): the reading procedure of section 9, step by step, with
// the category and reason of the first check that fails.
//
//   await ready(); read(bytes, {maxDecodedBytes, verifyChecksums, metadataOnly}) -> model
//
// model: the canonical dump's metadata (section 10; u64/i64 fields as BigInt)
// plus typed arrays `weights` (M), `means` (M x 4) and `covariances` (M x 16,
// full symmetric, row-major), float32 as section 5.6 defines them.
// Throws SogmmError(category, reason, message).
import { crc32c } from './crc32c.js';
import { SogmmError, fail, formatError } from './errors.js';
import { Block, WireError } from './wire.js';
import { decodeZstd } from './zstd.js';
import { decodeStrings } from './strings.js';
import { checkPose } from './pose.js';
import { checkValues } from './values.js';
import { FRAME_RECORD, PACKED_KEY_VALUES, unpackFrameRecord, unpackKeyValues } from './body_entries.js';
import { CODE_COLUMNS, dequantize } from './quantized.js';

export { SogmmError } from './errors.js';
export { crc32c } from './crc32c.js';
// read() decodes zstd arrays with WebAssembly: `await ready()` once before.
export { zstdReady as ready } from './zstd.js';

const MAGIC = [0x89, 0x53, 0x4f, 0x47, 0x0d, 0x0a, 0x1a, 0x0a];
const END = [0x53, 0x47, 0x4d, 0x4d]; // "SGMM"
const HEADER = 32;
const TRAILER = 4;
export const DEFAULT_MAX_DECODED_BYTES = 2 ** 30;
// Format 1.3: bits 1 (packed key/values) and 3 (a map's frame record);
// format 1.4: bit 2 (quantized components, section 5.7).
const QUANTIZED = 4n;
const KNOWN_FEATURES = PACKED_KEY_VALUES | FRAME_RECORD | QUANTIZED;

export const DTYPES = ['f32', 'f64'];
export const ORDERS = ['component_major', 'column_major'];
export const FILTERS = ['none', 'byte_stream_split', 'quantized'];
export const CODECS = ['none', 'zstd'];
export const LAYOUTS = ['upper_packed', 'full'];
export const ARRAY_NAMES = ['weights', 'means', 'covariances'];

function arrayRecord(t) {
  return {
    dtype: t.scalar(0, 'u8', 0), order: t.scalar(1, 'u8', 0), filter: t.scalar(2, 'u8', 0),
    codec: t.scalar(3, 'u8', 0), offset: t.scalar(4, 'u64', 0n), stored_length: t.scalar(5, 'u64', 0n),
    decoded_length: t.scalar(6, 'u64', 0n), crc32c: t.scalar(7, 'u32', 0),
  };
}

// Step 9: every field the schema knows, read through the verified wire
// access, so that the whole block is checked before any value is used.
function readMetadata(block) {
  const root = block.root();
  const m = {
    n_components: root.scalar(0, 'u64', 0n), dims: root.scalar(1, 'u32', 4),
    support_size: root.scalar(2, 'u64', 0n), covariance_layout: root.scalar(3, 'u8', 0),
  };
  m.arrays = [4, 5, 6].map((id) => {
    const t = root.table(id);
    if (t === null) throw new WireError(`required field ${ARRAY_NAMES[id - 4]} missing`);
    return arrayRecord(t);
  });
  m.features_required = root.scalar(7, 'u64', 0n);
  m.features_used = root.scalar(8, 'u64', 0n);
  m.axis_labels = root.strings(9);
  m.axis_units = root.strings(10);
  m.gray_min = root.scalar(11, 'f64', 0.0);
  m.gray_max = root.scalar(12, 'f64', 1.0);
  const f = root.table(13);
  m.fit = f === null ? null : {
    bandwidth: f.scalar(0, 'f64', 0.0), n_components_requested: f.scalar(1, 'u64', 0n),
    tol: f.scalar(2, 'f64', 0.0), reg_covar: f.scalar(3, 'f64', 0.0), max_iter: f.scalar(4, 'i32', 0),
    n_iter: f.scalar(5, 'i32', 0), converged: f.scalar(6, 'u8', 0),
    log_likelihood: f.scalar(7, 'f64', 0.0), seed: f.scalar(8, 'u64', 0n),
  };
  const c = root.table(14);
  m.camera = c === null ? null : {
    width: c.scalar(0, 'i32', 0), height: c.scalar(1, 'i32', 0), fx: c.scalar(2, 'f64', 0.0),
    fy: c.scalar(3, 'f64', 0.0), cx: c.scalar(4, 'f64', 0.0), cy: c.scalar(5, 'f64', 0.0),
    decimation: c.scalar(6, 'i32', 1), depth_scale: c.scalar(7, 'f64', 1000.0),
    depth_min: c.scalar(8, 'f64', 0.1), depth_max: c.scalar(9, 'f64', 3.0),
  };
  m.pose = root.doubles(15);
  m.producer_name = root.string(16);
  m.producer_version = root.string(17);
  m.created_unix_ms = root.scalar(18, 'i64', 0n);
  const kvs = root.tables(19) || [];
  m.key_values = kvs.map((kv) => [kv.string(0), kv.string(1)]);
  return m;
}

function sameStrings(list, expected) {
  return list.length === expected.length &&
    list.every((b, i) => b.length === expected[i].length && [...b].every((x, k) => x === expected[i].charCodeAt(k)));
}

// Step 11 (bad_metadata) and 11b (bad_pose).
function checkValuesOfMetadata(m, blockLength) {
  const bad = (why) => formatError('bad_metadata', why);
  if (m.dims !== 4) bad(`dims = ${m.dims}, not 4`);
  if (m.axis_labels !== null && !sameStrings(m.axis_labels, ['x', 'y', 'z', 'gray'])) bad('axis_labels are not x, y, z, gray');
  if (m.axis_units !== null && !sameStrings(m.axis_units, ['m', 'm', 'm', '1'])) bad('axis_units are not m, m, m, 1');
  if (m.gray_min !== 0 || m.gray_max !== 1) bad('gray range is not [0, 1]');
  if (m.fit !== null) {
    if (m.fit.converged > 1) bad('FitInfo.converged is neither 0 nor 1');
    m.fit.converged = m.fit.converged === 1;
    for (const k of ['bandwidth', 'tol', 'reg_covar', 'log_likelihood']) {
      if (!Number.isFinite(m.fit[k])) bad(`FitInfo.${k} is not finite`);
    }
  }
  if (m.camera !== null) {
    for (const k of ['fx', 'fy', 'cx', 'cy', 'depth_scale', 'depth_min', 'depth_max']) {
      if (!Number.isFinite(m.camera[k])) bad(`Camera.${k} is not finite`);
    }
  }
  decodeStrings(m, blockLength);
  if (m.pose !== null) {
    if (m.pose.length !== 16) bad(`pose has ${m.pose.length} values, not 16`);
    checkPose(m.pose);
  }
}

// Steps 1-16: header, trailer and metadata. Returns the dump's metadata and
// what the array steps need.
function readHead(data, maxDecodedBytes, verifyChecksums) {
  const size = data.length;
  const k = Math.min(size, 8);
  for (let i = 0; i < k; i++) if (data[i] !== MAGIC[i]) formatError('bad_magic', 'not a .sogmm file (wrong signature)');
  if (size < HEADER + TRAILER) formatError('truncated', `${size} bytes, shorter than header and trailer`);
  const dv = new DataView(data.buffer, data.byteOffset, data.byteLength);
  const major = dv.getUint16(8, true);
  const minor = dv.getUint16(10, true);
  const flags = dv.getUint32(12, true);
  const fileLength = dv.getBigUint64(16, true);
  const metaLength = dv.getUint32(24, true);
  const metaCrc = dv.getUint32(28, true);
  if (major !== 1) formatError('unsupported_version', `format major version ${major}`);
  if (flags !== 0) formatError('bad_header', 'reserved header flags set');
  if (fileLength > BigInt(size)) formatError('truncated', `file is ${size} bytes, header declares ${fileLength}`);
  if (fileLength < BigInt(size)) formatError('bad_header', 'data after the declared end of the file');
  for (let i = 0; i < 4; i++) if (data[size - 4 + i] !== END[i]) formatError('bad_trailer', 'end marker "SGMM" missing');
  const bodyStart = HEADER + Math.ceil(metaLength / 8) * 8;
  if (metaLength < 8 || metaLength >= 2 ** 31 - 1 || bodyStart + TRAILER > size) {
    formatError('bad_header', `metadata length ${metaLength} out of range`);
  }
  const meta = data.subarray(HEADER, HEADER + metaLength);
  if (verifyChecksums && crc32c(meta) !== metaCrc) formatError('checksum_mismatch', 'metadata CRC-32C');
  if (meta[4] !== END[0] || meta[5] !== END[1] || meta[6] !== END[2] || meta[7] !== END[3]) {
    formatError('bad_metadata', 'FlatBuffer file identifier is not "SGMM"');
  }
  let m;
  try {
    m = readMetadata(new Block(meta));
  } catch (e) {
    if (e instanceof WireError) formatError('bad_metadata', `FlatBuffers wire rules: ${e.message}`);
    throw e;
  }
  if (m.features_required & ~KNOWN_FEATURES) formatError('unsupported_feature', `features_required 0x${m.features_required.toString(16)}`);
  checkValuesOfMetadata(m, metaLength);
  if (m.covariance_layout >= LAYOUTS.length) formatError('unsupported_encoding', `covariance layout ${m.covariance_layout}`);
  for (const r of m.arrays) {
    if (r.dtype >= DTYPES.length || r.order >= ORDERS.length || r.filter >= FILTERS.length || r.codec >= CODECS.length) {
      formatError('unsupported_encoding', 'unknown dtype, order, filter or codec');
    }
  }
  const quantized = (m.features_required & QUANTIZED) !== 0n;
  for (const r of m.arrays) {
    if ((r.filter === 2) !== quantized) formatError('unsupported_encoding', 'filter QUANTIZED and feature bit 2 disagree');
    if (quantized && (r.dtype !== 0 || m.covariance_layout !== 0)) {
      formatError('unsupported_encoding', 'quantized components decode to float32, packed');
    }
  }
  const M = m.n_components;
  if (M === 0n) fail('invalid_data', 'empty', 'the model has no components (M = 0)');
  const cols = [1, 4, m.covariance_layout === 0 ? 10 : 16];
  let total = 0n;
  m.arrays.forEach((r, i) => {
    const expected = M * BigInt(cols[i] * (r.dtype === 1 ? 8 : 4));
    if (r.decoded_length !== expected) {
      fail('invalid_data', 'length_mismatch', `${ARRAY_NAMES[i]}: decoded_length ${r.decoded_length}, M x C x width = ${expected}`);
    }
    total += expected;
  });
  if (total > BigInt(maxDecodedBytes)) fail('limit', 'limit', `${total} decoded bytes declared, cap ${maxDecodedBytes}`);
  const bodyEnd = fileLength - BigInt(TRAILER);
  m.arrays.forEach((r, i) => {
    const end = r.offset + r.stored_length;
    if (r.offset % 8n !== 0n || r.offset < BigInt(bodyStart) || end > bodyEnd) {
      formatError('bad_layout', `${ARRAY_NAMES[i]} outside the body or misaligned`);
    }
    const filtered = quantized ? M * BigInt(4 * CODE_COLUMNS[i]) : r.decoded_length;
    if (r.codec === 0 && r.stored_length !== filtered) formatError('bad_layout', `${ARRAY_NAMES[i]}: raw array of the wrong length`);
    for (const o of m.arrays.slice(0, i)) {
      if (r.stored_length > 0n && o.stored_length > 0n && r.offset < o.offset + o.stored_length && o.offset < end) {
        formatError('bad_layout', `${ARRAY_NAMES[i]} overlaps an earlier array`);
      }
    }
  });
  return { m, major, minor, fileLength, metaLength, cols, bodyStart, total, quantized };
}

const LITTLE_ENDIAN = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

// Steps 17-18 for one array: decode (codec, then filter and order undone),
// check the CRC-32C of the canonical bytes, and return the float32 values.
function decodeArray(data, r, rows, cols, name, verifyChecksums) {
  const width = r.dtype === 1 ? 8 : 4;
  const n = rows * cols;
  const stored = data.subarray(Number(r.offset), Number(r.offset + r.stored_length));
  const bytes = r.codec === 1 ? decodeZstd(stored, n * width) : stored;
  const canonical = r.filter === 1 || r.order === 1 ? canonicalBytes(bytes, rows, cols, width, r.filter === 1, r.order === 1) : bytes;
  if (verifyChecksums && crc32c(canonical) !== r.crc32c) formatError('checksum_mismatch', `${name} CRC-32C`);
  // Section 5.6: float32 values; an F64 value rounds to nearest (Float32Array does).
  if (LITTLE_ENDIAN) {
    // Fresh and aligned unless it is the stored bytes, a view into the file
    // (maybe misaligned; Buffer.slice would share): those are copied.
    const own = canonical === stored ? new Uint8Array(canonical) : canonical;
    return width === 4 ? new Float32Array(own.buffer, own.byteOffset, n) : Float32Array.from(new Float64Array(own.buffer, own.byteOffset, n));
  }
  const out = new Float32Array(n);
  const dv = new DataView(canonical.buffer, canonical.byteOffset, canonical.byteLength);
  for (let i = 0; i < n; i++) out[i] = width === 8 ? dv.getFloat64(8 * i, true) : dv.getFloat32(4 * i, true);
  return out;
}

// Stored elements e = first .. first + count - 1 of a byte_stream_split
// float32 array of n elements (byte k of e at k n + e) as words at
// d, d + step, ... A function of its own with one loop, so that V8's
// on-stack replacement optimises it once, cold, for every column.
function unsplitWords(bytes, n, words, first, count, d, step) {
  const n2 = 2 * n;
  const n3 = 3 * n;
  for (let e = first, end = first + count; e < end; e++, d += step) {
    words[d] = bytes[e] | (bytes[n + e] << 8) | (bytes[n2 + e] << 16) | (bytes[n3 + e] << 24);
  }
}

// The canonical (component-major, unsplit) bytes of an array stored with
// byte_stream_split and/or column_major: byte k of stored element e is at
// k * n + e when split, else at e * width + k; element e is (m, c) at
// c * rows + m when column-major, else m * cols + c. One tight loop per byte
// plane and column, with no branch inside: a 50,000-component map has
// 3 million bytes to move while the page waits.
function canonicalBytes(bytes, rows, cols, width, split, columnMajor) {
  const n = rows * cols;
  const out = new Uint8Array(n * width);
  if (split && width === 4 && LITTLE_ENDIAN) { // float32 (the usual case): a word at a time
    const words = new Uint32Array(out.buffer);
    if (!columnMajor) unsplitWords(bytes, n, words, 0, n, 0, 1);
    for (let c = 0; columnMajor && c < cols; c++) unsplitWords(bytes, n, words, c * rows, rows, c, cols);
    return out;
  }
  const byteStride = split ? n : 1;
  const elementStride = split ? 1 : width;
  for (let k = 0; k < width; k++) {
    for (let c = 0; c < cols; c++) {
      if (columnMajor) { // elements (m, c), m = 0..rows-1, stored in a row
        let src = k * byteStride + c * rows * elementStride;
        for (let d = c * width + k, m = 0; m < rows; m++, d += cols * width, src += elementStride) out[d] = bytes[src];
      } else {
        let src = k * byteStride + c * elementStride;
        for (let d = c * width + k, m = 0; m < rows; m++, d += cols * width, src += cols * elementStride) out[d] = bytes[src];
      }
    }
  }
  return out;
}

// Steps 17, 17b and 18 of a file with quantized components (section 5.7):
// every array's codes, the model they decode to, then each array's CRC-32C
// over the little-endian float32 bytes of that model.
function readQuantized(data, records, M, verifyChecksums) {
  const codes = records.map((r, i) => {
    const K = CODE_COLUMNS[i];
    const stored = data.subarray(Number(r.offset), Number(r.offset + r.stored_length));
    const bytes = r.codec === 1 ? decodeZstd(stored, M * K * 4) : stored;
    const canonical = canonicalBytes(bytes, M, K, 4, true, r.order === 1);
    const dv = new DataView(canonical.buffer, canonical.byteOffset, canonical.byteLength);
    const out = new Int32Array(M * K);
    for (let t = 0; t < M * K; t++) {
      const z = dv.getUint32(4 * t, true);
      out[t] = z % 2 === 0 ? z / 2 : -(z + 1) / 2;
    }
    return out;
  });
  const values = dequantize(codes, M);
  values.forEach((v, i) => {
    const bytes = new Uint8Array(4 * v.length);
    const dv = new DataView(bytes.buffer);
    v.forEach((x, t) => dv.setFloat32(4 * t, x, true));
    if (verifyChecksums && crc32c(bytes) !== records[i].crc32c) formatError('checksum_mismatch', `${ARRAY_NAMES[i]} CRC-32C`);
  });
  return values;
}

/** Reads a .sogmm file (Uint8Array) by spec/format.md section 9. */
export function read(data, { maxDecodedBytes = DEFAULT_MAX_DECODED_BYTES, verifyChecksums = true, metadataOnly = false } = {}) {
  if (!(data instanceof Uint8Array)) data = new Uint8Array(data);
  const { m, major, minor, fileLength, metaLength, cols, bodyStart, total, quantized } = readHead(data, maxDecodedBytes, verifyChecksums);
  const file = {
    format_version: `${major}.${minor}`, file_length: fileLength, metadata_length: metaLength,
    features_required: m.features_required, features_used: m.features_used,
    covariance_layout: LAYOUTS[m.covariance_layout],
  };
  ARRAY_NAMES.forEach((name, i) => {
    const r = m.arrays[i];
    file[name] = {
      dtype: DTYPES[r.dtype], order: ORDERS[r.order], filter: FILTERS[r.filter], codec: CODECS[r.codec],
      offset: r.offset, stored_length: r.stored_length, decoded_length: r.decoded_length, crc32c: r.crc32c,
    };
  });
  const model = {
    file, n_components: m.n_components, support_size: m.support_size,
    axis_labels: ['x', 'y', 'z', 'gray'], axis_units: ['m', 'm', 'm', '1'],
    fit: m.fit, camera: m.camera, pose: m.pose,
    producer_name: m.producer_name, producer_version: m.producer_version,
    created_unix_ms: m.created_unix_ms, key_values: m.key_values,
  };
  if (metadataOnly) return model;
  const M = Number(m.n_components);
  const [weights, means, stored] = quantized ? readQuantized(data, m.arrays, M, verifyChecksums)
    : ARRAY_NAMES.map((name, i) => decodeArray(data, m.arrays[i], M, cols[i], name, verifyChecksums));
  model.weights = weights;
  model.means = means;
  model.covariances = checkValues(weights, means, stored, M, m.covariance_layout === 0);
  // Steps 20 and 21: key/values whose bytes are in the body.
  let end = fileLength - BigInt(TRAILER);
  let decoded = total;
  if (m.features_required & PACKED_KEY_VALUES) {
    const p = unpackKeyValues(data, model.key_values, end, bodyStart, m.arrays, decoded, maxDecodedBytes, verifyChecksums);
    model.key_values = p.keyValues;
    end = p.begin;
    decoded += p.decoded;
  }
  if (m.features_required & FRAME_RECORD) {
    model.key_values = unpackFrameRecord(data, model.key_values, end, bodyStart, m.arrays, decoded, maxDecodedBytes, verifyChecksums);
  }
  return model;
}

/** The value of the first key_values entry with this key, or undefined. */
export function getValue(model, key) {
  const kv = model.key_values.find(([k]) => k === key);
  return kv === undefined ? undefined : kv[1];
}

export function isSogmmError(e) {
  return e instanceof SogmmError;
}
