#include "sequence.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "file_util.hpp"
#include "sogmm/error.hpp"
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

std::vector<SequenceFrame> list_sequence(const std::string& dir) {
  require(fs::is_directory(dir), ErrorCode::Io, dir + ": no such folder (expected DIR/depth and DIR/color)");
  const auto depth = list_images(fs::path(dir) / "depth", {".png"});
  const auto color = list_images(fs::path(dir) / "color", {".jpg", ".jpeg", ".png"});
  require(!depth.empty(), ErrorCode::InvalidData, dir + "/depth: no .png depth image");
  require(depth.size() == color.size(), ErrorCode::InvalidData,
          dir + ": " + std::to_string(depth.size()) + " depth images but " + std::to_string(color.size()) +
              " color images");
  std::vector<SequenceFrame> frames(depth.size());
  for (std::size_t i = 0; i < depth.size(); ++i) frames[i] = {i, depth[i], color[i]};
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

std::vector<Pose> read_trajectory(const std::string& path) {
  std::ifstream in(path);
  require(fs::is_regular_file(path) && in.good(), ErrorCode::Io, path + ": cannot open trajectory (no such file)");
  std::vector<Pose> poses;
  std::string line;
  int line_no = 0;
  auto next_line = [&](std::string& out) {
    while (std::getline(in, out)) {
      ++line_no;
      if (out.find_first_not_of(" \t\r") != std::string::npos) return true;
    }
    return false;
  };
  while (next_line(line)) {
    {
      std::istringstream h(line);
      long long a = 0, b = 0, c = 0;
      require(static_cast<bool>(h >> a >> b >> c), ErrorCode::InvalidData,
              path + ":" + std::to_string(line_no) + ": expected a header line 'i j n'");
    }
    Pose p{};
    for (int r = 0; r < 4; ++r) {
      require(next_line(line), ErrorCode::InvalidData,
              path + ":" + std::to_string(line_no) + ": truncated 4x4 matrix");
      std::istringstream row(line);
      for (int c = 0; c < 4; ++c)
        require(static_cast<bool>(row >> p[4 * r + c]) && std::isfinite(p[4 * r + c]), ErrorCode::InvalidData,
                path + ":" + std::to_string(line_no) + ": expected 4 finite numbers");
    }
    // Rigid by the rule every pose in the library follows (kPoseTolerance).
    const std::string problem = rigid_pose_error(p);
    require(problem.empty(), ErrorCode::InvalidData,
            path + ":" + std::to_string(line_no) + ": pose " + std::to_string(poses.size()) +
                " is not a rigid transform: " + problem);
    poses.push_back(p);
  }
  require(!poses.empty(), ErrorCode::InvalidData, path + ": no pose in the trajectory");
  return poses;
}

void write_trajectory(const std::string& path, const std::vector<Pose>& poses) {
  std::string text;
  char buf[256];
  for (std::size_t i = 0; i < poses.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%zu %zu %zu\n", i, i + 1, poses.size());
    text += buf;
    for (int r = 0; r < 4; ++r) {
      std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g %.17g\n", poses[i][4 * r], poses[i][4 * r + 1],
                    poses[i][4 * r + 2], poses[i][4 * r + 3]);
      text += buf;
    }
  }
  write_file_atomic(path, text.data(), text.size());
}

}  // namespace sogmm::tools
