// Every component's k-sigma ellipsoid in one indexed triangle mesh, written
// straight into typed arrays (no object per component). Not instanced:
// software WebGL (SwiftShader, what headless Chromium has without a GPU)
// pays a fixed cost per instance, so a 52,497-component map of octahedra took
// 1.65 s to draw instanced and 0.4 s as one mesh of the same triangles.
// Beyond 20,000 components even that is too many triangles: impostors.js
// draws one point sprite per component instead.
// Component k owns vertices [V k, V (k + 1)) and triangles [T k, T (k + 1)),
// in file order: a draw range shows the first n components (a map's state
// after a frame) and a hit triangle names its component.
import * as THREE from 'three';
import { mergeVertices } from 'three/examples/jsm/utils/BufferGeometryUtils.js';

// The unit sphere as a polyhedron: positions (also its normals) and triangles.
const SPHERES = [() => new THREE.IcosahedronGeometry(1, 0), () => new THREE.IcosahedronGeometry(1, 1)];
function unitSphere(level) {
  const g = SPHERES[level]();
  g.deleteAttribute('normal');
  g.deleteAttribute('uv');
  const indexed = mergeVertices(g);
  return { position: indexed.attributes.position.array, index: indexed.index.array };
}

/**
 * A mesh for M components at a level of detail: 1, an 80-triangle icosphere;
 * 0, an icosahedron (20 triangles); smooth-shaded. Place and colour it
 * before drawing.
 */
export function ellipsoidMesh(M, level) {
  const unit = unitSphere(level);
  const V = unit.position.length / 3;
  const I = unit.index.length;
  const index = new Uint32Array(I * M);
  for (let k = 0, o = 0; k < M; k++) for (let i = 0; i < I; i++) index[o++] = V * k + unit.index[i];
  const geo = new THREE.BufferGeometry();
  geo.setIndex(new THREE.BufferAttribute(index, 1));
  geo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * V * M), 3));
  // Colours as 16-bit fractions: half the bytes a first frame uploads, and no
  // banding in dark grays (8 bits would band: the colours are linear).
  geo.setAttribute('color', new THREE.BufferAttribute(new Uint16Array(3 * V * M), 3, true));
  geo.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(3 * V * M), 3));
  const mesh = new THREE.Mesh(geo, new THREE.MeshLambertMaterial({ vertexColors: true }));
  // The model is framed whole: culling would only cost a pass over the
  // vertices (the bounding sphere) before the first frame; a raycast
  // computes the sphere when it first needs it.
  mesh.frustumCulled = false;
  mesh.userData = { unit: unit.position, V, trianglesPer: I / 3, M };
  return mesh;
}

/**
 * Maps the unit sphere onto each component's k-sigma ellipsoid: x = mean +
 * k L u with L L^T the spatial covariance (Cholesky), so that
 * (x - mean)^T S^-1 (x - mean) = k^2; the normal there is L^-T u.
 * No eigen-decomposition: L maps the sphere onto the same ellipsoid.
 * cov: M x 16 row-major, means: M x 4.
 */
export function placeEllipsoids(mesh, cov, means, sigmas) {
  const { unit, V, M } = mesh.userData;
  const pos = mesh.geometry.attributes.position.array;
  const nor = mesh.geometry.attributes.normal.array;
  for (let k = 0; k < M; k++) {
    const o = 16 * k;
    const l00 = Math.sqrt(Math.max(cov[o], 0));
    const l10 = l00 > 0 ? cov[o + 4] / l00 : 0;
    const l20 = l00 > 0 ? cov[o + 8] / l00 : 0;
    const l11 = Math.sqrt(Math.max(cov[o + 5] - l10 * l10, 0));
    const l21 = l11 > 0 ? (cov[o + 9] - l20 * l10) / l11 : 0;
    const l22 = Math.sqrt(Math.max(cov[o + 10] - l20 * l20 - l21 * l21, 0));
    const mx = means[4 * k];
    const my = means[4 * k + 1];
    const mz = means[4 * k + 2];
    let p = 3 * V * k;
    for (let v = 0; v < V; v++, p += 3) {
      const x = unit[3 * v];
      const y = unit[3 * v + 1];
      const z = unit[3 * v + 2];
      pos[p] = mx + sigmas * l00 * x;
      pos[p + 1] = my + sigmas * (l10 * x + l11 * y);
      pos[p + 2] = mz + sigmas * (l20 * x + l21 * y + l22 * z);
    }
    // L^-1 (lower triangular) by substitution; a zero pivot (a flat
    // ellipsoid, which a valid file does not have) leaves that axis out.
    const i00 = l00 > 0 ? 1 / l00 : 0;
    const i11 = l11 > 0 ? 1 / l11 : 0;
    const i22 = l22 > 0 ? 1 / l22 : 0;
    const i10 = -l10 * i00 * i11;
    const i21 = -l21 * i11 * i22;
    const i20 = -(l20 * i00 + l21 * i10) * i22;
    p = 3 * V * k;
    for (let v = 0; v < V; v++, p += 3) {
      const x = unit[3 * v];
      const y = unit[3 * v + 1];
      const z = unit[3 * v + 2];
      nor[p] = i00 * x + i10 * y + i20 * z; // (L^-T u): column i of L^-1 dotted with u
      nor[p + 1] = i11 * y + i21 * z;
      nor[p + 2] = i22 * z;
    }
  }
  mesh.geometry.attributes.position.needsUpdate = true;
  mesh.geometry.attributes.normal.needsUpdate = true;
  mesh.geometry.boundingSphere = null;
}

/** Sets every vertex of component k to colourOf(k, colour) (a THREE.Color it fills). */
export function colourEllipsoids(mesh, colourOf) {
  const { V, M } = mesh.userData;
  const col = mesh.geometry.attributes.color.array;
  const c = new THREE.Color();
  for (let k = 0; k < M; k++) {
    colourOf(k, c);
    const r = Math.round(65535 * c.r);
    const g = Math.round(65535 * c.g);
    const b = Math.round(65535 * c.b);
    for (let v = 0, p = 3 * V * k; v < V; v++, p += 3) {
      col[p] = r;
      col[p + 1] = g;
      col[p + 2] = b;
    }
  }
  mesh.geometry.attributes.color.needsUpdate = true;
}

/** Draws only the first n components. */
export function showFirst(mesh, n) {
  mesh.geometry.setDrawRange(0, 3 * mesh.userData.trianglesPer * n);
}

/** The component of a raycast hit on the mesh. */
export function componentOf(mesh, hit) {
  return Math.floor(hit.faceIndex / mesh.userData.trianglesPer);
}
