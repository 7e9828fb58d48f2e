// The library's one positive-definiteness test and the stored covariance it
// applies to (see sogmm/gmm.hpp).
#include <cmath>

#include "sogmm/gmm.hpp"

namespace sogmm {

// Normative arithmetic (spec/format.md section 9, step 19d): binary64, sums in
// increasing k, no fused multiply-add (this file is compiled with
// -ffp-contract=off), so every reader that follows the spec and this library
// reach the same verdict on the same stored values.
bool stored_cholesky(const double* a, double* l_out) {
  double l[4][4] = {};
  for (int j = 0; j < 4; ++j) {
    double d = a[j * 4 + j];
    for (int k = 0; k < j; ++k) d -= l[j][k] * l[j][k];
    if (!(d > 0.0)) return false;
    l[j][j] = std::sqrt(d);
    for (int i = j + 1; i < 4; ++i) {
      double s = a[i * 4 + j];
      for (int k = 0; k < j; ++k) s -= l[i][k] * l[j][k];
      l[i][j] = s / l[j][j];
    }
  }
  if (l_out) {
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) l_out[i * 4 + j] = l[i][j];
  }
  return true;
}

void stored_symmetric_part(const float* c, double* s) {
  for (int r = 0; r < 4; ++r)
    for (int q = 0; q < 4; ++q)
      s[r * 4 + q] = static_cast<float>((static_cast<double>(c[r * 4 + q]) + c[q * 4 + r]) / 2.0);
}

}  // namespace sogmm
