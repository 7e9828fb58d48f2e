// Load time of a `sogmm view` page in headless Chromium (Debian's, software
// WebGL): the page's own parse + first-frame time (window.sogmmViewer.timings,
// the first frame waited for with a one-pixel read) and the time from
// navigation to ready, median of N runs.
//   node browser/load_time.mjs PAGE.html [RUNS=5] [CHROMIUM=/usr/bin/chromium]
import { chromium } from 'playwright-core';

const [page, runs = '5', exe = '/usr/bin/chromium'] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: exe,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const rows = [];
for (let i = 0; i < Number(runs); i++) {
  const p = await browser.newPage({ viewport: { width: 1000, height: 700 } });
  const t0 = Date.now();
  await p.goto(`file://${page}`);
  await p.waitForFunction(() => window.sogmmViewer && window.sogmmViewer.status !== 'loading', null, { timeout: 120000 });
  const wall = Date.now() - t0;
  const s = await p.evaluate(() => ({ status: window.sogmmViewer.status, n: window.sogmmViewer.nComponents, ...window.sogmmViewer.timings }));
  rows.push({ ...s, navigationToReadyMs: wall });
  console.log(JSON.stringify(rows[rows.length - 1]));
  await p.close();
}
await browser.close();
const median = (k) => rows.map((r) => r[k]).sort((a, b) => a - b)[Math.floor(rows.length / 2)];
console.log(`median of ${rows.length}: parse ${median('parseMs').toFixed(0)} ms, first frame ${median('firstFrameMs').toFixed(0)} ms, ` +
  `parse + first frame ${median('totalMs').toFixed(0)} ms, navigation to ready ${median('navigationToReadyMs')} ms (${rows[0].n} components)`);
