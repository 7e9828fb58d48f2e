// What a map file stores beyond its components: the provenance keys
// kMapFramesKey and kMapOptionsKey (sogmm/map.hpp, spec/format.md 2.3).
#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "map_state.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/shortest_decimal.hpp"
#include "text_rows.hpp"

namespace sogmm {
namespace detail {

// One line per frame: index, points, novel points, then the 12 entries of the
// pose's first three rows (the last row of a rigid pose is 0 0 0 1), each at
// round-trip precision, then the map's components after the frame.
std::string frames_text(const std::vector<FrameStats>& frames, std::size_t first) {
  std::string text;
  char buf[64];
  for (std::size_t k = first; k < frames.size(); ++k) {
    const FrameStats& f = frames[k];
    std::snprintf(buf, sizeof buf, "%" PRIu64 " %zu %zu", f.index, f.n_points, f.n_novel);
    text += buf;
    for (int i = 0; i < 12; ++i) text += " " + checked::exact(f.pose[i]);
    text += " " + std::to_string(f.n_components) + "\n";
  }
  return text;
}

}  // namespace detail

namespace {

// The options as `name=value` pairs for people (spec/format.md 2.3), numbers
// in their shortest round-trip form: 0.7, not 0.69999999999999996.
std::string options_text(const MapOptions& o) {
  return "novelty=" + std::to_string(o.novelty ? 1 : 0) + " novelty_threshold=" + shortest_decimal(o.novelty_threshold) +
         " batch_size=" + std::to_string(o.batch_size) +
         " novelty_bandwidth_scale=" + shortest_decimal(o.novelty_bandwidth_scale) +
         " revisit_refit_ratio=" + shortest_decimal(o.revisit_refit_ratio) + " fusion=" + std::to_string(o.fusion ? 1 : 0) +
         " fusion_method=" + (o.fusion_method == FusionMethod::Hellinger ? "hellinger" : "kl") +
         " fusion_threshold=" + shortest_decimal(o.fusion_threshold) + " index_sigmas=" + shortest_decimal(o.index_sigmas) +
         " bandwidth=" + shortest_decimal(o.fit.bandwidth) + " warm_start=" + std::to_string(o.warm_start ? 1 : 0) +
         " component_precision=" + shortest_decimal(o.component_precision);
}

// One count: decimal digits only. operator>> into an unsigned type reads a
// sign and wraps it (-1 as 2^64 - 1), so the token is checked first.
template <typename T>
bool read_count(std::istream& in, T& out) {
  std::string token;
  if (!(in >> token) || token.find_first_not_of("0123456789") != std::string::npos) return false;
  std::istringstream digits(token);
  return static_cast<bool>(digits >> out) && digits.eof();
}

}  // namespace

namespace detail {

std::vector<FrameStats> parse_frames(const std::string& text, std::uint64_t first_index, const char* key) {
  std::vector<FrameStats> frames;
  detail::for_each_text_row(text, std::string("map: key ") + key, [&](std::istream& row, auto bad) {
    std::uint64_t index = 0;
    std::size_t n_points = 0, n_novel = 0;
    if (!(read_count(row, index) && read_count(row, n_points) && read_count(row, n_novel)))
      throw bad("expected 'index points novel' (unsigned integers) and 12 pose entries");
    if (index != first_index + frames.size())
      throw bad("frame index " + std::to_string(index) + ", expected " + std::to_string(first_index + frames.size()));
    if (n_novel > n_points) throw bad("more novel points than points");
    FrameStats f;
    f.index = index;
    f.n_points = n_points;
    f.n_novel = n_novel;
    for (int i = 0; i < 12; ++i)
      if (!(row >> f.pose[i])) throw bad("expected 12 pose entries");
    // The component count after the frame (absent in files of before it was
    // recorded: 0, which no warm start trusts).
    std::string rest;
    if (row >> rest) {
      std::istringstream count(rest);
      if (!read_count(count, f.n_components) || !count.eof())
        throw bad("expected a component count after the pose, got '" + rest + "'");
      if (row >> rest) throw bad("unexpected '" + rest + "' after the component count");
    }
    f.pose[15] = 1.0;
    const std::string problem = rigid_pose_error(f.pose);
    if (!problem.empty()) throw bad("pose is not rigid: " + problem);
    frames.push_back(f);
  });
  return frames;
}

}  // namespace detail

namespace {

// With options.warm_start, the loaded map's first flush warm-starts like any
// later one: from the last flush's fit in its camera. That fit is the block of
// components the last flush appended, found from the per-frame component
// counts (the last frame whose count grew), fitted in the camera of the
// latest frame up to it that gave points; moved back there with its weights
// renormalised. Not bitwise the fit before the save (two float moves, and
// merge() rescaled the weights), and with fusion the fused ones are missing
// from the block. Files without counts, or whose last count is not the
// model's size, leave it cold.
void restore_warm_start(Map::State& s) {
  const std::vector<FrameStats>& f = s.frames;
  const std::size_t m = s.model.gmm.size();
  if (!s.options.warm_start || f.empty() || f.back().n_components != m) return;
  std::size_t last = f.size() - 1;
  while (last > 0 && f[last - 1].n_components == m) --last;
  const std::size_t before = last > 0 ? f[last - 1].n_components : 0;
  if (before >= m) return;
  std::size_t camera = last;
  while (camera > 0 && f[camera].n_novel == 0) --camera;
  Gmm block;
  block.resize(m - before);
  double total = 0.0;
  for (std::size_t k = before; k < m; ++k) total += s.model.gmm.weights[k];
  if (!(total > 0)) return;
  for (std::size_t k = before; k < m; ++k) {
    block.weights[k - before] = static_cast<float>(s.model.gmm.weights[k] / total);
    std::copy_n(s.model.gmm.mean(k), 4, block.means.data() + 4 * (k - before));
    std::copy_n(s.model.gmm.covariance(k), 16, block.covariances.data() + 16 * (k - before));
  }
  block.support_size = std::max<std::uint64_t>(1, f[camera].n_novel);
  s.previous_pose = detail::anchored(s.origin, f[camera].pose);
  s.previous_fit = transform(block, inverse_rigid(s.previous_pose));
}

}  // namespace

Model Map::to_model() const {
  require(s_->n_pending == 0, ErrorCode::InvalidArgument,
          "map: " + std::to_string(s_->n_pending) + " points are pending; flush first (a map file holds components only)");
  (void)model();  // Error(InvalidData) for an empty map
  // The components as the map holds them, with the origin as their pose
  // (spec/format.md 2.3): a world-frame file would round them to float32
  // world coordinates (6.25 cm steps at 1000 km).
  Model m = s_->model;
  if (!detail::is_zero(s_->origin)) {
    Pose pose = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    for (int i = 0; i < 3; ++i) pose[4 * i + 3] = s_->origin[i];
    m.pose = pose;
  }
  erase_value(m, kMapFramesKey);
  erase_value(m, kMapOptionsKey);
  m.key_values.emplace_back(kMapFramesKey, detail::frames_text(s_->frames));
  m.key_values.emplace_back(kMapOptionsKey, options_text(s_->options));
  detail::write_identity(m, s_->journal);
  return m;
}

Map Map::from_model(const Model& model, const MapOptions& options) {
  require(coordinate_frame(model) == "world", ErrorCode::InvalidArgument,
          "map: the model is in the " + coordinate_frame(model) + " frame; a map holds a world-frame model");
  validate(model.gmm);
  require(model.gmm.support_size > 0, ErrorCode::InvalidArgument,
          "map: the model's support size is 0 (unknown); a map weighs its components against new points by the "
          "points they stand for: rebuild the model with its support size");
  Map map(options);
  State& s = *map.s_;
  s.model = model;
  s.origin = detail::split_origin(s.model);
  detail::require_origin(s.origin);
  s.origin_fixed = true;
  if (!detail::is_zero(s.origin)) s.world = detail::world_frame(s.model, s.origin);
  if (const std::string* frames = find_value(model, kMapFramesKey)) s.frames = detail::parse_frames(*frames);
  // The provenance lives in s.frames now; to_model() writes it afresh.
  erase_value(s.model, kMapFramesKey);
  erase_value(s.model, kMapOptionsKey);
  detail::read_identity(s.model, s.journal);
  if (model.camera.known) s.camera = model.camera.camera;
  restore_warm_start(s);
  detail::Searches searches = detail::searches_of(s.model.gmm, s.options.index_sigmas);
  s.index = std::move(searches.index);
  s.marginals = std::move(searches.marginals);
  return map;
}

}  // namespace sogmm
