// sogmm_frame: accessors, intrinsics, and the fit and map insert that take a
// frame. Both hand the frame's pixels to the RGB-D calls, so a frame gives
// bitwise what those calls give with the same pixels.
#include <memory>
#include <string>
#include <vector>

#include "frame_handle.hpp"
#include "internal.hpp"

namespace {

// The colour bytes and layout the RGB-D calls take: a frame without a colour
// image is fitted with gray 0, as the CLI's depth-only frames are.
struct ColorArg {
  std::vector<std::uint8_t> zeros;
  const std::uint8_t* data;
  std::int32_t format;
};

ColorArg color_of(const sogmm_frame& f) {
  ColorArg c{{}, f.color.data(), f.color_format};
  if (f.color_format == 0) {
    c.zeros.assign(static_cast<std::size_t>(f.width) * f.height, 0);
    c.data = c.zeros.data();
    c.format = SOGMM_COLOR_GRAY8;
  }
  return c;
}

void require_intrinsics(const sogmm_frame& f) {
  if (!f.has_intrinsics)
    sogmm_capi::fail(SOGMM_E_INVALID_ARG, "the frame has no intrinsics (call sogmm_frame_set_intrinsics first)");
}

}  // namespace

extern "C" {

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

SOGMM_API sogmm_status sogmm_fit_frame(sogmm_model** out, const sogmm_frame* frame, const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    sogmm_capi::require_nonnull(frame, "frame");
    require_intrinsics(*frame);
    const ColorArg c = color_of(*frame);
    return sogmm_fit_rgbd(out, frame->depth.data(), c.data, c.format, frame->width, frame->height, frame->fx,
                          frame->fy, frame->cx, frame->cy, options);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_insert_frame(sogmm_map* map, const sogmm_frame* frame, const double* pose) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(map, "map");
    sogmm_capi::require_nonnull(frame, "frame");
    require_intrinsics(*frame);
    const ColorArg c = color_of(*frame);
    return sogmm_map_insert_rgbd(map, frame->depth.data(), c.data, c.format, frame->width, frame->height,
                                 frame->fx, frame->fy, frame->cx, frame->cy, pose);
  }
  SOGMM_CATCH
}

}  // extern "C"
