// Verified FlatBuffers access: the wire rules of spec/format.md section 4.3,
// checked on every read. Any breach throws WireError, which the reader
// reports as step 9 (bad_metadata). Hand-written because the spec states the
// rules exactly and a generic verifier may differ from them.
const MAX_DEPTH = 64;
const MAX_TABLE_VISITS = 100000;

export class WireError extends Error {}

function bad(message) {
  throw new WireError(message);
}

export class Block {
  constructor(bytes) {
    this.bytes = bytes;
    this.n = bytes.length;
    this.view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    this.visits = 0;
  }

  // [pos, pos + size) inside the block and pos a multiple of align.
  check(pos, size, align) {
    if (pos < 0 || size < 0 || pos + size > this.n || pos % align !== 0) {
      bad(`${size} bytes at ${pos} outside the block or misaligned`);
    }
  }

  u16(pos) { this.check(pos, 2, 2); return this.view.getUint16(pos, true); }
  u32(pos) { this.check(pos, 4, 4); return this.view.getUint32(pos, true); }
  i32(pos) { this.check(pos, 4, 4); return this.view.getInt32(pos, true); }

  // Rule 2: the target of the uoffset at `at`, non-zero and inside the block.
  follow(at) {
    const o = this.u32(at);
    if (o === 0 || at + o >= this.n) bad(`offset at ${at} is 0 or points outside the block`);
    return at + o;
  }

  // Rule 6: the raw bytes of the string at q, NUL-terminated.
  stringAt(q) {
    const n = this.u32(q);
    this.check(q + 4, n + 1, 1);
    if (this.bytes[q + 4 + n] !== 0) bad(`string at ${q} not NUL-terminated`);
    return this.bytes.subarray(q + 4, q + 4 + n);
  }

  root() {
    return new Table(this, this.follow(0), 1);
  }
}

// Scalar kinds: [size, DataView getter]; u64/i64 come back as BigInt.
const KINDS = {
  u8: [1, (v, p) => v.getUint8(p)],
  i32: [4, (v, p) => v.getInt32(p, true)],
  u32: [4, (v, p) => v.getUint32(p, true)],
  u64: [8, (v, p) => v.getBigUint64(p, true)],
  i64: [8, (v, p) => v.getBigInt64(p, true)],
  f64: [8, (v, p) => v.getFloat64(p, true)],
};

export class Table {
  // Rules 3 and 8: the table's vtable and inline bytes inside the block;
  // depth at most 64 and at most 100,000 visits over the whole block.
  constructor(block, t, depth) {
    if (depth > MAX_DEPTH) bad('tables nested too deep');
    if (++block.visits > MAX_TABLE_VISITS) bad('more than 100000 table visits');
    this.b = block;
    this.t = t;
    this.depth = depth;
    const vt = t - block.i32(t);
    block.check(vt, 4, 2);
    this.vt = vt;
    this.vs = block.u16(vt);
    if (this.vs < 4 || this.vs % 2 !== 0) bad(`vtable size ${this.vs}`);
    block.check(vt, this.vs, 2);
    this.ts = block.u16(vt + 2);
    if (this.ts < 4) bad(`table inline size ${this.ts}`);
    block.check(t, this.ts, 4);
  }

  // Rule 4: the field's offset in the table (0 = absent), checked for size z.
  field(id, z) {
    const slot = 4 + 2 * id;
    const fo = slot + 2 <= this.vs ? this.b.u16(this.vt + slot) : 0;
    if (fo !== 0) {
      if (fo < 4 || fo + z > this.ts) bad(`field ${id} outside its table`);
      this.b.check(this.t + fo, z, z);
    }
    return fo;
  }

  scalar(id, kind, dflt) {
    const [z, get] = KINDS[kind];
    const fo = this.field(id, z);
    return fo ? get(this.b.view, this.t + fo) : dflt;
  }

  target(id) {
    const fo = this.field(id, 4);
    return fo ? this.b.follow(this.t + fo) : null;
  }

  table(id) {
    const q = this.target(id);
    return q === null ? null : new Table(this.b, q, this.depth + 1);
  }

  string(id) {
    const q = this.target(id);
    return q === null ? null : this.b.stringAt(q);
  }

  // Rule 5: [start, count] of a vector of z-byte elements.
  vector(id, z) {
    const q = this.target(id);
    if (q === null) return null;
    const n = this.b.u32(q);
    this.b.check(q + 4, n * z, z);
    return [q + 4, n];
  }

  strings(id) {
    const v = this.vector(id, 4);
    if (v === null) return null;
    const out = [];
    for (let i = 0; i < v[1]; i++) out.push(this.b.stringAt(this.b.follow(v[0] + 4 * i)));
    return out;
  }

  tables(id) {
    const v = this.vector(id, 4);
    if (v === null) return null;
    const out = [];
    for (let i = 0; i < v[1]; i++) out.push(new Table(this.b, this.b.follow(v[0] + 4 * i), this.depth + 1));
    return out;
  }

  doubles(id) {
    const v = this.vector(id, 8);
    if (v === null) return null;
    const out = [];
    for (let i = 0; i < v[1]; i++) out.push(this.b.view.getFloat64(v[0] + 8 * i, true));
    return out;
  }
}
