#include "eval_pixels.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

#include "sogmm/inference.hpp"

namespace sogmm::tools {

namespace {

// A frame seen on one grid: observed depth and gray per pixel of the
// decimated camera (-1 = no valid depth), its points, and which pixels count.
struct Grid {
  Camera camera;
  std::vector<float> depth, gray;
  std::vector<std::uint8_t> mask;  // 1 = compared
  std::vector<float> points;       // rows x y z gray of the compared pixels
};

// The frame on the grid of decimation `e`; with `exclude` > 0, pixels on the
// grid of decimation `exclude` (source coordinates both multiples of it)
// are left out.
Grid observe(const LoadedFrame& frame, const Camera& camera, const DepthOptions& depth, int e, int exclude) {
  DepthOptions de = depth;
  de.decimate = e;
  const PointCloud cloud = backproject(frame.view(camera), de);
  Grid g;
  g.camera = decimated(camera, e);
  std::vector<float> z(cloud.size()), gray(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    z[i] = cloud.xyzg[4 * i + 2];
    gray[i] = cloud.xyzg[4 * i + 3];
  }
  g.depth = project_to_image(cloud.view(), z.data(), g.camera, -1.f);
  g.gray = project_to_image(cloud.view(), gray.data(), g.camera, -1.f);
  const std::size_t w = static_cast<std::size_t>(g.camera.width);
  g.mask.assign(g.depth.size(), 1);
  if (exclude > 0)
    for (std::size_t i = 0; i < g.mask.size(); ++i) {
      const std::size_t u = (i % w) * static_cast<std::size_t>(e), v = (i / w) * static_cast<std::size_t>(e);
      if (u % static_cast<std::size_t>(exclude) == 0 && v % static_cast<std::size_t>(exclude) == 0) g.mask[i] = 0;
    }
  // The compared pixels' points, rebuilt from the observed images exactly as
  // back-projection computes them on this grid.
  for (std::size_t i = 0; i < g.depth.size(); ++i) {
    if (g.mask[i] == 0 || g.depth[i] < 0) continue;
    const double zz = g.depth[i];
    const double u = static_cast<double>(i % w), v = static_cast<double>(i / w);
    g.points.insert(g.points.end(), {static_cast<float>((u - g.camera.cx) * zz / g.camera.fx),
                                     static_cast<float>((v - g.camera.cy) * zz / g.camera.fy), g.depth[i], g.gray[i]});
  }
  return g;
}

RenderScores compare(const Gmm& gmm, const Grid& g, const DepthOptions& depth, double data_range,
                     double surface_sigma) {
  RenderOptions o;
  o.surface_sigma = surface_sigma;
  o.depth_min = depth.depth_min;
  o.depth_max = depth.depth_max;
  return score_render(render_expected_surface(gmm, g.camera, o), g.depth, g.gray, g.mask, data_range);
}

double mean_ll(const Gmm& gmm, const std::vector<float>& points) {
  if (points.empty()) return std::nan("");
  return mean_log_likelihood(gmm, points.data(), points.size() / 4, 4);
}

}  // namespace

PixelFigures pixel_figures(const Gmm& gmm, const LoadedFrame& frame, const Camera& camera, const DepthOptions& depth,
                           double data_range, double surface_sigma) {
  PixelFigures p;
  p.decimate = depth.decimate;
  const Grid fit = observe(frame, camera, depth, depth.decimate, 0);
  const Grid held = observe(frame, camera, depth, depth.decimate + 1, depth.decimate);
  p.fit_grid = compare(gmm, fit, depth, data_range, surface_sigma);
  p.heldout = compare(gmm, held, depth, data_range, surface_sigma);
  p.log_likelihood = mean_ll(gmm, fit.points);
  p.log_likelihood_heldout = mean_ll(gmm, held.points);
  p.n_points_heldout = held.points.size() / 4;
  return p;
}

void add_to_json(const PixelFigures& p, nlohmann::json& j) {
  // JSON has no NaN: a figure without pixels is null.
  auto num = [](double x) { return std::isnan(x) ? nlohmann::json() : nlohmann::json(x); };
  j["heldout_decimate"] = p.decimate + 1;
  j["n_pixels"] = p.fit_grid.n_observed;
  j["depth_mae"] = num(p.fit_grid.depth_mae);
  j["empty_share"] = num(p.fit_grid.empty_share);
  j["pixel_psnr"] = num(p.fit_grid.psnr);
  j["n_pixels_heldout"] = p.heldout.n_observed;
  j["depth_mae_heldout"] = num(p.heldout.depth_mae);
  j["empty_share_heldout"] = num(p.heldout.empty_share);
  j["pixel_psnr_heldout"] = num(p.heldout.psnr);
  j["log_likelihood_fit_grid"] = num(p.log_likelihood);
  j["log_likelihood_heldout"] = num(p.log_likelihood_heldout);
}

void print_pixel_figures(const PixelFigures& p) {
  std::printf("per visible pixel   the model's first surface along each pixel's ray vs the frame\n");
  std::printf("  %-28s %10s %10s %10s %10s\n", "grid", "pixels", "depth MAE", "empty", "PSNR dB");
  const auto row = [](const char* name, const RenderScores& s) {
    std::printf("  %-28s %10zu %8.2f mm %9.1f%% %10.2f\n", name, s.n_observed, 1000 * s.depth_mae,
                100 * s.empty_share, s.psnr);
  };
  char fit[64], held[64];
  std::snprintf(fit, sizeof fit, "fitting (d = %d)", p.decimate);
  std::snprintf(held, sizeof held, "held-out (d = %d minus d = %d)", p.decimate + 1, p.decimate);
  row(fit, p.fit_grid);
  row(held, p.heldout);
  std::printf("mean log-likelihood %.4f on the fitting grid, %.4f held out (%zu points)\n", p.log_likelihood,
              p.log_likelihood_heldout, p.n_points_heldout);
}

}  // namespace sogmm::tools
