#include "ndt_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "sogmm/error.hpp"

namespace sogmm::bench {

namespace {
constexpr std::int64_t kIndexBias = std::int64_t{1} << 20;  // 21 bits per axis
constexpr double kEigenFloorRatio = 1.0 / 100.0;
constexpr double kTruncation = 2.5;

double truncated_normal(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  for (;;) {
    const double z = normal(rng);
    if (std::fabs(z) < kTruncation) return z;
  }
}
}  // namespace

std::vector<std::size_t> proportional_allocation(const std::vector<std::size_t>& counts, std::size_t n) {
  std::vector<std::size_t> out(counts.size(), 0);
  const long double total = std::accumulate(counts.begin(), counts.end(), static_cast<long double>(0));
  if (counts.empty() || total <= 0) return out;
  std::vector<std::pair<long double, std::size_t>> remainders;
  remainders.reserve(counts.size());
  std::size_t given = 0;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const long double exact = static_cast<long double>(n) * counts[i] / total;
    out[i] = static_cast<std::size_t>(std::floor(exact));
    given += out[i];
    remainders.emplace_back(exact - out[i], i);
  }
  std::stable_sort(remainders.begin(), remainders.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t k = 0; given < n; ++k, ++given) ++out[remainders[k % remainders.size()].second];
  return out;
}

NdtMap::NdtMap(double voxel) : voxel_(voxel) {
  require(std::isfinite(voxel) && voxel > 0, ErrorCode::InvalidArgument, "NDT voxel size must be > 0");
}

std::int64_t NdtMap::key_of(std::int64_t ix, std::int64_t iy, std::int64_t iz) const {
  return ((ix + kIndexBias) << 42) | ((iy + kIndexBias) << 21) | (iz + kIndexBias);
}

void NdtMap::build(const PointsView& points) {
  require_finite_points(points, "NDT input cloud");
  for (std::size_t i = 0; i < points.size; ++i) {
    const float* p = points[i];
    std::int64_t idx[3];
    for (int a = 0; a < 3; ++a) {
      const double f = std::floor(p[a] / voxel_);
      require(std::fabs(f) < kIndexBias - 1, ErrorCode::InvalidData, "NDT: point outside the voxel index range");
      idx[a] = static_cast<std::int64_t>(f);
    }
    const std::int64_t key = key_of(idx[0], idx[1], idx[2]);
    auto it = index_.find(key);
    std::size_t c;
    if (it == index_.end()) {
      c = cells_.size();
      index_.emplace(key, c);
      NdtCell cell;
      cell.ix = idx[0];
      cell.iy = idx[1];
      cell.iz = idx[2];
      cells_.push_back(cell);
      sums_.emplace_back();
    } else {
      c = it->second;
    }
    // Accumulate relative to the voxel corner: small numbers, no cancellation.
    const double d[3] = {p[0] - idx[0] * voxel_, p[1] - idx[1] * voxel_, p[2] - idx[2] * voxel_};
    Sums& s = sums_[c];
    for (int a = 0; a < 3; ++a) s.s[a] += d[a];
    s.ss[0] += d[0] * d[0];
    s.ss[1] += d[0] * d[1];
    s.ss[2] += d[0] * d[2];
    s.ss[3] += d[1] * d[1];
    s.ss[4] += d[1] * d[2];
    s.ss[5] += d[2] * d[2];
    s.g += p[3];
    ++cells_[c].count;
  }
  for (std::size_t c = 0; c < cells_.size(); ++c) {
    NdtCell& cell = cells_[c];
    const Sums& s = sums_[c];
    const double n = static_cast<double>(cell.count);
    const double m[3] = {s.s[0] / n, s.s[1] / n, s.s[2] / n};
    cell.mean[0] = cell.ix * voxel_ + m[0];
    cell.mean[1] = cell.iy * voxel_ + m[1];
    cell.mean[2] = cell.iz * voxel_ + m[2];
    cell.cov[0] = s.ss[0] / n - m[0] * m[0];
    cell.cov[1] = s.ss[1] / n - m[0] * m[1];
    cell.cov[2] = s.ss[2] / n - m[0] * m[2];
    cell.cov[3] = s.ss[3] / n - m[1] * m[1];
    cell.cov[4] = s.ss[4] / n - m[1] * m[2];
    cell.cov[5] = s.ss[5] / n - m[2] * m[2];
    cell.gray = s.g / n;
    Eigen::Matrix3d cov;
    cov << cell.cov[0], cell.cov[1], cell.cov[2], cell.cov[1], cell.cov[3], cell.cov[4], cell.cov[2], cell.cov[4],
        cell.cov[5];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    Eigen::Vector3d ev = eig.eigenvalues().cwiseMax(0.0);
    const double floor = ev.maxCoeff() * kEigenFloorRatio;
    ev = ev.cwiseMax(floor);
    const Eigen::Matrix3d a = eig.eigenvectors() * ev.cwiseSqrt().asDiagonal();
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) cell.factor[3 * r + k] = a(r, k);
  }
}

float NdtMap::gray_at(const float* xyz, std::size_t* used_fallback) const {
  require(!cells_.empty(), ErrorCode::InvalidData, "NDT map is empty");
  std::int64_t idx[3];
  bool in_range = true;
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor(xyz[a] / voxel_);
    in_range = in_range && std::isfinite(f) && std::fabs(f) < kIndexBias - 1;
    idx[a] = in_range ? static_cast<std::int64_t>(f) : 0;
  }
  if (in_range) {
    auto it = index_.find(key_of(idx[0], idx[1], idx[2]));
    if (it != index_.end()) return static_cast<float>(cells_[it->second].gray);
  }
  if (used_fallback) ++*used_fallback;
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_c = 0;
  for (std::size_t c = 0; c < cells_.size(); ++c) {
    const NdtCell& cell = cells_[c];
    const double dx = (cell.ix + 0.5) * voxel_ - xyz[0];
    const double dy = (cell.iy + 0.5) * voxel_ - xyz[1];
    const double dz = (cell.iz + 0.5) * voxel_ - xyz[2];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 < best) {
      best = d2;
      best_c = c;
    }
  }
  return static_cast<float>(cells_[best_c].gray);
}

std::vector<float> NdtMap::sample(std::size_t n, std::uint64_t seed) const {
  std::vector<std::size_t> counts(cells_.size());
  for (std::size_t c = 0; c < cells_.size(); ++c) counts[c] = cells_[c].count;
  const std::vector<std::size_t> share = proportional_allocation(counts, n);
  std::vector<float> out;
  out.reserve(3 * n);
  std::mt19937_64 rng(seed);
  for (std::size_t c = 0; c < cells_.size(); ++c) {
    const NdtCell& cell = cells_[c];
    for (std::size_t k = 0; k < share[c]; ++k) {
      const double z[3] = {truncated_normal(rng), truncated_normal(rng), truncated_normal(rng)};
      for (int r = 0; r < 3; ++r) {
        const double v = cell.mean[r] + cell.factor[3 * r] * z[0] + cell.factor[3 * r + 1] * z[1] +
                         cell.factor[3 * r + 2] * z[2];
        out.push_back(static_cast<float>(v));
      }
    }
  }
  return out;
}

}  // namespace sogmm::bench
