// The components of a model read as surface patches (private): the flat
// elliptical disc of each component's two largest principal axes, and the
// Euclidean distance of a point to one disc (surface_distance.cpp,
// collision.cpp; the construction: sogmm/surface_distance.hpp).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "sogmm/gmm.hpp"

namespace sogmm::detail {

struct Disc {
  Eigen::Vector3d mu, e1, e2, normal;
  double a = 0, b = 0;  ///< semi-axes along e1, e2, a >= b > 0
  double radius = 0;    ///< a: every point of the disc is within it of mu
  double sigma = 0;     ///< the component's standard deviation along the normal (its thickness)
};

/// The discs of every component out to k standard deviations. Throws
/// Error(Numeric) naming a component whose spatial covariance is not
/// positive definite.
std::vector<Disc> discs_of(const Gmm& gmm, double k);

/// Whether x projects along d's normal onto d (its face, not beyond its rim).
bool over_face(const Disc& d, const Eigen::Vector3d& x);

/// The distance of x to disc d; `from` receives x minus the nearest point of d.
double disc_distance(const Disc& d, const Eigen::Vector3d& x, Eigen::Vector3d& from);

}  // namespace sogmm::detail
