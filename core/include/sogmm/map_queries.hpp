// World-frame queries on a map (issue 18): score, regress gray and sample the
// map directly, without exporting it.
//
// Each answer is exactly (bitwise) the same query on map.model(), the map's
// world-frame model: these functions call the model queries of
// sogmm/inference.hpp on it (no copy). They do not use the component index:
// the index holds a component where a point is within index_sigmas (3) of it
// per axis, and a component beyond that still contributes up to exp(-4.5) of
// its peak, so a local sum would differ from the model's. An exact pruning
// would need boxes of about 39 sigma (where exp underflows in double), which
// hold most of a room's components. Pending points are not in the map.
#pragma once

#include <cstddef>
#include <cstdint>

#include "sogmm/inference.hpp"
#include "sogmm/map.hpp"
#include "sogmm/progress.hpp"

namespace sogmm {

/// score_samples (sogmm/inference.hpp) of n world points under the map:
/// dims 4 = rows (x, y, z, gray), joint; dims 3 = rows (x, y, z), marginal.
/// Errors: the map has no component -> Error(InvalidData) (checked first);
/// then as score_samples. `progress` (optional) receives Stage::Scoring
/// reports and may cancel, as in sogmm/query_progress.hpp.
void score_samples(const Map& map, const float* points, std::size_t n, int dims, double* out,
                   const QueryOptions& options = {}, const ProgressSink& progress = {});

/// regress_gray (sogmm/inference.hpp) at n world points (rows of 3 floats):
/// expected gray into `mean`, its variance into `variance` (may be null).
/// Errors and progress as score_samples above, with Stage::Regression.
void regress_gray(const Map& map, const float* xyz, std::size_t n, float* mean, float* variance,
                  const QueryOptions& options = {}, const ProgressSink& progress = {});

/// sample (sogmm/inference.hpp) of n world points from the map, rows of
/// `dims` floats grouped by component; the same seed gives the same points.
/// Errors: empty map -> Error(InvalidData); then as sample. `progress`
/// receives Stage::Sampling reports and may cancel.
void sample(const Map& map, std::size_t n, std::uint64_t seed, int dims, float* out, double truncation = kDefaultSampleTruncation,
            const ProgressSink& progress = {});

}  // namespace sogmm
