// Redwood .log trajectories: per frame a header line "i j n" and four lines
// of a row-major 4x4 camera-to-world matrix. Read and written here once for
// the C API, the bindings and the CLI.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace sogmm::format {

/// A trajectory: block k holds poses[k] (row-major 4x4 rigid transform),
/// and ids[k] is the first number of its header line, the frame it belongs to.
struct Trajectory {
  std::vector<std::array<double, 16>> poses;
  std::vector<long long> ids;
};

/// Parses the text of a .log file; `name` names it in messages. Blank lines
/// are skipped. Throws Error(InvalidData) naming the line when a header is
/// not three integers, a matrix is truncated or holds a non-finite or
/// missing number, a pose is not a rigid transform (sogmm::rigid_pose_error,
/// the one pose rule of the library), or there is no pose at all.
Trajectory parse_trajectory_log(const std::string& text, const std::string& name);

/// Reads a .log file (at most 1 GiB). Throws Error(Io) when it cannot be read
/// or is not a regular file (a FIFO is refused, never waited on), else as
/// parse_trajectory_log.
Trajectory read_trajectory_log(const std::string& path);

/// The text of a .log file: block k has the header "k k+1 n" and the pose
/// with 17 significant digits (read back bitwise).
std::string format_trajectory_log(const std::vector<std::array<double, 16>>& poses);

/// Writes format_trajectory_log(poses) to `path` atomically (format::write_file:
/// on failure the previous file is untouched). Throws Error(Io).
void write_trajectory_log(const std::string& path, const std::vector<std::array<double, 16>>& poses);

}  // namespace sogmm::format
