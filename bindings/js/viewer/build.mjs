// Builds the single-file viewer page of `sogmm view`: bundles viewer/main.js
// (the reader, three.js) with esbuild into page.html's script slot and
// writes tools/sogmm/viewer/viewer_page.html, the file the CLI embeds.
// Usage: node viewer/build.mjs [OUT]   (default: the committed page)
import { build } from 'esbuild';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const out = process.argv[2] || path.resolve(here, '../../../tools/sogmm/viewer/viewer_page.html');
const result = await build({
  entryPoints: [path.join(here, 'main.js')],
  bundle: true,
  minify: true,
  format: 'iife',
  target: 'es2020',
  legalComments: 'eof',
  write: false,
  logLevel: 'warning',
});
// Packages whose notices esbuild does not keep (no @license comment): their
// LICENSE files, which the page redistributes in binary form (zstddec embeds
// libzstd compiled to WebAssembly, BSD-3-Clause).
const notices = ['zstddec'].map((name) => {
  const text = fs.readFileSync(path.join(here, '../node_modules', name, 'LICENSE'), 'utf8');
  if (text.includes('*/')) throw new Error(`${name}'s LICENSE would close its comment`);
  return `\n/*! ${name}: ${text}*/\n`;
});
const js = result.outputFiles[0].text + notices.join('');
if (/<\/script/i.test(js) || js.includes('@@SOGMM_')) throw new Error('bundle contains a </script or a page marker');
const template = fs.readFileSync(path.join(here, 'page.html'), 'utf8');
const page = template.replace('@@SOGMM_VIEWER_JS@@', () => js);
fs.mkdirSync(path.dirname(out), { recursive: true });
fs.writeFileSync(out, page);
console.log(`${out}: ${page.length} bytes`);
