// Step 11b (spec/format.md section 9): the pose is a rigid transform, with
// the arithmetic of the spec (binary64, sums in the order written).
import { fail } from './errors.js';

function badPose(message) {
  fail('invalid_data', 'bad_pose', message);
}

export function checkPose(p) {
  if (!p.every(Number.isFinite)) badPose('a pose entry is not finite');
  if (!(p[12] === 0 && p[13] === 0 && p[14] === 0 && p[15] === 1)) badPose('the last row is not 0 0 0 1');
  const r = (k, l) => p[4 * k + l];
  for (let i = 0; i < 3; i++) {
    for (let j = 0; j < 3; j++) {
      const dot = (r(0, i) * r(0, j) + r(1, i) * r(1, j)) + r(2, i) * r(2, j);
      if (!(Math.abs(dot - (i === j ? 1 : 0)) <= 1e-3)) badPose('the rotation is not orthonormal');
    }
  }
  const det = r(0, 0) * (r(1, 1) * r(2, 2) - r(1, 2) * r(2, 1)) -
              r(0, 1) * (r(1, 0) * r(2, 2) - r(1, 2) * r(2, 0)) +
              r(0, 2) * (r(1, 0) * r(2, 1) - r(1, 1) * r(2, 0));
  if (!(det > 0)) badPose('the rotation is a reflection');
}
