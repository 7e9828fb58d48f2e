// Renders of a map kept between queries (map_renders.hpp) and
// Map::frame_depth, which fills them.
#include "map_renders.hpp"

#include <string>

#include "map_state.hpp"
#include "sogmm/error.hpp"
#include "sogmm/render.hpp"

namespace sogmm::detail {

FrameRenders::Depth FrameRenders::find(std::uint64_t revision, std::size_t frame) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (revision != revision_ || frame >= depth_.size()) return nullptr;
  return depth_[frame];
}

void FrameRenders::keep(std::uint64_t revision, std::size_t frame, Depth depth) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (revision != revision_) {
    depth_.clear();
    bytes_ = 0;
    revision_ = revision;
  }
  const std::size_t bytes = depth->size() * sizeof(float);
  if (bytes_ + bytes > kBudgetBytes) return;
  if (frame >= depth_.size()) depth_.resize(frame + 1);
  if (depth_[frame]) return;  // another thread rendered it first: the same image
  depth_[frame] = std::move(depth);
  bytes_ += bytes;
}

}  // namespace sogmm::detail

namespace sogmm {

std::shared_ptr<const std::vector<float>> Map::frame_depth(std::size_t frame, int threads) const {
  const State& s = *s_;
  require(frame < s.frames.size(), ErrorCode::InvalidArgument,
          "map: frame " + std::to_string(frame) + " is not recorded (the map has " + std::to_string(s.frames.size()) +
              " frames)");
  (void)model();  // Error(InvalidData) for an empty map
  // The map's own components from the frame's pose in the anchored frame:
  // the world-frame model would render float32 world coordinates.
  const Model& m = s.model;
  require(m.camera.known, ErrorCode::InvalidData, "map: no camera is recorded (points-only inserts), nothing to render");
  if (auto kept = s.renders.find(s.revision, frame)) return kept;
  RenderOptions ro;
  ro.depth_min = m.camera.depth_min;
  ro.depth_max = m.camera.depth_max;
  ro.threads = threads;
  auto depth = std::make_shared<const std::vector<float>>(
      render(m.gmm, decimated(m.camera.camera, m.camera.decimation), detail::anchored(s.origin, s.frames[frame].pose), ro)
          .depth);
  s.renders.keep(s.revision, frame, depth);
  return depth;
}

}  // namespace sogmm
