// score_samples and regress_gray (sogmm/inference.hpp): the model packed once
// per call, then blocks of points through the vectorised kernels
// (query_kernel.hpp), in parallel over blocks. Exact by default; with
// QueryOptions::truncation_nats > 0, each block evaluates only the components
// that a spatial index and a bound cannot rule out.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "finite_rows.hpp"
#include "gmm_eigen.hpp"
#include "parallel.hpp"
#include "query_cull.hpp"
#include "query_kernel.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/component_index.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm {
namespace {

using detail::checked_llt;
using detail::kQueryBlock;
using detail::kQueryStride;
constexpr double kLog2Pi = 1.8378770664093454836;
using Mat4 = Eigen::Matrix4d;
using Mat3 = Eigen::Matrix3d;

using detail::covariance_of;
using detail::mean_of;
double log_weight(double w) { return w > 0 ? std::log(w) : -std::numeric_limits<double>::infinity(); }

// Writes mean, L^-1 (lower, row by row) and log w - log det L - D/2 log 2 pi
// of one D-dimensional Gaussian; returns the position after them.
template <int D>
double* pack_density(const Eigen::Matrix<double, D, 1>& mean, const Eigen::Matrix<double, D, D>& l, double lw,
                     double* out) {
  const Eigen::Matrix<double, D, D> inv_l =
      l.template triangularView<Eigen::Lower>().solve(Eigen::Matrix<double, D, D>::Identity());
  for (int i = 0; i < D; ++i) *out++ = mean[i];
  for (int i = 0; i < D; ++i)
    for (int j = 0; j <= i; ++j) *out++ = inv_l(i, j);
  *out++ = lw - l.diagonal().array().log().sum() - 0.5 * D * kLog2Pi;
  return out;
}

// The prior of the gray regression (issue 14 item 4): one broad Gaussian
// component in xyz that carries the mixture's prior gray (mean sum pi_m mu_g
// and total variance sum pi_m (Sigma_gg + (mu_g - mean)^2)) and no spatial
// gain. Its covariance is kBackgroundScale^2 times the mixture's total
// spatial covariance and its weight kBackgroundWeight times the mixture's, so
// on the surface its share is negligible (~1e-9 of a component at 1 sigma),
// while a point beyond about 6.5 standard deviations of every component is
// explained by it: the answer falls back smoothly to the prior instead of
// following the nearest component's regression line without bound. Both
// constants are dimensionless, so translating or scaling the model moves the
// background with it.
constexpr double kBackgroundWeight = 1e-6;
constexpr double kBackgroundScale = 10.0;

// Packs the background into the 3-D layout (gain 0, the prior's gray and variance).
void pack_background(const Gmm& gmm, double* out) {
  // Weighted moments in double, centred (two passes), so that a model far
  // from the origin or with large gray means loses nothing to cancellation.
  const std::size_t m = gmm.size();
  double w = 0.0;
  Eigen::Vector4d mu = Eigen::Vector4d::Zero();
  for (std::size_t k = 0; k < m; ++k) {
    w += gmm.weights[k];
    mu += gmm.weights[k] * mean_of(gmm, k);
  }
  mu /= w;
  Mat4 c = Mat4::Zero();
  for (std::size_t k = 0; k < m; ++k) {
    const Eigen::Vector4d d = mean_of(gmm, k) - mu;
    c += gmm.weights[k] * (covariance_of(gmm, k) + d * d.transpose());
  }
  c /= w;
  const Mat3 cov = kBackgroundScale * kBackgroundScale * c.topLeftCorner<3, 3>();
  const Mat3 l = checked_llt(cov, "the prior's spatial covariance").matrixL();
  out = pack_density<3>(mu.head<3>(), l, std::log(kBackgroundWeight * w), out);
  *out++ = 0.0;
  *out++ = 0.0;
  *out++ = 0.0;
  *out++ = mu[3];
  *out++ = c(3, 3);
}

// The model in the kernels' layout (query_kernel.hpp): D = 3 with the
// regression's gain, mean gray and conditional variance per component, plus
// the background as entry M when `background`; D = 4 for the joint density.
std::vector<double> pack_model(const Gmm& gmm, int dims, bool background, int threads) {
  validate(gmm);
  const std::size_t m = gmm.size();
  // Component ids (and the background's, m) are uint32 in the kernels.
  checked::to_int<std::uint32_t>(static_cast<double>(m) + 1.0, "number of components");
  std::vector<double> params(checked::mul<std::size_t>(m + (background ? 1 : 0), kQueryStride, "query parameters"),
                             0.0);
  // In parallel: done once per call, yet serial it would cap the speed-up
  // of a query on a large model (Amdahl).
  detail::parallel_for(m, detail::team_size(threads), 64, [&](std::size_t k, int) {
    double* out = &params[k * kQueryStride];
    const Mat4 c = covariance_of(gmm, k);
    const Mat4 l = detail::cholesky_of(c, k);
    const double lw = log_weight(gmm.weights[k]);
    if (dims == 4) {
      pack_density<4>(mean_of(gmm, k), l, lw, out);
      return;
    }
    const Mat3 lxx = l.topLeftCorner<3, 3>();  // the spatial covariance's factor
    out = pack_density<3>(mean_of(gmm, k).head<3>(), lxx, lw, out);
    // Gain A = Sigma_gx Sigma_xx^-1 and conditional variance Sigma_gg - A Sigma_xg.
    const Eigen::Vector3d sxg = c.topRightCorner<3, 1>();
    const Eigen::Vector3d gain =
        lxx.transpose().triangularView<Eigen::Upper>().solve(lxx.triangularView<Eigen::Lower>().solve(sxg));
    for (int i = 0; i < 3; ++i) *out++ = gain[i];
    *out++ = gmm.mean(k)[3];
    *out++ = std::max(0.0, c(3, 3) - gain.dot(sxg));
  });
  if (background) pack_background(gmm, &params[m * kQueryStride]);
  return params;
}

void check_options(const QueryOptions& o) {
  require(std::isfinite(o.truncation_nats) && o.truncation_nats >= 0, ErrorCode::InvalidArgument,
          "query truncation_nats must be finite and >= 0 (0 = exact), got " + checked::exact(o.truncation_nats));
}

// Runs `kernel` over the points in blocks of kQueryBlock, in parallel, and
// hands each block's state to `emit(index of the block's point p, state, p)`.
// Exact: every component (the list `all`) for every block, points in input
// order. Culled: points in the culler's order, components it selects.
template <class State, class Kernel, class Emit>
void run_blocks(const float* points, std::size_t n, int width, const std::vector<double>& params,
                const std::vector<std::uint32_t>& all, const detail::QueryCuller* culler, int threads,
                Kernel kernel, Emit emit) {
  const std::size_t n_blocks = (n + kQueryBlock - 1) / kQueryBlock;
  const int team = detail::team_size(threads);
  std::vector<double> scratch(checked::mul<std::size_t>(static_cast<std::size_t>(team), detail::kQueryScratch,
                                                        "query scratch"));
  std::vector<detail::CullScratch> cull(culler ? static_cast<std::size_t>(team) : 0);
  detail::parallel_for(n_blocks, team, 1, [&](std::size_t b, int thread) {
    alignas(64) double coord[4][kQueryBlock];
    std::size_t index[kQueryBlock];
    const std::size_t first = b * kQueryBlock;
    const int count = static_cast<int>(std::min<std::size_t>(kQueryBlock, n - first));
    for (int p = 0; p < kQueryBlock; ++p) {
      // Entries past the last point repeat it (finite, ignored).
      const std::size_t i = first + static_cast<std::size_t>(std::min(p, count - 1));
      index[p] = culler ? culler->order()[i] : i;
      for (int j = 0; j < width; ++j) coord[j][p] = points[static_cast<std::size_t>(width) * index[p] + j];
    }
    const detail::QueryBlock block{{coord[0], coord[1], coord[2], coord[3]}, count};
    double* s = &scratch[static_cast<std::size_t>(thread) * detail::kQueryScratch];
    State state;
    state.reset();
    if (culler)
      culler->evaluate(block, cull[static_cast<std::size_t>(thread)],
                       [&](const std::uint32_t* list, std::size_t k) { kernel(block, params.data(), list, k, s, state); },
                       state.max);
    else
      kernel(block, params.data(), all.data(), all.size(), s, state);
    for (int p = 0; p < count; ++p) emit(index[p], state, p);
  });
}

std::vector<std::uint32_t> iota(std::size_t m) {
  std::vector<std::uint32_t> v(m);
  for (std::size_t k = 0; k < m; ++k) v[k] = static_cast<std::uint32_t>(k);
  return v;
}

template <class Kernel>
void score_with(const Gmm& gmm, const float* points, std::size_t n, int dims, double* out, const QueryOptions& o,
                Kernel kernel) {
  const std::vector<double> params = pack_model(gmm, dims, false, o.threads);
  const std::size_t m = gmm.size();
  std::unique_ptr<detail::QueryCuller> culler;
  if (o.truncation_nats > 0)
    culler = std::make_unique<detail::QueryCuller>(gmm, params, dims, false, o.truncation_nats, points, n, dims,
                                                   detail::team_size(o.threads));
  run_blocks<detail::ScoreState>(points, n, dims, params, culler ? std::vector<std::uint32_t>{} : iota(m),
                                 culler.get(), o.threads, kernel,
                                 [&](std::size_t i, const detail::ScoreState& st, int p) {
                                   out[i] = st.max[p] + std::log(st.sum[p]);
                                 });
}

}  // namespace

