// The RGB-D frame a single-frame benchmark reads: --depth, --color and
// --intrinsics (all required) and --decimate, one declaration for every
// sogmm-perf program that fits one frame.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "image_io.hpp"
#include "sogmm/camera.hpp"

namespace sogmm::perf {

struct FrameFlags {
  std::string depth, color, intrinsics;
  DepthOptions depth_options;  ///< --decimate (a program may add more of its fields as flags)

  /// Adds --depth, --color, --intrinsics and --decimate to `app`.
  void add_to(CLI::App& app) {
    app.add_option("--depth", depth)->required();
    app.add_option("--color", color)->required();
    app.add_option("--intrinsics", intrinsics)->required();
    app.add_option("--decimate", depth_options.decimate);
  }
  /// The full-size camera of --intrinsics.
  Camera camera() const { return read_intrinsics_json(intrinsics); }
  /// The frame's images as read.
  tools::LoadedFrame frame() const { return tools::load_frame(depth, color); }
  /// The frame's valid pixels back-projected with `depth_options`.
  PointCloud cloud() const { return backproject(frame().view(camera()), depth_options); }
};

}  // namespace sogmm::perf
