// The EM's sufficient statistics of one float32 row on AVX-512 (private to
// em_kernel.cpp's AVX-512 object; included only where __AVX512F__ is set).
//
// Why: the portable loop (em_kernel.cpp, add_statistics) is an OpenMP simd
// reduction of 15 accumulators. GCC lowers each to an array of 16 lanes:
// lane j sums the terms of points first + 16 i + j (i over the whole
// vectors), the points after the last whole vector are added one by one to
// lane 0, and the result is 0 + lane 0 + lane 1 + ... + lane 15, one scalar
// addition after another from memory (225 dependent additions a row, ~40% of
// the loop's own time on a truncated d = 1 fit's rows of ~100 points). Here
// the same lanes are summed in the same order, but for the 15 accumulators
// at once: the accumulator vectors are transposed (lane j of every
// accumulator in one vector) and the 16 vectors added in lane order. Every
// statistic is the same float as the portable loop's, so the fit keeps its
// bits; one pass holds all 15 accumulators in AVX-512's 32 registers.
#pragma once

#include <immintrin.h>

#include <cmath>

#if defined(__GNUC__) && !defined(__clang__)
// GCC 12's AVX-512 intrinsics start from _mm512_undefined_ps() and warn that
// it "may be used uninitialized" (GCC bug 105593, fixed in 13): not ours (as
// in occupancy_kernel.cpp). Only for this header: pushed here, popped at its end.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include "em_kernel.hpp"

