// Sampling, merging and rigid transforms of a model (score_samples and
// regress_gray are in query.cpp).
#include "sogmm/inference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Core>
#include <Eigen/LU>

#include "covariance_storage.hpp"
#include "gmm_eigen.hpp"
#include "progress.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/random.hpp"
#include "sogmm/model.hpp"

namespace sogmm {
namespace {

using Mat4 = Eigen::Matrix4d;
using Mat3 = Eigen::Matrix3d;

using detail::covariance_of;
using detail::mean_of;

// Draws between progress reports.
constexpr std::size_t kPointsPerChunk = 64;

}  // namespace

void sample(const Gmm& gmm, std::size_t n, std::uint64_t seed, int dims, float* out, double truncation) {
  require(dims == 3 || dims == 4, ErrorCode::InvalidArgument, "dims must be 3 or 4, got " + std::to_string(dims));
  require(truncation > 0, ErrorCode::InvalidArgument, "truncation must be > 0");
  validate(gmm);
  if (n == 0) return;
  require(out != nullptr, ErrorCode::InvalidArgument, "output must not be null");
  const std::size_t m = gmm.size();
  Rng rng(seed);
  // Multinomial counts: each draw picks a component by its cumulative weight.
  std::vector<double> cumulative(m);
  double running = 0.0;
  for (std::size_t k = 0; k < m; ++k) cumulative[k] = (running += gmm.weights[k]);
  std::vector<std::size_t> counts(m, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const double u = rng.uniform() * running;
    const std::size_t k = std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin();
    ++counts[std::min(k, m - 1)];
  }
  const TruncatedNormal truncated(truncation);
  detail::progress_begin(Stage::Sampling, n);
  std::size_t row = 0;
  for (std::size_t k = 0; k < m; ++k) {
    if (counts[k] == 0) continue;
    const Mat4 l = detail::cholesky_of(gmm, k);
    const Eigen::Vector4d mu = mean_of(gmm, k);
    for (std::size_t j = 0; j < counts[k]; ++j, ++row) {
      if (row % kPointsPerChunk == 0) detail::progress_at(row);
      Eigen::Vector4d z;
      for (int i = 0; i < 4; ++i) z[i] = std::isinf(truncation) ? rng.normal() : truncated(rng);
      const Eigen::Vector4d x = mu + l * z;
      for (int i = 0; i < dims; ++i) out[dims * row + i] = static_cast<float>(x[i]);
    }
  }
}

Gmm merge(const Gmm& a, const Gmm& b) {
  validate(a);
  validate(b);
  Gmm out;
  out.support_size = checked::add<std::uint64_t>(a.support_size, b.support_size, "merged support size");
  // Support 0 means unknown. Weighing a known count against an unknown one
  // would be a guess (the old rule gave the unknown model weight 0 and so
  // dropped it silently); two unknowns count equally.
  const bool a_known = a.support_size > 0, b_known = b.support_size > 0;
  require(a_known == b_known, ErrorCode::InvalidArgument,
          std::string("merge: model ") + (a_known ? "b" : "a") + " has support size 0 (unknown) and model " +
              (a_known ? "a" : "b") + " has " + std::to_string(a_known ? a.support_size : b.support_size) +
              ": the weights cannot be combined; give both models their number of points (or neither)");
  const double sa = static_cast<double>(a.support_size), sb = static_cast<double>(b.support_size);
  const double fa = a_known ? sa / (sa + sb) : 0.5;
  const double fb = a_known ? sb / (sa + sb) : 0.5;
  out.weights.reserve(a.size() + b.size());
  for (float w : a.weights) out.weights.push_back(static_cast<float>(w * fa));
  for (float w : b.weights) out.weights.push_back(static_cast<float>(w * fb));
  out.means = a.means;
  out.means.insert(out.means.end(), b.means.begin(), b.means.end());
  out.covariances = a.covariances;
  out.covariances.insert(out.covariances.end(), b.covariances.begin(), b.covariances.end());
  return out;
}

Gmm transform(const Gmm& gmm, const std::array<double, 16>& pose) {
  validate(gmm);
  const std::string pose_problem = rigid_pose_error(pose);
  require(pose_problem.empty(), ErrorCode::InvalidArgument, "pose: " + pose_problem);
  // The identity keeps every bit: the arithmetic below would turn a -0
  // coordinate into +0, and a map that merges or loads at the identity must
  // hold exactly the components it was given.
  static constexpr std::array<double, 16> kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  if (pose == kIdentity) return gmm;
  const Eigen::Matrix4d t = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(pose.data());
  const Mat3 r = t.topLeftCorner<3, 3>();
  // Acting on (x, y, z, g) with the block-diagonal [R 0; 0 1].
  Mat4 a = Mat4::Identity();
  a.topLeftCorner<3, 3>() = r;
  Eigen::Vector4d shift = Eigen::Vector4d::Zero();
  shift.head<3>() = t.topRightCorner<3, 1>();
  Gmm out = gmm;
  for (std::size_t k = 0; k < gmm.size(); ++k) {
    const Eigen::Vector4d mu = a * mean_of(gmm, k) + shift;
    const Mat4 moved = a * covariance_of(gmm, k) * a.transpose();
    // Its symmetric part, bit-symmetric once in float32, into a new matrix:
    // `moved = 0.5 * (moved + moved.transpose())` would be evaluated in place
    // (Eigen's aliasing), reading entries it already overwrote, and left the
    // map's covariances asymmetric by ~1e-23, so that a saved map was stored
    // in the FULL layout and its reload differed (fuzz_map, issue 36).
    const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> c = 0.5 * (moved + moved.transpose());
    for (int i = 0; i < 4; ++i) out.means[4 * k + i] = static_cast<float>(mu[i]);
    // A finite pose can still move a mean out of float32 range (a translation
    // of 1e39): an error here rather than a model that no later call accepts.
    // (Messages are built only on failure: a map has tens of thousands of components.)
    for (int i = 0; i < 4; ++i) {
      if (!std::isfinite(out.means[4 * k + i]))
        throw Error(ErrorCode::InvalidArgument, "pose moves the mean of component " + std::to_string(k) +
                                                    " to coordinate " + std::to_string(i) + " = " +
                                                    checked::exact(mu[i]) + ", beyond the float32 range");
    }
    for (int i = 0; i < 16; ++i) {
      if (!(std::fabs(c(i / 4, i % 4)) <= static_cast<double>(std::numeric_limits<float>::max())))
        throw Error(ErrorCode::InvalidArgument, "pose makes the covariance of component " + std::to_string(k) +
                                                    " beyond the float32 range (entry " + std::to_string(i) + " = " +
                                                    checked::exact(c(i / 4, i % 4)) + ")");
    }
    // Stored as the EM stores its covariances: the nearest float32 rounding
    // when it is positive definite and within 1e-9 nats (every component of
    // an ordinary scene: the bits of plain rounding), otherwise the float32
    // matrix nearest in divergence that is. A thin component turned by a
    // pose can round to an indefinite matrix (its small eigenvalue is below
    // the rounding of its large entries), and such a model could not be
    // saved, scored or sampled (fuzz_api found one: a fit, a transform, a save).
    try {
      detail::store_covariance(c.data(), &out.covariances[16 * k]);
    } catch (const Error& e) {
      throw Error(ErrorCode::Numeric, "pose: the moved covariance of component " + std::to_string(k) +
                                          " cannot be stored in float32 (" + e.what() + ")");
    }
  }
  return out;
}

std::size_t paper_model_bytes(const Gmm& gmm) { return 4 * gmm.size() * (1 + 10 + 4); }

}  // namespace sogmm
