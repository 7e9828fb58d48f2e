// The two decoders behind sogmm/frame_image.hpp. Each turns libpng's or
// libjpeg's error exits (longjmp) into sogmm::Error without skipping a C++
// destructor: the setjmp sits in small functions whose frames hold only C
// data, and every allocation is made outside them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "sogmm/frame_image.hpp"

namespace sogmm::format::detail {

/// True when the bytes start with the PNG resp. JPEG signature.
bool is_png(const void* data, std::size_t size);
bool is_jpeg(const void* data, std::size_t size);

/// Throws Error(Limit) naming `name` unless width * height <= kMaxFramePixels.
void check_frame_size(std::uint64_t width, std::uint64_t height, const std::string& name);

/// See decode_depth_png / decode_color_image (the PNG and JPEG cases).
DepthImage png_depth(const void* data, std::size_t size, const std::string& name);
ColorImage png_color(const void* data, std::size_t size, const std::string& name);
ColorImage jpeg_color(const void* data, std::size_t size, const std::string& name);

}  // namespace sogmm::format::detail
