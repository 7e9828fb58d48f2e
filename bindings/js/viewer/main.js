// The viewer of `sogmm view`: reads the .sogmm embedded in the page (or one
// dropped on it) with the independent JavaScript reader, and draws it with
// three.js: ellipsoids (one mesh, or one point sprite each in a large model), sampled points, a map's cameras with a
// slider over its frames, a picked component's numbers and the metadata.
// window.sogmmViewer exposes the state for the browser test.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { read, ready, getValue, SogmmError } from '../src/reader.js';
import { symmetricEigen, cholesky4 } from './geometry.js';
import { ellipsoidMesh, placeEllipsoids, colourEllipsoids, showFirst, componentOf } from './ellipsoids.js';
import { impostorCloud, placeImpostors, colourImpostors, showFirstImpostors, pickImpostor } from './impostors.js';
import { parseMapFrames } from './provenance.js';

const BACKGROUND = 0x101418;
const SAMPLE_COUNT = 100000;
// Components above which drawing is coarser: 80 triangles per ellipsoid up
// to DETAILED, 20 up to LARGE (400,000 at most), one point sprite each beyond
// (impostors.js: software WebGL pays per vertex and triangle).
const DETAILED = 5000;
const LARGE = 20000;
// The two ways to draw the ellipsoids, with the same operations.
const MESHES = {
  create: (M) => ellipsoidMesh(M, M <= DETAILED ? 1 : 0),
  place: placeEllipsoids,
  colour: colourEllipsoids,
  showFirst,
  pick(mesh, ndc) {
    raycaster.setFromCamera(ndc, camera);
    const hit = raycaster.intersectObject(mesh, false)[0];
    return hit ? componentOf(mesh, hit) : null;
  },
};
const SPRITES = {
  create: impostorCloud,
  place: placeImpostors,
  colour: colourImpostors,
  showFirst: showFirstImpostors,
  pick: (points, ndc) => pickImpostor(points, ndc, camera, renderer.getDrawingBufferSize(new THREE.Vector2())),
};
// The page's cap on decoded arrays (spec/format.md section 8: applications
// may choose their own): 128 MiB, about 2.2 million float32 components, whose
// point sprites take another 100 MB. The reference cap (1 GiB) would let a
// valid but huge file keep the tab busy for minutes and then run it out of
// memory; this one answers at once with the reason `limit`.
const MAX_DECODED_BYTES = 2 ** 27;
const $ = (id) => document.getElementById(id);
// The zstd decoder (WebAssembly) compiles in the background from here on;
// should that fail, loading a file shows why.
const decoderReady = ready();
decoderReady.catch(() => {});
const state = { status: 'loading', reason: null, drawn: 0, frame: null, frames: 0, timings: {} };
window.sogmmViewer = state;

// --- scene -------------------------------------------------------------
// Multisampling costs software WebGL (headless Chromium) several times the
// fill: a model of more than LARGE components is drawn without it, so that
// its first frame stays fast. The canvas is replaced when that changes.
let renderer = null;
function useRenderer(antialias) {
  if (renderer && renderer.antialias === antialias) return;
  if (renderer) {
    renderer.dispose();
    renderer.domElement.remove();
  }
  renderer = new THREE.WebGLRenderer({ antialias, preserveDrawingBuffer: true });
  renderer.antialias = antialias;
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.setClearColor(BACKGROUND, 1);
  // Opaque objects only: sorting them by depth would cost a bounding sphere
  // (a pass over every vertex) before the first frame, for nothing.
  renderer.sortObjects = false;
  $('view').appendChild(renderer.domElement);
}
const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.2);
sun.position.set(1, 2, 1.5);
scene.add(sun);
// The file's frame is the camera's (x right, y down, z forward); three.js is
// y up: a half turn about x shows the model the right way up.
const world = new THREE.Group();
world.rotation.x = Math.PI;
scene.add(world);
const camera = new THREE.PerspectiveCamera(50, window.innerWidth / window.innerHeight, 0.01, 1000);
const controls = new OrbitControls(camera, $('view'));
let frameRequested = false;
function draw() {
  if (frameRequested) return;
  frameRequested = true;
  requestAnimationFrame(() => { frameRequested = false; if (renderer) renderer.render(scene, camera); });
}
controls.addEventListener('change', draw);
window.addEventListener('resize', () => {
  if (renderer) renderer.setSize(window.innerWidth, window.innerHeight);
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  draw();
});

