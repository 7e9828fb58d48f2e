// Value checks: finiteness, weights, symmetry, positive definiteness, pose.
#include "checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "container.hpp"
#include "sogmm/model.hpp"

namespace sogmm::format::detail {
namespace {

constexpr int kUpper[10][2] = {{0, 0}, {0, 1}, {0, 2}, {0, 3}, {1, 1}, {1, 2}, {1, 3}, {2, 2}, {2, 3}, {3, 3}};

[[noreturn]] void numeric(const char* reason, const std::string& detail) {
  fail(ErrorCode::Numeric, reason, detail);
}

bool all_finite(const std::vector<double>& v, std::size_t* index) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      *index = i;
      return false;
    }
  }
  return true;
}

// Cholesky-Banachiewicz on the lower triangle, in double, ascending sums;
// true when every pivot is > 0.
bool cholesky_ok(const double* a) {
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
  return true;
}

}  // namespace

void unpack_upper(const double* packed, double* full) {
  for (int t = 0; t < 10; ++t) {
    full[kUpper[t][0] * 4 + kUpper[t][1]] = packed[t];
    full[kUpper[t][1] * 4 + kUpper[t][0]] = packed[t];
  }
}

void check_values(const ArraysView& a) {
  std::size_t i = 0;
  if (!all_finite(*a.weights, &i)) numeric("non_finite", "weight of component " + std::to_string(i) + " is not finite");
  if (!all_finite(*a.means, &i)) numeric("non_finite", "mean of component " + std::to_string(i / 4) + " is not finite");
  const std::size_t c = a.packed ? 10 : 16;
  if (!all_finite(*a.cov, &i)) {
    numeric("non_finite", "covariance of component " + std::to_string(i / c) + " is not finite");
  }
  double sum = 0.0;
  for (std::size_t k = 0; k < a.m; ++k) {
    const double w = (*a.weights)[k];
    if (w < 0.0) numeric("bad_weights", "weight of component " + std::to_string(k) + " is negative");
    sum += w;
  }
  if (std::fabs(sum - 1.0) > kWeightSumTolerance) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", sum);
    numeric("bad_weights", std::string("weights sum to ") + buf + ", not 1 (tolerance 1e-4)");
  }
  double full[16];
  for (std::size_t k = 0; k < a.m; ++k) {
    const double* src = a.cov->data() + k * c;
    if (a.packed) {
      unpack_upper(src, full);
    } else {
      std::copy(src, src + 16, full);
      double scale = 0.0, asym = 0.0;
      for (int r = 0; r < 4; ++r) {
        for (int q = 0; q < 4; ++q) {
          scale = std::max(scale, std::fabs(full[r * 4 + q]));
          asym = std::max(asym, std::fabs(full[r * 4 + q] - full[q * 4 + r]));
        }
      }
      if (asym > kSymmetryTolerance * scale) {
        numeric("not_symmetric", "covariance of component " + std::to_string(k) + " is not symmetric");
      }
    }
    if (!cholesky_ok(full)) {
      numeric("not_spd", "covariance of component " + std::to_string(k) + " is not positive definite");
    }
  }
}

void check_pose(const std::array<double, 16>& p) {
  // The library's one pose rule (sogmm/model.hpp), so that every pose that
  // sogmm_model_set_pose accepts can be saved and loaded again.
  const std::string problem = rigid_pose_error(p);
  if (!problem.empty()) fail(ErrorCode::InvalidData, "bad_pose", "pose: " + problem);
}

}  // namespace sogmm::format::detail
