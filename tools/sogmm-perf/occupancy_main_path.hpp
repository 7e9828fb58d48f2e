// Occupancy as main answered it at 0f45b28, before the block path of issue 31
// (core/src/occupancy.cpp): each point asks every frame whose frustum box
// holds it, with Phi cut at 40 sigma (where it underflows in double), so
// that sogmm-occupancy-octomap --compare-main times both in one run and
// reports how far the block path's answers are from it. Renders come from
// the map's cache (call sogmm::occupancy first). Bench-only: not a public path.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "frame_index.hpp"
#include "parallel.hpp"
#include "sogmm/map.hpp"
#include "sogmm/occupancy.hpp"

namespace sogmm_bench {

inline double main_phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// The evidence sums of 0f45b28, in frame order, one frame at a time.
struct MainEvidence {
  double unknown = 1.0, occupied = 0.0, free = 0.0;
  void add(double r, double surface, const sogmm::OccupancyOptions& o) {
    constexpr double kExact = 40.0;
    if ((r - surface + o.thickness) / o.surface_sigma < -kExact) {
      unknown = 0.0;
      free += 1.0;
      return;
    }
    if ((r - surface - o.thickness) / o.surface_sigma > kExact) return;
    const double e = 1.0 - main_phi((r - surface + o.thickness) / o.surface_sigma);
    const double b = main_phi((r - surface - o.thickness) / o.surface_sigma);
    unknown *= b;
    free += e;
    occupied += std::max(0.0, 1.0 - e - b);
  }
  void finish(double& probability, std::uint8_t& state) const {
    const double seen = occupied + free;
    const double q = seen > 0 ? occupied / seen : 0.5;
    probability = std::min(1.0, std::max(0.0, (1.0 - unknown) * q + 0.5 * unknown));
    const double occ = (1.0 - unknown) * q, fr = (1.0 - unknown) * (1.0 - q);
    sogmm::OccupancyState s = sogmm::OccupancyState::Free;
    if (unknown >= occ && unknown >= fr) s = sogmm::OccupancyState::Unknown;
    else if (occ >= fr) s = sogmm::OccupancyState::Occupied;
    state = static_cast<std::uint8_t>(s);
  }
};

// main's scoring loop (the map must have frames, a camera and components).
inline void main_occupancy(const sogmm::Map& map, const float* xyz, std::size_t n, double* probability,
                           std::uint8_t* state, int threads, const sogmm::OccupancyOptions& options = {}) {
  using namespace sogmm;
  const CameraInfo& info = map.model().camera;
  std::vector<Pose> poses;
  for (const FrameStats& f : map.frames()) poses.push_back(f.pose);
  const detail::FrameIndex index(poses, decimated(info.camera, info.decimation), info.depth_min, info.depth_max);
  std::vector<std::shared_ptr<const std::vector<float>>> depth(poses.size());
  for (std::size_t f = 0; f < poses.size(); ++f) depth[f] = map.frame_depth(f, threads);
  detail::parallel_for(n, detail::team_size(threads), 1024, [&](std::size_t i, int) {
    const double x[3] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    MainEvidence ev;
    if (const auto* frames = index.candidates(x))
      for (std::uint32_t f : *frames) {
        const detail::Projection p = index.project(f, x);
        if (p.pixel < 0) continue;
        const float d = (*depth[f])[static_cast<std::size_t>(p.pixel)];
        if (std::isnan(d)) continue;
        ev.add(p.depth * p.ray, d * p.ray, options);
      }
    ev.finish(probability[i], state[i]);
  });
}

}  // namespace sogmm_bench
