// World-frame queries on a map: the model queries on Map::model()
// (sogmm/map_queries.hpp).
#include "sogmm/map_queries.hpp"

#include "sogmm/inference.hpp"
#include "sogmm/query_progress.hpp"

namespace sogmm {

// Map::model() throws Error(InvalidData) for a map without components, before
// any other check.

void score_samples(const Map& map, const float* points, std::size_t n, int dims, double* out,
                   const QueryOptions& options, const ProgressSink& progress) {
  score_samples(map.model().gmm, points, n, dims, out, options, progress);
}

void regress_gray(const Map& map, const float* xyz, std::size_t n, float* mean, float* variance,
                  const QueryOptions& options, const ProgressSink& progress) {
  regress_gray(map.model().gmm, xyz, n, mean, variance, options, progress);
}

void sample(const Map& map, std::size_t n, std::uint64_t seed, int dims, float* out, double truncation,
            const ProgressSink& progress) {
  const Gmm& gmm = map.model().gmm;
  const ProgressScope scope(progress);  // sample() reports Stage::Sampling itself
  sample(gmm, n, seed, dims, out, truncation);
}

}  // namespace sogmm
