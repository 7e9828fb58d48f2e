// The committed fuzz corpus (tests/fuzz: the conformance vectors, the seeds
// and regressions of the format targets) through the JavaScript reader, then
// seeded byte-level mutants of the valid vectors: every input is either read
// (a model satisfying the invariants of step 19) or rejected with a
// SogmmError; never another exception, never a hang (node's test timeout).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { read, ready, SogmmError } from '../src/reader.js';

await ready();
const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../..');
const FORMAT_TARGETS = ['load_memory', 'load_file', 'verify'];

function files(dir) {
  if (!fs.existsSync(dir)) return [];
  return fs.readdirSync(dir, { withFileTypes: true }).flatMap((e) => {
    const p = path.join(dir, e.name);
    return e.isDirectory() ? files(p) : e.name.endsWith('.md') ? [] : [p];
  });
}

function judge(data) {
  let model;
  try {
    model = read(data);
  } catch (e) {
    assert.ok(e instanceof SogmmError, `not a SogmmError: ${e && e.stack}`);
    assert.match(e.category, /^(format|limit|invalid_data|numeric)$/);
    return 'reject';
  }
  const M = Number(model.n_components);
  assert.equal(model.weights.length, M);
  let sum = 0;
  for (const w of model.weights) { assert.ok(w >= 0); sum += w; }
  assert.ok(Math.abs(sum - 1) <= 1e-4);
  for (const x of model.means) assert.ok(Number.isFinite(x));
  for (let k = 0; k < M; k++) {
    for (let i = 0; i < 4; i++) {
      assert.ok(model.covariances[16 * k + 5 * i] > 0);
      for (let j = 0; j < 4; j++) assert.equal(model.covariances[16 * k + 4 * i + j], model.covariances[16 * k + 4 * j + i]);
    }
  }
  return 'accept';
}

test('committed corpus', () => {
  const corpus = [
    ...files(path.join(ROOT, 'spec/conformance/valid')), ...files(path.join(ROOT, 'spec/conformance/invalid')),
    ...FORMAT_TARGETS.flatMap((t) => [...files(path.join(ROOT, 'tests/fuzz/seeds', t)), ...files(path.join(ROOT, 'tests/fuzz/regressions', t))]),
  ];
  assert.ok(corpus.length > 50, `${corpus.length} inputs`);
  for (const f of corpus) judge(fs.readFileSync(f));
});

test('seeded mutants of the valid vectors', () => {
  let state = 12345; // xorshift32: the same mutants on every run
  const rand = (n) => {
    state ^= state << 13; state >>>= 0; state ^= state >>> 17; state ^= state << 5; state >>>= 0;
    return state % n;
  };
  const valid = files(path.join(ROOT, 'spec/conformance/valid')).filter((f) => f.endsWith('.sogmm'));
  const seen = { accept: 0, reject: 0 };
  for (let i = 0; i < 3000; i++) {
    const data = Uint8Array.from(fs.readFileSync(valid[rand(valid.length)]));
    let bytes = data;
    for (let e = 1 + rand(3); e > 0; e--) {
      const kind = rand(4);
      if (kind === 0) bytes[rand(bytes.length)] ^= 1 << rand(8);
      else if (kind === 1) bytes[rand(bytes.length)] = rand(256);
      else if (kind === 2) bytes[rand(bytes.length)] = [0, 0xff, 0x7f, 0x80][rand(4)];
      else bytes = bytes.subarray(0, rand(bytes.length));
    }
    seen[judge(bytes)]++;
  }
  assert.ok(seen.reject > 0);
});
