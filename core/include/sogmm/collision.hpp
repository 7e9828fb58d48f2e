// Collision probability of an ellipsoidal robot against the surface a model
// represents (issue 31), on the discs of sogmm/surface_distance.hpp.
//
// The robot is E = {x : (x - c)^T S^-1 (x - c) <= 1} (centre c, shape S:
// symmetric positive definite; a sphere of radius r is S = r^2 I). Each
// component's disc D_k is a surface patch whose position along its normal
// is uncertain by sigma_k, the component's standard deviation along its
// smallest principal axis (the surface noise it was fitted to). In the
// robot's frame y = S^-1/2 (x - c), E is the unit ball and D_k an ellipse
// (the affine image of one); with p the ellipse's point nearest to the
// origin, the robot's clearance from D_k along the ray through p is
//   g_k = (|p| - 1) |S^1/2 p / |p||   (metres; negative when they overlap),
// and the patch touches the robot with probability P_k = Phi(-g_k / sigma_k).
// The answer is max_k P_k: the probability of the most likely contact, a
// lower bound of the union's (the patches of one surface are not
// independent, and a product over them would count one surface many times).
// It is 1/2 at contact, above 0.99 for a robot that reaches 2.33 sigma into
// a patch, below 0.00135 for one 3 sigma clear of every patch (g_k is at
// least the Euclidean clearance: it is the distance between a point of E's
// boundary and a point of D_k), and falls as the robot backs away from a
// surface along its normal (tested; not proven for every path).
#pragma once

#include <cstddef>

#include "sogmm/gmm.hpp"
#include "sogmm/progress.hpp"
#include "sogmm/surface_distance.hpp"

namespace sogmm {

/// P(collision) of n robots (`centers`: n rows of 3 doubles, `shapes`: n
/// row-major 3 x 3 matrices S) against `gmm` (its frame) into `out` (n
/// values in [0, 1]). Components farther than 8 sigma_k beyond the robot's
/// bounding sphere and the disc's radius are skipped (their P_k is below
/// Phi(-8) = 6e-16). Errors: a model without components or a non-finite
/// centre -> Error(InvalidData); a shape that is not finite, symmetric
/// (relative 1e-9) and positive definite -> Error(InvalidArgument) naming
/// the robot; options as surface_distance. `threads`, `progress`
/// (Stage::Scoring, step = robots) as surface_distance.
void collision_probability(const Gmm& gmm, const double* centers, const double* shapes, std::size_t n, double* out,
                           const SurfaceDistanceOptions& options = {}, int threads = 0,
                           const ProgressSink& progress = {});

}  // namespace sogmm
