// The registration's pair kernel, compiled once per instruction set (see
// registration_kernel.hpp for what it computes and why).
#include "fast_exp.hpp"
#include "registration_kernel.hpp"

#ifndef SOGMM_ISA
#error "compile with -DSOGMM_ISA=<name>"
#endif

namespace sogmm::detail::SOGMM_ISA {

void registration_pairs(const double* records, const RegistrationPairs& pairs, std::size_t count) {
  const std::uint32_t* __restrict id = pairs.id;
  const double* __restrict px = pairs.x;
  const double* __restrict py = pairs.y;
  const double* __restrict pz = pairs.z;
  const double* __restrict pg = pairs.gray;
  double* __restrict lp = pairs.log_density;
  double* __restrict prx = pairs.pr_x;
  double* __restrict pry = pairs.pr_y;
  double* __restrict prz = pairs.pr_z;
  double* __restrict quad = pairs.quad;
#pragma omp simd
  for (std::ptrdiff_t j = 0; j < static_cast<std::ptrdiff_t>(count); ++j) {
    // An index into the records, not a pointer per lane: GCC gathers from
    // a base and a vector of offsets only.
    const std::ptrdiff_t k = std::ptrdiff_t{kPairRecord} * id[j];
    const auto c = [&](int field) { return records[k + field]; };
    const double x = px[j], y = py[j], z = pz[j];
    const double dg = pg[j] - c(kMuGray);
    const double rx = (x - c(kMuX)) - c(kGainX) * dg;
    const double ry = (y - c(kMuY)) - c(kGainY) * dg;
    const double rz = (z - c(kMuZ)) - c(kGainZ) * dg;
    const double qx = c(kP00) * rx + c(kP01) * ry + c(kP02) * rz;
    const double qy = c(kP01) * rx + c(kP11) * ry + c(kP12) * rz;
    const double qz = c(kP02) * rx + c(kP12) * ry + c(kP22) * rz;
    const double q = rx * qx + ry * qy + rz * qz;
    const double l = c(kLogNorm) + (c(kLogNormGray) - 0.5 * dg * dg * c(kInvSgg)) - 0.5 * q;
    lp[j] = l;
    prx[j] = qx;
    pry[j] = qy;
    prz[j] = qz;
    quad[j] = q;
  }
}

// fast_exp_double: std::exp would be a library call per pair.
void registration_terms(const double* log_density, const double* top, double* term, std::size_t count) {
  // term may be log_density (in place: each j reads, then writes, its own).
  const double* lp = log_density;
  const double* __restrict t = top;
  double* e = term;
#pragma omp simd
  for (std::size_t j = 0; j < count; ++j) e[j] = fast_exp_double(lp[j] - t[j]);
}

}  // namespace sogmm::detail::SOGMM_ISA
