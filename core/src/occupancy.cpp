// Occupancy of world points from a map's own frames (sogmm/occupancy.hpp).
#include "sogmm/occupancy.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "finite_rows.hpp"
#include "frame_index.hpp"
#include "parallel.hpp"
#include "progress.hpp"
#include "sogmm/error.hpp"
#include "sogmm/options.hpp"

namespace sogmm {

namespace {

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// The evidence of all frames at one point, and its probability and state.
struct Evidence {
  double unknown = 1.0;   // U = prod_f b_f
  double occupied = 0.0;  // sum_f o_f
  double free = 0.0;      // sum_f e_f

  void add(double r, double surface, const OccupancyOptions& o) {
    // Far from the surface the terms are exactly 0 or 1 in double (Phi
    // underflows below -38.5 sigma), so they are taken without erfc: the
    // same bits, and most query points are far in front of a surface.
    constexpr double kExact = 40.0;
    if ((r - surface + o.thickness) / o.surface_sigma < -kExact) {  // e = 1, b = 0, o = 0
      unknown = 0.0;
      free += 1.0;
      return;
    }
    if ((r - surface - o.thickness) / o.surface_sigma > kExact) return;  // e = 0, b = 1, o = 0
    const double e = 1.0 - normal_cdf((r - surface + o.thickness) / o.surface_sigma);
    const double b = normal_cdf((r - surface - o.thickness) / o.surface_sigma);
    unknown *= b;
    free += e;
    occupied += std::max(0.0, 1.0 - e - b);
  }
  void finish(double& probability, std::uint8_t* state) const {
    const double seen = occupied + free;
    const double q = seen > 0 ? occupied / seen : 0.5;
    probability = std::min(1.0, std::max(0.0, (1.0 - unknown) * q + 0.5 * unknown));
    if (state == nullptr) return;
    const double occ = (1.0 - unknown) * q, fr = (1.0 - unknown) * (1.0 - q);
    OccupancyState s = OccupancyState::Free;
    if (unknown >= occ && unknown >= fr) s = OccupancyState::Unknown;
    else if (occ >= fr) s = OccupancyState::Occupied;
    *state = static_cast<std::uint8_t>(s);
  }
};

void world_point(const float* xyz, std::size_t i, double x[3]) {
  for (int k = 0; k < 3; ++k) x[k] = xyz[3 * i + k];
}

}  // namespace

void validate(const OccupancyOptions& options) {
  require_option(OptionKey::OCCUPANCY_SIGMA, options.surface_sigma, "occupancy surface_sigma");
  require_option(OptionKey::OCCUPANCY_THICKNESS, options.thickness, "occupancy thickness");
}

void occupancy(const Map& map, const float* xyz, std::size_t n, double* probability, std::uint8_t* state,
               const OccupancyOptions& options, int threads, const ProgressSink& progress) {
  validate(options);
  if (n == 0) return;
  require(xyz != nullptr && probability != nullptr, ErrorCode::InvalidArgument, "occupancy: null input or output");
  detail::require_finite_rows(xyz, n, 3, "points for occupancy");
  const ProgressScope scope(progress);
  const int team = detail::team_size(threads);

  const bool observed = map.size() > 0 && !map.frames().empty() && map.model().camera.known;
  if (!observed) {
    for (std::size_t i = 0; i < n; ++i) Evidence{}.finish(probability[i], state ? state + i : nullptr);
    return;
  }
  const CameraInfo& info = map.model().camera;
  const Camera camera = decimated(info.camera, info.decimation);
  std::vector<Pose> poses;
  for (const FrameStats& f : map.frames()) poses.push_back(f.pose);
  const detail::FrameIndex index(poses, camera, info.depth_min, info.depth_max);

  // Which frames see at least one point: only those are rendered.
  std::vector<std::atomic<bool>> seen(poses.size());
  detail::parallel_for(n, team, 4096, [&](std::size_t i, int) {
    double x[3];
    world_point(xyz, i, x);
    const auto* frames = index.candidates(x);
    if (frames == nullptr) return;
    for (std::uint32_t f : *frames)
      if (!seen[f].load(std::memory_order_relaxed) && index.project(f, x).pixel >= 0)
        seen[f].store(true, std::memory_order_relaxed);
  });
  std::vector<std::shared_ptr<const std::vector<float>>> depth(poses.size());
  for (std::size_t f = 0; f < poses.size(); ++f)
    if (seen[f]) depth[f] = map.frame_depth(f, threads);

  detail::progress_begin(Stage::Scoring, n);
  detail::parallel_for(n, team, 1024, [&](std::size_t i, int) {
    double x[3];
    world_point(xyz, i, x);
    Evidence ev;
    if (const auto* frames = index.candidates(x))
      for (std::uint32_t f : *frames) {
        const detail::Projection p = index.project(f, x);
        if (p.pixel < 0) continue;
        const float d = (*depth[f])[static_cast<std::size_t>(p.pixel)];
        if (std::isnan(d)) continue;  // no surface rendered: no evidence
        ev.add(p.depth * p.ray, d * p.ray, options);
      }
    ev.finish(probability[i], state ? state + i : nullptr);
  });
}

}  // namespace sogmm
