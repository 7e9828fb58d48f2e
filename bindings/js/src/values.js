// Step 19 (spec/format.md section 9) on the float32 values of section 5.6,
// widened to binary64, and the full symmetric covariances of section 5.1.
import { fail } from './errors.js';

const UPPER = [[0, 0], [0, 1], [0, 2], [0, 3], [1, 1], [1, 2], [1, 3], [2, 2], [2, 3], [3, 3]];
const UPPER_AT = UPPER.map(([i, j]) => 4 * i + j);
const UPPER_MIRROR = UPPER.map(([i, j]) => 4 * j + i);

function numeric(reason, message) {
  fail('numeric', reason, message);
}

// 19d: the Cholesky factorisation of the spec, in its order of operations.
// `a` is row-major 4x4; only entries on and below the diagonal are read.
// One scratch factor for all components: no allocation per component.
const l = new Float64Array(16);
function choleskyOk(a) {
  for (let j = 0; j < 4; j++) {
    let d = a[4 * j + j];
    for (let k = 0; k < j; k++) d -= l[4 * j + k] * l[4 * j + k];
    if (!(d > 0)) return false;
    l[4 * j + j] = Math.sqrt(d);
    for (let i = j + 1; i < 4; i++) {
      let s = a[4 * i + j];
      for (let k = 0; k < j; k++) s -= l[4 * i + k] * l[4 * j + k];
      l[4 * i + j] = s / l[4 * j + j];
    }
  }
  return true;
}

/**
 * Checks weights, means and stored covariances (19a-d) and returns the
 * covariances as M full symmetric row-major 4x4 matrices (Float32Array).
 */
export function checkValues(weights, means, stored, M, packed) {
  for (const arr of [weights, means, stored]) {
    // x - x is 0 for a finite x and NaN for NaN or infinity.
    for (let i = 0; i < arr.length; i++) if (arr[i] - arr[i] !== 0) numeric('non_finite', 'NaN or infinity in the arrays');
  }
  let sum = 0;
  for (let i = 0; i < M; i++) {
    if (weights[i] < 0) numeric('bad_weights', `weight ${i} is negative`);
  }
  for (let i = 0; i < M; i++) sum += weights[i];
  if (!(Math.abs(sum - 1) <= 1e-4)) numeric('bad_weights', `weights sum to ${sum}`);
  const cov = new Float32Array(16 * M);
  const a = new Float64Array(16);
  for (let k = 0; k < M; k++) {
    if (packed) {
      for (let t = 0; t < 10; t++) a[UPPER_AT[t]] = a[UPPER_MIRROR[t]] = stored[10 * k + t];
    } else {
      let scale = 0;
      let asym = 0;
      for (let i = 0; i < 16; i++) scale = Math.max(scale, Math.abs(stored[16 * k + i]));
      for (let i = 0; i < 4; i++) {
        for (let j = 0; j < 4; j++) asym = Math.max(asym, Math.abs(stored[16 * k + 4 * i + j] - stored[16 * k + 4 * j + i]));
      }
      if (asym > 1e-5 * scale) numeric('not_symmetric', `covariance ${k} is not symmetric`);
      for (let i = 0; i < 4; i++) {
        for (let j = 0; j < 4; j++) a[4 * i + j] = Math.fround((stored[16 * k + 4 * i + j] + stored[16 * k + 4 * j + i]) / 2);
      }
    }
    if (!choleskyOk(a)) numeric('not_spd', `covariance ${k} is not positive definite`);
    cov.set(a, 16 * k);
  }
  return cov;
}
