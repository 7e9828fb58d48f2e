// sogmm_frame: made from arrays in memory, its accessors and intrinsics. The
// fit, the map insert and the back-projection that take a frame are in fit.cpp,
// map.cpp and rgbd.cpp; frames from image files in frame_io.cpp.
#include <cstring>
#include <limits>
#include <memory>
#include <string>

#include "frame_handle.hpp"
#include "internal.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/fit.hpp"

namespace {

using sogmm_capi::fail;

// Bytes per pixel of a colour layout; SOGMM_E_INVALID_ARG for an unknown one.
std::size_t color_pixel_bytes(std::int32_t format) {
  switch (format) {
    case SOGMM_COLOR_GRAY8: return 1;
    case SOGMM_COLOR_RGB8: return 3;
    case SOGMM_COLOR_GRAY_F32: return sizeof(float);
    default: fail(SOGMM_E_INVALID_ARG, "unknown color_format " + std::to_string(format));
  }
}

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_frame_from_arrays(sogmm_frame** out, uint32_t width, uint32_t height,
                                               const uint16_t* depth, const void* color, int32_t color_format) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    sogmm_capi::require_nonnull(depth, "depth");
    if (color == nullptr && color_format != 0)
      fail(SOGMM_E_NULL_ARG, "color is NULL but color_format is " + std::to_string(color_format) +
                                 " (0 = no colour image)");
    const std::size_t color_bytes = color == nullptr ? 0 : color_pixel_bytes(color_format);
    const std::uint32_t kMax = static_cast<std::uint32_t>(std::numeric_limits<std::int32_t>::max());
    if (width == 0 || height == 0 || width > kMax || height > kMax)
      fail(SOGMM_E_INVALID_ARG, "image size " + std::to_string(width) + " x " + std::to_string(height) +
                                    " is invalid (each side in [1, 2^31-1])");
    // The frame reader's limit (as many pixels as one fit takes), checked
    // before anything is copied.
    const std::uint64_t pixels = std::uint64_t{width} * height;
    if (pixels > sogmm::kMaxPoints)
      fail(SOGMM_E_LIMIT, "image of " + std::to_string(width) + " x " + std::to_string(height) + " = " +
                              std::to_string(pixels) + " pixels exceeds the limit of " +
                              std::to_string(sogmm::kMaxPoints));
    auto f = std::make_unique<sogmm_frame>();
    f->width = width;
    f->height = height;
    f->depth.assign(depth, depth + pixels);
    if (color != nullptr) {
      const auto* bytes = static_cast<const std::uint8_t*>(color);
      f->color.assign(bytes, bytes + pixels * color_bytes);
      f->color_format = color_format;
    }
    *out = f.release();
  }
  SOGMM_CATCH
}

SOGMM_API void sogmm_frame_free(sogmm_frame* frame) { delete frame; }

SOGMM_API uint32_t sogmm_frame_width(const sogmm_frame* frame) { return frame ? frame->width : 0; }
SOGMM_API uint32_t sogmm_frame_height(const sogmm_frame* frame) { return frame ? frame->height : 0; }
SOGMM_API const uint16_t* sogmm_frame_depth(const sogmm_frame* frame) {
  return frame ? frame->depth.data() : nullptr;
}
SOGMM_API const uint8_t* sogmm_frame_color(const sogmm_frame* frame) {
  return frame && frame->color_format != 0 ? frame->color.data() : nullptr;
}
SOGMM_API int32_t sogmm_frame_color_format(const sogmm_frame* frame) { return frame ? frame->color_format : 0; }

SOGMM_API sogmm_status sogmm_frame_set_intrinsics(sogmm_frame* frame, double fx, double fy, double cx, double cy) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(frame, "frame");
    frame->fx = fx;
    frame->fy = fy;
    frame->cx = cx;
    frame->cy = cy;
    frame->has_intrinsics = true;
  }
  SOGMM_CATCH
}

}  // extern "C"
