// Every component of a large model as ONE point sprite whose fragment shader
// draws the component's projected k-sigma ellipse, shaded as an ellipsoid,
// with its front surface's depth. Software WebGL (SwiftShader, headless
// Chromium without a GPU) pays per vertex and per triangle: a 52,497-component
// map drew in about 0.9 s as 420,000 octahedron triangles (ellipsoids.js);
// one vertex per component: 52,497 points drew in about half that. (One
// screen-space triangle per component instead of a point was no faster.)
// Component k is vertex k, in file order: a draw range shows the first n
// components (a map's state after a frame), as in ellipsoids.js.
// The projection is the first-order one of EWA splatting (Zwicker et al.;
// the 3D Gaussian Splatting viewers do the same): the view-space covariance V
// seen through the Jacobian J of the perspective at the mean gives the 2x2
// screen covariance J V J^T of the ellipse.
import * as THREE from 'three';

const vertexShader = /* glsl */ `
attribute vec3 covXX; // the spatial covariance's rows, upper part: xx xy xz
attribute vec3 covYY; // yy yz zz
attribute vec3 tint;
uniform float sigmas;
uniform vec2 viewport; // drawing buffer pixels
uniform float maxPointSize;
varying vec3 vTint;
varying vec3 vConic; // the screen ellipse {d : d^T Q d <= 1} in pixels: Q's a, b, c
varying float vSize;
varying float vDepth; // view-space distance of the mean along -z
varying float vThickness; // k-sigma half-depth of the ellipsoid along the view axis
void main() {
  vec4 mv = modelViewMatrix * vec4(position, 1.0);
  gl_Position = projectionMatrix * mv;
  mat3 r = mat3(modelViewMatrix);
  mat3 s = mat3(covXX.x, covXX.y, covXX.z, covXX.y, covYY.x, covYY.y, covXX.z, covYY.y, covYY.z);
  mat3 v = r * s * transpose(r);
  float z = max(-mv.z, 1e-6);
  vec2 f = 0.5 * viewport * vec2(projectionMatrix[0][0], projectionMatrix[1][1]);
  // Screen position f * (x, y) / z (y up): its derivatives by view x, y, z.
  vec3 jx = vec3(f.x / z, 0.0, f.x * mv.x / (z * z));
  vec3 jy = vec3(0.0, f.y / z, f.y * mv.y / (z * z));
  float k2 = sigmas * sigmas;
  // Covariance of the screen ellipse, with a quarter pixel added on the
  // diagonal so that a component thinner than a pixel still shows.
  float a = k2 * dot(jx, v * jx) + 0.25;
  float b = k2 * dot(jx, v * jy);
  float c = k2 * dot(jy, v * jy) + 0.25;
  float det = max(a * c - b * b, 1e-12);
  vConic = vec3(c, -b, a) / det;
  vSize = min(2.0 * sqrt(max(a, c)) + 1.0, maxPointSize);
  gl_PointSize = vSize;
  vDepth = z;
  // Along the view axis through the mean the ellipsoid spans k / sqrt((V^-1)_zz)
  // = k sqrt(det V / minor_zz V) either side.
  float minor = max(v[0][0] * v[1][1] - v[0][1] * v[0][1], 1e-30);
  vThickness = sigmas * sqrt(max(determinant(v), 0.0) / minor);
  vTint = tint;
}`;

