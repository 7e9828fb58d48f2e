// sogmm_map_score_samples_f32, sogmm_map_regress_gray_f32,
// sogmm_map_sample_f32: world-frame queries on a map handle
// (sogmm/map_queries.hpp), with the checks of the model queries (queries.hpp).
#include <cstddef>

#include "internal.hpp"
#include "map_handle.hpp"
#include "queries.hpp"
#include "sogmm/map_queries.hpp"

namespace {

using sogmm_capi::require_dims;
using sogmm_capi::require_nonnull;

// The checks every map query starts with (sogmm.h): the map, then that it
// has components (a query of an empty map fails even for n == 0).
void require_map_with_components(const sogmm_map* map) {
  require_nonnull(map, "map");
  (void)map->map.model();  // SOGMM_E_INVALID_DATA for an empty map
}

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_map_score_samples_f32(const sogmm_map* map, const float* points, size_t n,
                                                   int32_t dims, const sogmm_options* options, double* out) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_score_samples_f32");
    require_dims(dims);
    require_map_with_components(map);
    sogmm_capi::run_score_query(points, n, dims, options, out, [&](double* dst, const sogmm::QueryOptions& query, const sogmm::ProgressSink& sink) {
      sogmm::score_samples(map->map, points, n, dims, dst, query, sink);
    });
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_regress_gray_f32(const sogmm_map* map, const float* xyz, size_t n,
                                                  const sogmm_options* options, float* mean_out,
                                                  float* variance_out) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_regress_gray_f32");
    require_map_with_components(map);
    sogmm_capi::run_regress_query(xyz, n, options, mean_out, variance_out,
                                  [&](float* mean, float* variance, const sogmm::QueryOptions& query, const sogmm::ProgressSink& sink) {
                                    sogmm::regress_gray(map->map, xyz, n, mean, variance, query, sink);
                                  });
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_map_sample_f32(const sogmm_map* map, size_t n, uint64_t seed, int32_t dims,
                                            const sogmm_options* options, float* out) {
  SOGMM_TRY {
    require_nonnull(map, "map");
    const sogmm_capi::MapReader use(map, "sogmm_map_sample_f32");
    require_dims(dims);
    require_map_with_components(map);
    if (n == 0) return SOGMM_OK;
    require_nonnull(out, "out");
    const std::size_t count = sogmm::checked::mul<std::size_t>(n, static_cast<std::size_t>(dims), "samples");
    const sogmm_options& o = sogmm_capi::opts_or_default(options);
    sogmm_capi::write_on_success(o.progress != nullptr, out, count, [&](float* dst) {
      sogmm::sample(map->map, n, seed, dims, dst, o.settings.sample.truncation, sogmm_capi::progress_sink(o));
    });
  }
  SOGMM_CATCH
}

}  // extern "C"
