// Unsigned distance from points to the surface a model represents, and its
// gradient (issue 31).
#pragma once

namespace sogmm {

/// How surface_distance() reads the components as surface patches.
struct SurfaceDistanceOptions {
  /// Each component is the flat elliptical disc spanned by its two largest
  /// principal axes, out to this many standard deviations. In (0, 10].
  double disc_sigmas = 2.0;
};

}  // namespace sogmm
