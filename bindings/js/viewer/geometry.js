// Small dense linear algebra for the viewer: symmetric eigen-decomposition
// (cyclic Jacobi, n <= 4) for the picked component's eigenvalues, Cholesky
// factors for sampling (ellipsoids.js maps the unit sphere with its own
// 3 x 3 factor, written into the vertices directly).

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
