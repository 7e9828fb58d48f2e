// Rendering a model into a pinhole camera (issue 29 part 3): what the model
// shows from a pose, pixel by pixel: the first surface along each pixel's
// ray, its depth, and the gray regressed there with its variance. The C API
// (sogmm_model_render_f32, sogmm_map_render_f32), the bindings and the
// `sogmm render` / `sogmm eval` tools all call these functions.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "sogmm/camera.hpp"
#include "sogmm/gmm.hpp"
#include "sogmm/point_cloud.hpp"
#include "sogmm/progress.hpp"

namespace sogmm {

/// How render_expected_surface looks for surfaces.
struct RenderOptions {
  /// Only modes at depth t in (depth_min, depth_max] (metres along the
  /// camera's z axis) count as surfaces; DepthOptions' defaults.
  double depth_min = DepthOptions{}.depth_min;
  double depth_max = DepthOptions{}.depth_max;
  /// A pixel whose ray passes farther than this many standard deviations
  /// (Mahalanobis distance) from every component's mean shows nothing.
  double max_mahalanobis = 3.0;
  /// 0 (default): every mode found is a surface. s > 0: a mode is a surface
  /// only where the evidence sum_k exp(-D_k^2 / 2) at its 3-D point (D_k its
  /// Mahalanobis distance to component k, weights aside) reaches
  /// exp(-s^2 / 2), that of one component at s sigma; a ray that grazes the
  /// tail of a nearer object's components beyond its silhouette then passes
  /// on to the surface behind. s = 2 is the edge of the uniform disc a flat
  /// component is fitted to; gaps between components that cover less than
  /// that show as empty pixels (README, "Per visible pixel").
  double surface_sigma = 0.0;
  /// Worker threads (0 = OpenMP's default, at most 4 x processors). The
  /// images are bitwise the same for any count.
  int threads = 0;
};

/// Throws Error(InvalidArgument) unless 0 <= depth_min < depth_max, both
/// finite, max_mahalanobis finite and > 0, surface_sigma finite and >= 0 and
/// threads >= 0.
void validate(const RenderOptions& options);

/// Rendered images, row-major width x height. A pixel with nothing to show
/// is NaN in all three images (0 is a valid gray, and a depth of 0 would read
/// as a point at the camera).
struct RenderedImages {
  int width = 0;
  int height = 0;
  std::vector<float> depth;     ///< z of the first surface, metres (camera frame)
  std::vector<float> gray;      ///< E[gray | xyz] at that surface point
  std::vector<float> variance;  ///< Var[gray | xyz] there
};

/// Per component, the pieces of its spatial marginal that a ray needs: the
/// precision P = Sigma_xx^-1 (upper triangle xx xy xz yy yz zz), P mu,
/// mu^T P mu and log(w (2 pi)^-3/2 det(Sigma_xx)^-1/2). Throws
/// Error(Numeric) naming the component when Sigma_xx is not positive definite.
struct RayComponent {
  double p[6];
  double pm[3];
  double mpm;
  double log_amp;
};
std::vector<RayComponent> ray_components(const Gmm& gmm);

/// The model's expected surface seen by `camera` at the camera frame's
/// origin (the model's means in that camera's coordinates). For each pixel
/// ray x(t) = t d, d = ((u - cx)/fx, (v - cy)/fy, 1), every component's
/// spatial marginal restricted to the ray is a scaled 1-D Gaussian in t. A
/// 1-D mean shift from each component peak on the ray that lies in
/// (depth_min, depth_max] and within max_mahalanobis of its component climbs
/// to a mode of the ray's 1-D mixture (components within max(8,
/// max_mahalanobis) sigma shape it); with surface_sigma > 0 only modes with
/// that much evidence count. The pixel's depth is the nearest such mode in
/// range: the first surface a camera would see, not the densest (a dense
/// wall behind a sparse object is occluded). Gray and its variance are
/// regress_gray at that 3-D point. `progress` (optional) receives
/// Stage::Rendering reports (step = image rows done, total = height) and may
/// cancel (Error(Cancelled)). Errors: validate(camera), validate(options),
/// ray_components.
RenderedImages render_expected_surface(const Gmm& gmm, const Camera& camera, const RenderOptions& options = {},
                                       const ProgressSink& progress = {});

/// The same from a camera-to-world pose (row-major 4x4 rigid transform; a
/// pose that is not rigid -> Error(InvalidArgument) naming what is wrong):
/// `gmm` is in world coordinates and is moved into the camera's frame with
/// the pose's inverse first. Moving model and pose together by one rigid
/// transform renders the same images (up to rounding).
RenderedImages render(const Gmm& gmm, const Camera& camera, const std::array<double, 16>& camera_to_world,
                      const RenderOptions& options = {}, const ProgressSink& progress = {});

/// Regresses gray (and its variance) at given camera-frame points (x, y, z,
/// gray; gray ignored) and projects them into `camera` with a z-buffer (the
/// nearest point wins): depth = the point's z. Pixels no point projects to
/// are NaN.
RenderedImages render_at_points(const Gmm& gmm, const PointsView& points, const Camera& camera);

/// A rendering compared with an observed frame, pixel by pixel.
struct RenderScores {
  std::size_t n_observed = 0;  ///< pixels with an observed depth (and not masked)
  std::size_t n_both = 0;      ///< of those, pixels the rendering shows too
  double empty_share = 0.0;    ///< 1 - n_both / n_observed: observed pixels the rendering leaves empty
  double depth_mae = 0.0;      ///< mean |rendered - observed| depth over n_both pixels (m); NaN if none
  double psnr = 0.0;           ///< gray PSNR over the n_both pixels, peak data_range (psnr_images); NaN if none
};

/// Compares `rendered` with an observed depth and gray image of the same
/// size (row-major; observed pixels < 0 or NaN are empty). `mask` (may be
/// empty) excludes pixels where it is 0. data_range as psnr_images.
/// Throws Error(InvalidArgument) when the sizes differ.
RenderScores score_render(const RenderedImages& rendered, const std::vector<float>& observed_depth,
                          const std::vector<float>& observed_gray, const std::vector<std::uint8_t>& mask = {},
                          double data_range = 1.0);

}  // namespace sogmm
