// A rendering compared with an observed frame, pixel by pixel
// (score_render, sogmm/render.hpp).
#include <cmath>
#include <limits>
#include <string>

#include "sogmm/error.hpp"
#include "sogmm/metrics.hpp"
#include "sogmm/render.hpp"

namespace sogmm {

RenderScores score_render(const RenderedImages& rendered, const std::vector<float>& observed_depth,
                          const std::vector<float>& observed_gray, const std::vector<std::uint8_t>& mask,
                          double data_range) {
  const std::size_t pixels = rendered.depth.size();
  require(observed_depth.size() == pixels && observed_gray.size() == pixels && rendered.gray.size() == pixels &&
              (mask.empty() || mask.size() == pixels),
          ErrorCode::InvalidArgument,
          "score_render: the rendered, observed and mask images differ in size (" + std::to_string(pixels) +
              " rendered pixels)");
  RenderScores s;
  // psnr_images' convention: -1 marks a pixel left out of the comparison.
  std::vector<float> truth(pixels, -1.f), estimate(pixels, -1.f);
  double abs_sum = 0.0;
  for (std::size_t i = 0; i < pixels; ++i) {
    if (!mask.empty() && mask[i] == 0) continue;
    if (!(observed_depth[i] >= 0.f)) continue;  // NaN or < 0: no observation
    ++s.n_observed;
    if (std::isnan(rendered.depth[i])) continue;
    ++s.n_both;
    abs_sum += std::abs(static_cast<double>(rendered.depth[i]) - observed_depth[i]);
    truth[i] = observed_gray[i];
    estimate[i] = rendered.gray[i];
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  s.empty_share = s.n_observed > 0 ? 1.0 - static_cast<double>(s.n_both) / static_cast<double>(s.n_observed) : nan;
  s.depth_mae = s.n_both > 0 ? abs_sum / static_cast<double>(s.n_both) : nan;
  s.psnr = s.n_both > 0 ? psnr_images(truth.data(), estimate.data(), pixels, data_range).psnr : nan;
  return s;
}

}  // namespace sogmm
