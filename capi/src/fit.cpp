// Fitting: from an N x 4 point array (self-organizing or fixed K) and from a
// raw RGB-D frame.
#include <cmath>
#include <limits>
#include <string>

#include "internal.hpp"
#include "sogmm/camera.hpp"
#include "sogmm/fit.hpp"

namespace {

using sogmm_capi::fail;
using sogmm_capi::require_nonnull;

sogmm::FitOptions fit_options(const sogmm_options& o, std::size_t k) {
  sogmm::FitOptions f;
  f.bandwidth = o.bandwidth;
  f.n_components = k;
  f.mode_counter = o.mode_counter == SOGMM_MODE_COUNTER_GAUSSIAN_BLURRING
                       ? sogmm::ModeCounter::GaussianBlurring
                       : sogmm::ModeCounter::FlatBinned;
  f.seed = static_cast<std::uint64_t>(o.seed);
  f.n_init = static_cast<int>(o.n_init);
  f.em.tol = o.tol;
  f.em.reg_covar = o.reg_covar;
  f.em.max_iter = static_cast<int>(o.max_iter);
  f.em.threads = static_cast<int>(o.threads);
  f.em.truncation_nats = o.truncation_nats;
  return f;
}

/// Runs the fit on checked points and wraps the result (fit report, fit
/// parameters, timings) in a new handle.
sogmm_model* fit_to_handle(const float* points, std::size_t n, std::size_t k, const sogmm_options& o) {
  if (n == 0) fail(SOGMM_E_INVALID_DATA, "n is 0: nothing to fit");
  const std::size_t count = sogmm_capi::checked_mul(n, 4, "points");
  // The size limit first, so an oversized input is refused before it is read.
  if (n > sogmm::kMaxPoints)
    fail(SOGMM_E_LIMIT, "n = " + std::to_string(n) + " points exceeds the limit of " +
                            std::to_string(sogmm::kMaxPoints) + " per fit");
  // Checked here, before any parallel region of the core runs.
  sogmm_capi::require_finite(points, count, "points");
  if (k > n)
    fail(SOGMM_E_INVALID_ARG, "K = " + std::to_string(k) + " components requested for only " +
                                  std::to_string(n) + " points");
  const sogmm::FitOptions fo = fit_options(o, k);
  sogmm::PointsView view;
  view.data = points;
  view.size = n;
  sogmm::FitResult r = sogmm::fit(view, fo);

  auto handle = std::make_unique<sogmm_model>();
  sogmm::Model& m = handle->model;
  m.gmm = std::move(r.gmm);
  if (m.gmm.support_size == 0) m.gmm.support_size = n;
  m.fit.known = true;
  m.fit.bandwidth = k > 0 ? 0.0 : o.bandwidth;
  m.fit.n_components_requested = k;
  m.fit.tol = o.tol;
  m.fit.reg_covar = o.reg_covar;
  m.fit.max_iter = static_cast<std::int32_t>(o.max_iter);
  m.fit.n_iter = r.em.iterations;
  m.fit.converged = r.em.converged;
  m.fit.log_likelihood = r.em.log_likelihood;
  m.fit.seed = fo.seed + static_cast<std::uint64_t>(r.run);  // the kept run's seed
  m.created_unix_ms = sogmm_capi::creation_time_now();
  handle->timings.known = true;
  handle->timings.n_points = r.n_points ? r.n_points : n;
  handle->timings.seconds_mode_count = r.seconds_mode_count;
  handle->timings.seconds_seeding = r.seconds_seeding;
  handle->timings.seconds_em = r.seconds_em;
  handle->timings.seconds_total = r.seconds_total;
  handle->timings.n_init = fo.n_init;
  handle->timings.run = r.run;
  return handle.release();
}

void require_intrinsic(double v, bool positive, const char* name) {
  if (!std::isfinite(v) || (positive && !(v > 0)))
    fail(SOGMM_E_INVALID_ARG, std::string(name) + " = " + std::to_string(v) + " is invalid (" +
                                  (positive ? "must be finite and > 0)" : "must be finite)"));
}

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_fit_points_f32(sogmm_model** out, const float* points, size_t n,
                                            const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::reset_out(out);
    require_nonnull(out, "out");
    require_nonnull(points, "points");
    const sogmm_options& o = sogmm_capi::opts_or_default(options);
    *out = fit_to_handle(points, n, static_cast<std::size_t>(o.n_components), o);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_fit_points_fixed_k_f32(sogmm_model** out, const float* points, size_t n,
                                                    size_t k, const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::reset_out(out);
    require_nonnull(out, "out");
    require_nonnull(points, "points");
    if (k == 0) fail(SOGMM_E_INVALID_ARG, "k is 0: a fixed-K fit needs k >= 1");
    *out = fit_to_handle(points, n, k, sogmm_capi::opts_or_default(options));
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_fit_rgbd(sogmm_model** out, const uint16_t* depth, const uint8_t* color,
                                      int32_t color_format, uint32_t width, uint32_t height, double fx,
                                      double fy, double cx, double cy, const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::reset_out(out);
    require_nonnull(out, "out");
    require_nonnull(depth, "depth");
    require_nonnull(color, "color");
    if (color_format != SOGMM_COLOR_GRAY8 && color_format != SOGMM_COLOR_RGB8)
      fail(SOGMM_E_INVALID_ARG, "unknown color_format " + std::to_string(color_format));
    const std::uint32_t kMax = static_cast<std::uint32_t>(std::numeric_limits<std::int32_t>::max());
    if (width == 0 || height == 0 || width > kMax || height > kMax)
      fail(SOGMM_E_INVALID_ARG, "image size " + std::to_string(width) + " x " + std::to_string(height) +
                                    " is invalid (each side in [1, 2^31-1])");
    const std::size_t pixels = sogmm_capi::checked_mul(width, height, "image");
    sogmm_capi::checked_mul(pixels, 3, "color image");
    require_intrinsic(fx, true, "fx");
    require_intrinsic(fy, true, "fy");
    require_intrinsic(cx, false, "cx");
    require_intrinsic(cy, false, "cy");
    const sogmm_options& o = sogmm_capi::opts_or_default(options);

    sogmm::Camera camera;
    camera.width = static_cast<int>(width);
    camera.height = static_cast<int>(height);
    camera.fx = fx;
    camera.fy = fy;
    camera.cx = cx;
    camera.cy = cy;
    sogmm::DepthOptions depth_options;
    depth_options.depth_scale = o.depth_scale;
    depth_options.depth_min = o.depth_min;
    depth_options.depth_max = o.depth_max;
    depth_options.decimate = static_cast<int>(o.decimation);
    if (!(o.depth_min < o.depth_max))
      fail(SOGMM_E_INVALID_ARG, "depth range: SOGMM_OPT_DEPTH_MIN = " + std::to_string(o.depth_min) +
                                    " must be < SOGMM_OPT_DEPTH_MAX = " + std::to_string(o.depth_max));
    if (o.decimation > static_cast<std::int64_t>(width) || o.decimation > static_cast<std::int64_t>(height))
      fail(SOGMM_E_INVALID_ARG, "decimation " + std::to_string(o.decimation) +
                                    " leaves no pixel of a " + std::to_string(width) + " x " +
                                    std::to_string(height) + " image");
    sogmm::validate(camera);
    sogmm::validate(depth_options);

    const sogmm::GrayImage gray =
        color_format == SOGMM_COLOR_RGB8
            ? sogmm::gray_from_rgb_image(color, camera.width, camera.height)
            : sogmm::gray_from_u8_image(color, camera.width, camera.height);
    sogmm::RgbdView frame;
    frame.depth = depth;
    frame.gray = gray.pixels.data();
    frame.camera = camera;
    const sogmm::PointCloud cloud = sogmm::backproject(frame, depth_options);
    if (cloud.size() == 0)
      fail(SOGMM_E_INVALID_DATA, "no pixel has a depth in the valid range after decimation");

    std::unique_ptr<sogmm_model> handle(
        fit_to_handle(cloud.xyzg.data(), cloud.size(), static_cast<std::size_t>(o.n_components), o));
    sogmm::CameraInfo& ci = handle->model.camera;
    ci.known = true;
    ci.camera = camera;
    ci.decimation = static_cast<std::int32_t>(o.decimation);
    ci.depth_scale = o.depth_scale;
    ci.depth_min = o.depth_min;
    ci.depth_max = o.depth_max;
    *out = handle.release();
  }
  SOGMM_CATCH
}

}  // extern "C"
