// RGB-D frames: the checks and back-projection shared by sogmm_fit_frame,
// sogmm_map_insert_frame and sogmm_frame_to_points_f32, so all three see
// exactly the same points.
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "frame_handle.hpp"
#include "internal.hpp"
#include "sogmm/checked.hpp"

namespace sogmm_capi {
namespace {

void require_intrinsic(double v, bool positive, const char* name) {
  if (!std::isfinite(v) || (positive && !(v > 0)))
    fail(SOGMM_E_INVALID_ARG, std::string(name) + " = " + sogmm::checked::exact(v) + " is invalid (" +
                                  (positive ? "must be finite and > 0)" : "must be finite)"));
}

/// Float gray as given (the caller's normalisation, e.g. of a thermal image);
/// every pixel must be finite so that no NaN reaches a point.
sogmm::GrayImage gray_from_f32_image(const std::uint8_t* bytes, int width, int height) {
  sogmm::GrayImage g;
  g.width = width;
  g.height = height;
  g.pixels.resize(sogmm::checked::mul<std::size_t>(width, height, "float gray pixels"));
  std::memcpy(g.pixels.data(), bytes, g.pixels.size() * sizeof(float));  // the caller's floats, any alignment
  for (std::size_t i = 0; i < g.pixels.size(); ++i)
    if (!std::isfinite(g.pixels[i]))
      fail(SOGMM_E_INVALID_DATA, "color: gray pixel (" + std::to_string(i % width) + ", " +
                                     std::to_string(i / width) + ") is not finite");
  return g;
}

}  // namespace

RgbdPoints backproject_frame(const sogmm_frame* f, const sogmm_options& o) {
  require_nonnull(f, "frame");
  if (!f->has_intrinsics) fail(SOGMM_E_INVALID_ARG, "the frame has no intrinsics (call sogmm_frame_set_intrinsics first)");
  const std::uint32_t width = f->width, height = f->height;
  const double fx = f->fx, fy = f->fy, cx = f->cx, cy = f->cy;
  require_intrinsic(fx, true, "fx");
  require_intrinsic(fy, true, "fy");
  require_intrinsic(cx, false, "cx");
  require_intrinsic(cy, false, "cy");

  RgbdPoints r;
  r.camera.width = static_cast<int>(width);
  r.camera.height = static_cast<int>(height);
  r.camera.fx = fx;
  r.camera.fy = fy;
  r.camera.cx = cx;
  r.camera.cy = cy;
  r.depth = o.settings.depth;
  require_depth_range(o);
  const std::int64_t decimation = r.depth.decimate;
  if (decimation > static_cast<std::int64_t>(width) || decimation > static_cast<std::int64_t>(height))
    fail(SOGMM_E_INVALID_ARG, "decimation " + std::to_string(decimation) + " leaves no pixel of a " +
                                  std::to_string(width) + " x " + std::to_string(height) + " image");
  // Before the color image is converted: the size limit and the finiteness of
  // the back-projection depend on the image size and parameters only.
  sogmm::check_backprojection(r.camera, r.depth);

  // A frame without a colour image is fitted with gray 0, as the CLI's
  // depth-only frames are.
  const std::uint8_t* color = f->color.data();
  sogmm::GrayImage gray;
  switch (f->color_format) {
    case SOGMM_COLOR_RGB8: gray = sogmm::gray_from_rgb_image(color, r.camera.width, r.camera.height); break;
    case SOGMM_COLOR_GRAY8: gray = sogmm::gray_from_u8_image(color, r.camera.width, r.camera.height); break;
    case SOGMM_COLOR_GRAY_F32: gray = gray_from_f32_image(color, r.camera.width, r.camera.height); break;
    default:
      gray.width = r.camera.width;
      gray.height = r.camera.height;
      gray.pixels.assign(static_cast<std::size_t>(width) * height, 0.0f);
  }
  sogmm::RgbdView frame;
  frame.depth = f->depth.data();
  frame.gray = gray.pixels.data();
  frame.camera = r.camera;
  r.cloud = sogmm::backproject(frame, r.depth);
  return r;
}

}  // namespace sogmm_capi

extern "C" {

SOGMM_API sogmm_status sogmm_frame_to_points_f32(float* out, size_t capacity, size_t* n_points,
                                                 const sogmm_frame* frame, const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(n_points, "n_points");
    if (out == nullptr && capacity != 0) sogmm_capi::fail(SOGMM_E_NULL_ARG, "out is NULL but capacity is not 0");
    const sogmm_capi::RgbdPoints r = sogmm_capi::backproject_frame(frame, sogmm_capi::opts_or_default(options));
    const std::size_t n = r.cloud.size();
    if (out != nullptr && capacity < r.cloud.xyzg.size()) {
      *n_points = n;  // the documented exception: the size to allocate comes with the error
      sogmm_capi::fail(SOGMM_E_BUFFER_TOO_SMALL, "out has room for " + std::to_string(capacity) +
                                                     " floats but the frame has " + std::to_string(n) +
                                                     " points (" + std::to_string(r.cloud.xyzg.size()) + " floats)");
    }
    if (out != nullptr && n > 0) std::memcpy(out, r.cloud.xyzg.data(), r.cloud.xyzg.size() * sizeof(float));
    *n_points = n;
  }
  SOGMM_CATCH
}

}  // extern "C"
