// Rendering a model into a camera: gray at given or expected depths, the
// conditional standard deviation, and the side-by-side comparison picture.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/gmm.hpp"

namespace sogmm::tools {

/// A rendered view: per pixel (row-major, camera.width x camera.height) the
/// regressed gray, its conditional standard deviation and the depth used;
/// pixels with nothing to show hold -1 in all three.
struct RenderedView {
  int width = 0, height = 0;
  std::vector<float> gray, stddev, depth;
};

/// Regresses gray (and its standard deviation) at the given points (rows of
/// 4 floats; the 4th is ignored) and projects them with a z-buffer.
RenderedView render_at_points(const Gmm& gmm, const std::vector<float>& xyzg, const Camera& camera);

/// The model's own expected surface, without a depth image. For each pixel
/// ray x(t) = t d (d = ((u - cx)/fx, (v - cy)/fy, 1), t = depth), each
/// component's 3-D marginal restricted to the ray is a scaled 1-D Gaussian in
/// t. 1-D mean shift from every component peak on the ray in (depth_min,
/// depth_max] climbs to a mode of that 1-D mixture; the pixel's depth is the
/// nearest such mode: the first surface a camera would see, not the densest
/// one (a dense wall behind a sparse object in front is occluded). A pixel
/// whose ray stays outside the `max_mahalanobis`-sigma ellipsoid of every
/// component shows nothing. Gray and its standard deviation are then
/// regressed at the 3-D point of that depth.
RenderedView render_expected_surface(const Gmm& gmm, const Camera& camera, double depth_min, double depth_max,
                                     double max_mahalanobis = 3.0);

/// 8-bit gray image (one channel) of values in [0, 1]; -1 (empty) pixels are 0.
std::vector<std::uint8_t> gray_to_u8(const std::vector<float>& values);

/// An 8-bit BGR image of `values` through a colour map (OpenCV INFERNO) scaled
/// 0..vmax, upscaled by `scale`, empty pixels dark gray, with a vertical
/// colour bar labelled 0..vmax and a title line; width/height returned.
std::vector<std::uint8_t> heat_map_with_bar(const std::vector<float>& values, int width, int height, double vmax,
                                            int scale, const std::string& title, int* out_width, int* out_height);

/// The comparison picture: original gray | regressed gray | |error| heat map
/// with colour bar, each panel upscaled by `scale`, a title line above each
/// and `headline` (e.g. the PSNR) across the top. BGR, size returned.
std::vector<std::uint8_t> compose_compare(const std::vector<float>& truth, const std::vector<float>& estimate,
                                          int width, int height, double error_max, int scale,
                                          const std::string& headline, int* out_width, int* out_height);

}  // namespace sogmm::tools