let current = null; // {model, mesh, drawing (MESHES or SPRITES), points, cameras, frames}

function clearScene() {
  if (!current) return;
  for (const o of [current.mesh, current.points, current.cameras]) {
    if (!o) continue;
    world.remove(o);
    o.geometry.dispose();
    o.material.dispose();
  }
  current = null;
}

// --- colours -------------------------------------------------------------
function weightColour(t, out) { // t in [0, 1]: dark blue -> teal -> yellow
  out.setRGB(0.27 + 0.7 * t * t, 0.0 + 0.9 * t, 0.33 + 0.3 * Math.sin(Math.PI * t) - 0.2 * t);
  return out;
}

// A gray in sRGB (the file's gray) as linear light, the renderer's working
// colour space: the sRGB transfer function of IEC 61966-2-1, as
// Color.setRGB(g, g, g, SRGBColorSpace) applies it to each channel, once
// per component instead of three times through three.js's colour management
// (70 ms of a 52,497-component map's first frame).
function grayToLinear(g) {
  return g < 0.04045 ? g * 0.0773993808 : Math.pow(g * 0.9478672986 + 0.0521327014, 2.4);
}

function colourComponents(mesh, model, by) { // current.drawing set
  if (by !== 'weight') {
    current.drawing.colour(mesh, (k, c) => {
      const g = grayToLinear(Math.min(Math.max(model.means[4 * k + 3], 0), 1));
      c.setRGB(g, g, g);
    });
    return;
  }
  const M = Number(model.n_components);
  let lo = Infinity;
  let hi = -Infinity;
  for (let k = 0; k < M; k++) {
    const w = Math.log(Math.max(model.weights[k], 1e-12));
    lo = Math.min(lo, w);
    hi = Math.max(hi, w);
  }
  current.drawing.colour(mesh, (k, c) => weightColour(hi > lo ? (Math.log(Math.max(model.weights[k], 1e-12)) - lo) / (hi - lo) : 1, c));
}

// --- samples ---------------------------------------------------------------
function samplePoints(model, n) {
  const M = Number(model.n_components);
  const cdf = new Float64Array(M);
  let s = 0;
  for (let k = 0; k < M; k++) cdf[k] = (s += model.weights[k]);
  const factors = [];
  for (let k = 0; k < M; k++) factors.push(cholesky4(model.covariances.subarray(16 * k, 16 * k + 16)));
  let seed = 1; // a fixed xorshift sequence: the same points on every load
  const uniform = () => {
    seed ^= seed << 13; seed >>>= 0; seed ^= seed >>> 17; seed ^= seed << 5; seed >>>= 0;
    return (seed + 0.5) / 4294967296;
  };
  const normal = () => Math.sqrt(-2 * Math.log(uniform())) * Math.cos(2 * Math.PI * uniform());
  const pos = new Float32Array(3 * n);
  const col = new Float32Array(3 * n);
  const z = [0, 0, 0, 0];
  for (let i = 0; i < n; i++) {
    const u = uniform() * s;
    let lo = 0;
    let hi = M - 1;
    while (lo < hi) { const mid = (lo + hi) >> 1; if (cdf[mid] < u) lo = mid + 1; else hi = mid; }
    const l = factors[lo];
    for (let d = 0; d < 4; d++) z[d] = normal();
    const x = [0, 0, 0, 0];
    for (let r = 0; r < 4; r++) {
      let v = model.means[4 * lo + r];
      for (let c = 0; c <= r; c++) v += l[4 * r + c] * z[c];
      x[r] = v;
    }
    pos.set(x.slice(0, 3), 3 * i);
    const g = new THREE.Color().setRGB(...Array(3).fill(Math.min(Math.max(x[3], 0), 1)), THREE.SRGBColorSpace);
    col.set([g.r, g.g, g.b], 3 * i);
  }
  const geo = new THREE.BufferGeometry();
  geo.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  geo.setAttribute('color', new THREE.BufferAttribute(col, 3));
  return new THREE.Points(geo, new THREE.PointsMaterial({ size: 2, sizeAttenuation: false, vertexColors: true }));
}

