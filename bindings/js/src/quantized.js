// Quantized components (spec/format.md section 5.7, format 1.4, feature bit
// 2): the integer codes of the three arrays decoded to the float32 model by
// the section's formulas, in binary64 and in their order of operations (JS
// numbers are binary64 and never fused), so the bits equal every reader's.
import { fail } from './errors.js';

export const CODE_COLUMNS = [1, 5, 14];

// 2^e for an integer e of the normal binary64 range, from its bits (exact).
const scratch = new DataView(new ArrayBuffer(8));
function pow2(e) {
  scratch.setUint32(0, (e + 1023) << 20);
  scratch.setUint32(4, 0);
  return scratch.getFloat64(0);
}

function bad(k, what) {
  fail('invalid_data', 'bad_quantization', `component ${k}: ${what}`);
}

// mf(c, f) = (F + (c mod F)) 2^(floor(c / F) - f) and its exponent floor(c / F).
function miniFloat(c, f) {
  const big = 2 ** f; // f <= 16: exact
  const e = Math.floor(c / big);
  return [(big + (c - e * big)) * pow2(e - f), e];
}

/** codes: three Int32Arrays (M x 1, M x 5, M x 14, component-major) ->
 *  [weights, means, packed covariances] as Float32Arrays. */
export function dequantize(codes, M) {
  const [cw, cm, cc] = codes;
  const omega = new Float64Array(M);
  let total = 0;
  for (let k = 0; k < M; k++) {
    const [o, e] = miniFloat(cw[k], 3);
    if (e < -126 || e > 0) bad(k, 'weight code out of range');
    omega[k] = o;
    total += o;
  }
  const weights = new Float32Array(M);
  for (let k = 0; k < M; k++) weights[k] = omega[k] / total;
  const means = new Float32Array(4 * M);
  const cov = new Float32Array(10 * M);
  for (let k = 0; k < M; k++) {
    const c = cc.subarray(14 * k, 14 * k + 14);
    const f = c[0];
    if (f < 0 || f > 16) bad(k, 'f out of range');
    const lam = [];
    for (let i = 1; i <= 4; i++) {
      const [val, e] = miniFloat(c[i], f);
      if (e < -126 || e > 127) bad(k, 'variance code out of range');
      lam.push(val);
    }
    const v = lam[3];
    const r = c[5], u = c[6], Y = c[7], Z = c[8], T = c[9], sb = c[10];
    if (r < 0 || r > 24) bad(k, 'r out of range');
    if (u < 0 || u > 24) bad(k, 'u out of range');
    if (BigInt(Y) * BigInt(Y) + BigInt(Z) * BigInt(Z) > 4n ** BigInt(r)) bad(k, 'tilt codes of norm above 1');
    if (T < -(2 ** u) || T > 2 ** u) bad(k, 'turn code out of range');
    if (sb < 0 || sb > 40) bad(k, 's out of range');
    const y = Y * pow2(-r), z = Z * pow2(-r), t = T * pow2(-u);
    const w = Math.sqrt(1 - (y * y + z * z));
    const a0 = w, a1 = w * t, a2 = y + z * t, a3 = z - y * t;
    const n = ((a0 * a0 + a1 * a1) + a2 * a2) + a3 * a3;
    const q = 2 / n;
    const R = [
      [1 - q * (a2 * a2 + a3 * a3), q * (a1 * a2 - a0 * a3), q * (a1 * a3 + a0 * a2)],
      [q * (a1 * a2 + a0 * a3), 1 - q * (a1 * a1 + a3 * a3), q * (a2 * a3 - a0 * a1)],
      [q * (a1 * a3 - a0 * a2), q * (a2 * a3 + a0 * a1), 1 - q * (a1 * a1 + a2 * a2)],
    ];
    const beta = [c[11] * pow2(-sb), c[12] * pow2(-sb), c[13] * pow2(-sb)];
    const S = (a, b) => ((lam[0] * R[a][0]) * R[b][0] + (lam[1] * R[a][1]) * R[b][1]) + (lam[2] * R[a][2]) * R[b][2];
    const tau = [0, 1, 2].map((i) => Math.sqrt(lam[i]) * beta[i]);
    const G = (a) => Math.sqrt(v) * ((R[a][0] * tau[0] + R[a][1] * tau[1]) + R[a][2] * tau[2]);
    const s33 = v * (1 + ((beta[0] * beta[0] + beta[1] * beta[1]) + beta[2] * beta[2]));
    // UPPER_PACKED order: 00 01 02 03 11 12 13 22 23 33
    cov.set([S(0, 0), S(0, 1), S(0, 2), G(0), S(1, 1), S(1, 2), G(1), S(2, 2), G(2), s33], 10 * k);
    const mc = cm.subarray(5 * k, 5 * k + 5);
    if (mc[0] < 0 || mc[0] > 40) bad(k, 'e out of range');
    const h = pow2(-mc[0]);
    const yt = [0, 1, 2].map((i) => Math.sqrt(lam[i]) * (mc[1 + i] * h));
    for (let a = 0; a < 3; a++) means[4 * k + a] = (R[a][0] * yt[0] + R[a][1] * yt[1]) + R[a][2] * yt[2];
    means[4 * k + 3] = Math.sqrt(v) * (mc[4] * h);
  }
  return [weights, means, cov];
}
