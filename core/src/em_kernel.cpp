// The EM block kernels, compiled once per instruction set (see
// em_kernel.hpp). The loops run over the points of a block with the
// component's parameters broadcast, so the compiler vectorizes them at
// whatever width the translation unit is compiled for.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "em_kernel.hpp"
#include "fast_exp.hpp"
#if defined(__AVX512F__) && defined(__AVX512DQ__)
#include "em_statistics_avx512.hpp"
#endif

#ifndef SOGMM_ISA
#error "compile with -DSOGMM_ISA=<name>"
#endif

namespace sogmm::detail::SOGMM_ISA {
namespace {

// One component's log-densities log w + log det U - 2 log 2 pi - |d^T U|^2 / 2
// with d = x - mu, U upper triangular, from its parameters `q` in the packed
// layout, computed in T: float, or double for a flagged component (the
// whitened coordinate U^T (x - mu) of a component that is thin and large
// cancels too many digits in float32; the points' float32 coordinates are
// exact in double). Raises `mx` to the running maximum per point and returns
// the row's maximum.
template <typename T>
float log_density_row(const Block& block, const T* q, float* __restrict lp, float* __restrict mx) {
  const float* __restrict px = block.xyzg[0];
  const float* __restrict py = block.xyzg[1];
  const float* __restrict pz = block.xyzg[2];
  const float* __restrict pg = block.xyzg[3];
  const T m0 = q[0], m1 = q[1], m2 = q[2], m3 = q[3];
  const T u00 = q[4], u01 = q[5], u02 = q[6], u03 = q[7], u11 = q[8], u12 = q[9], u13 = q[10], u22 = q[11],
          u23 = q[12], u33 = q[13], c = q[14];
  const int count = block.count;
  float lmax = -std::numeric_limits<float>::infinity();
#pragma omp simd reduction(max : lmax)
  for (int p = 0; p < count; ++p) {
    const T d0 = px[p] - m0, d1 = py[p] - m1, d2 = pz[p] - m2, d3 = pg[p] - m3;
    const T y0 = d0 * u00;
    const T y1 = d0 * u01 + d1 * u11;
    const T y2 = d0 * u02 + d1 * u12 + d2 * u22;
    const T y3 = d0 * u03 + d1 * u13 + d2 * u23 + d3 * u33;
    const float l = static_cast<float>(c - T(0.5) * (y0 * y0 + y1 * y1 + y2 * y2 + y3 * y3));
    lp[p] = l;
    mx[p] = l > mx[p] ? l : mx[p];  // (a ternary vectorizes where fmax on a stored array did not)
    lmax = l > lmax ? l : lmax;
  }
  return lmax;
}

// One component's sufficient statistics over the block, centred at its mean
// `q` (packed layout), from its exp(lp - max) row `e`, accumulated in T
// within the block and then added to `st` in double. T is double for a
// flagged component: in float32 the second moments of a 1 km plane (entries
// ~1e4 m^2) would carry errors far above its 1e-4 m^2 thickness.
template <typename T>
void add_statistics(const Block& block, int first, int last, const T* q, const float* __restrict e,
                    const float* __restrict inv_sum, double* st) {
  const float* __restrict px = block.xyzg[0];
  const float* __restrict py = block.xyzg[1];
  const float* __restrict pz = block.xyzg[2];
  const float* __restrict pg = block.xyzg[3];
  const T m0 = q[0], m1 = q[1], m2 = q[2], m3 = q[3];
  // Two passes over the block, each with few enough accumulators to stay in
  // registers (15 at once spill on AVX2's 16 vector registers). Each
  // accumulator sees the same operations in the same order as in one pass;
  // every product r * d_i is also used by a further product, as in one pass,
  // so the compiler never fuses it into its sum (which would round differently).
  T s0 = 0, s1 = 0, c00 = 0, c01 = 0, c02 = 0, c03 = 0;
#pragma omp simd reduction(+ : s0, s1, c00, c01, c02, c03)
  for (int p = first; p < last; ++p) {
    const T r = e[p] * inv_sum[p];
    const T d0 = px[p] - m0, d1 = py[p] - m1, d2 = pz[p] - m2, d3 = pg[p] - m3;
    const T r0 = r * d0;
    s0 += r;
    s1 += r0;
    c00 += r0 * d0;
    c01 += r0 * d1;
    c02 += r0 * d2;
    c03 += r0 * d3;
  }
  T s2 = 0, s3 = 0, s4 = 0, c11 = 0, c12 = 0, c13 = 0, c22 = 0, c23 = 0, c33 = 0;
#pragma omp simd reduction(+ : s2, s3, s4, c11, c12, c13, c22, c23, c33)
  for (int p = first; p < last; ++p) {
    const T r = e[p] * inv_sum[p];
    const T d1 = py[p] - m1, d2 = pz[p] - m2, d3 = pg[p] - m3;
    const T r1 = r * d1, r2 = r * d2, r3 = r * d3;
    s2 += r1;
    s3 += r2;
    s4 += r3;
    c11 += r1 * d1;
    c12 += r1 * d2;
    c13 += r1 * d3;
    c22 += r2 * d2;
    c23 += r2 * d3;
    c33 += r3 * d3;
  }
  st[0] += s0;
  st[1] += s1;
  st[2] += s2;
  st[3] += s3;
  st[4] += s4;
  st[5] += c00;
  st[6] += c01;
  st[7] += c02;
  st[8] += c03;
  st[9] += c11;
  st[10] += c12;
  st[11] += c13;
  st[12] += c22;
  st[13] += c23;
  st[14] += c33;
}

// exp(lp - max) in place over points [first, last) of one row, added to
// `sum`; returns the largest value.
float exp_row(float* __restrict e, const float* __restrict mx, float* __restrict sum, int first, int last) {
  float emax = 0.0f;
#pragma omp simd reduction(max : emax)
  for (int p = first; p < last; ++p) {
    const float v = fast_exp(e[p] - mx[p]);
    e[p] = v;
    sum[p] += v;
    emax = v > emax ? v : emax;
  }
  return emax;
}

// The first and last of a row's `count` points whose lp - max is at least
// -nats, in `lo`, `hi` (count, -1 when there is none).
void near_points(const float* __restrict lp, const float* __restrict mx, int count, float nats, int& lo, int& hi) {
  int l = count, h = -1;
#pragma omp simd reduction(min : l) reduction(max : h)
  for (int p = 0; p < count; ++p) {
    const bool near = lp[p] - mx[p] >= -nats;
    l = near && p < l ? p : l;
    h = near && p > h ? p : h;
  }
  lo = l;
  hi = h;
}

}  // namespace

void em_log_density(const Block& block, const float* params, const double* exact, const std::uint32_t* components,
                    std::size_t n, float* rows, float* row_lp_max, float* max_lp) {
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t at = components[i] * static_cast<std::size_t>(kParamStride);
    row_lp_max[i] = params[at + 15] != 0.0f ? log_density_row(block, exact + at, rows + i * kBlock, max_lp)
                                            : log_density_row(block, params + at, rows + i * kBlock, max_lp);
  }
}

