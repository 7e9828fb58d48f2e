// RGB-D frames: argument checks and back-projection shared by sogmm_fit_rgbd
// and sogmm_rgbd_to_points_f32, so both see exactly the same points.
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

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

RgbdPoints backproject_rgbd(const std::uint16_t* depth, const std::uint8_t* color, std::int32_t color_format,
                            std::uint32_t width, std::uint32_t height, double fx, double fy, double cx, double cy,
                            const sogmm_options& o) {
  require_nonnull(depth, "depth");
  require_nonnull(color, "color");
  if (color_format != SOGMM_COLOR_GRAY8 && color_format != SOGMM_COLOR_RGB8 && color_format != SOGMM_COLOR_GRAY_F32)
    fail(SOGMM_E_INVALID_ARG, "unknown color_format " + std::to_string(color_format));
  const std::uint32_t kMax = static_cast<std::uint32_t>(std::numeric_limits<std::int32_t>::max());
  if (width == 0 || height == 0 || width > kMax || height > kMax)
    fail(SOGMM_E_INVALID_ARG, "image size " + std::to_string(width) + " x " + std::to_string(height) +
                                  " is invalid (each side in [1, 2^31-1])");
  const std::size_t pixels = sogmm::checked::mul<std::size_t>(width, height, "image pixels");
  sogmm::checked::bytes(pixels, sizeof(float), "color image bytes");
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

  const sogmm::GrayImage gray =
      color_format == SOGMM_COLOR_RGB8     ? sogmm::gray_from_rgb_image(color, r.camera.width, r.camera.height)
      : color_format == SOGMM_COLOR_GRAY8 ? sogmm::gray_from_u8_image(color, r.camera.width, r.camera.height)
                                          : gray_from_f32_image(color, r.camera.width, r.camera.height);
  sogmm::RgbdView frame;
  frame.depth = depth;
  frame.gray = gray.pixels.data();
  frame.camera = r.camera;
  r.cloud = sogmm::backproject(frame, r.depth);
  return r;
}

}  // namespace sogmm_capi

extern "C" {

SOGMM_API sogmm_status sogmm_rgbd_to_points_f32(float* out, size_t capacity, size_t* n_points, const uint16_t* depth,
                                                const uint8_t* color, int32_t color_format, uint32_t width,
                                                uint32_t height, double fx, double fy, double cx, double cy,
                                                const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(n_points, "n_points");
    if (out == nullptr && capacity != 0) sogmm_capi::fail(SOGMM_E_NULL_ARG, "out is NULL but capacity is not 0");
    const sogmm_capi::RgbdPoints r = sogmm_capi::backproject_rgbd(
        depth, color, color_format, width, height, fx, fy, cx, cy, sogmm_capi::opts_or_default(options));
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
