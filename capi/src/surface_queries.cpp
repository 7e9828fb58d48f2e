// sogmm_map_occupancy_f32, sogmm_*_surface_distance_f32 and
// sogmm_*_collision_probability: what a planner asks a map (issue 31), from
// sogmm/occupancy.hpp and sogmm/surface_distance.hpp, with the checks of the
// other queries (queries.hpp).
#include <cstddef>
#include <cstdint>

#include "internal.hpp"
#include "map_handle.hpp"
#include "queries.hpp"
#include "sogmm/collision.hpp"
#include "sogmm/occupancy.hpp"
#include "sogmm/surface_distance.hpp"

namespace {

// The body of a distance query after the handle checks: n == 0 writes
// nothing; the gradient is optional; with a progress callback the outputs are
// written only on success.
template <class Gmmish>
void run_distance(const Gmmish& source, const float* xyz, size_t n, const sogmm_options* options,
                  double* distance_out, double* gradient_out) {
  if (n == 0) return;
  sogmm_capi::require_query_input(xyz, n, 3, "xyz", distance_out, "distance_out");
  const sogmm_options& o = sogmm_capi::opts_or_default(options);
  const bool progress = o.progress != nullptr;
  sogmm_capi::write_on_success(progress, distance_out, n, [&](double* distance) {
    sogmm_capi::write_on_success(progress, gradient_out, 3 * n, [&](double* gradient) {
      sogmm::surface_distance(source, xyz, n, distance, gradient, o.settings.surface, o.settings.query.threads,
                              sogmm_capi::progress_sink(o));
    });
  });
}

// The body of a collision query after the handle checks.
void run_collision(const sogmm::Gmm& gmm, const double* centers, const double* shapes, size_t n,
                   const sogmm_options* options, double* out) {
  if (n == 0) return;
  sogmm_capi::require_nonnull(centers, "centers");
  sogmm_capi::require_nonnull(shapes, "shapes");
  sogmm_capi::require_nonnull(out, "out");
  const sogmm_options& o = sogmm_capi::opts_or_default(options);
  sogmm_capi::write_on_success(o.progress != nullptr, out, n, [&](double* dst) {
    sogmm::collision_probability(gmm, centers, shapes, n, dst, o.settings.surface, o.settings.query.threads,
                                 sogmm_capi::progress_sink(o));
  });
}

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_map_occupancy_f32(const sogmm_map* map, const float* xyz, size_t n,
                                               const sogmm_options* options, double* probability_out,
                                               uint8_t* state_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_occupancy_f32");
    if (n == 0) return SOGMM_OK;
    sogmm_capi::require_query_input(xyz, n, 3, "xyz", probability_out, "probability_out");
    const sogmm_options& o = sogmm_capi::opts_or_default(options);
    const bool progress = o.progress != nullptr;
    sogmm_capi::write_on_success(progress, probability_out, n, [&](double* probability) {
      sogmm_capi::write_on_success(progress, state_out, n, [&](std::uint8_t* state) {
        sogmm::occupancy(map->map, xyz, n, probability, state, o.settings.occupancy, o.settings.query.threads,
                         sogmm_capi::progress_sink(o));
      });
    });
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_surface_distance_f32(const sogmm_model* model, const float* xyz, size_t n,
                                                        const sogmm_options* options, double* distance_out,
                                                        double* gradient_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(model, "model");
    run_distance(model->model.gmm, xyz, n, options, distance_out, gradient_out);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_surface_distance_f32(const sogmm_map* map, const float* xyz, size_t n,
                                                      const sogmm_options* options, double* distance_out,
                                                      double* gradient_out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_surface_distance_f32");
    (void)map->map.model();  // SOGMM_E_INVALID_DATA for an empty map, even for n == 0
    run_distance(map->map, xyz, n, options, distance_out, gradient_out);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_collision_probability(const sogmm_model* model, const double* centers,
                                                         const double* shapes, size_t n,
                                                         const sogmm_options* options, double* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(model, "model");
    run_collision(model->model.gmm, centers, shapes, n, options, out);
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_collision_probability(const sogmm_map* map, const double* centers,
                                                       const double* shapes, size_t n,
                                                       const sogmm_options* options, double* out) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_collision_probability");
    run_collision(map->map.model().gmm, centers, shapes, n, options, out);
  }
  SOGMM_CATCH
}

}  // extern "C"
