// Reading RGB-D frames from image files (decoded by the library:
// sogmm/frame_image.hpp) and writing PNGs (OpenCV, the tools only).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/camera.hpp"

namespace sogmm::tools {

/// A frame loaded from files: 16-bit depth and gray in [0, 1], same size.
struct LoadedFrame {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> depth;
  std::vector<float> gray;
  /// View for the core with the given intrinsics.
  RgbdView view(const Camera& camera) const { return {depth.data(), gray.data(), camera}; }
};

/// Loads a 16-bit (or 8-bit, widened) single-channel depth PNG and a color or
/// gray image (PNG/JPEG) with the library's reader; color becomes gray with
/// 0.299/0.587/0.114. Throws as format::read_depth_png / read_color_image
/// (Io, Format, InvalidData, Limit, naming the file) and Error(InvalidData)
/// for images of different sizes.
LoadedFrame load_frame(const std::string& depth_path, const std::string& color_path);

/// Loads only a depth image (as load_frame); the gray is all zeros.
LoadedFrame load_depth(const std::string& depth_path);

/// Writes an 8-bit image (1 channel gray or 3 channels in OpenCV's BGR order)
/// as PNG atomically; throws Error(Io).
void write_png(const std::string& path, int width, int height, int channels, const std::uint8_t* data);
/// Writes a 16-bit single-channel image (e.g. depth in millimetres) as PNG atomically.
void write_png16(const std::string& path, int width, int height, const std::uint16_t* data);

}  // namespace sogmm::tools
