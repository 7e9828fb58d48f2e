// `sogmm view` in a real browser: headless Chromium (Debian's /usr/bin/chromium,
// software WebGL) driven by playwright-core. For a fitted frame and a map:
// no console error, the canvas shows the scene (share of non-background
// pixels, mean colour near the model's weight-averaged gray), the slider draws
// as many components as the provenance says after each frame, the map drawn
// as point sprites (the large-model path) matches its mesh, a click shows
// a component, and a damaged file shows its reason. Screenshots go to
// SOGMM_SCREENSHOTS when set (docs/viewer, see README.md).
// Env: SOGMM_CLI (the sogmm executable), SOGMM_RGBD (livingroom folder; absent:
// synthetic frames), SOGMM_CHROMIUM (default /usr/bin/chromium).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { chromium } from 'playwright-core';
import { read, ready, getValue } from '../src/reader.js';
import { canvasStats } from './page_stats.js';

await ready();
const CLI = process.env.SOGMM_CLI;
const CHROMIUM = process.env.SOGMM_CHROMIUM || '/usr/bin/chromium';
const RGBD = process.env.SOGMM_RGBD || '/work/shared/data/rgbd/livingroom';
const SHOTS = process.env.SOGMM_SCREENSHOTS;
const LOOP_FRAMES = process.env.SOGMM_LOOP_FRAMES || '60';
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'sogmm-view-'));
const sogmm = (...args) => execFileSync(CLI, args, { encoding: 'utf8' });

let browser;
before(async () => {
  assert.ok(CLI && fs.existsSync(CLI), 'SOGMM_CLI must name the sogmm executable');
  browser = await chromium.launch({
    executablePath: CHROMIUM,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
  });
});
after(async () => {
  if (browser) await browser.close();
  fs.rmSync(tmp, { recursive: true, force: true });
});

// Opens a page written by `sogmm view`; returns {page, errors}.
async function open(html) {
  const page = await browser.newPage({ viewport: { width: 1000, height: 700 } });
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('request', (r) => { if (!r.url().startsWith('file:') && !r.url().startsWith('data:')) errors.push(`network: ${r.url()}`); });
  await page.goto(`file://${html}`);
  await page.waitForFunction(() => window.sogmmViewer && window.sogmmViewer.status !== 'loading', null, { timeout: 60000 });
  return { page, errors };
}

// The reference colour: the weight-averaged mean gray of the components.
function meanGray(model) {
  let g = 0;
  for (let k = 0; k < model.weights.length; k++) g += model.weights[k] * model.means[4 * k + 3];
  return g;
}

function checkScene(stats, model, what) {
  assert.ok(stats.share > 0.05 && stats.share < 0.9, `${what}: ${(100 * stats.share).toFixed(1)}% of the canvas drawn`);
  const [r, g, b] = stats.mean;
  assert.ok(Math.abs(r - g) < 0.03 && Math.abs(g - b) < 0.03, `${what}: gray colouring gives gray pixels (${stats.mean})`);
  // Lambert shading scales the albedo (the component's gray) by the light
  // that reaches each face: the drawn mean stays within 0.25 of it.
  assert.ok(Math.abs(g - meanGray(model)) < 0.25, `${what}: mean ${g.toFixed(3)} vs model gray ${meanGray(model).toFixed(3)}`);
}

async function shot(page, name) {
  if (!SHOTS) return;
  fs.mkdirSync(SHOTS, { recursive: true });
  await page.screenshot({ path: path.join(SHOTS, name) });
}

function fittedFrame() {
  const out = path.join(tmp, 'frame.sogmm');
  if (fs.existsSync(path.join(RGBD, 'depth/00000.png'))) {
    sogmm('fit', '--depth', path.join(RGBD, 'depth/00000.png'), '--color', path.join(RGBD, 'color/00000.jpg'),
      '--intrinsics', path.join(RGBD, 'intrinsics.json'), '--decimate', '5', '--bandwidth', '0.02', '-o', out);
  } else {
    console.log(`# ${RGBD} absent: the synthetic demo frame instead of livingroom frame 0`);
    const dir = path.join(tmp, 'synthetic');
    sogmm('demo', '--write-frame', dir);
    sogmm('fit', '--depth', path.join(dir, 'depth/00000.png'), '--color', path.join(dir, 'color/00000.png'),
      '--intrinsics', path.join(dir, 'intrinsics.json'), '--decimate', '5', '--bandwidth', '0.02', '-o', out);
  }
  return out;
}

