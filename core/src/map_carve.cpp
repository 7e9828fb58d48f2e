// The free-space carve of the map (MapOptions::free_space_carve): an RGB-D
// insert reshapes the map components whose tails hang where the frame sees
// past them.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>

#include "map_depth_view.hpp"
#include "map_state.hpp"
#include "parallel.hpp"

namespace sogmm::detail {
namespace {

constexpr int kSamples = 256;
// A component is reshaped only where the frame shows some of it: at least
// this share of its samples on the frame's observed surface.
constexpr double kMinOnSurface = 0.05;

using Samples = std::array<std::array<double, 4>, kSamples>;

// kSamples standard normal 4-vectors (Box-Muller on mt19937_64, whose output
// the standard fixes, so every platform draws the same), whitened: their mean
// is 0 and their covariance I up to rounding. A component none of whose
// samples is dropped keeps its moments, and the carve adds no noise of the
// draw to the moments it changes beyond the dropped samples' share.
const Samples& unit_samples() {
  static const Samples z = [] {
    Samples s{};
    std::mt19937_64 rng(0x5A3C0FFEEULL);
    const double two_pi = 2.0 * 3.14159265358979323846;
    auto uniform = [&] { return (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53; };
    for (auto& row : s)
      for (int d = 0; d < 4; d += 2) {
        const double r = std::sqrt(-2.0 * std::log(uniform())), t = two_pi * uniform();
        row[d] = r * std::cos(t);
        row[d + 1] = r * std::sin(t);
      }
    double mean[4] = {}, cov[16] = {}, l[16];
    for (const auto& row : s)
      for (int d = 0; d < 4; ++d) mean[d] += row[d] / kSamples;
    for (auto& row : s)
      for (int d = 0; d < 4; ++d) row[d] -= mean[d];
    for (const auto& row : s)
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) cov[4 * i + j] += row[i] * row[j] / kSamples;
    stored_cholesky(cov, l);  // 256 draws in 4-D: positive definite
    for (auto& row : s)  // row <- L^-1 row (forward substitution)
      for (int i = 0; i < 4; ++i) {
        double v = row[i];
        for (int k = 0; k < i; ++k) v -= l[4 * i + k] * row[k];
        row[i] = v / l[4 * i + i];
      }
    return s;
  }();
  return z;
}

}  // namespace

namespace {

// Component k of `g` reshaped by one view (MapOptions::free_space_carve):
// true with its new mean and covariance in `mean_out`, `cov_out`.
bool carve_one(const Gmm& g, std::size_t k, const DepthView& view, const Pose& to_camera_pose, double share,
               float mean_out[4], float cov_out[16]) {
  float c[4];
  to_camera(to_camera_pose, g.mean(k), c);
  if (view.classify(c) == Seen::Outside) return false;  // the frame says nothing about its core
  double a[16], l[16];
  for (int i = 0; i < 16; ++i) a[i] = g.covariance(k)[i];
  if (!stored_cholesky(a, l)) return false;
  const Samples& z = unit_samples();
  const std::size_t min_free = static_cast<std::size_t>(std::ceil(share * kSamples));
  const std::size_t min_on = static_cast<std::size_t>(std::ceil(kMinOnSurface * kSamples));
  std::size_t n_free = 0, n_on = 0;
  double kept_sum[4] = {}, kept_sq[16] = {};
  for (int j = 0; j < kSamples; ++j) {
    float x[4], xc[4];
    double dx[4];
    for (int r = 0; r < 4; ++r) {
      double v = 0;
      for (int q = 0; q <= r; ++q) v += l[4 * r + q] * z[j][q];
      dx[r] = v;  // the sample minus the mean
      x[r] = static_cast<float>(g.mean(k)[r] + v);
    }
    to_camera(to_camera_pose, x, xc);
    if (view.surely_free(xc)) {
      ++n_free;
      continue;
    }
    if (view.classify(xc) == Seen::OnSurface) ++n_on;
    for (int r = 0; r < 4; ++r) {
      kept_sum[r] += dx[r];
      for (int q = 0; q < 4; ++q) kept_sq[4 * r + q] += dx[r] * dx[q];
    }
  }
  if (n_free < min_free || n_on < min_on || 2 * n_free > static_cast<std::size_t>(kSamples)) return false;
  // The moments of the kept samples, about the old mean (double), then
  // symmetric and positive definite in float, or the component stays.
  const double n = static_cast<double>(kSamples - n_free);
  double m[4], cov[16], check[16];
  for (int r = 0; r < 4; ++r) m[r] = kept_sum[r] / n;
  for (int r = 0; r < 4; ++r)
    for (int q = 0; q < 4; ++q) cov[4 * r + q] = kept_sq[4 * r + q] / n - m[r] * m[q];
  for (int r = 0; r < 4; ++r)
    for (int q = 0; q < r; ++q) cov[4 * r + q] = cov[4 * q + r] = 0.5 * (cov[4 * r + q] + cov[4 * q + r]);
  for (int r = 0; r < 4; ++r) mean_out[r] = static_cast<float>(g.mean(k)[r] + m[r]);
  for (int i = 0; i < 16; ++i) {
    cov_out[i] = static_cast<float>(cov[i]);
    check[i] = cov_out[i];
  }
  return stored_cholesky(check, l);  // the library's own test: the map stores only what validate() accepts
}

}  // namespace

bool carving(const MapOptions& o) { return o.novelty && o.free_space_carve > 0 && !o.warm_start; }

std::vector<std::size_t> plan_free_space_carve(const Map::State& s, const SeenFrame& frame, Gmm& carved) {
  const MapOptions& o = s.options;
  const Gmm& map = s.model.gmm;
  std::vector<std::size_t> changed;
  if (!carving(o) || map.size() == 0) return changed;
  std::vector<std::uint8_t> carve(map.size(), 0);
  std::vector<float> means(4 * map.size()), covs(16 * map.size());
  parallel_for(map.size(), team_size(o.fit.em.threads), 16, [&](std::size_t k, int) {
    carve[k] = carve_one(map, k, frame.view, frame.to_camera, o.free_space_carve, means.data() + 4 * k,
                         covs.data() + 16 * k);
  });
  carved = map;
  for (std::size_t k = 0; k < map.size(); ++k) {
    if (!carve[k]) continue;
    changed.push_back(k);
    std::copy_n(means.data() + 4 * k, 4, carved.means.data() + 4 * k);
    std::copy_n(covs.data() + 16 * k, 16, carved.covariances.data() + 16 * k);
  }
  return changed;
}

void carve_by_seen_frames(const Map::State& s, Gmm& batch) {
  const MapOptions& o = s.options;
  if (!carving(o) || s.seen_frames.empty()) return;
  // Each component by every frame in insert order (each carve samples the
  // component as the previous one left it); components are independent.
  parallel_for(batch.size(), team_size(o.fit.em.threads), 1, [&](std::size_t k, int) {
    float m[4], c[16];
    for (const SeenFrame& f : s.seen_frames)
      if (carve_one(batch, k, f.view, f.to_camera, o.free_space_carve, m, c)) {
        std::copy_n(m, 4, batch.means.data() + 4 * k);
        std::copy_n(c, 16, batch.covariances.data() + 16 * k);
      }
  });
}

}  // namespace sogmm::detail
