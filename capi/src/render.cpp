// sogmm_model_render_f32 and sogmm_map_render_f32: a model or map rendered
// from a pinhole camera and a pose (sogmm/render.hpp) into caller-allocated
// images.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>

#include "internal.hpp"
#include "map_handle.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/render.hpp"

static_assert(SOGMM_MAX_RENDER_PIXELS == sogmm::kMaxPoints, "sogmm.h states the core's pixel limit");

namespace {

using sogmm_capi::fail;
using sogmm_capi::require_nonnull;

// Checks the arguments every render takes, then renders `gmm` and copies the
// images out (only once the whole rendering succeeded: a cancel or an error
// leaves the outputs untouched).
void render_into(const sogmm::Gmm& gmm, std::uint32_t width, std::uint32_t height, double fx, double fy, double cx,
                 double cy, const double* camera_to_world, const sogmm_options* options, float* depth_out,
                 float* gray_out, float* variance_out) {
  // The size first: an empty image has no buffers to pass (bindings call
  // with NULL outputs for it and get the size named).
  constexpr std::uint32_t kMax = static_cast<std::uint32_t>(std::numeric_limits<std::int32_t>::max());
  if (width == 0 || height == 0 || width > kMax || height > kMax)
    fail(SOGMM_E_INVALID_ARG, "image size " + std::to_string(width) + " x " + std::to_string(height) +
                                  " (each must be in [1, 2^31 - 1])");
  require_nonnull(depth_out, "depth_out");
  require_nonnull(gray_out, "gray_out");
  const sogmm::Camera camera{static_cast<int>(width), static_cast<int>(height), fx, fy, cx, cy};
  std::array<double, 16> pose{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  if (camera_to_world != nullptr) pose = sogmm_capi::require_rigid(camera_to_world, "camera_to_world");
  const sogmm_options& o = sogmm_capi::opts_or_default(options);
  sogmm::RenderOptions ro = o.settings.render;
  ro.depth_min = o.settings.depth.depth_min;
  ro.depth_max = o.settings.depth.depth_max;
  ro.threads = o.settings.query.threads;
  const sogmm::RenderedImages r = sogmm::render(gmm, camera, pose, ro, sogmm_capi::progress_sink(o));
  std::copy(r.depth.begin(), r.depth.end(), depth_out);
  std::copy(r.gray.begin(), r.gray.end(), gray_out);
  if (variance_out != nullptr) std::copy(r.variance.begin(), r.variance.end(), variance_out);
}

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_model_render_f32(const sogmm_model* model, uint32_t width, uint32_t height, double fx,
                                              double fy, double cx, double cy, const double* camera_to_world,
                                              const sogmm_options* options, float* depth_out, float* gray_out,
                                              float* variance_out) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    render_into(model->model.gmm, width, height, fx, fy, cx, cy, camera_to_world, options, depth_out, gray_out,
                variance_out);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_render_f32(const sogmm_map* map, uint32_t width, uint32_t height, double fx,
                                            double fy, double cx, double cy, const double* camera_to_world,
                                            const sogmm_options* options, float* depth_out, float* gray_out,
                                            float* variance_out) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    // Shared use, as every const map call: an insert or flush (from another
    // thread, or from this render's progress callback) would change the model
    // under the render (fuzz_map found the callback's flush succeeding).
    const sogmm_capi::MapReader use(map, "sogmm_map_render_f32");
    const sogmm::Model& model = map->map.model();  // SOGMM_E_INVALID_DATA for an empty map
    render_into(model.gmm, width, height, fx, fy, cx, cy, camera_to_world, options, depth_out, gray_out,
                variance_out);
  }
  SOGMM_CATCH
}

}  // extern "C"
