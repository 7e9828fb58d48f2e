// Section 5.4: a Compressed_Block that decodes to more than the frame's
// Block_Maximum_Size breaks RFC 8878 but passes the frame rules (it shows
// only once decoded); readers SHOULD reject it (libzstd 1.5.6 and later do;
// 1.5.4 only when streaming), so no conformance vector has one: tested here.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { decodeZstd, zstdReady } from '../src/zstd.js';

await zstdReady();

// `zstd -19 --no-check` of 'abcd' x 1000 (4000 bytes): one Compressed_Block
// of 11 bytes, raw literals "abcd" and one sequence (offset 4, match 3996).
const BLOCK = [0x5d, 0x00, 0x00, 0x20, 0x61, 0x62, 0x63, 0x64, 0x01, 0x00, 0x99, 0xe7, 0x5f, 0x22];
const CONTENT = 'abcd'.repeat(1000);

// The same block in a frame with a Window_Descriptor (Frame_Content_Size in
// 2 bytes, 4000 - 256 = 0x0ea0): Block_Maximum_Size = the window.
function frame(windowDescriptor) {
  return new Uint8Array([0x28, 0xb5, 0x2f, 0xfd, 0x40, windowDescriptor, 0xa0, 0x0e, ...BLOCK]);
}

test('the block decodes within a 4 KiB window', () => {
  const out = decodeZstd(frame(2 << 3), 4000); // Exponent 2: 4096 bytes
  assert.equal(Buffer.from(out).toString('latin1'), CONTENT);
});

test('the block decodes to more than a 1 KiB window: rejected', () => {
  assert.throws(() => decodeZstd(frame(0), 4000), (e) => {
    assert.equal(e.reason, 'decompression_failed');
    assert.match(e.message, /do not decode/);
    return true;
  });
});
