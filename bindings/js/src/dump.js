// The canonical JSON dump of spec/format.md section 10, as text: u64/i64
// fields exact (BigInt), every double at round-trip precision, -0.0 kept.
import { ARRAY_NAMES } from './reader.js';

function num(x) {
  if (typeof x === 'bigint') return x.toString();
  if (Object.is(x, -0)) return '-0.0';
  return String(x); // shortest text that reads back as the same binary64
}

function value(v) {
  if (v === null) return 'null';
  if (typeof v === 'number' || typeof v === 'bigint') return num(v);
  if (typeof v === 'boolean') return v ? 'true' : 'false';
  if (typeof v === 'string') return JSON.stringify(v);
  if (Array.isArray(v) || ArrayBuffer.isView(v)) return `[${Array.from(v, value).join(',')}]`;
  return `{${Object.entries(v).map(([k, x]) => `${JSON.stringify(k)}:${value(x)}`).join(',')}}`;
}

function rows(flat, n) {
  const out = [];
  for (let i = 0; i < flat.length; i += n) out.push(flat.subarray(i, i + n));
  return out;
}

/** The canonical dump of a model from read(), compact JSON text. */
export function dumpJson(model) {
  const obj = { ...model };
  if (model.weights !== undefined) {
    obj.means = rows(model.means, 4);
    obj.covariances = rows(model.covariances, 16).map((c) => rows(c, 4));
  }
  for (const name of ARRAY_NAMES) if (!(name in model)) delete obj[name];
  return value(obj);
}
