// RGB-D sequences on disk: DIR/depth/*.png + DIR/color/*.{jpg,png}, a Redwood
// trajectory (.log) of camera-to-world poses, and "A:B" frame ranges.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "sogmm/model.hpp"

namespace sogmm::tools {

/// Row-major 4x4 rigid transform.
using Pose = std::array<double, 16>;

/// One frame of a sequence: its index in name order and its two files.
struct SequenceFrame {
  std::size_t index = 0;
  std::string depth;
  std::string color;
};

/// Lists DIR/depth/*.png and DIR/color/*.{jpg,jpeg,png}, each sorted by file
/// name, paired in that order. Throws Error(Io) when a folder is missing and
/// Error(InvalidData) when the two folders hold different numbers of images.
std::vector<SequenceFrame> list_sequence(const std::string& dir);

/// Parses a frame selection: "I" (one frame), "A:B" (A <= i < B; A or B may
/// be empty = start/end) or "A:B:S" (step S). Throws Error(InvalidArgument).
std::vector<std::size_t> parse_frame_range(const std::string& text, std::size_t count);

/// Reads a Redwood .log trajectory: per frame a line "i j n" then four lines
/// of a 4x4 camera-to-world matrix. Entry k of the result is the pose of the
/// k-th block (the frame with index k in name order). Throws Error(Io) when
/// the file cannot be read and Error(InvalidData) naming the line when it is
/// malformed or a matrix is not a rigid transform.
std::vector<Pose> read_trajectory(const std::string& path);

/// Inverse of a rigid transform (the core's, sogmm/model.hpp).
using sogmm::inverse_rigid;

/// Writes a trajectory in the same format (atomically).
void write_trajectory(const std::string& path, const std::vector<Pose>& poses);

}  // namespace sogmm::tools
