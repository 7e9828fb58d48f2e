// The novelty test of the map: each point's 3-D marginal log-likelihood under
// the local submap (sogmm/map.hpp).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "map_state.hpp"
#include "parallel.hpp"
#include "sogmm/error.hpp"

namespace sogmm::detail {

Marginal3 marginal3(const Gmm& gmm, std::size_t m) {
  const float* mu = gmm.mean(m);
  const float* c = gmm.covariance(m);
  double s[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s[i][j] = c[4 * i + j];
  // Cholesky of Sigma_xx in double.
  double l[3][3] = {};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j <= i; ++j) {
      double v = s[i][j];
      for (int k = 0; k < j; ++k) v -= l[i][k] * l[j][k];
      if (i == j) {
        require(v > 0 && std::isfinite(v), ErrorCode::Numeric,
                "map: component " + std::to_string(m) + " has a spatial covariance that is not positive definite");
        l[i][i] = std::sqrt(v);
      } else {
        l[i][j] = v / l[j][j];
      }
    }
  }
  Marginal3 r{};
  // Inverse of the lower-triangular factor by forward substitution.
  const double i00 = 1.0 / l[0][0], i11 = 1.0 / l[1][1], i22 = 1.0 / l[2][2];
  const double i10 = -l[1][0] * i00 * i11;
  const double i21 = -l[2][1] * i11 * i22;
  const double i20 = -(l[2][0] * i00 + l[2][1] * i10) * i22;
  r.linv[0] = i00;
  r.linv[1] = i10;
  r.linv[2] = i11;
  r.linv[3] = i20;
  r.linv[4] = i21;
  r.linv[5] = i22;
  for (int i = 0; i < 3; ++i) r.mu[i] = mu[i];
  const double log_2pi = std::log(2.0 * 3.14159265358979323846);
  r.log_norm = -1.5 * log_2pi - std::log(l[0][0]) - std::log(l[1][1]) - std::log(l[2][2]);
  const double w = gmm.weights[m];
  // A zero weight never explains a point: -inf drops it from every sum.
  r.log_count = w > 0 ? std::log(w) + std::log(static_cast<double>(std::max<std::uint64_t>(gmm.support_size, 1)))
                      : -std::numeric_limits<double>::infinity();
  return r;
}

Searches searches_of(const Gmm& gmm, double index_sigmas) {
  Searches s{ComponentIndex(index_sigmas), {}};
  s.marginals.reserve(gmm.size());
  for (std::size_t k = 0; k < gmm.size(); ++k) s.marginals.push_back(marginal3(gmm, k));
  s.index.build(gmm);
  return s;
}

namespace {
// -0.0 and 0.0 are one voxel: == says so, and the hash reads bits.
double canonical(double v) { return v == 0.0 ? 0.0 : v; }
}  // namespace

std::size_t PendingVoxelHash::operator()(const PendingVoxel& k) const {
  std::uint64_t h = 0x9e3779b97f4a7c15ULL;
  for (double d : k.v) {
    std::uint64_t bits = 0;
    const double c = canonical(d);
    std::memcpy(&bits, &c, sizeof bits);
    h ^= bits + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
  }
  return static_cast<std::size_t>(h);
}

PendingVoxel pending_voxel(const double xyz[3]) {
  PendingVoxel p;
  for (int i = 0; i < 3; ++i) p.v[i] = canonical(std::floor(xyz[i] / kPendingVoxel));
  return p;
}

bool near_pending(const PendingVoxelSet& voxels, const PendingVoxel& voxel) {
  if (voxels.empty()) return false;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const PendingVoxel n{{canonical(voxel.v[0] + dx), canonical(voxel.v[1] + dy), canonical(voxel.v[2] + dz)}};
        if (voxels.count(n) > 0) return true;
      }
  return false;
}

void local_log_likelihood(const ComponentIndex& index, const std::vector<Marginal3>& marginals, int threads,
                          const double* xyz, std::size_t n, double* out, std::int64_t* dominant) {
  const double neg_inf = -std::numeric_limits<double>::infinity();
  const int team = team_size(threads);
  std::vector<std::vector<std::uint32_t>> scratch(team);
  std::vector<std::vector<double>> terms(team);
  std::vector<ComponentIndex::Cursor> cursors(team);
  // Each point on its own: the weights are renormalised over the components
  // whose box holds it (its neighbourhood), so nothing outside that
  // neighbourhood changes its score, and the sums run in id order (the same
  // value whatever the team size).
  parallel_for(n, team, 256, [&](std::size_t i, int t) {
    std::vector<std::uint32_t>& ids = scratch[t];
    index.query_point(xyz + 3 * i, ids, cursors[t]);
    std::vector<double>& v = terms[t];
    v.clear();
    double best = neg_inf, best_count = neg_inf;
    std::int64_t arg = -1;
    for (std::uint32_t id : ids) {
      const Marginal3& c = marginals[id];
      const double lp = c.log_count + log_density(c, xyz + 3 * i);
      v.push_back(lp);
      if (lp > best) {  // ties: the lowest id (ids ascend)
        best = lp;
        arg = id;
      }
      best_count = std::max(best_count, c.log_count);
    }
    if (dominant) dominant[i] = arg;
    if (!(best > neg_inf)) {
      out[i] = neg_inf;
      return;
    }
    double sum = 0.0, count = 0.0;
    for (std::size_t k = 0; k < ids.size(); ++k) {
      sum += std::exp(v[k] - best);
      count += std::exp(marginals[ids[k]].log_count - best_count);
    }
    out[i] = best + std::log(sum) - best_count - std::log(count);
  });
}

}  // namespace sogmm::detail
