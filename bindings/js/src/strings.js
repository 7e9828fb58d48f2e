// Step 11, strings (spec/format.md section 4.4): producer_name,
// producer_version and every key and value are valid UTF-8 without U+0000,
// and together (a shared string once per use) at most L bytes.
import { formatError } from './errors.js';

// fatal: reject overlong forms, surrogates, code points above U+10FFFF;
// ignoreBOM: a leading U+FEFF is text, not a marker to strip.
const UTF8 = new TextDecoder('utf-8', { fatal: true, ignoreBOM: true });

function text(bytes) {
  if (bytes === null) return '';
  if (bytes.includes(0)) formatError('bad_metadata', 'a string contains U+0000');
  try {
    return UTF8.decode(bytes);
  } catch {
    return formatError('bad_metadata', 'a string is not valid UTF-8');
  }
}

/** Replaces the raw strings of the metadata `m` by their text, or rejects. */
export function decodeStrings(m, blockLength) {
  const raw = [m.producer_name, m.producer_version, ...m.key_values.flat()];
  const total = raw.reduce((s, b) => s + (b === null ? 0 : b.length), 0);
  if (total > blockLength) formatError('bad_metadata', `strings total ${total} bytes, more than the metadata block`);
  m.producer_name = text(m.producer_name);
  m.producer_version = text(m.producer_version);
  m.key_values = m.key_values.map(([k, v]) => [text(k), text(v)]);
}
