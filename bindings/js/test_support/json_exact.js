// A JSON parser that keeps every number exactly: integers (no '.', no
// exponent) as BigInt, others as binary64 (so "-0.0" stays -0). JSON.parse
// would round the u64 fields of the dumps (e.g. a seed above 2^53).
export function parseExact(text) {
  let i = 0;
  const ws = () => { while (/\s/.test(text[i])) i++; };
  const value = () => {
    ws();
    const c = text[i];
    if (c === '{') {
      i++;
      const obj = {};
      ws();
      if (text[i] === '}') { i++; return obj; }
      for (;;) {
        ws();
        const k = value();
        ws();
        i++; // ':'
        obj[k] = value();
        ws();
        if (text[i++] === '}') return obj;
      }
    }
    if (c === '[') {
      i++;
      const arr = [];
      ws();
      if (text[i] === ']') { i++; return arr; }
      for (;;) {
        arr.push(value());
        ws();
        if (text[i++] === ']') return arr;
      }
    }
    if (c === '"') {
      const start = i;
      i++;
      while (text[i] !== '"') i += text[i] === '\\' ? 2 : 1;
      i++;
      return JSON.parse(text.slice(start, i));
    }
    const m = /^(?:true|false|null|-?\d+(?:\.\d+)?(?:[eE][+-]?\d+)?)/.exec(text.slice(i, i + 64));
    if (!m) throw new SyntaxError(`JSON at ${i}`);
    i += m[0].length;
    if (m[0] === 'true') return true;
    if (m[0] === 'false') return false;
    if (m[0] === 'null') return null;
    return /^-?\d+$/.test(m[0]) ? BigInt(m[0]) : Number(m[0]);
  };
  return value();
}

/** Equality of JSON values: integers compare as integers, doubles with Object.is. */
export function sameJson(a, b) {
  const isNum = (x) => typeof x === 'number' || typeof x === 'bigint';
  if (isNum(a) && isNum(b)) {
    if (typeof a === 'bigint' && typeof b === 'bigint') return a === b;
    if (typeof a === 'bigint') return Number.isInteger(b) && BigInt(b) === a;
    if (typeof b === 'bigint') return Number.isInteger(a) && BigInt(a) === b;
    return Object.is(a, b);
  }
  if (Array.isArray(a) && Array.isArray(b)) return a.length === b.length && a.every((x, k) => sameJson(x, b[k]));
  if (a && b && typeof a === 'object' && typeof b === 'object') {
    const ka = Object.keys(a);
    const kb = Object.keys(b);
    return ka.length === kb.length && ka.every((k, n) => k === kb[n] && sameJson(a[k], b[k]));
  }
  return a === b;
}
