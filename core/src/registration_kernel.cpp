// The registration's pair kernel, compiled once per instruction set (see
// registration_kernel.hpp for what it computes and why).
#include "fast_exp.hpp"
#include "fast_log.hpp"
#include "registration_kernel.hpp"

#ifndef SOGMM_ISA
#error "compile with -DSOGMM_ISA=<name>"
#endif

namespace sogmm::detail::SOGMM_ISA {

namespace {

// The pairs without (kNoise false) or with the points' depth-noise axes: two
// loops, so that the plain one pays nothing for the option.
template <bool kNoise>
void score_pairs(const double* records, const RegistrationPairs& pairs, std::size_t count) {
  const std::uint32_t* __restrict id = pairs.id;
  const double* __restrict px = pairs.x;
  const double* __restrict py = pairs.y;
  const double* __restrict pz = pairs.z;
  const double* __restrict pg = pairs.gray;
  const double* __restrict pux = pairs.ux;
  const double* __restrict puy = pairs.uy;
  const double* __restrict puz = pairs.uz;
  double* __restrict lp = pairs.log_density;
  double* __restrict prx = pairs.pr_x;
  double* __restrict pry = pairs.pr_y;
  double* __restrict prz = pairs.pr_z;
  double* __restrict quad = pairs.quad;
  double* __restrict pux_out = pairs.pu_x;
  double* __restrict puy_out = pairs.pu_y;
  double* __restrict puz_out = pairs.pu_z;
  double* __restrict shrink = pairs.shrink;
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
    double qx = c(kP00) * rx + c(kP01) * ry + c(kP02) * rz;
    double qy = c(kP01) * rx + c(kP11) * ry + c(kP12) * rz;
    double qz = c(kP02) * rx + c(kP12) * ry + c(kP22) * rz;
    double q = rx * qx + ry * qy + rz * qz;
    double l = c(kLogNorm) + (c(kLogNormGray) - 0.5 * dg * dg * c(kInvSgg));
    if constexpr (kNoise) {
      const double ux = pux[j], uy = puy[j], uz = puz[j];
      const double vx = c(kP00) * ux + c(kP01) * uy + c(kP02) * uz;
      const double vy = c(kP01) * ux + c(kP11) * uy + c(kP12) * uz;
      const double vz = c(kP02) * ux + c(kP12) * uy + c(kP22) * uz;
      const double grow = 1.0 + (ux * vx + uy * vy + uz * vz);  // >= 1: P is positive definite
      const double f = 1.0 / grow;
      const double ru = rx * vx + ry * vy + rz * vz;  // r^T P u
      const double fru = f * ru;
      qx -= fru * vx;
      qy -= fru * vy;
      qz -= fru * vz;
      q -= fru * ru;
      l -= 0.5 * fast_log_ge1(grow);
      pux_out[j] = vx;
      puy_out[j] = vy;
      puz_out[j] = vz;
      shrink[j] = f;
    }
    lp[j] = l - 0.5 * q;
    prx[j] = qx;
    pry[j] = qy;
    prz[j] = qz;
    quad[j] = q;
  }
}

}  // namespace

void registration_pairs(const double* records, const RegistrationPairs& pairs, std::size_t count) {
  if (pairs.ux != nullptr)
    score_pairs<true>(records, pairs, count);
  else
    score_pairs<false>(records, pairs, count);
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
