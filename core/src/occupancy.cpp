// Occupancy of world points from a map's own frames (sogmm/occupancy.hpp).
#include "sogmm/occupancy.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "finite_rows.hpp"
#include "depth_tiles.hpp"
#include "frame_index.hpp"
#include "occupancy_evidence.hpp"
#include "occupancy_kernel.hpp"
#include "occupancy_phi.hpp"
#include "parallel.hpp"
#include "progress.hpp"
#include "sogmm/error.hpp"
#include "sogmm/options.hpp"
#include "z_order.hpp"

namespace sogmm {

namespace {

using detail::Evidence;

// Points per block: the frames' whole evidence is decided once per block.
constexpr std::size_t kBlock = detail::kOccupancyBlock;

// One thread's block: its points and their evidence as arrays, and the
// frames its points ask.
struct Scratch {
  detail::OccupancyLanes lanes;
  std::vector<std::uint32_t> asked;
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

  // Blocks of points near each other (Z-order), with their boxes and the
  // frames listed in the grid cells of their points (sorted).
  const std::vector<std::size_t> order = detail::z_ordered_coarse(xyz, n, 3, team);
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::array<double, 6>> box(blocks);
  std::vector<std::vector<std::uint32_t>> frames(blocks);
  std::vector<std::atomic<bool>> seen(poses.size());
  detail::parallel_for(blocks, team, 16, [&](std::size_t blk, int) {
    const std::size_t first = blk * kBlock, last = std::min(n, first + kBlock);
    auto& b = box[blk];
    for (std::size_t j = first; j < last; ++j) {
      double x[3];
      world_point(xyz, order[j], x);
      for (int k = 0; k < 3; ++k) {
        b[k] = j == first ? x[k] : std::min(b[k], x[k]);
        b[3 + k] = j == first ? x[k] : std::max(b[3 + k], x[k]);
      }
    }
    // Most blocks lie in one grid cell: one look-up gives every point's list.
    const bool one_cell = index.one_cell(b.data(), b.data() + 3);
    const std::vector<std::uint32_t>* previous = nullptr;
    for (std::size_t j = first; j < (one_cell ? first + 1 : last); ++j) {
      double x[3];
      world_point(xyz, order[j], x);
      const auto* list = index.candidates(x);
      if (list == nullptr || list == previous) continue;
      previous = list;
      auto& f = frames[blk];
      const auto mid = static_cast<std::ptrdiff_t>(f.size());
      f.insert(f.end(), list->begin(), list->end());
      std::inplace_merge(f.begin(), f.begin() + mid, f.end());
      f.erase(std::unique(f.begin(), f.end()), f.end());
    }
    // Only frames that see a query point are rendered.
    for (std::uint32_t f : frames[blk]) {
      if (seen[f].load(std::memory_order_relaxed) || !index.may_see(f, b.data(), b.data() + 3) ||
          !index.view(f, b.data(), b.data() + 3).visible)
        continue;
      for (std::size_t j = first; j < last; ++j) {
        double x[3];
        world_point(xyz, order[j], x);
        if (index.project(f, x).pixel >= 0) {
          seen[f].store(true, std::memory_order_relaxed);
          break;
        }
      }
    }
  });
  // One frame per thread: a render of the small decimated image splits
  // poorly over threads (its parallel loop waited a third of the time), and
  // the image does not depend on the thread count.
  std::vector<std::size_t> wanted;
  for (std::size_t f = 0; f < poses.size(); ++f)
    if (seen[f]) wanted.push_back(f);
  // Each frame's depth tiles are built in the same loop (one parallel
  // region fewer to wait at the end of).
  std::vector<std::shared_ptr<const std::vector<float>>> depth(poses.size());
  std::vector<detail::DepthTiles> tiles(poses.size());
  detail::parallel_for(wanted.size(), team, 1, [&](std::size_t k, int) {
    const std::size_t f = wanted[k];
    depth[f] = map.frame_depth(f, 1);
    tiles[f] = detail::DepthTiles(*depth[f], camera.width, camera.height);
  });

  // Per block, a frame that gives every point of the block whole evidence
  // (more than h + 9 sigma in front of its surface: free; behind it, or no
  // surface, or not seen: nothing) is decided once from the block's box and
  // the depth range under it; the others are asked for each point, in frame
  // order. The result is bitwise the one of asking every frame for every
  // point with this Evidence (whole evidence enters the sums as a count, the
  // rest in frame order; test OccupancyBlocks.BitwiseTheAnswerOfEveryFrame),
  // and within the bound of occupancy_evidence.hpp of the model's formula.
  const double band = (options.thickness + detail::kExactSigmas * options.surface_sigma) * (1.0 + 1e-9) + 1e-9;
  std::vector<Scratch> scratch(static_cast<std::size_t>(team));
  const detail::OccupancyFrameFn kernel = detail::occupancy_frame_kernel();
  const Camera& cam = index.camera();
  const detail::OccupancyFrame each{nullptr, nullptr, cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height,
                                    index.depth_min(), index.depth_max(), nullptr, band, options.thickness,
                                    options.surface_sigma, detail::phi_table().coefficients()};
  detail::progress_begin(Stage::Scoring, n);
  detail::parallel_for(blocks, team, 4, [&](std::size_t blk, int thread) {
    const auto& b = box[blk];
    auto& asked = scratch[static_cast<std::size_t>(thread)].asked;
    detail::OccupancyFrame frame = each;
    asked.clear();
    std::uint64_t whole_free = 0;
    for (std::uint32_t f : frames[blk]) {
      if (!depth[f] || !index.may_see(f, b.data(), b.data() + 3)) continue;  // sees no query point
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
    // Frame by frame over the block's points, at the vector width
    // (occupancy_kernel.hpp: the per-point sums still run in frame order,
    // with the scalar Evidence's arithmetic, so the bits are those of asking
    // point by point).
    const std::size_t first = blk * kBlock, count = std::min(n, first + kBlock) - first;
    detail::OccupancyLanes& w = scratch[static_cast<std::size_t>(thread)].lanes;
    const double whole = static_cast<double>(whole_free);
    for (std::size_t j = 0; j < count; ++j) {
      const std::size_t i = order[first + j];
      w.x[j] = xyz[3 * i];
      w.y[j] = xyz[3 * i + 1];
      w.z[j] = xyz[3 * i + 2];
      w.unknown[j] = whole_free > 0 ? 0.0 : 1.0;
      w.occupied[j] = 0.0;
      w.free[j] = 0.0;
      w.whole_free[j] = whole;
    }
    for (std::uint32_t f : asked) {
      const detail::FrameView& view = index.frame(f);
      frame.r = view.r.data();
      frame.t = view.t.data();
      frame.depth = depth[f]->data();
      kernel(frame, w, static_cast<int>(count));
    }
    for (std::size_t j = 0; j < count; ++j) {
      detail::Evidence ev;
      ev.unknown = w.unknown[j];
      ev.occupied = w.occupied[j];
      ev.free = w.free[j];
      ev.whole_free = static_cast<std::uint64_t>(w.whole_free[j]);
      ev.finish(probability[order[first + j]], state ? state + order[first + j] : nullptr);
    }
  });
}

}  // namespace sogmm
