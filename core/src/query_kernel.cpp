// The query block kernels, compiled once per instruction set (see
// query_kernel.hpp). Each chunk of components is evaluated into scratch
// rows (one per component, kQueryBlock points wide), then folded into the
// running per-point state.
#include <algorithm>
#include <cmath>
#include <limits>

#include "fast_exp.hpp"
#include "query_kernel.hpp"

#ifndef SOGMM_ISA
#error "compile with -DSOGMM_ISA=<name>"
#endif

namespace sogmm::detail::SOGMM_ISA {
namespace {

constexpr int P = kQueryBlock;
// fast_exp_double is exactly 0 below -708: a row whose largest term is that
// far below every point's maximum adds exactly 0 and is skipped.
constexpr double kZeroBelow = -708.0;

// log w + log N of the chunk's components into rows (one row of P per
// component) and each row's largest value into row_max; raises max.
template <int D>
void log_terms(const QueryBlock& b, const double* params, const std::uint32_t* comps, std::size_t n, double* rows,
               double* row_max, double* max) {
  const double* __restrict x0 = b.coord[0];
  const double* __restrict x1 = b.coord[1];
  const double* __restrict x2 = b.coord[2];
  const double* __restrict x3 = b.coord[D == 4 ? 3 : 2];
  double* __restrict mx = max;
  for (std::size_t i = 0; i < n; ++i) {
    const double* q = params + static_cast<std::size_t>(comps[i]) * kQueryStride;
    double* __restrict lp = rows + i * P;
    double lmax = -std::numeric_limits<double>::infinity();
    if constexpr (D == 3) {
      const double m0 = q[0], m1 = q[1], m2 = q[2], a00 = q[3], a10 = q[4], a11 = q[5], a20 = q[6], a21 = q[7],
                   a22 = q[8], c = q[9];
#pragma omp simd reduction(max : lmax)
      for (int p = 0; p < P; ++p) {
        const double d0 = x0[p] - m0, d1 = x1[p] - m1, d2 = x2[p] - m2;
        const double y0 = a00 * d0, y1 = a10 * d0 + a11 * d1, y2 = a20 * d0 + a21 * d1 + a22 * d2;
        const double l = c - 0.5 * (y0 * y0 + y1 * y1 + y2 * y2);
        lp[p] = l;
        mx[p] = l > mx[p] ? l : mx[p];
        lmax = l > lmax ? l : lmax;
      }
    } else {
      const double m0 = q[0], m1 = q[1], m2 = q[2], m3 = q[3], a00 = q[4], a10 = q[5], a11 = q[6], a20 = q[7],
                   a21 = q[8], a22 = q[9], a30 = q[10], a31 = q[11], a32 = q[12], a33 = q[13], c = q[14];
#pragma omp simd reduction(max : lmax)
      for (int p = 0; p < P; ++p) {
        const double d0 = x0[p] - m0, d1 = x1[p] - m1, d2 = x2[p] - m2, d3 = x3[p] - m3;
        const double y0 = a00 * d0, y1 = a10 * d0 + a11 * d1, y2 = a20 * d0 + a21 * d1 + a22 * d2;
        const double y3 = a30 * d0 + a31 * d1 + a32 * d2 + a33 * d3;
        const double l = c - 0.5 * (y0 * y0 + y1 * y1 + y2 * y2 + y3 * y3);
        lp[p] = l;
        mx[p] = l > mx[p] ? l : mx[p];
        lmax = l > lmax ? l : lmax;
      }
    }
    row_max[i] = lmax;
  }
}

// Rescales sums kept relative to old_max to new_max (exp(-inf) is 0: a
// point's first chunk) and returns the lowest new maximum of the block.
double lowest(const double* max, int count) {
  double lo = max[0];
  for (int p = 1; p < count; ++p) lo = std::min(lo, max[p]);
  return lo;
}

template <int D>
void score(const QueryBlock& b, const double* params, const std::uint32_t* comps, std::size_t n, double* scratch,
           ScoreState& st) {
  alignas(64) double new_max[P];
  double row_max[kQueryChunk];
  for (std::size_t c0 = 0; c0 < n; c0 += kQueryChunk) {
    const std::size_t cn = std::min(kQueryChunk, n - c0);
    for (int p = 0; p < P; ++p) new_max[p] = st.max[p];
    log_terms<D>(b, params, comps + c0, cn, scratch, row_max, new_max);
#pragma omp simd
    for (int p = 0; p < P; ++p) {
      st.sum[p] = st.max[p] == new_max[p] ? st.sum[p] : st.sum[p] * fast_exp_double(st.max[p] - new_max[p]);
      st.max[p] = new_max[p];
    }
    const double skip_below = lowest(st.max, b.count) + kZeroBelow;
    double* __restrict sum = st.sum;
    const double* __restrict mx = st.max;
    for (std::size_t i = 0; i < cn; ++i) {
      if (row_max[i] < skip_below) continue;
      const double* __restrict lp = scratch + i * P;
#pragma omp simd
      for (int p = 0; p < P; ++p) sum[p] += fast_exp_double(lp[p] - mx[p]);
    }
  }
}

}  // namespace

void query_score3(const QueryBlock& b, const double* params, const std::uint32_t* comps, std::size_t n,
                  double* scratch, ScoreState& st) {
  score<3>(b, params, comps, n, scratch, st);
}

void query_score4(const QueryBlock& b, const double* params, const std::uint32_t* comps, std::size_t n,
                  double* scratch, ScoreState& st) {
  score<4>(b, params, comps, n, scratch, st);
}

void query_regress(const QueryBlock& b, const double* params, const std::uint32_t* comps, std::size_t n,
                   double* scratch, RegressState& st) {
  alignas(64) double new_max[P];
  alignas(64) double cw[P], cs[P], cv[P], cm2[P];
  double row_max[kQueryChunk];
  double* lambda = scratch + kQueryChunk * P;
  const double* __restrict x0 = b.coord[0];
  const double* __restrict x1 = b.coord[1];
  const double* __restrict x2 = b.coord[2];
  for (std::size_t c0 = 0; c0 < n; c0 += kQueryChunk) {
    const std::size_t cn = std::min(kQueryChunk, n - c0);
    for (int p = 0; p < P; ++p) new_max[p] = st.max[p];
    log_terms<3>(b, params, comps + c0, cn, scratch, row_max, new_max);
#pragma omp simd
    for (int p = 0; p < P; ++p) {
      const double s = st.max[p] == new_max[p] ? 1.0 : fast_exp_double(st.max[p] - new_max[p]);
      st.w[p] *= s;
      st.m2[p] *= s;
      st.v[p] *= s;
      st.max[p] = new_max[p];
      cw[p] = cs[p] = cv[p] = cm2[p] = 0.0;
    }
    const double skip_below = lowest(st.max, b.count) + kZeroBelow;
    const double* __restrict mx = st.max;
    // Weights exp(term - max) in place of the terms, the conditional means
    // lambda = mean_g + gain . (x - mu) beside them, and the chunk's sums.
    for (std::size_t i = 0; i < cn; ++i) {
      if (row_max[i] < skip_below) continue;
      const double* q = params + static_cast<std::size_t>(comps[c0 + i]) * kQueryStride;
      const double m0 = q[0], m1 = q[1], m2 = q[2], g0 = q[10], g1 = q[11], g2 = q[12], mg = q[13], nu2 = q[14];
      double* __restrict e = scratch + i * P;
      double* __restrict la = lambda + i * P;
#pragma omp simd
      for (int p = 0; p < P; ++p) {
        const double w = fast_exp_double(e[p] - mx[p]);
        const double l = mg + g0 * (x0[p] - m0) + g1 * (x1[p] - m1) + g2 * (x2[p] - m2);
        e[p] = w;
        la[p] = l;
        cw[p] += w;
        cs[p] += w * l;
        cv[p] += w * nu2;
      }
    }
    // The chunk's mean, then its squared deviations about it.
#pragma omp simd
    for (int p = 0; p < P; ++p) cs[p] = cw[p] > 0.0 ? cs[p] / cw[p] : 0.0;
    for (std::size_t i = 0; i < cn; ++i) {
      if (row_max[i] < skip_below) continue;
      const double* __restrict e = scratch + i * P;
      const double* __restrict la = lambda + i * P;
#pragma omp simd
      for (int p = 0; p < P; ++p) {
        const double d = la[p] - cs[p];
        cm2[p] += e[p] * d * d;
      }
    }
    // Merge the chunk into the running moments (Chan et al.).
#pragma omp simd
    for (int p = 0; p < P; ++p) {
      const double w = st.w[p] + cw[p];
      const double f = cw[p] > 0.0 ? cw[p] / w : 0.0;
      const double d = cs[p] - st.mean[p];
      st.mean[p] += d * f;
      st.m2[p] += cm2[p] + d * d * st.w[p] * f;
      st.v[p] += cv[p];
      st.w[p] = w;
    }
  }
}

}  // namespace sogmm::detail::SOGMM_ISA