// --- cameras of a map ----------------------------------------------------------
function frustums(frames, cam) {
  const w = cam ? cam.width : 640;
  const h = cam ? cam.height : 480;
  const fx = cam && cam.fx > 0 ? cam.fx : 525;
  const fy = cam && cam.fy > 0 ? cam.fy : 525;
  const cx = cam ? cam.cx : (w - 1) / 2;
  const cy = cam ? cam.cy : (h - 1) / 2;
  const d = 0.15; // metres: the frustum's drawn depth
  const corners = [[0, 0], [w, 0], [w, h], [0, h]].map(([u, v]) => [(u - cx) / fx * d, (v - cy) / fy * d, d]);
  const pos = [];
  const apply = (p, q) => [0, 1, 2].map((r) => p[4 * r] * q[0] + p[4 * r + 1] * q[1] + p[4 * r + 2] * q[2] + p[4 * r + 3]);
  for (const f of frames) {
    const o = apply(f.pose, [0, 0, 0]);
    const c = corners.map((q) => apply(f.pose, q));
    for (let i = 0; i < 4; i++) pos.push(...o, ...c[i], ...c[i], ...c[(i + 1) % 4]);
  }
  const geo = new THREE.BufferGeometry();
  geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  const colours = new Float32Array(pos.length);
  geo.setAttribute('color', new THREE.BufferAttribute(colours, 3));
  return new THREE.LineSegments(geo, new THREE.LineBasicMaterial({ vertexColors: true }));
}

const SEGMENTS_PER_FRAME = 8; // 4 rays and 4 edges: 16 vertices
function highlightFrames(lines, upTo) {
  const col = lines.geometry.attributes.color;
  const frames = col.count / (2 * SEGMENTS_PER_FRAME);
  for (let f = 0; f < frames; f++) {
    const rgb = f === upTo ? [1, 0.35, 0.2] : f < upTo ? [0.35, 0.6, 0.9] : [0.25, 0.28, 0.32];
    for (let v = 0; v < 2 * SEGMENTS_PER_FRAME; v++) col.setXYZ(f * 2 * SEGMENTS_PER_FRAME + v, ...rgb);
  }
  col.needsUpdate = true;
}

// --- panels ------------------------------------------------------------------
const fmt = (x) => (typeof x === 'number' ? Number(x.toPrecision(6)).toString() : String(x));

function showMetadata(model, name, frames) {
  const lines = [`file: ${name}`, `components: ${model.n_components}   support: ${model.support_size}`,
    `format ${model.file.format_version}, ${model.file.file_length} bytes, covariances ${model.file.covariance_layout}`,
    `producer: ${model.producer_name} ${model.producer_version}`];
  if (model.created_unix_ms > 0n) lines.push(`created: ${new Date(Number(model.created_unix_ms)).toISOString()}`);
  if (model.fit) lines.push(`fit: ${Object.entries(model.fit).map(([k, v]) => `${k}=${fmt(v)}`).join(' ')}`);
  if (model.camera) lines.push(`camera: ${Object.entries(model.camera).map(([k, v]) => `${k}=${fmt(v)}`).join(' ')}`);
  if (model.pose) lines.push(`pose: [${model.pose.map(fmt).join(' ')}]`);
  for (const [k, v] of model.key_values) {
    const shown = v.length > 160 ? `${v.slice(0, 160)}... (${v.length} characters)` : v;
    lines.push(k === 'map_frames' ? `map_frames: ${frames.length} frames` : `${k}: ${shown}`);
  }
  $('meta').textContent = lines.join('\n');
  $('meta').style.display = 'block';
}

function showComponent(model, k) {
  const cov = model.covariances.subarray(16 * k, 16 * k + 16);
  const { values } = symmetricEigen(cov, 4);
  const row = (i) => Array.from(cov.subarray(4 * i, 4 * i + 4), (x) => x.toExponential(3).padStart(11)).join(' ');
  $('pick').textContent = [`component ${k}`, `weight ${model.weights[k].toPrecision(6)}`,
    `mean (x y z gray) ${Array.from(model.means.subarray(4 * k, 4 * k + 4), fmt).join(' ')}`,
    'covariance (x y z gray):', ...[0, 1, 2, 3].map(row),
    `eigenvalues ${values.map((x) => x.toExponential(3)).join(' ')}`].join('\n');
  $('pick').style.display = 'block';
  state.picked = k;
}

