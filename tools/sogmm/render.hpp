// Pictures of a rendered model (the rendering itself is in the core,
// sogmm/render.hpp): gray, the conditional standard deviation as a heat map,
// and the side-by-side comparison with a frame.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/render.hpp"

namespace sogmm::tools {

/// A rendered view: per pixel (row-major, camera.width x camera.height) the
/// regressed gray, its conditional standard deviation and the depth used;
/// pixels with nothing to show hold -1 in all three.
struct RenderedView {
  int width = 0, height = 0;
  std::vector<float> gray, stddev, depth;
};

/// The view of core images (sogmm/render.hpp) that the panels draw: NaN
/// pixels become -1, the variance its square root.
RenderedView panel_view(const RenderedImages& images);

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
