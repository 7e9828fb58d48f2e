// What the map shows from each of its frames' poses, kept between queries
// (private; map_state.hpp, occupancy.cpp). Occupancy renders the map from
// every frame that sees a query point; a planner asks many times between two
// inserts, so the renders are kept until the map's components change.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace sogmm::detail {

/// Per frame, a depth image rendered at one revision of the components.
/// Thread-safe: const map queries run concurrently.
class FrameRenders {
 public:
  using Depth = std::shared_ptr<const std::vector<float>>;

  /// The image of `frame` at `revision`, or null when none is kept.
  Depth find(std::uint64_t revision, std::size_t frame) const;
  /// Keeps `depth` as `frame`'s image at `revision` (forgetting every image
  /// of an older revision) unless that would hold more than kBudgetBytes.
  void keep(std::uint64_t revision, std::size_t frame, Depth depth);

  /// At most this many bytes of images are kept (64 MiB: 1,300 frames of a
  /// 640 x 480 camera at decimation 5); beyond, images are rendered per call.
  static constexpr std::size_t kBudgetBytes = std::size_t{64} << 20;

 private:
  mutable std::mutex mutex_;
  std::uint64_t revision_ = 0;
  std::size_t bytes_ = 0;
  std::vector<Depth> depth_;
};

}  // namespace sogmm::detail