function showError(e) {
  clearScene();
  useRenderer(renderer ? renderer.antialias : true);
  const what = e instanceof SogmmError ? `Cannot read this file: ${e.reason} (${e.category})\n${e.message}` : `Viewer error: ${e && e.message}`;
  $('error').textContent = what;
  $('error').style.display = 'block';
  $('meta').style.display = 'none';
  $('frames').style.display = 'none';
  state.status = 'error';
  state.reason = e instanceof SogmmError ? e.reason : 'viewer_error';
  state.category = e instanceof SogmmError ? e.category : null;
  draw();
}

// --- loading ------------------------------------------------------------------
function setFrame(f) {
  if (!current || !current.frames.length) return;
  const fr = current.frames[f];
  const M = Number(current.model.n_components);
  state.drawn = fr.nComponents === null ? M : Math.min(fr.nComponents, M);
  current.drawing.showFirst(current.mesh, state.drawn);
  state.frame = f;
  $('frame').value = String(f);
  $('frame-label').textContent = `after frame ${f} of ${current.frames.length - 1}: ${state.drawn} components ` +
    `(${fr.nPoints} points, ${fr.nNovel} novel)`;
  highlightFrames(current.cameras, f);
  draw();
}

function frameCamera(model, overhead) {
  const box = new THREE.Box3();
  const p = new THREE.Vector3();
  const M = Number(model.n_components);
  for (let k = 0; k < M; k++) box.expandByPoint(p.set(model.means[4 * k], -model.means[4 * k + 1], -model.means[4 * k + 2]));
  const centre = box.getCenter(new THREE.Vector3());
  const size = Math.max(box.getSize(new THREE.Vector3()).length(), 0.1);
  controls.target.copy(centre);
  // A frame: the viewpoint of its camera, backed off a little. A map (world
  // frame, a room seen from inside): from above, so its cameras show.
  if (overhead) camera.position.set(centre.x, centre.y + 0.75 * size, centre.z + 0.45 * size);
  else camera.position.set(centre.x, centre.y + 0.15 * size, centre.z + 0.9 * size);
  camera.near = size / 1000;
  camera.far = size * 100;
  camera.updateProjectionMatrix();
  controls.update();
}

// options.spritesAbove: the component count above which the ellipsoids are
// point sprites (default LARGE; the browser test lowers it to check them).
// Resolves once the first frame is drawn or the error shown.
async function load(bytes, name, options = {}) {
  const t0 = performance.now();
  $('error').style.display = 'none';
  $('pick').style.display = 'none';
  state.status = 'loading';
  let model;
  let tDecoder;
  try {
    await decoderReady; // compiling since the script started; 0.02-0.05 s left here
    tDecoder = performance.now();
    model = read(bytes, { maxDecodedBytes: MAX_DECODED_BYTES });
  } catch (e) {
    showError(e);
    return;
  }
  const t1 = performance.now();
  clearScene();
  const M = Number(model.n_components);
  // The WebGL context is created here, not while the arrays are read: at load
  // average 14-18 that took the first frame 0.23 s longer (median of 7), the
  // GPU process setting it up while this thread read.
  useRenderer(M <= LARGE);
  const drawing = M > (options.spritesAbove ?? LARGE) ? SPRITES : MESHES;
  const mesh = drawing.create(M);
  world.add(mesh);
  const frames = parseMapFrames(getValue(model, 'map_frames'));
  const cameras = frames.length ? frustums(frames, model.camera) : null;
  if (cameras) world.add(cameras);
  // The shaders compile in the GPU process while the vertices are written
  // here (the programs are checked at their first use, in the first frame).
  // Drawing one ellipsoid before the arrays are read, to compile them then,
  // was slower: 0.17 s more before the first frame, 0.14 s less in it.
  renderer.compile(scene, camera);
  drawing.place(mesh, model.covariances, model.means, Number(document.querySelector('input[name=sigma]:checked').value));
  current = { model, mesh, drawing, points: null, cameras, frames, name };
  colourComponents(mesh, model, document.querySelector('input[name=colour]:checked').value);
  state.frames = frames.length;
  state.nComponents = M;
  state.sprites = drawing === SPRITES;
  state.drawn = M;
  state.frame = null;
  mesh.visible = $('show-ellipsoids').checked;
  if (cameras) cameras.visible = $('show-cameras').checked;
  if ($('show-samples').checked) toggleSamples();
  $('title').textContent = name;
  $('status').textContent = `${M} components`;
  showMetadata(model, name, frames);
  if (frames.length) {
    $('frames').style.display = 'block';
    $('frame').max = String(frames.length - 1);
    setFrame(frames.length - 1);
  } else {
    $('frames').style.display = 'none';
  }
  frameCamera(model, frames.length > 0);
  const tScene = performance.now();
  renderer.render(scene, camera);
  // Reading one pixel waits for the GPU: the first frame is really drawn.
  renderer.getContext().readPixels(0, 0, 1, 1, 0x1908, 0x1401, new Uint8Array(4));
  const t2 = performance.now();
  // sinceNavigationMs: from the start of navigation (performance's time
  // origin) to the first frame, script compilation and base64 included.
  // decoderWaitMs: the part of parseMs spent waiting for the zstd decoder.
  state.timings = {
    decoderWaitMs: tDecoder - t0, parseMs: t1 - t0, sceneMs: tScene - t1, renderMs: t2 - tScene, firstFrameMs: t2 - t1,
    totalMs: t2 - t0, sinceNavigationMs: t2,
  };
  state.status = 'ready';
}

