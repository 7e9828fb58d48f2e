// The sogmm_frame handle (sogmm.h, "frames from image files"): decoded
// pixels plus intrinsics. Shared by frame.cpp and frame_io.cpp. Never installed.
#pragma once

#include <cstdint>
#include <vector>

#include "sogmm/sogmm.h"

struct sogmm_frame {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<std::uint16_t> depth;  ///< width * height raw values
  std::int32_t color_format = 0;     ///< SOGMM_COLOR_GRAY8 / _RGB8, 0 = no colour image
  std::vector<std::uint8_t> color;   ///< in color_format's layout; empty without one
  bool has_intrinsics = false;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
};
