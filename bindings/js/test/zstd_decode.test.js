// What the frame rules of section 5.4 cannot see, only decoding does, on
// hand-made frames (RFC 8878): a Compressed_Block that decodes to more than
// the frame's Block_Maximum_Size (readers SHOULD reject it; the libzstd that
// zstddec compiles does, the Debian 1.5.4 one only when streaming, so no
// conformance vector has one), and frames whose content differs from their
// Frame_Content_Size, down to an empty frame, which the decoder's wrapper
// cannot tell from a failure by the length it returns.
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

// A frame with a Window_Descriptor (1 KiB) and a 4-byte Frame_Content_Size
// of 0, then its blocks.
function emptyFrame(...blocks) {
  return new Uint8Array([0x28, 0xb5, 0x2f, 0xfd, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, ...blocks]);
}

test('an empty frame decodes to no bytes', () => {
  const out = decodeZstd(emptyFrame(0x01, 0x00, 0x00), 0); // the last block: Raw, 0 bytes
  assert.equal(out.length, 0);
});

test('a frame of content size 0 whose block holds a byte: rejected', () => {
  assert.throws(() => decodeZstd(emptyFrame(0x09, 0x00, 0x00, 0x41), 0), (e) => {
    assert.equal(e.reason, 'decompression_failed');
    return true;
  });
});

test('two frames decode to their contents in turn; one byte short of its content size: rejected', () => {
  const both = new Uint8Array([...frame(2 << 3), ...emptyFrame(0x01, 0x00, 0x00)]);
  assert.equal(Buffer.from(decodeZstd(both, 4000)).toString('latin1'), CONTENT);
  // The first frame declares 4001 bytes (0x0ea1 + 256) and holds 4000.
  const short = frame(2 << 3);
  short[6] = 0xa1;
  assert.throws(() => decodeZstd(short, 4001), (e) => {
    assert.equal(e.reason, 'decompression_failed');
    return true;
  });
});