const fragmentShader = /* glsl */ `
uniform mat4 projectionMatrix;
uniform vec3 sunDirection; // view space, towards the light
uniform vec3 sunColour;    // colour times intensity
uniform vec3 upDirection;  // view space
uniform vec3 skyColour;
uniform vec3 groundColour;
varying vec3 vTint;
varying vec3 vConic;
varying float vSize;
varying float vDepth;
varying float vThickness;
void main() {
  vec2 d = (gl_PointCoord - 0.5) * vec2(1.0, -1.0) * vSize;
  vec2 g = vec2(vConic.x * d.x + vConic.y * d.y, vConic.y * d.x + vConic.z * d.y);
  float q = dot(d, g);
  if (q > 1.0) discard;
  float h = sqrt(1.0 - q);
  // The normal of a sphere of the ellipse's mean radius, bent by the conic:
  // exact for a round component, a fair shading for the others.
  float radius = inversesqrt(sqrt(max(vConic.x * vConic.z - vConic.y * vConic.y, 1e-30)));
  vec3 n = normalize(vec3(g * radius, h));
  // Lambert under the scene's hemisphere and directional lights, as the
  // mesh path's MeshLambertMaterial (irradiance times albedo over pi).
  vec3 irradiance = mix(groundColour, skyColour, 0.5 * dot(n, upDirection) + 0.5)
                  + sunColour * max(dot(n, sunDirection), 0.0);
  gl_FragColor = vec4(vTint * irradiance * 0.3183098861837907, 1.0);
  #include <colorspace_fragment>
  // The front surface's depth: nearer than the mean by h times the half-depth.
  float zf = max(vDepth - h * vThickness, 1e-6);
  float ndc = (projectionMatrix[2][2] * -zf + projectionMatrix[3][2]) / zf;
  gl_FragDepth = 0.5 * ndc + 0.5;
}`;

/** Point sprites for M components; place and colour them before drawing. */
export function impostorCloud(M) {
  const geo = new THREE.BufferGeometry();
  geo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * M), 3));
  geo.setAttribute('covXX', new THREE.BufferAttribute(new Float32Array(3 * M), 3));
  geo.setAttribute('covYY', new THREE.BufferAttribute(new Float32Array(3 * M), 3));
  // Float colours: as three 16-bit fractions (ellipsoids.js) the first frame
  // took 0.14 s longer here, a 6-byte vertex format that WebGL's backend
  // converts.
  geo.setAttribute('tint', new THREE.BufferAttribute(new Float32Array(3 * M), 3));
  const uniforms = {
    sigmas: { value: 1 },
    viewport: { value: new THREE.Vector2(1, 1) },
    maxPointSize: { value: 64 },
    sunDirection: { value: new THREE.Vector3() },
    sunColour: { value: new THREE.Color() },
    upDirection: { value: new THREE.Vector3() },
    skyColour: { value: new THREE.Color() },
    groundColour: { value: new THREE.Color() },
  };
  const points = new THREE.Points(geo, new THREE.ShaderMaterial({ uniforms, vertexShader, fragmentShader }));
  points.frustumCulled = false; // framed whole; see ellipsoids.js
  points.userData = { M, means: null, cov: null };
  // The lights and the viewport are read at each draw (the camera moves).
  points.onBeforeRender = (renderer, scene, camera) => {
    const u = points.material.uniforms;
    renderer.getDrawingBufferSize(u.viewport.value);
    const gl = renderer.getContext();
    u.maxPointSize.value = gl.getParameter(gl.ALIASED_POINT_SIZE_RANGE)[1];
    scene.traverseVisible((o) => {
      if (o.isDirectionalLight) {
        u.sunDirection.value.copy(o.position).sub(o.target.position).normalize().transformDirection(camera.matrixWorldInverse);
        u.sunColour.value.copy(o.color).multiplyScalar(o.intensity);
      } else if (o.isHemisphereLight) {
        u.upDirection.value.copy(o.position).normalize().transformDirection(camera.matrixWorldInverse);
        u.skyColour.value.copy(o.color).multiplyScalar(o.intensity);
        u.groundColour.value.copy(o.groundColor).multiplyScalar(o.intensity);
      }
    });
  };
  return points;
}

/** Writes each component's mean and spatial covariance (cov: M x 16 row-major, means: M x 4). */
export function placeImpostors(points, cov, means, sigmas) {
  const { M } = points.userData;
  const attr = points.geometry.attributes;
  const pos = attr.position.array;
  const xx = attr.covXX.array;
  const yy = attr.covYY.array;
  for (let k = 0; k < M; k++) {
    const o = 16 * k;
    const p = 3 * k;
    pos[p] = means[4 * k];
    pos[p + 1] = means[4 * k + 1];
    pos[p + 2] = means[4 * k + 2];
    xx[p] = cov[o];
    xx[p + 1] = cov[o + 1];
    xx[p + 2] = cov[o + 2];
    yy[p] = cov[o + 5];
    yy[p + 1] = cov[o + 6];
    yy[p + 2] = cov[o + 10];
  }
  points.material.uniforms.sigmas.value = sigmas;
  points.userData.means = means;
  points.userData.cov = cov;
  for (const a of ['position', 'covXX', 'covYY']) attr[a].needsUpdate = true;
}

