// Step 19 (spec/format.md section 9) on the float32 values of section 5.6,
// widened to binary64, and the full symmetric covariances of section 5.1.
import { fail } from './errors.js';

function numeric(reason, message) {
  fail('numeric', reason, message);
}

// 19d: the Cholesky factorisation of the spec, in its order of operations,
// on the entries on and below the diagonal (a_ij, i >= j). Straight-line code
// on locals: the page runs it once, cold, over 50,000 components, where a loop
// over a scratch matrix took 0.1 s before the engine optimised it.
function choleskyOk(a00, a10, a11, a20, a21, a22, a30, a31, a32, a33) {
  if (!(a00 > 0)) return false;
  const l00 = Math.sqrt(a00);
  const l10 = a10 / l00;
  const l20 = a20 / l00;
  const l30 = a30 / l00;
  const d1 = a11 - l10 * l10;
  if (!(d1 > 0)) return false;
  const l11 = Math.sqrt(d1);
  const l21 = (a21 - l20 * l10) / l11;
  const l31 = (a31 - l30 * l10) / l11;
  const d2 = (a22 - l20 * l20) - l21 * l21;
  if (!(d2 > 0)) return false;
  const l32 = ((a32 - l30 * l20) - l31 * l21) / Math.sqrt(d2);
  return ((a33 - l30 * l30) - l31 * l31) - l32 * l32 > 0;
}

// UPPER_PACKED component k (section 5.1: 00 01 02 03 11 12 13 22 23 33)
// checked and written to cov as the full row-major matrix.
function packedComponent(stored, k, cov) {
  const i = 10 * k;
  const s0 = stored[i];
  const s1 = stored[i + 1];
  const s2 = stored[i + 2];
  const s3 = stored[i + 3];
  const s4 = stored[i + 4];
  const s5 = stored[i + 5];
  const s6 = stored[i + 6];
  const s7 = stored[i + 7];
  const s8 = stored[i + 8];
  const s9 = stored[i + 9];
  if (!choleskyOk(s0, s1, s4, s2, s5, s7, s3, s6, s8, s9)) numeric('not_spd', `covariance ${k} is not positive definite`);
  const o = 16 * k;
  cov[o] = s0; cov[o + 1] = s1; cov[o + 2] = s2; cov[o + 3] = s3;
  cov[o + 4] = s1; cov[o + 5] = s4; cov[o + 6] = s5; cov[o + 7] = s6;
  cov[o + 8] = s2; cov[o + 9] = s5; cov[o + 10] = s7; cov[o + 11] = s8;
  cov[o + 12] = s3; cov[o + 13] = s6; cov[o + 14] = s8; cov[o + 15] = s9;
}

// FULL component k: symmetric within 1e-5 of its largest entry, its
// symmetric part checked and written to cov.
function fullComponent(stored, k, cov, a) {
  const o = 16 * k;
  let scale = 0;
  let asym = 0;
  for (let i = 0; i < 16; i++) scale = Math.max(scale, Math.abs(stored[o + i]));
  for (let i = 0; i < 4; i++) {
    for (let j = 0; j < 4; j++) asym = Math.max(asym, Math.abs(stored[o + 4 * i + j] - stored[o + 4 * j + i]));
  }
  if (asym > 1e-5 * scale) numeric('not_symmetric', `covariance ${k} is not symmetric`);
  for (let i = 0; i < 4; i++) {
    for (let j = 0; j < 4; j++) a[4 * i + j] = Math.fround((stored[o + 4 * i + j] + stored[o + 4 * j + i]) / 2);
  }
  if (!choleskyOk(a[0], a[4], a[5], a[8], a[9], a[10], a[12], a[13], a[14], a[15])) {
    numeric('not_spd', `covariance ${k} is not positive definite`);
  }
  cov.set(a, o);
}

// Each hot loop is a function of its own: the page runs each once, cold, and
// V8 optimises a running loop on its own (on-stack replacement), so code
// after a loop that has not run yet would send it back to the interpreter.

// 19a: x - x is 0 for a finite x and NaN for NaN or infinity.
function allFinite(arr) {
  for (let i = 0; i < arr.length; i++) if (arr[i] - arr[i] !== 0) return false;
  return true;
}

// 19b: the sum of the weights, each checked >= 0 on the way.
function weightSum(weights, M) {
  let sum = 0;
  for (let i = 0; i < M; i++) {
    if (weights[i] < 0) numeric('bad_weights', `weight ${i} is negative`);
    sum += weights[i];
  }
  return sum;
}

function packedCovariances(stored, M, cov) {
  for (let k = 0; k < M; k++) packedComponent(stored, k, cov);
}

/**
 * Checks weights, means and stored covariances (19a-d) and returns the
 * covariances as M full symmetric row-major 4x4 matrices (Float32Array).
 */
export function checkValues(weights, means, stored, M, packed) {
  if (!allFinite(weights) || !allFinite(means) || !allFinite(stored)) numeric('non_finite', 'NaN or infinity in the arrays');
  const sum = weightSum(weights, M);
  if (!(Math.abs(sum - 1) <= 1e-4)) numeric('bad_weights', `weights sum to ${sum}`);
  const cov = new Float32Array(16 * M);
  if (packed) {
    packedCovariances(stored, M, cov);
  } else {
    const a = new Float64Array(16);
    for (let k = 0; k < M; k++) fullComponent(stored, k, cov, a);
  }
  return cov;
}
