// The truncated E-step's interval bounds (em_truncation.cpp), compiled once
// per instruction set like the EM kernels (see em_kernel.hpp) so that the
// loop over components runs at the CPU's vector width. Compiled without
// fused multiply-add (core/CMakeLists.txt): every bound is then the same
// sequence of IEEE double operations as the scalar loop on every target,
// which the proof in em_truncation.cpp (monotone in the box, bit for bit)
// and the ISA-independent component lists rely on.
#include <algorithm>
#include <cstddef>

#include "em_kernel.hpp"

#ifndef SOGMM_ISA
#error "compile with -DSOGMM_ISA=<name>"
#endif

namespace sogmm::detail::SOGMM_ISA {

void em_upper_bounds(const double* c, std::size_t m, const float* box, double* upper) {
  const double b0 = box[0], b1 = box[1], b2 = box[2], b3 = box[3];
  const double t0 = box[4], t1 = box[5], t2 = box[6], t3 = box[7];
  auto lohi = [](double u, double lo, double hi, double& ylo, double& yhi) {
    const double a = u * lo, b = u * hi;
    ylo += std::min(a, b);
    yhi += std::max(a, b);
  };
  // The distance of [ylo, yhi] from 0 (ylo <= yhi): ylo if > 0, -yhi if
  // yhi < 0, else 0; one of the two terms is always exactly 0, so the sum is
  // that distance bit for bit, without a branch.
  auto gap2 = [](double ylo, double yhi) {
    const double gap = std::max(ylo, 0.0) + std::max(-yhi, 0.0);
    return gap * gap;
  };
#pragma omp simd
  for (std::size_t k = 0; k < m; ++k) {
    const double l0 = b0 - c[k], l1 = b1 - c[m + k], l2 = b2 - c[2 * m + k], l3 = b3 - c[3 * m + k];
    const double h0 = t0 - c[k], h1 = t1 - c[m + k], h2 = t2 - c[2 * m + k], h3 = t3 - c[3 * m + k];
    // Column j of U: U_ij for i <= j (packed row-major: U00 U01 U02 U03 U11 U12 U13 U22 U23 U33).
    const double* u = c + 4 * m;
    double lo = 0.0, hi = 0.0, q_min = 0.0;
    lohi(u[k], l0, h0, lo, hi);
    q_min += gap2(lo, hi);
    lo = hi = 0.0;
    lohi(u[m + k], l0, h0, lo, hi);
    lohi(u[4 * m + k], l1, h1, lo, hi);
    q_min += gap2(lo, hi);
    lo = hi = 0.0;
    lohi(u[2 * m + k], l0, h0, lo, hi);
    lohi(u[5 * m + k], l1, h1, lo, hi);
    lohi(u[7 * m + k], l2, h2, lo, hi);
    q_min += gap2(lo, hi);
    lo = hi = 0.0;
    lohi(u[3 * m + k], l0, h0, lo, hi);
    lohi(u[6 * m + k], l1, h1, lo, hi);
    lohi(u[8 * m + k], l2, h2, lo, hi);
    lohi(u[9 * m + k], l3, h3, lo, hi);
    q_min += gap2(lo, hi);
    upper[k] = c[14 * m + k] - 0.5 * q_min;
  }
}

}  // namespace sogmm::detail::SOGMM_ISA
