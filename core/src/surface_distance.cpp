// Distance to the surface as the union of the components' discs
// (sogmm/surface_distance.hpp).
#include "sogmm/surface_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "disc_tree.hpp"
#include "finite_rows.hpp"
#include "parallel.hpp"
#include "progress.hpp"
#include "surface_discs.hpp"
#include "sogmm/error.hpp"
#include "sogmm/options.hpp"
#include "z_order.hpp"

namespace sogmm {

namespace {

using detail::Disc;
using detail::discs_of;

constexpr std::size_t kBlock = 64;

// The gradient where the nearest disc point is on a rim: the normal of the
// nearest disc face (a disc the point lies over) when that face is at most
// this much (metres) farther than the nearest disc, else the direction from
// the rim. A rim is where a component's disc is cut at disc_sigmas, seldom
// where the surface ends: a face just behind it says the surface goes on
// under the point. On the synthetic room with the livingroom's 2.78 mm depth
// noise (tools/sogmm-perf/gradient_reference_loop.py) 0.5 / 1 / 1.5 / 2 cm move
// the share within 10 degrees of the exact direction from 0.839 to 0.886 /
// 0.913 / 0.925 / 0.927, and the livingroom map against the denoised
// reference from 0.676 to 0.702 / 0.702 / 0.701 / 0.699 (gradient_reference_eval.py).
// The distance is the nearest disc's either way.
constexpr double kFaceTolerance = 0.015;

}  // namespace

void validate(const SurfaceDistanceOptions& options) {
  require_option(OptionKey::SURFACE_DISC_SIGMAS, options.disc_sigmas, "surface disc_sigmas");
}

void surface_distance(const Gmm& gmm, const float* xyz, std::size_t n, double* distance, double* gradient,
                      const SurfaceDistanceOptions& options, int threads, const ProgressSink& progress) {
  validate(options);
  require(gmm.size() > 0, ErrorCode::InvalidData, "surface distance: the model has no component");
  if (n == 0) return;
  require(xyz != nullptr && distance != nullptr, ErrorCode::InvalidArgument, "surface distance: null input or output");
  detail::require_finite_rows(xyz, n, 3, "points for surface distance");
  const ProgressScope scope(progress);
  const int team = detail::team_size(threads);
  const std::vector<Disc> discs = discs_of(gmm, options.disc_sigmas);
  const std::vector<std::size_t> order = detail::z_ordered(xyz, n, 3, team);
  const std::size_t blocks = (n + kBlock - 1) / kBlock;

  detail::progress_begin(Stage::Scoring, n);
  const detail::DiscTree tree(discs);
  // Per thread: scratch and the last answer, which starts the next point's
  // search (Z-order neighbours mostly share their nearest disc).
  struct Scratch {
    std::vector<std::pair<double, std::uint32_t>> stack;
    std::vector<std::uint32_t> leaves, walk;
    std::uint32_t hint = 0;
  };
  std::vector<Scratch> scratch(static_cast<std::size_t>(team));
  detail::parallel_for(blocks, team, 1, [&](std::size_t blk, int thread) {
    const std::size_t first = blk * kBlock, last = std::min(n, first + kBlock);
    Scratch& s = scratch[static_cast<std::size_t>(thread)];
    const auto point = [&](std::size_t j) {
      const std::size_t i = order[j];
      return Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    };
    const auto write = [&](std::size_t j, const detail::DiscTree::Nearest& best) {
      const std::size_t i = order[j];
      distance[i] = best.distance;
      if (gradient == nullptr) return;
      const Eigen::Vector3d x = point(j);
      detail::DiscTree::Nearest face;
      const detail::DiscTree::Nearest& from =
          !detail::over_face(discs[best.id], x) && tree.nearest_face_among(x, best.distance + kFaceTolerance, s.leaves, face)
              ? face
              : best;
      const double len = from.from.norm();
      const Eigen::Vector3d g = len > 0 ? Eigen::Vector3d(from.from / len) : discs[from.id].normal;
      for (int k = 0; k < 3; ++k) gradient[3 * i + k] = g(k);
    };
    // The block's first point searches the whole tree. Its nearest disc is
    // within `bound` of every point of the block, so the nearest disc of
    // each is in a leaf within `bound` of the block's box: the others search
    // those leaves only.
    // With a gradient the leaves reach kFaceTolerance farther, for the faces
    // behind a rim (write()), the first point's included; without one the
    // first point is done and its distance would only widen the search
    // (about 8% of a distance call on the 2697-component loop map).
    const detail::DiscTree::Nearest head = tree.nearest(point(first), s.hint, s.stack);
    double lo[3], hi[3], bound = gradient != nullptr ? head.distance : 0.0;
    for (int k = 0; k < 3; ++k) lo[k] = hi[k] = point(first)(k);
    for (std::size_t j = first + 1; j < last; ++j) {
      const Eigen::Vector3d x = point(j);
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], x(k));
        hi[k] = std::max(hi[k], x(k));
      }
      bound = std::max(bound, tree.upper_bound(head.id, x));
    }
    tree.leaves_near(lo, hi, bound + (gradient != nullptr ? kFaceTolerance : 0.0), s.leaves, s.walk);
    write(first, head);
    s.hint = head.id;
    for (std::size_t j = first + 1; j < last; ++j) {
      const detail::DiscTree::Nearest best = tree.nearest_among(point(j), s.hint, s.leaves);
      s.hint = best.id;
      write(j, best);
    }
  });
}

void surface_distance(const Map& map, const float* xyz, std::size_t n, double* distance, double* gradient,
                      const SurfaceDistanceOptions& options, int threads, const ProgressSink& progress) {
  surface_distance(map.model().gmm, xyz, n, distance, gradient, options, threads, progress);
}

}  // namespace sogmm
