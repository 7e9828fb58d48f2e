// Redwood .log trajectories (sogmm/trajectory_log.hpp), moved here from the
// CLI with the same rules.
#include "sogmm/trajectory_log.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "sogmm/error.hpp"
#include "sogmm/format.hpp"
#include "sogmm/input_file.hpp"
#include "sogmm/model.hpp"

namespace sogmm::format {

Trajectory parse_trajectory_log(const std::string& text, const std::string& name) {
  std::istringstream in(text);
  Trajectory t;
  std::string line;
  int line_no = 0;
  auto next_line = [&](std::string& out) {
    while (std::getline(in, out)) {
      ++line_no;
      if (out.find_first_not_of(" \t\r") != std::string::npos) return true;
    }
    return false;
  };
  auto where = [&] { return name + ":" + std::to_string(line_no) + ": "; };
  while (next_line(line)) {
    long long id = 0;
    {
      std::istringstream h(line);
      long long b = 0, c = 0;
      require(static_cast<bool>(h >> id >> b >> c), ErrorCode::InvalidData, where() + "expected a header line 'i j n'");
    }
    std::array<double, 16> p{};
    for (int r = 0; r < 4; ++r) {
      require(next_line(line), ErrorCode::InvalidData, where() + "truncated 4x4 matrix");
      std::istringstream row(line);
      for (int c = 0; c < 4; ++c)
        require(static_cast<bool>(row >> p[4 * r + c]) && std::isfinite(p[4 * r + c]), ErrorCode::InvalidData,
                where() + "expected 4 finite numbers");
    }
    const std::string problem = rigid_pose_error(p);
    require(problem.empty(), ErrorCode::InvalidData,
            where() + "pose " + std::to_string(t.poses.size()) + " is not a rigid transform: " + problem);
    t.poses.push_back(p);
    t.ids.push_back(id);
  }
  require(!t.poses.empty(), ErrorCode::InvalidData, name + ": no pose in the trajectory");
  return t;
}

Trajectory read_trajectory_log(const std::string& path) {
  return parse_trajectory_log(read_input_file(path, "trajectory", std::uint64_t{1} << 30), path);
}

std::string format_trajectory_log(const std::vector<std::array<double, 16>>& poses) {
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
  return text;
}

void write_trajectory_log(const std::string& path, const std::vector<std::array<double, 16>>& poses) {
  const std::string text = format_trajectory_log(poses);
  write_file(path, text.data(), text.size());
}

}  // namespace sogmm::format
