// Small dense linear algebra for the viewer: symmetric eigen-decomposition
// (cyclic Jacobi, n <= 4) for the picked component's eigenvalues, Cholesky
// factors for sampling and for the instance transform that maps the unit
// sphere onto a component's k-sigma ellipsoid.

/** Eigenvalues (ascending) and eigenvectors (columns of v, row-major n x n) of symmetric a. */
export function symmetricEigen(a, n) {
  const m = Float64Array.from(a);
  const v = new Float64Array(n * n);
  for (let i = 0; i < n; i++) v[i * n + i] = 1;
  for (let sweep = 0; sweep < 50; sweep++) {
    let off = 0;
    for (let p = 0; p < n; p++) for (let q = p + 1; q < n; q++) off += m[p * n + q] * m[p * n + q];
    if (off < 1e-30) break;
    for (let p = 0; p < n; p++) {
      for (let q = p + 1; q < n; q++) {
        const apq = m[p * n + q];
        if (apq === 0) continue;
        const theta = (m[q * n + q] - m[p * n + p]) / (2 * apq);
        const t = Math.sign(theta || 1) / (Math.abs(theta) + Math.sqrt(theta * theta + 1));
        const c = 1 / Math.sqrt(t * t + 1);
        const s = t * c;
        for (let k = 0; k < n; k++) { // columns p, q of m
          const mkp = m[k * n + p];
          const mkq = m[k * n + q];
          m[k * n + p] = c * mkp - s * mkq;
          m[k * n + q] = s * mkp + c * mkq;
        }
        for (let k = 0; k < n; k++) { // rows p, q
          const mpk = m[p * n + k];
          const mqk = m[q * n + k];
          m[p * n + k] = c * mpk - s * mqk;
          m[q * n + k] = s * mpk + c * mqk;
        }
        for (let k = 0; k < n; k++) {
          const vkp = v[k * n + p];
          const vkq = v[k * n + q];
          v[k * n + p] = c * vkp - s * vkq;
          v[k * n + q] = s * vkp + c * vkq;
        }
      }
    }
  }
  const order = [...Array(n).keys()].sort((i, j) => m[i * n + i] - m[j * n + j]);
  const values = order.map((i) => m[i * n + i]);
  const vectors = new Float64Array(n * n);
  order.forEach((src, dst) => { for (let k = 0; k < n; k++) vectors[k * n + dst] = v[k * n + src]; });
  return { values, vectors };
}

/**
 * Column-major 4x4 (three.js Matrix4.elements order) mapping the unit sphere
 * onto the k-sigma ellipsoid of component c: x = mean + k L u with L L^T the
 * spatial covariance (Cholesky), so {x : (x - mean)^T S^-1 (x - mean) = k^2}.
 * No eigen-decomposition: L maps the sphere onto the same ellipsoid.
 */
export function ellipsoidMatrix(cov, means, c, sigmas, out, offset) {
  const o = 16 * c;
  const a = cov[o];
  const b = cov[o + 4];
  const d = cov[o + 5];
  const e = cov[o + 8];
  const f = cov[o + 9];
  const g = cov[o + 10];
  const l00 = Math.sqrt(Math.max(a, 0));
  const l10 = l00 > 0 ? b / l00 : 0;
  const l20 = l00 > 0 ? e / l00 : 0;
  const l11 = Math.sqrt(Math.max(d - l10 * l10, 0));
  const l21 = l11 > 0 ? (f - l20 * l10) / l11 : 0;
  const l22 = Math.sqrt(Math.max(g - l20 * l20 - l21 * l21, 0));
  // Columns of k L (column-major: out[4 j + i] = row i of column j).
  out.set([sigmas * l00, sigmas * l10, sigmas * l20, 0, 0, sigmas * l11, sigmas * l21, 0, 0, 0, sigmas * l22, 0,
    means[4 * c], means[4 * c + 1], means[4 * c + 2], 1], offset);
}

/** Lower Cholesky factor (row-major 4x4) of a positive definite 4x4. */
export function cholesky4(a) {
  const l = new Float64Array(16);
  for (let j = 0; j < 4; j++) {
    let d = a[5 * j];
    for (let k = 0; k < j; k++) d -= l[4 * j + k] * l[4 * j + k];
    l[5 * j] = Math.sqrt(Math.max(d, 0));
    for (let i = j + 1; i < 4; i++) {
      let s = a[4 * i + j];
      for (let k = 0; k < j; k++) s -= l[4 * i + k] * l[4 * j + k];
      l[4 * i + j] = l[5 * j] > 0 ? s / l[5 * j] : 0;
    }
  }
  return l;
}
