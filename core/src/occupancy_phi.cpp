// The table of Phi (occupancy_phi.hpp).
#include "occupancy_phi.hpp"

#include <cmath>

namespace sogmm::detail {

PhiTable::PhiTable() : coefficients_(4 * static_cast<std::size_t>(kIntervals)) {
  const double w = 1.0 / kPerUnit, inv_sqrt_2pi = 0.3989422804014327;
  const auto phi = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  for (int i = 0; i < kIntervals; ++i) {
    const double x0 = kLo + i * w, x1 = kLo + (i + 1) * w;
    const double f0 = phi(x0), f1 = phi(x1);
    // Derivatives with respect to t = (x - x0) / w.
    const double m0 = w * inv_sqrt_2pi * std::exp(-0.5 * x0 * x0), m1 = w * inv_sqrt_2pi * std::exp(-0.5 * x1 * x1);
    const double df = f1 - f0;
    double* c = &coefficients_[4 * static_cast<std::size_t>(i)];
    c[0] = f0;
    c[1] = m0;
    c[2] = 3.0 * df - 2.0 * m0 - m1;
    c[3] = m0 + m1 - 2.0 * df;
  }
}

const PhiTable& phi_table() {
  static const PhiTable table;
  return table;
}

}  // namespace sogmm::detail
