// RGB-D sequences on disk: DIR/depth/*.png + DIR/color/*.{jpg,png}, a Redwood
// trajectory (.log) of camera-to-world poses, and "A:B" frame ranges.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "sogmm/model.hpp"
#include "sogmm/trajectory_log.hpp"

namespace sogmm::tools {

/// Row-major 4x4 rigid transform.
using Pose = std::array<double, 16>;

/// One frame of a sequence: its position in name order, its number and its two files.
struct SequenceFrame {
  std::size_t index = 0;  ///< position in name order (what --frames selects)
  long long id = -1;      ///< the frame number its names carry (00012.png: 12); -1 when paired by order
  std::string depth;
  std::string color;
};

/// Lists DIR/depth/*.png and DIR/color/*.{jpg,jpeg,png}, each sorted by file
/// name. By default a depth and a color image are paired by the frame number
/// of their names (the name without extension is a decimal number, as
/// 00012.png); a name that is not a number, a number used twice or a depth
/// image without the color image of its number -> Error(InvalidData) naming
/// the file. With `pair_by_order` the k-th depth goes with the k-th color
/// whatever the names. Throws Error(Io) when a folder is missing and
/// Error(InvalidData) when the two folders hold different numbers of images.
std::vector<SequenceFrame> list_sequence(const std::string& dir, bool pair_by_order = false);

/// Parses a frame selection: "I" (one frame), "A:B" (A <= i < B; A or B may
/// be empty = start/end) or "A:B:S" (step S). Throws Error(InvalidArgument).
std::vector<std::size_t> parse_frame_range(const std::string& text, std::size_t count);

/// A Redwood .log trajectory and its reader (the library's: sogmm/trajectory_log.hpp).
using format::Trajectory;
using format::read_trajectory_log;

/// The poses of read_trajectory_log in file order (entry k = block k).
std::vector<Pose> read_trajectory(const std::string& path);

/// A model's components in the camera of `camera_to_world`, the model taken
/// as world-frame. A "world" model's pose maps its frame to the world
/// (spec/format.md 2.1; a map far from the world origin stores its origin so,
/// 2.3.1): composed in double before the one float32 transform.
Gmm in_camera(const Model& model, const Pose& camera_to_world);

/// The pose of each selected frame (entry k for frames[selected[k]]): the
/// pose whose id is the frame's number, or with `pair_by_order` the pose of
/// the frame's position in name order. A frame without its pose, or a
/// number that two poses claim (by number only) -> Error(InvalidData) naming
/// `path`, the frame and the way out (--pair-by-order).
std::vector<Pose> poses_of_frames(const Trajectory& trajectory, const std::string& path,
                                  const std::vector<SequenceFrame>& frames, const std::vector<std::size_t>& selected,
                                  bool pair_by_order);

/// Inverse of a rigid transform (the core's, sogmm/model.hpp).
using sogmm::inverse_rigid;

/// Writes a trajectory in the same format (atomically; the library's writer).
using format::write_trajectory_log;

}  // namespace sogmm::tools
