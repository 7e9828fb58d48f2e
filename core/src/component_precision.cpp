// Rounding a map's components to their own precision; component_precision.hpp
// says how and why.
#include "component_precision.hpp"

#include <algorithm>
#include <cmath>

namespace sogmm::detail {
namespace {

// The exponent of the largest power of two <= x (x > 0, finite).
int floor_log2(double x) {
  int e = 0;
  std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1)
  return e - 1;
}

// v rounded to nearest (ties to even) on the grid 2^g: exact in float32, as
// the result has no more significant bits than v.
float to_grid(float v, int g) {
  return static_cast<float>(std::ldexp(std::nearbyint(std::ldexp(static_cast<double>(v), -g)), g));
}

// trace(S^-1) = ||L^-1||_F^2 from the factor L (row-major, lower): column j
// of L^-1 by forward substitution, sums in increasing k.
double trace_of_inverse(const double* l) {
  double t = 0;
  for (int j = 0; j < 4; ++j) {
    double x[4] = {0, 0, 0, 0};
    for (int i = j; i < 4; ++i) {
      double s = i == j ? 1.0 : 0.0;
      for (int k = j; k < i; ++k) s -= l[4 * i + k] * x[k];
      x[i] = s / l[4 * i + i];
      t += x[i] * x[i];
    }
  }
  return t;
}

}  // namespace

Gmm round_to_precision(const Gmm& gmm, double precision) {
  if (precision <= 0) return gmm;
  Gmm out = gmm;
  for (std::size_t k = 0; k < out.size(); ++k) {
    double s[16], l[16];
    stored_symmetric_part(gmm.covariance(k), s);
    if (!stored_cholesky(s, l)) continue;  // validate() refuses it elsewhere
    const double t = trace_of_inverse(l);
    if (!std::isfinite(t) || t <= 0) continue;
    const int gm = floor_log2(precision / std::sqrt(t));
    const int gc = floor_log2(precision / (2 * t));
    float cov[16];
    for (int i = 0; i < 16; ++i) cov[i] = to_grid(gmm.covariance(k)[i], gc);
    double rounded[16];
    stored_symmetric_part(cov, rounded);
    if (!stored_cholesky(rounded)) continue;
    std::copy_n(cov, 16, out.covariances.data() + 16 * k);
    for (int i = 0; i < 4; ++i) out.means[4 * k + i] = to_grid(gmm.mean(k)[i], gm);
  }
  return out;
}

Pose recorded_pose(const Pose& pose, double precision) {
  if (!(precision > 0)) return pose;
  Pose out = pose;
  for (int i = 0; i < 12; ++i) out[i] = std::ldexp(std::nearbyint(std::ldexp(pose[i], -kPoseGridLog2)), kPoseGridLog2);
  return out;
}

}  // namespace sogmm::detail
