// The evidence of a map's frames about one point, and its probability and
// state (private; occupancy.cpp, tests/core/test_occupancy_blocks.cpp). The
// model is in sogmm/occupancy.hpp and spec/api.md, "Occupancy".
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "occupancy_phi.hpp"
#include "sogmm/occupancy.hpp"

namespace sogmm::detail {

/// Phi is taken as exactly 0 below -kExactSigmas and 1 above it. Above
/// +9 sigma 0.5 erfc already rounds to 1 in double; below -9 sigma the true
/// value is under 1.2e-19. The cut makes a frame whose surface is more than
/// h + 9 sigma from a point give whole evidence (free, or none), which a test
/// over a box of points decides once for all of them (occupancy.cpp).
/// Between the cuts Phi is the table of occupancy_phi.hpp, within
/// kPhiTableError = 1e-10 of 0.5 erfc(-x / sqrt 2). So every e_f, b_f is
/// within eps = 1e-10 of the model's (spec/api.md 4.9) and o_f within 2 eps,
/// and with F frames seeing a point: |U - U'| <= F eps (a product of factors
/// in [0, 1]); (1 - U) <= S = sum_f (o_f + e_f) (as 1 - prod b_f <= sum (1 - b_f)),
/// so where S >= 6 F eps the pooled share moves (1 - U) q by at most 10 F eps,
/// and where S < 6 F eps both (1 - U) q are below 15 F eps: |dP| <= 16 F eps
/// (plus the sums' rounding, F 2^-52). Measured on the synthetic loop map
/// (2763 components, 300 frames, 614,400 points) against a67de64 (std::erfc):
/// see README section 7 (sogmm-occupancy-octomap --compare-main).
inline constexpr double kExactSigmas = 9.0;

struct Evidence {
  double unknown = 1.0;         ///< U = prod_f b_f
  double occupied = 0.0;        ///< sum_f o_f
  double free = 0.0;            ///< sum_f e_f over the frames with 0 < b_f
  std::uint64_t whole_free = 0; ///< frames with e_f = 1, b_f = 0 (summed apart, so the order of frames
                                ///< that give whole evidence does not change a bit)

  static double phi(double x) {
    if (x < -kExactSigmas) return 0.0;
    if (x > kExactSigmas) return 1.0;
    return phi_table()(x);
  }

  /// `count` frames that see the point more than h + 9 sigma in front of their surface.
  void add_whole_free(std::uint64_t count) {
    if (count == 0) return;
    unknown = 0.0;
    whole_free += count;
  }
  /// A frame that sees the point at distance r along its ray, whose surface is at `surface` there.
  void add(double r, double surface, const OccupancyOptions& o) {
    const double front = (r - surface + o.thickness) / o.surface_sigma;
    if (front < -kExactSigmas) return add_whole_free(1);  // e = 1, b = 0, o = 0
    const double back = (r - surface - o.thickness) / o.surface_sigma;
    if (back > kExactSigmas) return;  // e = 0, b = 1, o = 0: no evidence
    const double e = 1.0 - phi(front);
    const double b = phi(back);
    unknown *= b;
    free += e;
    occupied += std::max(0.0, 1.0 - e - b);
  }
  void finish(double& probability, std::uint8_t* state) const {
    const double all_free = free + static_cast<double>(whole_free);
    const double seen = occupied + all_free;
    const double q = seen > 0 ? occupied / seen : 0.5;
    probability = std::min(1.0, std::max(0.0, (1.0 - unknown) * q + 0.5 * unknown));
    if (state == nullptr) return;
    const double occ = (1.0 - unknown) * q, fr = (1.0 - unknown) * (1.0 - q);
    OccupancyState s = OccupancyState::Free;
    if (unknown >= occ && unknown >= fr) s = OccupancyState::Unknown;
    else if (occ >= fr) s = OccupancyState::Occupied;
    *state = static_cast<std::uint8_t>(s);
  }
};

}  // namespace sogmm::detail