/** Sets component k's colour to colourOf(k, colour) (a THREE.Color it fills). */
export function colourImpostors(points, colourOf) {
  const { M } = points.userData;
  const col = points.geometry.attributes.tint.array;
  const c = new THREE.Color();
  for (let k = 0; k < M; k++) {
    colourOf(k, c);
    col[3 * k] = c.r;
    col[3 * k + 1] = c.g;
    col[3 * k + 2] = c.b;
  }
  points.geometry.attributes.tint.needsUpdate = true;
}

/** Draws only the first n components. */
export function showFirstImpostors(points, n) {
  points.geometry.setDrawRange(0, n);
}

/**
 * The drawn component under a point of the canvas (ndc: x, y in [-1, 1]),
 * by the shaders' own projection on the CPU: of the components whose screen
 * ellipse holds the point, the one whose mean is nearest the camera; null
 * when none does.
 */
export function pickImpostor(points, ndc, camera, viewport) {
  const { means, cov } = points.userData;
  const sigmas = points.material.uniforms.sigmas.value;
  const n = Math.min(points.geometry.drawRange.count, points.userData.M);
  points.updateWorldMatrix(true, false);
  const mv = new THREE.Matrix4().multiplyMatrices(camera.matrixWorldInverse, points.matrixWorld).elements;
  const pr = camera.projectionMatrix.elements;
  const fx = 0.5 * viewport.x * pr[0];
  const fy = 0.5 * viewport.y * pr[5];
  const px = 0.5 * viewport.x * ndc.x; // the click, pixels from the centre
  const py = 0.5 * viewport.y * ndc.y;
  const r = [mv[0], mv[4], mv[8], mv[1], mv[5], mv[9], mv[2], mv[6], mv[10]]; // rows of the rotation
  const rs = new Float64Array(9);
  let best = null;
  let bestDepth = Infinity;
  for (let k = 0; k < n; k++) {
    const x = means[4 * k];
    const y = means[4 * k + 1];
    const w = means[4 * k + 2];
    const vx = mv[0] * x + mv[4] * y + mv[8] * w + mv[12];
    const vy = mv[1] * x + mv[5] * y + mv[9] * w + mv[13];
    const z = -(mv[2] * x + mv[6] * y + mv[10] * w + mv[14]);
    if (!(z > 0) || z >= bestDepth) continue;
    const dx = px - (fx * vx) / z;
    const dy = py - (fy * vy) / z;
    // V = R S R^T, but only J V J^T is needed: rows jx R and jy R against S.
    const o = 16 * k;
    const s = [cov[o], cov[o + 1], cov[o + 2], cov[o + 4], cov[o + 5], cov[o + 6], cov[o + 8], cov[o + 9], cov[o + 10]];
    const jx = [fx / z, 0, (fx * vx) / (z * z)];
    const jy = [0, fy / z, (fy * vy) / (z * z)];
    const ax = [0, 1, 2].map((c) => jx[0] * r[c] + jx[1] * r[3 + c] + jx[2] * r[6 + c]);
    const ay = [0, 1, 2].map((c) => jy[0] * r[c] + jy[1] * r[3 + c] + jy[2] * r[6 + c]);
    for (let i = 0; i < 3; i++) rs[i] = s[3 * i] * ax[0] + s[3 * i + 1] * ax[1] + s[3 * i + 2] * ax[2];
    for (let i = 0; i < 3; i++) rs[3 + i] = s[3 * i] * ay[0] + s[3 * i + 1] * ay[1] + s[3 * i + 2] * ay[2];
    const k2 = sigmas * sigmas;
    const a = k2 * (ax[0] * rs[0] + ax[1] * rs[1] + ax[2] * rs[2]) + 0.25;
    const b = k2 * (ay[0] * rs[0] + ay[1] * rs[1] + ay[2] * rs[2]);
    const c = k2 * (ay[0] * rs[3] + ay[1] * rs[4] + ay[2] * rs[5]) + 0.25;
    const det = a * c - b * b;
    if (det > 0 && (c * dx * dx - 2 * b * dx * dy + a * dy * dy) / det <= 1) {
      best = k;
      bestDepth = z;
    }
  }
  return best;
}
