// The per-pixel figures of `sogmm eval` (issue 29 part 3): the model
// rendered from the frame's camera (sogmm/render.hpp) against the frame's
// depth and gray, on the fitting grid and on a held-out grid, and the mean
// log-likelihood of the frame's points on both grids.
#pragma once

#include <cstddef>

#include <nlohmann/json.hpp>

#include "image_io.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/render.hpp"

namespace sogmm::tools {

/// The held-out grid of a fit at decimation d: the pixels of the d + 1 grid
/// (source pixels (u (d+1), v (d+1))) that are not on the fitting grid (both
/// coordinates multiples of d). The fit never saw them; they sample the same
/// surfaces as densely.
struct PixelFigures {
  int decimate = 1;           ///< the fitting grid d
  RenderScores fit_grid;      ///< rendered vs observed on the fitting grid
  RenderScores heldout;       ///< the same on the held-out grid
  double log_likelihood = 0;  ///< mean 4-D log-likelihood per point of the fitting grid's points
  double log_likelihood_heldout = 0;  ///< the same over the held-out grid's points
  std::size_t n_points_heldout = 0;
};

/// The figures of `gmm` (in the frame's camera coordinates) against `frame`
/// (full-size `camera`; decimation and depth range from `depth`);
/// `data_range` is the PSNR's peak (psnr_images); `surface_sigma` the
/// renders' RenderOptions::surface_sigma.
PixelFigures pixel_figures(const Gmm& gmm, const LoadedFrame& frame, const Camera& camera, const DepthOptions& depth,
                           double data_range, double surface_sigma);

/// Adds the figures to an `eval --json` object: depth_mae, empty_share,
/// pixel_psnr (fitting grid) and the same with _heldout, n_pixels and
/// n_pixels_heldout (observed pixels compared), log_likelihood_fit_grid,
/// log_likelihood_heldout, heldout_decimate.
void add_to_json(const PixelFigures& p, nlohmann::json& j);

/// Prints the figures as lines of the human table.
void print_pixel_figures(const PixelFigures& p);

}  // namespace sogmm::tools
