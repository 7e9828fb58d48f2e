// Small dense linear algebra for the viewer: symmetric eigen-decomposition
// (cyclic Jacobi, n <= 4), Cholesky factors for sampling, and the instance
// transform that maps the unit sphere onto a component's k-sigma ellipsoid.

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

/** The 3x3 spatial block of component k's 4x4 covariance (row-major Float32Array of M x 16). */
export function spatialCovariance(cov, k) {
  const o = 16 * k;
  return [cov[o], cov[o + 1], cov[o + 2], cov[o + 4], cov[o + 5], cov[o + 6], cov[o + 8], cov[o + 9], cov[o + 10]];
}

/**
 * Column-major 4x4 (three.js Matrix4.elements order) mapping the unit sphere
 * onto the k-sigma ellipsoid of component c: mean + V diag(k sqrt(lambda)).
 */
export function ellipsoidMatrix(cov, means, c, sigmas, out, offset) {
  const { values, vectors } = symmetricEigen(spatialCovariance(cov, c), 3);
  for (let j = 0; j < 3; j++) {
    const r = sigmas * Math.sqrt(Math.max(values[j], 0));
    for (let i = 0; i < 3; i++) out[offset + 4 * j + i] = vectors[3 * i + j] * r;
    out[offset + 4 * j + 3] = 0;
  }
  out[offset + 12] = means[4 * c];
  out[offset + 13] = means[4 * c + 1];
  out[offset + 14] = means[4 * c + 2];
  out[offset + 15] = 1;
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
