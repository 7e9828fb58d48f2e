// The novelty test of the map: each point's 3-D marginal log-likelihood under
// the local submap (sogmm/map.hpp).
#include <cmath>
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

void local_log_likelihood(const ComponentIndex& index, const std::vector<Marginal3>& marginals, int threads,
                          const double* xyz, std::size_t n, double* out) {
  const double neg_inf = -std::numeric_limits<double>::infinity();
  const std::size_t m = marginals.size();
  if (m == 0) {
    for (std::size_t i = 0; i < n; ++i) out[i] = neg_inf;
    return;
  }
  const int team = team_size(threads);
  // Per thread: the candidates of one point and which components any point
  // touched (the submap, over which the weights are renormalised).
  std::vector<std::vector<std::uint32_t>> scratch(team);
  std::vector<std::vector<std::uint8_t>> touched(team, std::vector<std::uint8_t>(m, 0));
  std::vector<std::vector<double>> terms(team);
  std::vector<ComponentIndex::Cursor> cursors(team);
  parallel_for(n, team, 256, [&](std::size_t i, int t) {
    std::vector<std::uint32_t>& ids = scratch[t];
    index.query_point(xyz + 3 * i, ids, cursors[t]);
    std::vector<double>& v = terms[t];
    v.clear();
    double best = neg_inf;
    for (std::uint32_t id : ids) {
      touched[t][id] = 1;
      const double lp = marginals[id].log_count + log_density(marginals[id], xyz + 3 * i);
      v.push_back(lp);
      if (lp > best) best = lp;
    }
    if (!(best > neg_inf)) {
      out[i] = neg_inf;
      return;
    }
    double sum = 0.0;
    for (double lp : v) sum += std::exp(lp - best);
    out[i] = best + std::log(sum);
  });
  // log of the submap's total count, log-sum-exp over the touched components
  // in id order (the same sum whatever the team size).
  double best = neg_inf;
  for (std::size_t k = 0; k < m; ++k) {
    bool hit = false;
    for (int t = 0; t < team; ++t) hit = hit || touched[t][k];
    touched[0][k] = hit;
    if (hit && marginals[k].log_count > best) best = marginals[k].log_count;
  }
  if (!(best > neg_inf)) return;  // no point met any component: every out is -inf already
  double sum = 0.0;
  for (std::size_t k = 0; k < m; ++k)
    if (touched[0][k]) sum += std::exp(marginals[k].log_count - best);
  const double log_total = best + std::log(sum);
  for (std::size_t i = 0; i < n; ++i) out[i] -= log_total;
}

}  // namespace sogmm::detail
