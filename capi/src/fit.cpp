// Fitting: from an N x 4 point array (self-organizing or fixed K) and from a
// raw RGB-D frame.
#include <memory>
#include <string>

#include "internal.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/fit_record.hpp"
#include "sogmm/warm_start.hpp"

namespace sogmm_capi {

sogmm::FitOptions fit_options(const sogmm_options& o, std::size_t k) {
  sogmm::FitOptions f = o.settings.fit;
  f.n_components = k;
  return f;
}

void require_depth_range(const sogmm_options& o) {
  const sogmm::DepthOptions& d = o.settings.depth;
  if (!(d.depth_min < d.depth_max))
    fail(SOGMM_E_INVALID_ARG, "depth range: SOGMM_OPT_DEPTH_MIN = " + sogmm::checked::exact(d.depth_min) +
                                  " must be < SOGMM_OPT_DEPTH_MAX = " + sogmm::checked::exact(d.depth_max));
}

}  // namespace sogmm_capi

namespace {

using sogmm_capi::fail;
using sogmm_capi::fit_options;
using sogmm_capi::require_nonnull;

/// Runs the fit on checked points (a warm start from `initial` if not null)
/// and wraps the result (fit report, fit parameters, timings) in a new handle.
/// `from_depth_image`: the points are sogmm_fit_frame's (the automatic depth
/// floor applies).
sogmm_model* fit_to_handle(const float* points, std::size_t n, const sogmm_options& o,
                           const sogmm::Gmm* initial = nullptr, bool from_depth_image = false) {
  const std::size_t k = o.settings.fit.n_components;  // 0: self-organizing
  if (n == 0) fail(SOGMM_E_INVALID_DATA, "n is 0: nothing to fit");
  const std::size_t count = sogmm::checked::mul<std::size_t>(n, 4, "points");
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
  view.from_depth_image = from_depth_image;
  sogmm::FitResult r = initial ? sogmm::fit_warm(view, *initial, fo, sogmm_capi::progress_sink(o), o.settings.warm)
                                : sogmm::fit(view, fo, sogmm_capi::progress_sink(o));

  auto handle = std::make_unique<sogmm_model>();
  sogmm::Model& m = handle->model;
  m.gmm = std::move(r.gmm);
  if (m.gmm.support_size == 0) m.gmm.support_size = n;
  sogmm::record_fit(m, r, fo);
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

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_fit_points_f32(sogmm_model** out, const float* points, size_t n,
                                            const sogmm_model* initial, const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    require_nonnull(points, "points");
    *out = fit_to_handle(points, n, sogmm_capi::opts_or_default(options),
                         initial != nullptr ? &initial->model.gmm : nullptr);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_fit_frame(sogmm_model** out, const sogmm_frame* frame, const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    const sogmm_options& o = sogmm_capi::opts_or_default(options);
    const sogmm_capi::RgbdPoints r = sogmm_capi::backproject_frame(frame, o);
    if (r.cloud.size() == 0)
      fail(SOGMM_E_INVALID_DATA, "no pixel has a depth in the valid range after decimation");

    std::unique_ptr<sogmm_model> handle(
        fit_to_handle(r.cloud.xyzg.data(), r.cloud.size(), o, nullptr, r.cloud.from_depth_image));
    sogmm::CameraInfo& ci = handle->model.camera;
    ci.known = true;
    ci.camera = r.camera;
    ci.decimation = r.depth.decimate;
    ci.depth_scale = r.depth.depth_scale;
    ci.depth_min = r.depth.depth_min;
    ci.depth_max = r.depth.depth_max;
    *out = handle.release();
  }
  SOGMM_CATCH
}

}  // extern "C"