double em_finish(const Block& block, const float* params, const double* exact, const std::uint32_t* components,
                 std::size_t n, float* rows, const float* max_lp, float* row_max, double* stats, float nats,
                 double* squares) {
  // row_max holds each row's largest log-density on entry (see em_kernel.hpp).
  const float* __restrict mx = max_lp;
  const int count = block.count;
  alignas(64) float sum[kBlock];
  alignas(64) float inv_sum[kBlock];
  // Per row (the first kRangedRows; a truncated block evaluates a few dozen):
  // the segments its exponentials and statistics run over, [segment_first,
  // segment_last). Rows beyond, and every row of an exact pass, run over all
  // points.
  constexpr std::size_t kRangedRows = 4096;
  std::uint8_t segment_first[kRangedRows], segment_last[kRangedRows];
  const bool ranged = nats < std::numeric_limits<float>::infinity();

  // exp(lp - max) in place, and its sum per point (log-sum-exp). fast_exp is
  // exactly 0 below -87, so a row below every point's maximum by more than
  // that contributes nothing anywhere: skip it.
  // (A vector reduction: a minimum does not round, and the one signed-zero
  // case it may resolve differently leaves every difference below the same.
  // As a scalar chain of dependent minimums it took ~8% of this function.)
  float lowest_max = mx[0];
#pragma omp simd reduction(min : lowest_max)
  for (int p = 1; p < count; ++p) lowest_max = mx[p] < lowest_max ? mx[p] : lowest_max;
  for (int p = 0; p < kBlock; ++p) sum[p] = 0.0f;
  for (std::size_t i = 0; i < n; ++i) {
    if (row_max[i] - lowest_max < -87.5f) {
      row_max[i] = 0.0f;
      continue;
    }
    float* e = rows + i * kBlock;
    if (ranged && i < kRangedRows) {
      // Only the aligned segments from the first to the last point within
      // nats of its maximum: every term left out (of the statistics and of
      // the normalisers) is more than nats below its point's best.
      int lo, hi;
      near_points(e, mx, count, nats, lo, hi);
      if (hi < lo) {  // no point within nats: the row adds nothing
        row_max[i] = 0.0f;
        continue;
      }
      segment_first[i] = static_cast<std::uint8_t>(lo / kSegment);
      segment_last[i] = static_cast<std::uint8_t>(hi / kSegment + 1);
      row_max[i] = exp_row(e, mx, sum, segment_first[i] * kSegment, std::min(count, segment_last[i] * kSegment));
    } else {
      row_max[i] = exp_row(e, mx, sum, 0, count);
    }
  }
  // The log-likelihood: sum of max + log(sum) per point. The sums are in
  // [1, n] (each point's largest term is exp(0) = 1), so the products of 16
  // of them in double stay far from overflow (n < 2^64) and 16 logs per
  // block replace 256: the log of a product of doubles differs from the sum
  // of their logs by a few ulps of the block's total, far below the EM's
  // tolerance. Lanes p mod 16 fix the order on every instruction set.
  constexpr int kLanes = 16;
  double product[kLanes], max_sum[kLanes];
  for (int j = 0; j < kLanes; ++j) {
    product[j] = 1.0;
    max_sum[j] = 0.0;
  }
  int base = 0;
  for (; base + kLanes <= count; base += kLanes)
    for (int j = 0; j < kLanes; ++j) {
      product[j] *= static_cast<double>(sum[base + j]);
      max_sum[j] += static_cast<double>(mx[base + j]);
    }
  for (int j = 0; base + j < count; ++j) {
    product[j] *= static_cast<double>(sum[base + j]);
    max_sum[j] += static_cast<double>(mx[base + j]);
  }
  double log_likelihood = 0.0;
  if (squares == nullptr) {
    for (int j = 0; j < kLanes; ++j) log_likelihood += max_sum[j] + std::log(product[j]);
    for (int p = 0; p < count; ++p) inv_sum[p] = 1.0f / sum[p];
  } else {
    double log_likelihood_squares = 0.0;
    for (int p = 0; p < count; ++p) {
      const double point_ll = static_cast<double>(mx[p]) + std::log(static_cast<double>(sum[p]));
      log_likelihood += point_ll;
      log_likelihood_squares += point_ll * point_ll;
      inv_sum[p] = 1.0f / sum[p];
    }
    *squares += log_likelihood_squares;
  }

  // Sufficient statistics centred at each component's mean. A component whose
  // responsibilities are all exactly 0 in this block adds nothing: skip it.
  for (std::size_t i = 0; i < n; ++i) {
    if (row_max[i] == 0.0f) continue;
    int first = 0, last = count;
    if (ranged && i < kRangedRows) {
      first = segment_first[i] * kSegment;
      last = std::min(count, segment_last[i] * kSegment);
    }
    const std::size_t at = components[i] * static_cast<std::size_t>(kParamStride);
    double* st = stats + components[i] * kStatStride;
    if (params[at + 15] != 0.0f)
      add_statistics(block, first, last, exact + at, rows + i * kBlock, inv_sum, st);
    else
#if defined(__AVX512F__) && defined(__AVX512DQ__)
      // The same floats as add_statistics<float>, its lanes summed for all
      // 15 sums at once (em_statistics_avx512.hpp).
      add_statistics_avx512(block, first, last, params + at, rows + i * kBlock, inv_sum, st);
#else
      add_statistics(block, first, last, params + at, rows + i * kBlock, inv_sum, st);
#endif
  }
  return log_likelihood;
}

}  // namespace sogmm::detail::SOGMM_ISA
