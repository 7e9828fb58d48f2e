// sogmm_frame_read / sogmm_frame_decode: the library's frame reader
// (sogmm/frame_image.hpp) behind the C API.
#include <memory>
#include <string>

#include "frame_handle.hpp"
#include "internal.hpp"
#include "sogmm/error.hpp"
#include "sogmm/frame_image.hpp"

namespace {

std::int32_t color_format_of(const sogmm::format::ColorImage& c) {
  return c.channels == 3 ? SOGMM_COLOR_RGB8 : SOGMM_COLOR_GRAY8;
}

// Depth and optional colour into a handle; the two must have one size.
sogmm_frame* make_frame(sogmm::format::DepthImage depth, const sogmm::format::ColorImage* color,
                        const std::string& depth_name, const std::string& color_name) {
  auto f = std::make_unique<sogmm_frame>();
  f->width = depth.width;
  f->height = depth.height;
  f->depth = std::move(depth.pixels);
  if (color != nullptr) {
    if (color->width != f->width || color->height != f->height)
      sogmm_capi::fail(SOGMM_E_INVALID_DATA, "images of different sizes: depth " + depth_name + " is " +
                                                 std::to_string(f->width) + "x" + std::to_string(f->height) +
                                                 ", color " + color_name + " is " + std::to_string(color->width) +
                                                 "x" + std::to_string(color->height));
    f->color_format = color_format_of(*color);
    f->color = color->bytes;
  }
  return f.release();
}

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_frame_read(sogmm_frame** out, const char* depth_path, const char* color_path) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    sogmm_capi::require_nonnull(depth_path, "depth_path");
    sogmm::format::DepthImage depth = sogmm::format::read_depth_png(depth_path);
    if (color_path == nullptr) {
      *out = make_frame(std::move(depth), nullptr, depth_path, "");
    } else {
      const sogmm::format::ColorImage color = sogmm::format::read_color_image(color_path);
      *out = make_frame(std::move(depth), &color, depth_path, color_path);
    }
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_frame_decode(sogmm_frame** out, const void* depth_data, size_t depth_size,
                                          const void* color_data, size_t color_size) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    sogmm_capi::require_nonnull(depth_data, "depth_data");
    sogmm::format::DepthImage depth = sogmm::format::decode_depth_png(depth_data, depth_size, "depth");
    if (color_data == nullptr) {
      *out = make_frame(std::move(depth), nullptr, "depth", "");
    } else {
      const sogmm::format::ColorImage color = sogmm::format::decode_color_image(color_data, color_size, "color");
      *out = make_frame(std::move(depth), &color, "depth", "color");
    }
  }
  SOGMM_CATCH
}

}  // extern "C"