function toggleSamples() {
  if (!current) return;
  if (!current.points) {
    current.points = samplePoints(current.model, Math.min(SAMPLE_COUNT, Math.max(1000, 20 * Number(current.model.n_components))));
    world.add(current.points);
  }
  current.points.visible = $('show-samples').checked;
  draw();
}

// --- interaction -------------------------------------------------------------
document.querySelectorAll('input[name=sigma]').forEach((el) => el.addEventListener('change', () => {
  if (current) { current.drawing.place(current.mesh, current.model.covariances, current.model.means, Number(el.value)); draw(); }
}));
document.querySelectorAll('input[name=colour]').forEach((el) => el.addEventListener('change', () => {
  if (current) { colourComponents(current.mesh, current.model, el.value); draw(); }
}));
$('show-ellipsoids').addEventListener('change', (e) => { if (current) { current.mesh.visible = e.target.checked; draw(); } });
$('show-cameras').addEventListener('change', (e) => { if (current && current.cameras) { current.cameras.visible = e.target.checked; draw(); } });
$('show-samples').addEventListener('change', toggleSamples);
$('frame').addEventListener('input', (e) => setFrame(Number(e.target.value)));

const raycaster = new THREE.Raycaster();
let downAt = null;
$('view').addEventListener('pointerdown', (e) => { downAt = [e.clientX, e.clientY]; });
$('view').addEventListener('pointerup', (e) => {
  if (!current || !downAt || Math.hypot(e.clientX - downAt[0], e.clientY - downAt[1]) > 4) return;
  const r = $('view').getBoundingClientRect();
  const k = current.drawing.pick(current.mesh, new THREE.Vector2(((e.clientX - r.left) / r.width) * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1));
  if (k !== null) showComponent(current.model, k);
});

window.addEventListener('dragover', (e) => { e.preventDefault(); $('drop').style.display = 'block'; });
window.addEventListener('dragleave', () => { $('drop').style.display = 'none'; });
window.addEventListener('drop', (e) => {
  e.preventDefault();
  $('drop').style.display = 'none';
  const file = e.dataTransfer && e.dataTransfer.files[0];
  if (file) file.arrayBuffer().then((b) => load(new Uint8Array(b), file.name)).catch(showError);
});

state.load = load;
state.setFrame = setFrame;
state.showComponent = (k) => current && showComponent(current.model, k);

// Native where the browser has it (Chromium 140+, Firefox 133+): a 2 MB
// model's base64 took 70-100 ms to decode with atob and a loop.
function fromBase64(text) {
  if (typeof Uint8Array.fromBase64 === 'function') return Uint8Array.fromBase64(text);
  const bin = atob(text);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return bytes;
}

// The model embedded by `sogmm view` (base64); a page without one waits for a drop.
const embedded = $('sogmm-model');
const text = embedded ? embedded.textContent.trim() : '';
if (/^[A-Za-z0-9+/=]+$/.test(text) && text.length > 0) {
  load(fromBase64(text), embedded.dataset.name || 'model.sogmm').catch(showError);
} else {
  useRenderer(true);
  state.status = 'empty';
  $('status').textContent = 'drop a .sogmm file here';
  draw();
}