namespace sogmm::detail::SOGMM_ISA {
namespace {

// r[o] becomes the o-th column of the 16 x 16 floats r (lane a of the new
// r[o] is lane o of the old r[a]).
inline void transpose16(__m512 r[16]) {
  __m512 t[16];
  for (int i = 0; i < 8; ++i) {
    t[2 * i] = _mm512_unpacklo_ps(r[2 * i], r[2 * i + 1]);
    t[2 * i + 1] = _mm512_unpackhi_ps(r[2 * i], r[2 * i + 1]);
  }
  for (int i = 0; i < 4; ++i) {
    const __m512d a = _mm512_castps_pd(t[4 * i]), b = _mm512_castps_pd(t[4 * i + 1]);
    const __m512d c = _mm512_castps_pd(t[4 * i + 2]), d = _mm512_castps_pd(t[4 * i + 3]);
    r[4 * i] = _mm512_castpd_ps(_mm512_unpacklo_pd(a, c));
    r[4 * i + 1] = _mm512_castpd_ps(_mm512_unpackhi_pd(a, c));
    r[4 * i + 2] = _mm512_castpd_ps(_mm512_unpacklo_pd(b, d));
    r[4 * i + 3] = _mm512_castpd_ps(_mm512_unpackhi_pd(b, d));
  }
  for (int i = 0; i < 4; ++i) {
    t[i] = _mm512_shuffle_f32x4(r[i], r[4 + i], 0x88);
    t[4 + i] = _mm512_shuffle_f32x4(r[i], r[4 + i], 0xdd);
    t[8 + i] = _mm512_shuffle_f32x4(r[8 + i], r[12 + i], 0x88);
    t[12 + i] = _mm512_shuffle_f32x4(r[8 + i], r[12 + i], 0xdd);
  }
  for (int i = 0; i < 4; ++i) {
    r[i] = _mm512_shuffle_f32x4(t[i], t[8 + i], 0x88);
    r[8 + i] = _mm512_shuffle_f32x4(t[i], t[8 + i], 0xdd);
    r[4 + i] = _mm512_shuffle_f32x4(t[4 + i], t[12 + i], 0x88);
    r[12 + i] = _mm512_shuffle_f32x4(t[4 + i], t[12 + i], 0xdd);
  }
}

// add_statistics for a float32 component (packed parameters `q`), the same
// statistics bit for bit: acc[a] is statistic a in st's order (sum r, sum r
// d (4), the upper triangle of sum r d d^T (10)); each term is the portable
// loop's (r = e / sum, d = x - mean, r d_i, and r d_i d_j as one fused
// multiply-add, as the compiler contracts it there).
void add_statistics_avx512(const Block& block, int first, int last, const float* q, const float* __restrict e,
                           const float* __restrict inv_sum, double* st) {
  const float* __restrict px = block.xyzg[0];
  const float* __restrict py = block.xyzg[1];
  const float* __restrict pz = block.xyzg[2];
  const float* __restrict pg = block.xyzg[3];
  __m512 acc[16];
  for (__m512& a : acc) a = _mm512_setzero_ps();
  const __m512 m0 = _mm512_set1_ps(q[0]), m1 = _mm512_set1_ps(q[1]), m2 = _mm512_set1_ps(q[2]),
               m3 = _mm512_set1_ps(q[3]);
  int p = first;
  for (; p + 16 <= last; p += 16) {
    const __m512 r = _mm512_mul_ps(_mm512_loadu_ps(e + p), _mm512_loadu_ps(inv_sum + p));
    const __m512 d0 = _mm512_sub_ps(_mm512_loadu_ps(px + p), m0), d1 = _mm512_sub_ps(_mm512_loadu_ps(py + p), m1);
    const __m512 d2 = _mm512_sub_ps(_mm512_loadu_ps(pz + p), m2), d3 = _mm512_sub_ps(_mm512_loadu_ps(pg + p), m3);
    const __m512 r0 = _mm512_mul_ps(r, d0), r1 = _mm512_mul_ps(r, d1), r2 = _mm512_mul_ps(r, d2),
                 r3 = _mm512_mul_ps(r, d3);
    acc[0] = _mm512_add_ps(acc[0], r);
    acc[1] = _mm512_add_ps(acc[1], r0);
    acc[2] = _mm512_add_ps(acc[2], r1);
    acc[3] = _mm512_add_ps(acc[3], r2);
    acc[4] = _mm512_add_ps(acc[4], r3);
    acc[5] = _mm512_fmadd_ps(r0, d0, acc[5]);
    acc[6] = _mm512_fmadd_ps(r0, d1, acc[6]);
    acc[7] = _mm512_fmadd_ps(r0, d2, acc[7]);
    acc[8] = _mm512_fmadd_ps(r0, d3, acc[8]);
    acc[9] = _mm512_fmadd_ps(r1, d1, acc[9]);
    acc[10] = _mm512_fmadd_ps(r1, d2, acc[10]);
    acc[11] = _mm512_fmadd_ps(r1, d3, acc[11]);
    acc[12] = _mm512_fmadd_ps(r2, d2, acc[12]);
    acc[13] = _mm512_fmadd_ps(r2, d3, acc[13]);
    acc[14] = _mm512_fmadd_ps(r3, d3, acc[14]);
  }
  if (p < last) {  // the points after the last whole vector, one by one into lane 0
    float l0[15];
    for (int a = 0; a < 15; ++a) l0[a] = _mm512_cvtss_f32(acc[a]);
    for (; p < last; ++p) {
      const float r = e[p] * inv_sum[p];
      const float d0 = px[p] - q[0], d1 = py[p] - q[1], d2 = pz[p] - q[2], d3 = pg[p] - q[3];
      const float r0 = r * d0, r1 = r * d1, r2 = r * d2, r3 = r * d3;
      l0[0] += r;
      l0[1] += r0;
      l0[2] += r1;
      l0[3] += r2;
      l0[4] += r3;
      l0[5] = std::fma(r0, d0, l0[5]);
      l0[6] = std::fma(r0, d1, l0[6]);
      l0[7] = std::fma(r0, d2, l0[7]);
      l0[8] = std::fma(r0, d3, l0[8]);
      l0[9] = std::fma(r1, d1, l0[9]);
      l0[10] = std::fma(r1, d2, l0[10]);
      l0[11] = std::fma(r1, d3, l0[11]);
      l0[12] = std::fma(r2, d2, l0[12]);
      l0[13] = std::fma(r2, d3, l0[13]);
      l0[14] = std::fma(r3, d3, l0[14]);
    }
    for (int a = 0; a < 15; ++a) acc[a] = _mm512_mask_mov_ps(acc[a], 1, _mm512_set1_ps(l0[a]));
  }
  transpose16(acc);
  __m512 sum = _mm512_setzero_ps();
  for (int j = 0; j < 16; ++j) sum = _mm512_add_ps(sum, acc[j]);
  const __m512d lo = _mm512_cvtps_pd(_mm512_castps512_ps256(sum));
  const __m512d hi = _mm512_cvtps_pd(_mm512_extractf32x8_ps(sum, 1));
  _mm512_storeu_pd(st, _mm512_add_pd(_mm512_loadu_pd(st), lo));
  _mm512_mask_storeu_pd(st + 8, 0x7f, _mm512_add_pd(_mm512_maskz_loadu_pd(0x7f, st + 8), hi));
}

}  // namespace
}  // namespace sogmm::detail::SOGMM_ISA

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
