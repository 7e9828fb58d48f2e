// One exact E-step of a given model with the EM's block kernels.
#include "point_scores.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gmm_eigen.hpp"
#include <Eigen/Core>

#include "em_kernel.hpp"
#include "fast_exp.hpp"
#include "parallel.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"

namespace sogmm::detail {
namespace {

constexpr double kLog2Pi = 1.8378770664093454836;
constexpr std::size_t kChunks = 16;  // fixed: the reduction order never depends on threads

// Component k in the kernels' packed layout (em_kernel.hpp), mean relative to `origin`.
void pack(const Gmm& gmm, std::size_t k, const double* origin, float* out) {
  const Eigen::Matrix4d l = cholesky_of(gmm, k);
  const Eigen::Matrix4d u = l.triangularView<Eigen::Lower>().solve(Eigen::Matrix4d::Identity()).transpose();
  for (int i = 0; i < 4; ++i) out[i] = static_cast<float>(static_cast<double>(gmm.mean(k)[i]) - origin[i]);
  int t = 4;
  for (int i = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j) out[t++] = static_cast<float>(u(i, j));
  const double w = gmm.weights[k];
  // A zero weight is a component that cannot explain anything: far below any other.
  const double lw = w > 0 ? std::log(w) : -1e30;
  out[14] = static_cast<float>(lw + u.diagonal().array().log().sum() - 2.0 * kLog2Pi);
  out[15] = 0.f;
}

}  // namespace

PointScores score_points(const PointsView& points, const Gmm& gmm, int threads, const std::vector<char>* counted) {
  const std::size_t n = points.size, m = gmm.size();
  double origin[4];
  for (int j = 0; j < 4; ++j) {
    float lo = points[0][j], hi = lo;
    for (std::size_t i = 1; i < n; ++i) {
      lo = std::min(lo, points[i][j]);
      hi = std::max(hi, points[i][j]);
    }
    origin[j] = 0.5 * (static_cast<double>(lo) + static_cast<double>(hi));
  }
  std::vector<float> params(checked::mul<std::size_t>(m, kParamStride, "score parameters"));
  for (std::size_t k = 0; k < m; ++k) pack(gmm, k, origin, &params[k * kParamStride]);
  std::vector<std::uint32_t> all(m);
  for (std::size_t k = 0; k < m; ++k) all[k] = static_cast<std::uint32_t>(k);

  PointScores out;
  out.log_likelihood.assign(n, 0.0);
  const std::size_t n_blocks = (n + kBlock - 1) / kBlock;
  const std::size_t per_chunk = (n_blocks + kChunks - 1) / kChunks;
  const std::size_t n_chunks = (n_blocks + per_chunk - 1) / per_chunk;
  std::vector<double> chunk_mass(checked::mul<std::size_t>(n_chunks, m, "score masses"), 0.0);
  const std::size_t scratch_floats = checked::mul<std::size_t>(kBlock + 1, m, "score scratch");
  const int team = team_size(threads);
  std::vector<float> scratch_all(checked::mul<std::size_t>(static_cast<std::size_t>(team), scratch_floats, "score scratch"));
  const EmKernels& kernels = em_kernels();
  parallel_for(n_chunks, team, 1, [&](std::size_t c, int thread) {
    float* rows = &scratch_all[static_cast<std::size_t>(thread) * scratch_floats];
    float* row_max = rows + m * kBlock;
    double* mass = &chunk_mass[c * m];
    alignas(64) float coord[4][kBlock];
    alignas(64) float max_lp[kBlock];
    alignas(64) float inv_sum[kBlock];
    for (std::size_t b = c * per_chunk; b < std::min(n_blocks, (c + 1) * per_chunk); ++b) {
      const std::size_t first = b * kBlock;
      const int count = static_cast<int>(std::min<std::size_t>(kBlock, n - first));
      for (int p = 0; p < count; ++p)
        for (int j = 0; j < 4; ++j)
          coord[j][p] = static_cast<float>(static_cast<double>(points[first + p][j]) - origin[j]);
      const Block block{{coord[0], coord[1], coord[2], coord[3]}, count};
      std::fill(max_lp, max_lp + kBlock, -std::numeric_limits<float>::infinity());
      kernels.log_density(block, params.data(), nullptr, all.data(), m, rows, row_max, max_lp);
      float lowest = max_lp[0];
      for (int p = 1; p < count; ++p) lowest = std::min(lowest, max_lp[p]);
      std::fill(inv_sum, inv_sum + kBlock, 0.0f);
      // exp(lp - max) in place and its sum per point; rows below every
      // point's maximum by more than 87 nats are exactly 0 (as em_finish).
      for (std::size_t k = 0; k < m; ++k) {
        if (row_max[k] - lowest < -87.5f) continue;
        float* e = rows + k * kBlock;
        for (int p = 0; p < count; ++p) {
          e[p] = fast_exp(e[p] - max_lp[p]);
          inv_sum[p] += e[p];
        }
      }
      for (int p = 0; p < count; ++p) {
        out.log_likelihood[first + p] = static_cast<double>(max_lp[p]) + std::log(static_cast<double>(inv_sum[p]));
        inv_sum[p] = counted && !(*counted)[first + p] ? 0.0f : 1.0f / inv_sum[p];
      }
      for (std::size_t k = 0; k < m; ++k) {
        if (row_max[k] - lowest < -87.5f) continue;
        const float* e = rows + k * kBlock;
        float s = 0.0f;
        for (int p = 0; p < count; ++p) s += e[p] * inv_sum[p];
        mass[k] += s;
      }
    }
  });
  out.mass.assign(m, 0.0);
  for (std::size_t c = 0; c < n_chunks; ++c)
    for (std::size_t k = 0; k < m; ++k) out.mass[k] += chunk_mass[c * m + k];
  return out;
}

}  // namespace sogmm::detail
