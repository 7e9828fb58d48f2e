// Pinhole camera, decimation and back-projection.
#include "sogmm/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/options.hpp"

namespace sogmm {

void validate(const Camera& c) {
  require(c.width > 0 && c.height > 0, ErrorCode::InvalidArgument,
          "camera size must be positive, got " + std::to_string(c.width) + "x" + std::to_string(c.height));
  require(std::isfinite(c.fx) && std::isfinite(c.fy) && c.fx > 0 && c.fy > 0, ErrorCode::InvalidArgument,
          "camera focal lengths fx, fy must be positive and finite");
  require(std::isfinite(c.cx) && std::isfinite(c.cy), ErrorCode::InvalidArgument,
          "camera principal point cx, cy must be finite");
}

void validate(const DepthOptions& o) {
  require_option(OptionKey::DEPTH_SCALE, o.depth_scale, "depth scale");
  require_option(OptionKey::DEPTH_MIN, o.depth_min, "depth_min");
  require_option(OptionKey::DEPTH_MAX, o.depth_max, "depth_max");
  require(std::isfinite(o.depth_min) && std::isfinite(o.depth_max) && o.depth_min >= 0 && o.depth_min < o.depth_max,
          ErrorCode::InvalidArgument,
          "depth range must satisfy 0 <= min < max, got (" + checked::exact(o.depth_min) + ", " +
              checked::exact(o.depth_max) + "]");
  require_option(OptionKey::DECIMATION, std::int64_t{o.decimate}, "decimation factor");
}

namespace {

bool fits_float(double v) { return std::isfinite(static_cast<float>(v)); }

// Largest |(p - c) z / f| over the pixel coordinates p in [0, size) and depths
// z in [0, z_max], computed as backproject() computes each coordinate: IEEE
// rounding is monotonic, so no pixel gives a larger magnitude.
double largest_coordinate(int size, double c, double f, double z_max) {
  const double span = std::max(std::fabs(0.0 - c), std::fabs(static_cast<double>(size - 1) - c));
  return span * z_max / f;
}

}  // namespace

void check_backprojection(const Camera& camera, const DepthOptions& options) {
  validate(camera);
  validate(options);
  const Camera cam = decimated(camera, options.decimate);
  const auto pixels = checked::mul<std::uint64_t>(static_cast<std::uint64_t>(cam.width),
                                                  static_cast<std::uint64_t>(cam.height), "decimated image pixels");
  require(pixels <= kMaxPoints, ErrorCode::Limit,
          "the decimated image has " + std::to_string(cam.width) + " x " + std::to_string(cam.height) + " = " +
              std::to_string(pixels) + " pixels, over the limit of " + std::to_string(kMaxPoints) +
              " points per fit: use a larger decimation");
  // A pixel is valid when depth_min < raw / depth_scale <= depth_max, raw <= 65535.
  const double z_raw_max = 65535.0 * (1.0 / options.depth_scale);
  if (!(z_raw_max > options.depth_min)) return;  // no pixel can be valid
  const double z_max = std::min(z_raw_max, options.depth_max);
  require(fits_float(z_max), ErrorCode::InvalidArgument,
          "depth scale " + checked::exact(options.depth_scale) + " and depth_max " + checked::exact(options.depth_max) +
              " let z reach " + checked::exact(z_max) + " m, beyond the float32 range");
  const double x_max = largest_coordinate(cam.width, cam.cx, cam.fx, z_max);
  require(fits_float(x_max), ErrorCode::InvalidArgument,
          "fx = " + checked::exact(camera.fx) + " and cx = " + checked::exact(camera.cx) + " let x reach " +
              checked::exact(x_max) + " m (depth up to " + checked::exact(z_max) +
              " m), beyond the float32 range: the intrinsics are invalid");
  const double y_max = largest_coordinate(cam.height, cam.cy, cam.fy, z_max);
  require(fits_float(y_max), ErrorCode::InvalidArgument,
          "fy = " + checked::exact(camera.fy) + " and cy = " + checked::exact(camera.cy) + " let y reach " +
              checked::exact(y_max) + " m (depth up to " + checked::exact(z_max) +
              " m), beyond the float32 range: the intrinsics are invalid");
}

Camera decimated(const Camera& camera, int d) {
  require(d >= 1, ErrorCode::InvalidArgument, "decimation factor must be >= 1, got " + std::to_string(d));
  require(camera.width / d >= 1 && camera.height / d >= 1, ErrorCode::InvalidArgument,
          "decimation factor " + std::to_string(d) + " leaves no pixels of a " + std::to_string(camera.width) + "x" +
              std::to_string(camera.height) + " image");
  Camera out = camera;
  out.width = camera.width / d;
  out.height = camera.height / d;
  out.fx /= d;
  out.fy /= d;
  out.cx /= d;
  out.cy /= d;
  return out;
}

float gray_from_rgb(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  return (0.299f * r + 0.587f * g + 0.114f * b) / 255.0f;
}

GrayImage gray_from_rgb_image(const std::uint8_t* rgb, int width, int height) {
  require(rgb != nullptr && width > 0 && height > 0, ErrorCode::InvalidData, "color image is empty");
  GrayImage out{width, height, std::vector<float>(checked::mul<std::size_t>(static_cast<std::size_t>(width), static_cast<std::size_t>(height), "gray image pixels"))};
  for (std::size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] = gray_from_rgb(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]);
  return out;
}

