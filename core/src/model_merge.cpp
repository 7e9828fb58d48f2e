// Merging models with their metadata: spec/format.md sections 2.1 and 2.2.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>

#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/model.hpp"

namespace sogmm {
namespace {

// How many fits a model holds: its merged_fits, or 1. A value that is not a
// count >= 2 (written by something else) counts as one fit.
std::uint64_t fit_count(const Model& m) {
  const std::string* v = find_value(m, kMergedFitsKey);
  if (v == nullptr || v->empty() || v->size() > 19 || !std::all_of(v->begin(), v->end(), [](char c) { return c >= '0' && c <= '9'; })) return 1;
  return std::max<std::uint64_t>(1, std::stoull(*v));
}

bool same_fit_settings(const FitInfo& a, const FitInfo& b) {
  return a.bandwidth == b.bandwidth && a.n_components_requested == b.n_components_requested && a.tol == b.tol &&
         a.reg_covar == b.reg_covar && a.max_iter == b.max_iter && a.seed == b.seed;
}

bool same_camera(const CameraInfo& a, const CameraInfo& b) {
  return a.known && b.known && a.camera.width == b.camera.width && a.camera.height == b.camera.height &&
         a.camera.fx == b.camera.fx && a.camera.fy == b.camera.fy && a.camera.cx == b.camera.cx &&
         a.camera.cy == b.camera.cy && a.decimation == b.decimation && a.depth_scale == b.depth_scale &&
         a.depth_min == b.depth_min && a.depth_max == b.depth_max;
}

}  // namespace

std::string coordinate_frame(const Model& m) {
  const std::string* v = find_value(m, kCoordinateFrameKey);
  return v == nullptr ? std::string("camera") : *v;
}

Model merge(const Model& a, const Model& b) {
  const std::string frame = coordinate_frame(a);
  if (frame != coordinate_frame(b)) {
    throw Error(ErrorCode::InvalidArgument, "merge: model a is in the " + frame + " frame and model b in the " +
                                                coordinate_frame(b) + " frame; move one first");
  }
  Model out;
  out.gmm = merge(a.gmm, b.gmm);
  if (a.fit.known && b.fit.known && same_fit_settings(a.fit, b.fit)) {
    out.fit = a.fit;
    // A file may hold any int32 here; a count of iterations is never negative,
    // so each side counts from 0 and the sum saturates (spec/format.md 2.2).
    const std::int64_t n_iter = std::int64_t{std::max(a.fit.n_iter, 0)} + std::max(b.fit.n_iter, 0);
    out.fit.n_iter = static_cast<std::int32_t>(std::min<std::int64_t>(n_iter, std::numeric_limits<std::int32_t>::max()));
    out.fit.converged = a.fit.converged && b.fit.converged;
    // Weighted as merge() weighs the components (support 0 on both: equally).
    const double sa = static_cast<double>(a.gmm.support_size), sb = static_cast<double>(b.gmm.support_size);
    const double fa = sa + sb > 0 ? sa / (sa + sb) : 0.5;
    out.fit.log_likelihood = fa * a.fit.log_likelihood + (1.0 - fa) * b.fit.log_likelihood;
  }
  if (same_camera(a.camera, b.camera)) out.camera = a.camera;
  if (frame != "camera") out.key_values.emplace_back(kCoordinateFrameKey, frame);
  // Counts read from files may be as large as 19 digits: the sum is checked.
  out.key_values.emplace_back(kMergedFitsKey,
                              std::to_string(checked::add(fit_count(a), fit_count(b), "merge: merged_fits")));
  return out;
}

}  // namespace sogmm
