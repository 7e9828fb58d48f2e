// Occupancy as main answered it at a67de64 (issue 31's block path with Phi
// from std::erfc, cut at 9 sigma, and every asked frame projected point by
// point), so that sogmm-occupancy-octomap --compare-main times it and this
// build in one run and reports how far this build's answers are from it.
// Renders come from the map's cache (call sogmm::occupancy first).
// Bench-only: not a public path.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "depth_tiles.hpp"
#include "frame_index.hpp"
#include "parallel.hpp"
#include "sogmm/map.hpp"
#include "sogmm/occupancy.hpp"
#include "z_order.hpp"

namespace sogmm_bench {

// a67de64's detail::Evidence: Phi = erfc / 2, exact outside +-9 sigma.
struct MainEvidence {
  double unknown = 1.0, occupied = 0.0, free = 0.0;
  std::uint64_t whole_free = 0;
  static double phi(double x) {
    if (x < -9.0) return 0.0;
    if (x > 9.0) return 1.0;
    return 0.5 * std::erfc(-x / std::sqrt(2.0));
  }
  void add_whole_free(std::uint64_t count) {
    if (count == 0) return;
    unknown = 0.0;
    whole_free += count;
  }
  void add(double r, double surface, const sogmm::OccupancyOptions& o) {
    const double front = (r - surface + o.thickness) / o.surface_sigma;
    if (front < -9.0) return add_whole_free(1);
    const double back = (r - surface - o.thickness) / o.surface_sigma;
    if (back > 9.0) return;
    const double e = 1.0 - phi(front);
    const double b = phi(back);
    unknown *= b;
    free += e;
    occupied += std::max(0.0, 1.0 - e - b);
  }
  void finish(double& probability, std::uint8_t& state) const {
    const double all_free = free + static_cast<double>(whole_free);
    const double seen = occupied + all_free;
    const double q = seen > 0 ? occupied / seen : 0.5;
    probability = std::min(1.0, std::max(0.0, (1.0 - unknown) * q + 0.5 * unknown));
    const double occ = (1.0 - unknown) * q, fr = (1.0 - unknown) * (1.0 - q);
    sogmm::OccupancyState s = sogmm::OccupancyState::Free;
    if (unknown >= occ && unknown >= fr) s = sogmm::OccupancyState::Unknown;
    else if (occ >= fr) s = sogmm::OccupancyState::Occupied;
    state = static_cast<std::uint8_t>(s);
  }
};

// a67de64's scoring (the map must have frames, a camera and components).
inline void main_occupancy(const sogmm::Map& map, const float* xyz, std::size_t n, double* probability,
                           std::uint8_t* state, int threads, const sogmm::OccupancyOptions& options = {}) {
  using namespace sogmm;
  constexpr std::size_t kBlock = 64;
  const int team = detail::team_size(threads);
  const CameraInfo& info = map.model().camera;
  const Camera camera = decimated(info.camera, info.decimation);
  std::vector<Pose> poses;
  for (const FrameStats& f : map.frames()) poses.push_back(f.pose);
  const detail::FrameIndex index(poses, camera, info.depth_min, info.depth_max);
  const auto point = [&](std::size_t i, double x[3]) {
    for (int k = 0; k < 3; ++k) x[k] = xyz[3 * i + k];
  };
  const std::vector<std::size_t> order = detail::z_ordered(xyz, n, 3, team);
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::array<double, 6>> box(blocks);
  std::vector<std::vector<std::uint32_t>> frames(blocks);
  std::vector<std::atomic<bool>> seen(poses.size());
  detail::parallel_for(blocks, team, 16, [&](std::size_t blk, int) {
    const std::size_t first = blk * kBlock, last = std::min(n, first + kBlock);
    auto& b = box[blk];
    const std::vector<std::uint32_t>* previous = nullptr;
    for (std::size_t j = first; j < last; ++j) {
      double x[3];
      point(order[j], x);
      for (int k = 0; k < 3; ++k) {
        b[k] = j == first ? x[k] : std::min(b[k], x[k]);
        b[3 + k] = j == first ? x[k] : std::max(b[3 + k], x[k]);
      }
      const auto* list = index.candidates(x);
      if (list == nullptr || list == previous) continue;
      previous = list;
      auto& f = frames[blk];
      const auto mid = static_cast<std::ptrdiff_t>(f.size());
      f.insert(f.end(), list->begin(), list->end());
      std::inplace_merge(f.begin(), f.begin() + mid, f.end());
      f.erase(std::unique(f.begin(), f.end()), f.end());
    }
    for (std::uint32_t f : frames[blk]) {
      if (seen[f].load(std::memory_order_relaxed) || !index.view(f, b.data(), b.data() + 3).visible) continue;
      for (std::size_t j = first; j < last; ++j) {
        double x[3];
        point(order[j], x);
        if (index.project(f, x).pixel >= 0) {
          seen[f].store(true, std::memory_order_relaxed);
          break;
        }
      }
    }
  });
  std::vector<std::shared_ptr<const std::vector<float>>> depth(poses.size());
  for (std::size_t f = 0; f < poses.size(); ++f)
    if (seen[f]) depth[f] = map.frame_depth(f, threads);
  std::vector<detail::DepthTiles> tiles(poses.size());
  detail::parallel_for(poses.size(), team, 1, [&](std::size_t f, int) {
    if (depth[f]) tiles[f] = detail::DepthTiles(*depth[f], camera.width, camera.height);
  });
  const double band = (options.thickness + 9.0 * options.surface_sigma) * (1.0 + 1e-9) + 1e-9;
  std::vector<std::vector<std::uint32_t>> scratch(static_cast<std::size_t>(team));
  detail::parallel_for(blocks, team, 4, [&](std::size_t blk, int thread) {
    const auto& b = box[blk];
    auto& asked = scratch[static_cast<std::size_t>(thread)];
    asked.clear();
    std::uint64_t whole_free = 0;
    for (std::uint32_t f : frames[blk]) {
      if (!depth[f]) continue;
      const detail::BoxView v = index.view(f, b.data(), b.data() + 3);
      if (!v.visible) continue;
      if (v.bounded) {
        const detail::DepthTiles::Range r = tiles[f].over(v.u0, v.v0, v.u1, v.v1);
        if (!r.any_surface) continue;
        if (v.z_lo - static_cast<double>(r.hi) > band) continue;
        if (v.seen_all && !r.any_empty && v.z_hi - static_cast<double>(r.lo) < -band) {
          ++whole_free;
          continue;
        }
      }
      asked.push_back(f);
    }
    const std::size_t first = blk * kBlock, last = std::min(n, first + kBlock);
    for (std::size_t j = first; j < last; ++j) {
      const std::size_t i = order[j];
      double x[3];
      point(i, x);
      MainEvidence ev;
      ev.add_whole_free(whole_free);
      for (std::uint32_t f : asked) {
        const detail::Projection p = index.project(f, x);
        if (p.pixel < 0) continue;
        const float d = (*depth[f])[static_cast<std::size_t>(p.pixel)];
        if (std::isnan(d)) continue;
        ev.add(p.depth * p.ray, d * p.ray, options);
      }
      ev.finish(probability[i], state[i]);
    }
  });
}

}  // namespace sogmm_bench
