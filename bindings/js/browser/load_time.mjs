// Load time of `sogmm view` pages in headless Chromium (Debian's, software
// WebGL): the page's own parse + first-frame time (window.sogmmViewer.timings,
// the first frame waited for with a one-pixel read) and the time from
// navigation to ready, median of N runs per page. Several pages are measured
// in turn within each round (A B A B ...), so that a busy machine slows each
// alike and their ratio holds.
//   node browser/load_time.mjs PAGE.html [PAGE2.html ...] [RUNS=5]
//   (SOGMM_CHROMIUM: the browser, default /usr/bin/chromium)
import { chromium } from 'playwright-core';

const args = process.argv.slice(2);
const pages = args.filter((a) => !/^\d+$/.test(a));
const runs = Number(args.find((a) => /^\d+$/.test(a)) || 5);
const browser = await chromium.launch({
  executablePath: process.env.SOGMM_CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const rows = pages.map(() => []);
for (let i = 0; i < runs; i++) {
  for (const [j, page] of pages.entries()) {
    const p = await browser.newPage({ viewport: { width: 1000, height: 700 } });
    const t0 = Date.now();
    await p.goto(`file://${page}`);
    await p.waitForFunction(() => window.sogmmViewer && window.sogmmViewer.status !== 'loading', null, { timeout: 120000 });
    const wall = Date.now() - t0;
    const s = await p.evaluate(() => ({ status: window.sogmmViewer.status, n: window.sogmmViewer.nComponents, ...window.sogmmViewer.timings }));
    rows[j].push({ ...s, navigationToReadyMs: wall });
    console.log(page, JSON.stringify(rows[j][rows[j].length - 1]));
    await p.close();
  }
}
await browser.close();
for (const [j, page] of pages.entries()) {
  const median = (k) => rows[j].map((r) => r[k]).sort((a, b) => a - b)[Math.floor(rows[j].length / 2)];
  console.log(`${page}: median of ${rows[j].length}: parse ${median('parseMs').toFixed(0)} ms, first frame ${median('firstFrameMs').toFixed(0)} ms, ` +
    `parse + first frame ${median('totalMs').toFixed(0)} ms, navigation to ready ${median('navigationToReadyMs')} ms (${rows[j][0].n} components)`);
  // Each of the page's timings (the parts need not add up to the medians above).
  const parts = Object.keys(rows[j][0]).filter((k) => k.endsWith('Ms') && typeof rows[j][0][k] === 'number');
  console.log(`  medians: ${parts.map((k) => `${k.slice(0, -2)} ${median(k).toFixed(0)}`).join(', ')}`);
}
