// Fusion of new map components into close existing ones (sogmm/map.hpp):
// distance of two 4-D Gaussians and their moment-matched merge.
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

#include "covariance_storage.hpp"
#include "map_state.hpp"

namespace sogmm::detail {
namespace {

using Vec4 = Eigen::Vector4d;
using Mat4 = Eigen::Matrix4d;

struct Gauss {
  Vec4 mu;
  Mat4 cov;
};

Gauss component(const Gmm& gmm, std::size_t m) {
  Gauss g;
  for (int i = 0; i < 4; ++i) g.mu[i] = gmm.mean(m)[i];
  for (int i = 0; i < 16; ++i) g.cov(i / 4, i % 4) = gmm.covariance(m)[i];
  g.cov = 0.5 * (g.cov + g.cov.transpose()).eval();
  return g;
}

// log det of an SPD matrix via Cholesky; NaN when not SPD.
double log_det(const Mat4& a, Eigen::LLT<Mat4>* keep = nullptr) {
  Eigen::LLT<Mat4> llt(a);
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::quiet_NaN();
  const double r = 2.0 * llt.matrixLLT().diagonal().array().log().sum();
  if (keep) *keep = llt;
  return r;
}

// Hellinger distance sqrt(1 - BC), BC = det(S1)^1/4 det(S2)^1/4 / det(S)^1/2
// exp(-d^T S^-1 d / 8), S = (S1 + S2) / 2.
double hellinger(const Gauss& a, const Gauss& b) {
  const Mat4 s = 0.5 * (a.cov + b.cov);
  Eigen::LLT<Mat4> llt;
  const double ld = log_det(s, &llt);
  const double la = log_det(a.cov), lb = log_det(b.cov);
  if (!std::isfinite(ld + la + lb)) return 1.0;
  const Vec4 d = a.mu - b.mu;
  const double maha = d.dot(llt.solve(d));
  const double log_bc = 0.25 * (la + lb) - 0.5 * ld - maha / 8.0;
  return std::sqrt(std::max(0.0, 1.0 - std::exp(std::min(0.0, log_bc))));
}

// KL(a || b) = (tr(Sb^-1 Sa) + d^T Sb^-1 d - 4 + ln det Sb - ln det Sa) / 2.
double kl(const Gauss& a, const Gauss& b) {
  Eigen::LLT<Mat4> lb;
  const double ldb = log_det(b.cov, &lb);
  const double lda = log_det(a.cov);
  if (!std::isfinite(lda + ldb)) return std::numeric_limits<double>::infinity();
  const Vec4 d = a.mu - b.mu;
  return 0.5 * (lb.solve(a.cov).trace() + d.dot(lb.solve(d)) - 4.0 + ldb - lda);
}

double distance(const Gauss& a, const Gauss& b, FusionMethod method) {
  return method == FusionMethod::Hellinger ? hellinger(a, b) : 0.5 * (kl(a, b) + kl(b, a));
}

}  // namespace

std::vector<std::size_t> fuse_new_components(Gmm& gmm, std::size_t first, const ComponentIndex& index,
                                             const MapOptions& options) {
  std::vector<std::size_t> changed;
  std::vector<std::uint8_t> removed(gmm.size(), 0);
  std::vector<std::uint32_t> candidates;
  for (std::size_t j = first; j < gmm.size(); ++j) {
    index.query_box(component_box(gmm, j, index.sigmas()), candidates);
    const Gauss gj = component(gmm, j);
    double best = options.fusion_threshold;
    std::size_t target = gmm.size();
    for (std::uint32_t i : candidates) {
      const double dist = distance(gj, component(gmm, i), options.fusion_method);
      if (dist < best) {
        best = dist;
        target = i;
      }
    }
    if (target == gmm.size()) continue;
    // Moment matching: mass, mean and covariance of the pair.
    const Gauss gi = component(gmm, target);
    const double wi = gmm.weights[target], wj = gmm.weights[j], w = wi + wj;
    const double fi = w > 0 ? wi / w : 0.5, fj = 1.0 - fi;
    const Vec4 mu = fi * gi.mu + fj * gj.mu;
    const Vec4 di = gi.mu - mu, dj = gj.mu - mu;
    Mat4 cov = fi * (gi.cov + di * di.transpose()) + fj * (gj.cov + dj * dj.transpose());
    cov = 0.5 * (cov + cov.transpose()).eval();
    gmm.weights[target] = static_cast<float>(w);
    float* mt = gmm.means.data() + 4 * target;
    float* ct = gmm.covariances.data() + 16 * target;
    for (int r = 0; r < 4; ++r) mt[r] = static_cast<float>(mu[r]);
    // Rounded to float32 as the fit rounds its covariances, so that the
    // fused model stays positive definite by the writer's test.
    const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> row = cov;
    store_covariance(row.data(), ct);
    removed[j] = 1;
    changed.push_back(target);
  }
  // Compact: drop the fused new components, keep the order of the rest.
  std::size_t out = first;
  for (std::size_t j = first; j < gmm.size(); ++j) {
    if (removed[j]) continue;
    if (out != j) {
      gmm.weights[out] = gmm.weights[j];
      std::copy_n(gmm.means.data() + 4 * j, 4, gmm.means.data() + 4 * out);
      std::copy_n(gmm.covariances.data() + 16 * j, 16, gmm.covariances.data() + 16 * out);
    }
    ++out;
  }
  gmm.resize(out);
  std::sort(changed.begin(), changed.end());
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  return changed;
}

}  // namespace sogmm::detail