GrayImage gray_from_u8_image(const std::uint8_t* gray, int width, int height) {
  require(gray != nullptr && width > 0 && height > 0, ErrorCode::InvalidData, "gray image is empty");
  GrayImage out{width, height, std::vector<float>(checked::mul<std::size_t>(static_cast<std::size_t>(width), static_cast<std::size_t>(height), "gray image pixels"))};
  for (std::size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] = gray[i] / 255.0f;
  return out;
}

namespace {

// Visits the valid pixels of the decimated frame in row-major order.
template <typename Visit>
void for_each_valid_pixel(const RgbdView& frame, const DepthOptions& options, Visit&& visit) {
  check_backprojection(frame.camera, options);
  require(frame.depth != nullptr, ErrorCode::InvalidData, "depth image is empty");
  require(frame.gray != nullptr, ErrorCode::InvalidData, "gray image is empty");
  const Camera cam = decimated(frame.camera, options.decimate);
  const double inv_scale = 1.0 / options.depth_scale;
  const std::size_t d = static_cast<std::size_t>(options.decimate);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      // Source pixel (d u, d v): the one the intrinsics divided by d describe
      // (see decimated()); (H/d - 1) d < H, so it is always inside the image.
      const std::size_t src = d * static_cast<std::size_t>(v) * frame.camera.width + d * static_cast<std::size_t>(u);
      const double z = frame.depth[src] * inv_scale;
      if (!(z > options.depth_min && z <= options.depth_max)) continue;
      visit(cam, u, v, z, frame.gray[src]);
    }
  }
}

}  // namespace

PointCloud backproject(const RgbdView& frame, const DepthOptions& options) {
  PointCloud cloud;
  cloud.from_depth_image = true;
  for_each_valid_pixel(frame, options, [&](const Camera& cam, int u, int v, double z, float g) {
    cloud.xyzg.push_back(static_cast<float>((u - cam.cx) * z / cam.fx));
    cloud.xyzg.push_back(static_cast<float>((v - cam.cy) * z / cam.fy));
    cloud.xyzg.push_back(static_cast<float>(z));
    cloud.xyzg.push_back(g);
  });
  return cloud;
}

std::vector<std::int32_t> valid_pixel_indices(const RgbdView& frame, const DepthOptions& options) {
  std::vector<std::int32_t> indices;
  for_each_valid_pixel(frame, options, [&](const Camera& cam, int u, int v, double, float) {
    indices.push_back(v * cam.width + u);
  });
  return indices;
}

std::vector<float> project_to_image(const PointsView& points, const float* values, const Camera& camera, float empty) {
  validate(camera);
  const std::size_t pixels = checked::mul<std::size_t>(static_cast<std::size_t>(camera.width), static_cast<std::size_t>(camera.height), "image pixels");
  std::vector<float> image(pixels, empty);
  std::vector<float> zbuf(pixels, std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < points.size; ++i) {
    const float* p = points[i];
    const double z = p[2];
    if (!(z > 0.0) || !std::isfinite(p[0]) || !std::isfinite(p[1])) continue;
    const double u = std::nearbyint(camera.fx * p[0] / z + camera.cx);
    const double v = std::nearbyint(camera.fy * p[1] / z + camera.cy);
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
    const std::size_t idx = static_cast<std::size_t>(v) * camera.width + static_cast<std::size_t>(u);
    if (z < zbuf[idx]) {
      zbuf[idx] = static_cast<float>(z);
      image[idx] = values[i];
    }
  }
  return image;
}

}  // namespace sogmm