test('a fitted frame', async () => {
  const model = fittedFrame();
  const html = path.join(tmp, 'frame.html');
  sogmm('view', model, '-o', html);
  const m = read(fs.readFileSync(model));
  const { page, errors } = await open(html);
  const state = await page.evaluate(() => window.sogmmViewer);
  assert.equal(state.status, 'ready');
  assert.equal(state.drawn, m.weights.length);
  checkScene(await page.evaluate(canvasStats), m, 'frame');
  await shot(page, 'view_frame.png');
  // A click in the middle of the drawn scene picks a component and shows it.
  await page.mouse.click(500, 420);
  const picked = await page.evaluate(() => window.sogmmViewer.picked);
  if (picked !== undefined) assert.match(await page.textContent('#pick'), /eigenvalues/);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a map: cameras and the slider over frames', async () => {
  const dir = path.join(tmp, 'loop');
  sogmm('demo', '--write-frame', dir, '--loop', '--frames', LOOP_FRAMES);
  const map = path.join(tmp, 'map.sogmm');
  sogmm('map', dir, '--trajectory', path.join(dir, 'trajectory.log'), '--intrinsics', path.join(dir, 'intrinsics.json'), '-o', map);
  const m = read(fs.readFileSync(map));
  const M = m.weights.length;
  // The provenance, read here independently of the page: the count after each frame.
  const counts = getValue(m, 'map_frames').trim().split('\n').map((l) => Number(l.split(' ')[15]));
  assert.ok(new Set(counts).size > 2, `the map grows over its frames: ${counts}`);
  const html = path.join(tmp, 'map.html');
  sogmm('view', map, '-o', html);
  const { page, errors } = await open(html);
  let state = await page.evaluate(() => window.sogmmViewer);
  assert.equal(state.status, 'ready');
  assert.equal(state.frames, counts.length);
  assert.equal(state.drawn, Math.min(counts[counts.length - 1], M));
  checkScene(await page.evaluate(canvasStats), m, 'map');
  await shot(page, 'view_map.png');
  let previousShare = -1;
  for (const f of [0, Math.floor(counts.length / 3), Math.floor((2 * counts.length) / 3), counts.length - 1]) {
    // Move the slider as a user would: its value, then its input event.
    await page.$eval('#frame', (el, v) => { el.value = String(v); el.dispatchEvent(new Event('input')); }, f);
    await page.waitForTimeout(50);
    state = await page.evaluate(() => window.sogmmViewer);
    assert.equal(state.frame, f);
    assert.equal(state.drawn, Math.min(counts[f], M), `frame ${f}`);
    const stats = await page.evaluate(canvasStats);
    // More components, never fewer pixels: the map only grows here (no fusion).
    if (counts[f] > 0) assert.ok(stats.share >= previousShare - 0.01, `frame ${f}: ${stats.share} after ${previousShare}`);
    previousShare = stats.share;
    if (f === Math.floor(counts.length / 3)) await shot(page, 'view_map_early.png');
  }
  // The same map as point sprites (the path of models above 20,000
  // components): about the same pixels and colour as the mesh, the slider,
  // and a click on the left wall picks a component there in both.
  const pick = async () => {
    await page.evaluate(() => { delete window.sogmmViewer.picked; });
    await page.mouse.click(200, 420);
    return page.evaluate(() => window.sogmmViewer.picked);
  };
  const meshStats = await page.evaluate(canvasStats);
  const meshPick = await pick();
  await page.evaluate((b64) => window.sogmmViewer.load(Uint8Array.from(atob(b64), (c) => c.charCodeAt(0)), 'map.sogmm',
    { spritesAbove: 0 }), fs.readFileSync(map).toString('base64'));
  state = await page.evaluate(() => window.sogmmViewer);
  assert.equal(state.status, 'ready');
  assert.equal(state.sprites, true);
  const spriteStats = await page.evaluate(canvasStats);
  checkScene(spriteStats, m, 'map as sprites');
  // The sprite is the ellipsoid's silhouette: measured 36.83% of the canvas
  // for both; the shading differs (mean gray 0.49 against 0.45).
  assert.ok(Math.abs(spriteStats.share - meshStats.share) < 0.03, `sprites ${spriteStats.share} vs mesh ${meshStats.share}`);
  assert.ok(Math.abs(spriteStats.mean[1] - meshStats.mean[1]) < 0.1, `sprites ${spriteStats.mean} vs mesh ${meshStats.mean}`);
  const spritePick = await pick();
  assert.ok(meshPick !== undefined && spritePick !== undefined, `picked: mesh ${meshPick}, sprites ${spritePick}`);
  const apart = Math.hypot(...[0, 1, 2].map((i) => m.means[4 * meshPick + i] - m.means[4 * spritePick + i]));
  assert.ok(apart < 0.2, `the two picks lie ${apart} m apart`);
  const third = Math.floor(counts.length / 3);
  await page.$eval('#frame', (el, v) => { el.value = String(v); el.dispatchEvent(new Event('input')); }, third);
  await page.waitForTimeout(50);
  assert.equal((await page.evaluate(() => window.sogmmViewer)).drawn, Math.min(counts[third], M));
  assert.ok((await page.evaluate(canvasStats)).share < spriteStats.share, 'fewer sprites after an early frame');
  assert.deepEqual(errors, []);
  await page.close();
});

test('a damaged file shows the reason and does not hang', async () => {
  const model = fittedFrame();
  const bytes = fs.readFileSync(model);
  bytes[bytes.length - 100] ^= 0x40; // inside the covariances: checksum_mismatch or decompression_failed
  const bad = path.join(tmp, 'damaged.sogmm');
  fs.writeFileSync(bad, bytes);
  let expected;
  try { read(bytes); } catch (e) { expected = e.reason; }
  assert.ok(expected, 'the damage is detected');
  const html = path.join(tmp, 'damaged.html');
  sogmm('view', bad, '-o', html, '--embed-invalid');
  const { page, errors } = await open(html);
  const state = await page.evaluate(() => window.sogmmViewer);
  assert.equal(state.status, 'error');
  assert.equal(state.reason, expected);
  assert.match(await page.textContent('#error'), new RegExp(expected));
  await shot(page, 'view_damaged.png');
  assert.deepEqual(errors, []);
  await page.close();
});
