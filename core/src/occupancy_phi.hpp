// The standard normal CDF Phi of occupancy's evidence (private;
// occupancy_evidence.hpp), from a table instead of std::erfc: the per-point
// work of a query is a few projections and two Phi per frame whose surface
// band holds the point, and erfc (with its exp) was a third of it.
//
// On [-9, 9] Phi is the cubic Hermite interpolant of Phi and its derivative
// phi (the normal pdf) at the nodes x_i = -9 + i / 64, kept as the cubic's
// four coefficients per interval. The interpolation error of a cubic Hermite
// interpolant on an interval of width w is at most w^4 / 384 max|f''''|;
// here f'''' = phi''' = (3x - x^3) phi(x), whose largest magnitude is
// 0.5506 (at x = +-0.742), so |error| <= 0.5506 / (384 * 64^4) = 8.55e-11; the
// coefficients (from std::erfc and std::exp, within a few 1e-16) and the
// evaluation add below 1e-14. Bound stated and tested (OccupancyPhi.*):
// |phi_table(x) - erfc(-x / sqrt 2) / 2| <= kPhiTableError for every x in [-9, 9].
#pragma once

#include <vector>

namespace sogmm::detail {

/// Largest |error| of PhiTable::operator() on [-9, 9] (the bound above, rounded up).
inline constexpr double kPhiTableError = 1e-10;

class PhiTable {
 public:
  static constexpr double kLo = -9.0, kHi = 9.0;
  static constexpr int kPerUnit = 64;
  static constexpr int kIntervals = static_cast<int>((kHi - kLo) * kPerUnit);

  PhiTable();
  /// Phi(x) for x in [kLo, kHi] (the caller cuts outside).
  double operator()(double x) const { return at(coefficients_.data(), x); }
  /// The four coefficients of each interval, in order (for the vector kernel).
  const double* coefficients() const { return coefficients_.data(); }
  /// Phi(x) from the coefficients `c` (the one evaluation of the table, so the
  /// scalar path and occupancy_kernel.cpp agree bitwise).
  static double at(const double* c, double x) {
    const double s = (x - kLo) * kPerUnit;
    int i = static_cast<int>(s);
    i = i < 0 ? 0 : (i >= kIntervals ? kIntervals - 1 : i);
    const double t = s - i;
    const int q = 4 * i;  // indexed reads, which vectorize as gathers
    return c[q] + t * (c[q + 1] + t * (c[q + 2] + t * c[q + 3]));
  }

 private:
  std::vector<double> coefficients_;
};

/// The table (built on first use; thread-safe).
const PhiTable& phi_table();

}  // namespace sogmm::detail
