#!/usr/bin/env node
// Reads many .sogmm files with the JavaScript reader, one verdict per line,
// in the format of tests/conformance/batch_reader.cpp so that the mutation
// test compares it with the C++ reader:
//   "accept <canonical JSON dump, compact>" | "reject <category> <reason>" | "error <message>"
// Usage: node bin/batch.js LIST   (LIST: one path per line)
import fs from 'node:fs';
import { read, ready, SogmmError } from '../src/reader.js';
import { dumpJson } from '../src/dump.js';

if (process.argv.length !== 3) {
  process.stderr.write('usage: batch.js LIST\n');
  process.exit(2);
}
await ready();
const lines = [];
for (const file of fs.readFileSync(process.argv[2], 'utf8').split('\n').filter(Boolean)) {
  try {
    lines.push(`accept ${dumpJson(read(fs.readFileSync(file)))}`);
  } catch (e) {
    // Anything but a SogmmError is a crash of the reader: a disagreement.
    lines.push(e instanceof SogmmError ? `reject ${e.category} ${e.reason}` : `error ${e && e.name}: ${e && e.message}`);
  }
}
process.stdout.write(lines.map((l) => `${l}\n`).join(''));
