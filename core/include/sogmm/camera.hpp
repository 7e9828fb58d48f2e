// Pinhole camera model and RGB-D frame back-projection (core::camera).
//
// The core works on raw, row-major pixel buffers; reading image files is the
// job of the tools (OpenCV), never of this header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/point_cloud.hpp"

namespace sogmm {

/// Pinhole intrinsics, Open3D's PinholeCameraIntrinsic names. Pixel (u, v)
/// with depth z back-projects to x = (u - cx) z / fx, y = (v - cy) z / fy.
struct Camera {
  int width = 0;     ///< image width in pixels
  int height = 0;    ///< image height in pixels
  double fx = 0.0;   ///< focal length along u, pixels
  double fy = 0.0;   ///< focal length along v, pixels
  double cx = 0.0;   ///< principal point u, pixels
  double cy = 0.0;   ///< principal point v, pixels
};

/// How a depth image becomes metric points.
struct DepthOptions {
  double depth_scale = 1000.0;  ///< raw units per metre (1000: millimetres; TUM uses 5000)
  double depth_min = 0.1;       ///< points with depth <= depth_min (m) are invalid
  double depth_max = 3.0;       ///< points with depth > depth_max (m) are invalid
  int decimate = 1;             ///< integer decimation factor d >= 1
};

/// Throws Error(InvalidArgument) unless width, height > 0 and fx, fy > 0 and
/// all values finite.
void validate(const Camera& camera);
/// Throws Error(InvalidArgument) unless depth_scale > 0, 0 <= min < max, d >= 1.
void validate(const DepthOptions& options);

/// Checks a frame's geometry before anything is allocated for it (backproject()
/// starts with this): validate(camera) and validate(options), a decimation that
/// leaves at least one pixel, at most kMaxPoints (sogmm/fit.hpp) pixels in the
/// decimated image (Error(Limit): no fit could take more points, and the
/// check needs only the image size), and intrinsics and depth options for which
/// every back-projected coordinate is finite in float32 (Error(InvalidArgument)
/// naming the values: e.g. fx = 1e-300 would give x = -inf).
void check_backprojection(const Camera& camera, const DepthOptions& options);

/// The camera of the image decimated by d: size (W/d, H/d) (integer division)
/// and intrinsics divided by d. The one decimation convention of SOGMM:
/// decimated pixel (u, v) is source pixel (d u, d v), so that pixel's ray is
/// exactly the ray of the divided intrinsics, whether or not d divides the
/// image size. (This equals OpenCV's INTER_NEAREST resize to (W/d, H/d) when d
/// divides W and H; for other d, INTER_NEAREST picks floor(u W / (W/d)), whose
/// ray the divided intrinsics do not describe: up to 12 mm off at d = 7 on
/// 640x480, issue 14 item 7.)
Camera decimated(const Camera& camera, int d);

/// Gray in [0, 1] from 8-bit RGB: (0.299 R + 0.587 G + 0.114 B) / 255.
float gray_from_rgb(std::uint8_t r, std::uint8_t g, std::uint8_t b);

/// A registered gray image as the core consumes it: width x height floats in
/// [0, 1], row-major.
struct GrayImage {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;
};

/// Converts interleaved 8-bit RGB (3 * width * height bytes) to gray.
GrayImage gray_from_rgb_image(const std::uint8_t* rgb, int width, int height);
/// Converts an 8-bit gray image to [0, 1] floats.
GrayImage gray_from_u8_image(const std::uint8_t* gray, int width, int height);

/// A frame: a 16-bit depth image and its registered gray image, both
/// `camera.width` x `camera.height`, row-major. The pointers are views.
struct RgbdView {
  const std::uint16_t* depth = nullptr;  ///< raw depth, depth_scale units per metre; 0 = no reading
  const float* gray = nullptr;           ///< gray in [0, 1]
  Camera camera;                         ///< intrinsics of these full-size images
};

/// Back-projects the valid pixels of a frame, after decimation, into (x, y, z,
/// gray) points in the camera frame (x right, y down, z forward; metres).
/// Decimated pixel (u, v) reads depth and gray at source pixel (d u, d v) and
/// back-projects with decimated(camera, d), so every point lies on the ray of
/// the source pixel its depth was read from (see decimated()). A pixel is valid when depth_min < depth / depth_scale <= depth_max. Points are
/// ordered row by row. Throws as check_backprojection() for a bad camera,
/// options or image size.
PointCloud backproject(const RgbdView& frame, const DepthOptions& options);

/// Pixel index (row-major) in the decimated image of every point that
/// backproject() returns, in the same order.
std::vector<std::int32_t> valid_pixel_indices(const RgbdView& frame, const DepthOptions& options);

/// Projects points into a width x height image of `camera` with a z-buffer:
/// the point nearest to the camera wins a pixel; empty pixels hold `empty`.
/// `values` holds one value per point (e.g. gray); points behind the camera
/// (z <= 0) or outside the image are ignored. Pixel = round(f x / z + c).
std::vector<float> project_to_image(const PointsView& points, const float* values,
                                    const Camera& camera, float empty = -1.0f);

/// Reads Open3D's PinholeCameraIntrinsic JSON ({"width", "height",
/// "intrinsic_matrix": 9 numbers, column-major}). Throws Error(Io) when the
/// file cannot be read and Error(Format) naming the missing/invalid field.
Camera read_intrinsics_json(const std::string& path);
/// Same, from the JSON text; `source` names it in error messages.
Camera parse_intrinsics_json(const std::string& text, const std::string& source = "intrinsics");

}  // namespace sogmm