void score_samples(const Gmm& gmm, const float* points, std::size_t n, int dims, double* out,
                   const QueryOptions& options) {
  require(dims == 3 || dims == 4, ErrorCode::InvalidArgument, "dims must be 3 or 4, got " + std::to_string(dims));
  check_options(options);
  if (n == 0) return;
  require(points != nullptr && out != nullptr, ErrorCode::InvalidArgument, "points and output must not be null");
  detail::require_finite_rows(points, n, static_cast<std::size_t>(dims), "points to score");
  const detail::QueryKernels& k = detail::query_kernels();
  score_with(gmm, points, n, dims, out, options, dims == 4 ? k.score4 : k.score3);
}

double mean_log_likelihood(const Gmm& gmm, const float* points, std::size_t n, int dims) {
  require(n > 0, ErrorCode::InvalidData, "no points to score");
  std::vector<double> lp(n);
  score_samples(gmm, points, n, dims, lp.data());
  double s = 0.0;
  for (double v : lp) s += v;
  return s / static_cast<double>(n);
}

void regress_gray(const Gmm& gmm, const float* xyz, std::size_t n, float* mean_out, float* variance_out,
                  const QueryOptions& options) {
  check_options(options);
  if (n == 0) return;
  require(xyz != nullptr && mean_out != nullptr, ErrorCode::InvalidArgument, "points and output must not be null");
  detail::require_finite_rows(xyz, n, 3, "points to regress");
  const std::vector<double> params = pack_model(gmm, 3, true, options.threads);
  const std::size_t m = gmm.size();
  std::unique_ptr<detail::QueryCuller> culler;
  if (options.truncation_nats > 0)
    culler = std::make_unique<detail::QueryCuller>(gmm, params, 3, true, options.truncation_nats, xyz, n, 3,
                                                   detail::team_size(options.threads));
  // The background (entry m) is in every block's list.
  run_blocks<detail::RegressState>(xyz, n, 3, params, culler ? std::vector<std::uint32_t>{} : iota(m + 1),
                                   culler.get(), options.threads, detail::query_kernels().regress,
                                   [&](std::size_t i, const detail::RegressState& st, int p) {
                                     mean_out[i] = static_cast<float>(st.mean[p]);
                                     // Law of total variance: within (v) plus between (m2) components.
                                     if (variance_out) variance_out[i] = static_cast<float>((st.v[p] + st.m2[p]) / st.w[p]);
                                   });
}

}  // namespace sogmm
