// Unsigned distance from points to the surface a model represents, and its
// gradient (issue 31).
//
// The construction. A SOGMM component is a surface patch: its spatial
// covariance is flat (the smallest principal axis is the surface's noise,
// millimetres; the two largest span the surface). Each component is read as
// the flat elliptical disc through its mean spanned by its two largest
// principal axes e1, e2, with semi-axes k sqrt(lambda1), k sqrt(lambda2)
// (k = disc_sigmas); the surface is the union of the discs, and the distance
// of a point is the Euclidean distance to the nearest disc: |c| above the
// disc's interior (c the offset along the normal), else the distance to the
// nearest point of its rim (a 1-D Newton solve of the point-to-ellipse
// problem, monotone from below). The gradient is the unit vector from that
// nearest point to the query point (on a disc: its normal), except where
// that point is on a rim and the point lies over some disc's face no more
// than 1.5 cm farther: then the normal of the nearest such face, pointing to
// the point (a rim is mostly where a component is cut at disc_sigmas, not
// where the surface ends; surface_distance.cpp, kFaceTolerance).
//
// Why not the IROS 2025 construction (Goel and Tabib, arXiv 2402.00186),
// which measures the distance to each component's ellipsoid at a fixed
// Mahalanobis radius: a point above a surface patch is then short of the
// surface by k times the patch's thickness, a bias of several millimetres
// against a 1 cm error budget; the disc keeps the mid-surface and has no
// such bias, and its distance is exact for the union of discs.
//
// The search is exact, bit for bit the brute-force answer (the nearest disc,
// the lowest component id among equal distances, its distance and gradient
// as computed for that disc alone, or for the face above): the discs sit in a tree of bounding
// boxes (median splits, 4 discs a leaf). Points go in Z-order blocks of 64;
// the first point of a block searches the tree depth first, nearer box
// first; its nearest disc is at most `bound` from every point of the block
// (a rim point of that disc gives the bound without a solve), so every
// block point's nearest disc lies in a leaf within `bound` of the block's
// box, and the other points search only those leaves. A leaf or a disc is
// skipped only when a lower bound of its distance (the box; then the
// circle of the disc's largest radius in its plane) exceeds the best
// distance found by more than 1e-9 of the scene's coordinates, far above
// the rounding of either, so no disc that could win or tie is skipped.
#pragma once

#include <cstddef>

#include "sogmm/gmm.hpp"
#include "sogmm/map.hpp"
#include "sogmm/progress.hpp"

namespace sogmm {

/// How surface_distance() reads the components as surface patches.
struct SurfaceDistanceOptions {
  /// Each component is the flat elliptical disc spanned by its two largest
  /// principal axes, out to this many standard deviations. In (0, 10].
  double disc_sigmas = 2.0;
};

/// Throws Error(InvalidArgument) unless disc_sigmas is in (0, 10].
void validate(const SurfaceDistanceOptions& options);

/// Unsigned distance (metres) of n points (`xyz`: rows of 3 floats, in the
/// model's frame) to the model's surface into `distance` (n values) and, if
/// `gradient` is not null, its gradient (n rows of 3: a unit vector pointing
/// away from the nearest surface point). `threads` as QueryOptions::threads;
/// the results do not depend on it. Errors: a model without components ->
/// Error(InvalidData); a non-finite point -> Error(InvalidData) naming its
/// row (nothing written); a spatial covariance that is not positive
/// definite -> Error(Numeric); bad options -> Error(InvalidArgument).
/// `progress` receives Stage::Scoring reports (step = points) and may cancel.
void surface_distance(const Gmm& gmm, const float* xyz, std::size_t n, double* distance, double* gradient,
                      const SurfaceDistanceOptions& options = {}, int threads = 0, const ProgressSink& progress = {});

/// The same for a map's world-frame model (an empty map -> Error(InvalidData)).
void surface_distance(const Map& map, const float* xyz, std::size_t n, double* distance, double* gradient,
                      const SurfaceDistanceOptions& options = {}, int threads = 0, const ProgressSink& progress = {});

}  // namespace sogmm
