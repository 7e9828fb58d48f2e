#include "sequence.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "file_util.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/model.hpp"

namespace sogmm::tools {

namespace fs = std::filesystem;

namespace {
std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::vector<std::string> list_images(const fs::path& dir, const std::vector<std::string>& exts) {
  require(fs::is_directory(dir), ErrorCode::Io, dir.string() + ": no such folder");
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string ext = lower(entry.path().extension().string());
    if (std::find(exts.begin(), exts.end(), ext) != exts.end()) out.push_back(entry.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}
}  // namespace

namespace {
const char kOrderHint[] = " (give --pair-by-order to pair files by order)";

// The frame number of an image name: the name without extension as a
// decimal number (00012.png: 12), -1 when it is not one.
long long frame_number(const std::string& path) {
  const std::string stem = fs::path(path).stem().string();
  if (stem.empty() || stem.size() > 18 || stem.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoll(stem);
}

long long numbered(const std::string& path) {
  const long long id = frame_number(path);
  require(id >= 0, ErrorCode::InvalidData,
          path + ": the name is not a frame number (as 00012.png), so it cannot be paired by number" + kOrderHint);
  return id;
}
}  // namespace

std::vector<SequenceFrame> list_sequence(const std::string& dir, bool pair_by_order) {
  require(fs::is_directory(dir), ErrorCode::Io, dir + ": no such folder (expected DIR/depth and DIR/color)");
  const auto depth = list_images(fs::path(dir) / "depth", {".png"});
  const auto color = list_images(fs::path(dir) / "color", {".jpg", ".jpeg", ".png"});
  require(!depth.empty(), ErrorCode::InvalidData, dir + "/depth: no .png depth image");
  require(depth.size() == color.size(), ErrorCode::InvalidData,
          dir + ": " + std::to_string(depth.size()) + " depth images but " + std::to_string(color.size()) +
              " color images");
  std::vector<SequenceFrame> frames(depth.size());
  if (pair_by_order) {
    for (std::size_t i = 0; i < depth.size(); ++i) frames[i] = {i, -1, depth[i], color[i]};
    return frames;
  }
  std::map<long long, std::string> color_of;
  for (const std::string& c : color)
    require(color_of.emplace(numbered(c), c).second, ErrorCode::InvalidData,
            c + ": a second color image of frame " + std::to_string(numbered(c)));
  std::set<long long> depth_ids;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const long long id = numbered(depth[i]);
    require(depth_ids.insert(id).second, ErrorCode::InvalidData,
            depth[i] + ": a second depth image of frame " + std::to_string(id));
    const auto c = color_of.find(id);
    require(c != color_of.end(), ErrorCode::InvalidData,
            depth[i] + ": no color image of frame " + std::to_string(id) + " in " + dir + "/color" + kOrderHint);
    frames[i] = {i, id, depth[i], c->second};
  }
  return frames;
}

std::vector<std::size_t> parse_frame_range(const std::string& text, std::size_t count) {
  auto bad = [&](const std::string& why) {
    return Error(ErrorCode::InvalidArgument, "--frames " + text + ": " + why);
  };
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ':')) parts.push_back(part);
  if (!text.empty() && text.back() == ':') parts.push_back("");
  if (parts.empty() || parts.size() > 3) throw bad("expected I, A:B or A:B:S");
  auto number = [&](const std::string& s, long long fallback) -> long long {
    if (s.empty()) return fallback;
    std::size_t used = 0;
    long long v = 0;
    try {
      v = std::stoll(s, &used);
    } catch (const std::exception&) {
      throw bad("'" + s + "' is not an integer");
    }
    if (used != s.size()) throw bad("'" + s + "' is not an integer");
    if (v < 0) throw bad("negative frame numbers are not supported");
    return v;
  };
  const long long n = static_cast<long long>(count);
  std::vector<std::size_t> out;
  if (parts.size() == 1) {
    const long long i = number(parts[0], -1);
    if (i < 0) throw bad("empty selection");
    if (i >= n) throw bad("frame " + std::to_string(i) + " does not exist (" + std::to_string(n) + " frames)");
    out.push_back(static_cast<std::size_t>(i));
    return out;
  }
  const long long a = number(parts[0], 0);
  const long long b = std::min(number(parts[1], n), n);
  const long long step = parts.size() == 3 ? number(parts[2], 1) : 1;
  if (step < 1) throw bad("step must be >= 1");
  for (long long i = a; i < b; i += step) out.push_back(static_cast<std::size_t>(i));
  if (out.empty()) throw bad("selects no frame (" + std::to_string(n) + " frames)");
  return out;
}

std::vector<Pose> read_trajectory(const std::string& path) { return read_trajectory_log(path).poses; }

Gmm in_camera(const Model& model, const Pose& camera_to_world) {
  const Pose to_camera = inverse_rigid(camera_to_world);
  const bool posed_world = model.pose && coordinate_frame(model) == "world";
  return transform(model.gmm, posed_world ? compose_poses(to_camera, *model.pose) : to_camera);
}

std::vector<Pose> poses_of_frames(const Trajectory& trajectory, const std::string& path,
                                  const std::vector<SequenceFrame>& frames, const std::vector<std::size_t>& selected,
                                  bool pair_by_order) {
  std::vector<Pose> out;
  if (pair_by_order) {
    require(trajectory.poses.size() >= selected.back() + 1, ErrorCode::InvalidData,
            path + ": has " + std::to_string(trajectory.poses.size()) + " poses but frame " +
                std::to_string(selected.back()) + " is selected");
    for (const std::size_t i : selected) out.push_back(trajectory.poses[i]);
    return out;
  }
  std::map<long long, std::size_t> block_of;
  for (std::size_t k = 0; k < trajectory.ids.size(); ++k)
    require(block_of.emplace(trajectory.ids[k], k).second, ErrorCode::InvalidData,
            path + ": two poses of frame " + std::to_string(trajectory.ids[k]) + kOrderHint);
  for (const std::size_t i : selected) {
    const auto b = block_of.find(frames[i].id);
    require(b != block_of.end(), ErrorCode::InvalidData,
            path + ": no pose of frame " + std::to_string(frames[i].id) + " (" + frames[i].depth + ")" + kOrderHint);
    out.push_back(trajectory.poses[b->second]);
  }
  return out;
}

}  // namespace sogmm::tools
