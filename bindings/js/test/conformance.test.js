// The JavaScript reader against the frozen vectors of spec/conformance
// (spec/format.md section 12): every valid vector decodes to exactly its
// canonical dump, every invalid one is rejected with its category and reason.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { read, ready, crc32c, SogmmError } from '../src/reader.js';
import { dumpJson } from '../src/dump.js';
import { parseExact, sameJson } from '../test_support/json_exact.js';

const HERE = path.dirname(fileURLToPath(import.meta.url));
const DIR = process.env.SOGMM_CONFORMANCE_DIR || path.resolve(HERE, '../../../spec/conformance');
await ready();
const manifest = JSON.parse(fs.readFileSync(path.join(DIR, 'manifest.json'), 'utf8'));

test('the manifest covers the reasons of section 9', () => {
  const reasons = new Set(manifest.vectors.map((v) => v.reason));
  for (const r of ['bad_magic', 'truncated', 'unsupported_version', 'unsupported_feature', 'checksum_mismatch',
    'bad_metadata', 'limit', 'non_finite', 'not_spd', 'bad_weights', 'empty', 'length_mismatch', 'decompression_failed']) {
    assert.ok(reasons.has(r), r);
  }
});

test('CRC-32C check values of section 6', () => {
  assert.equal(crc32c(new TextEncoder().encode('123456789')), 0xe3069283);
  assert.equal(crc32c(new Uint8Array(32)), 0x8a9136aa);
});

for (const v of manifest.vectors) {
  test(v.file, () => {
    const data = fs.readFileSync(path.join(DIR, v.file));
    if (v.expect === 'valid') {
      const got = parseExact(dumpJson(read(data)));
      const expected = parseExact(fs.readFileSync(path.join(DIR, v.json), 'utf8'));
      assert.ok(sameJson(got, expected), `dump of ${v.file} differs from ${v.json}`);
      const meta = read(data, { metadataOnly: true });
      assert.equal(meta.producer_name, expected.producer_name);
      assert.equal(meta.weights, undefined);
    } else {
      assert.throws(() => read(data), (e) => {
        assert.ok(e instanceof SogmmError, `not a SogmmError: ${e}`);
        assert.deepEqual([e.category, e.reason], [v.category, v.reason], e.message);
        return true;
      });
    }
  });
}
