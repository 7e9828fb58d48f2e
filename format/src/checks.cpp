// Value checks: finiteness, weights, symmetry, positive definiteness, pose.
#include "checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "container.hpp"
#include "sogmm/model.hpp"
#include "sogmm/checked.hpp"

namespace sogmm::format::detail {
namespace {

[[noreturn]] void numeric(const char* reason, const std::string& detail) {
  fail(ErrorCode::Numeric, reason, detail);
}

// Index of the first value that is not finite, or n.
std::size_t first_non_finite(const std::vector<float>& v) {
  std::size_t i = 0;
  while (i < v.size() && std::isfinite(v[i])) ++i;
  return i;
}

}  // namespace

void symmetrize(Gmm& g) {
  double s[16];
  for (std::size_t k = 0; k < g.size(); ++k) {
    float* c = g.covariances.data() + 16 * k;
    stored_symmetric_part(c, s);  // section 5.1
    std::copy(s, s + 16, c);
  }
  // The returned model keeps the library's invariant (see check_values).
  const std::string residual = validation_error(g, kWeightSumTolerance);
  if (!residual.empty()) numeric("not_spd", residual);
}

void check_values(const Gmm& g, bool delta) {
  const std::size_t m = g.size();
  // 19a. finite (an F64 value too large for float32 is infinite here)
  std::size_t i = first_non_finite(g.weights);
  if (i < g.weights.size()) {
    numeric("non_finite", "weight of component " + std::to_string(i) + " is not finite in float32");
  }
  if ((i = first_non_finite(g.means)) < g.means.size()) {
    numeric("non_finite", "mean of component " + std::to_string(i / 4) + " is not finite in float32");
  }
  if ((i = first_non_finite(g.covariances)) < g.covariances.size()) {
    numeric("non_finite", "covariance of component " + std::to_string(i / 16) + " is not finite in float32");
  }
  // 19b. weights
  double sum = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    const double w = g.weights[k];
    if (w < 0.0) {
      numeric("bad_weights", "weight of component " + std::to_string(k) + " is negative (" + checked::exact(w) + ")");
    }
    sum += w;
  }
  if (!delta && std::fabs(sum - 1.0) > kWeightSumTolerance) {
    numeric("bad_weights", "weights sum to " + checked::exact(sum) + ", not 1 (tolerance 1e-4)");
  }
  // 19c-d. per component: symmetric (exactly so when stored packed), positive definite
  double a[16];
  for (std::size_t k = 0; k < m; ++k) {
    std::copy(g.covariance(k), g.covariance(k) + 16, a);
    double scale = 0.0, asym = 0.0;
    for (int r = 0; r < 4; ++r) {
      for (int q = 0; q < 4; ++q) {
        scale = std::max(scale, std::fabs(a[r * 4 + q]));
        asym = std::max(asym, std::fabs(a[r * 4 + q] - a[q * 4 + r]));
      }
    }
    if (asym > kSymmetryTolerance * scale) {
      numeric("not_symmetric", "covariance of component " + std::to_string(k) + " is not symmetric");
    }
    stored_symmetric_part(g.covariance(k), a);  // what a reader returns, so what it tests
    if (!stored_cholesky(a)) {
      numeric("not_spd", "covariance of component " + std::to_string(k) + " is not positive definite");
    }
  }
  // sogmm::validate makes these tests with the same Cholesky (stored_cholesky),
  // so this never fires today; it keeps every model a reader returns inside
  // the library's invariant should either list of checks grow.
  if (delta) return;
  const std::string residual = validation_error(g, kWeightSumTolerance);
  if (!residual.empty()) numeric("not_spd", residual);

}

void check_metadata_numbers(const Model& model, ErrorCode code) {
  auto finite = [&](double v, const char* what) {
    if (!std::isfinite(v)) fail(code, "bad_metadata", std::string(what) + " is " + checked::exact(v) + ", not finite");
  };
  if (model.fit.known) {
    const FitInfo& f = model.fit;
    finite(f.bandwidth, "fit.bandwidth");
    finite(f.tol, "fit.tol");
    finite(f.reg_covar, "fit.reg_covar");
    finite(f.log_likelihood, "fit.log_likelihood");
  }
  if (model.camera.known) {
    const CameraInfo& c = model.camera;
    finite(c.camera.fx, "camera.fx");
    finite(c.camera.fy, "camera.fy");
    finite(c.camera.cx, "camera.cx");
    finite(c.camera.cy, "camera.cy");
    finite(c.depth_scale, "camera.depth_scale");
    finite(c.depth_min, "camera.depth_min");
    finite(c.depth_max, "camera.depth_max");
  }
}

void check_pose(const std::array<double, 16>& p) {
  // The library's one pose rule (sogmm/model.hpp), so that every pose that
  // sogmm_model_set_pose accepts can be saved and loaded again.
  const std::string problem = rigid_pose_error(p);
  if (!problem.empty()) fail(ErrorCode::InvalidData, "bad_pose", "pose: " + problem);
}

}  // namespace sogmm::format::detail
