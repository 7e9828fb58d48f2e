// The occupancy frame kernel, compiled once per instruction set (see
// occupancy_kernel.hpp for why every width gives the scalar path's bits).
// Two vector passes: every point is projected and compared with the render
// (most are more than the band in front of the surface, or behind it, and
// are done there); the few within the band are gathered into a short list
// whose Phi terms are evaluated in a second pass, then added point by point.
#include <cmath>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#if defined(__GNUC__) && !defined(__clang__)
// GCC 12's AVX-512 intrinsics start from _mm512_undefined_pd() and warn that
// it "may be used uninitialized" (GCC bug 105593, fixed in 13): not ours.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include "occupancy_evidence.hpp"
#include "occupancy_kernel.hpp"
#include "occupancy_phi.hpp"

#ifndef SOGMM_ISA
#error "compile with -DSOGMM_ISA=<name>"
#endif

namespace sogmm::detail::SOGMM_ISA {
namespace {

constexpr int B = kOccupancyBlock;
// The AVX-512 packing below stores whole groups of 8 lanes: it needs B to be
// a multiple of 8 to stay inside the arrays.
static_assert(B % 8 == 0, "the occupancy block must be a whole number of 8-lane groups");

// Evidence::phi as selects (x is held inside the table's range first, so
// its index is defined; inside, the table sees x itself).
inline double phi(const double* c, double x) {
  const double inside = x < PhiTable::kLo ? PhiTable::kLo : (x > PhiTable::kHi ? PhiTable::kHi : x);
  const double table = PhiTable::at(c, inside);
  return x < -kExactSigmas ? 0.0 : (x > kExactSigmas ? 1.0 : table);
}

}  // namespace

void occupancy_frame(const OccupancyFrame& f, OccupancyLanes& lanes, int count) {
  const double r0 = f.r[0], r1 = f.r[1], r2 = f.r[2], r3 = f.r[3], r4 = f.r[4], r5 = f.r[5], r6 = f.r[6],
               r7 = f.r[7], r8 = f.r[8], t0 = f.t[0], t1 = f.t[1], t2 = f.t[2];
  const double fx = f.fx, fy = f.fy, cx = f.cx, cy = f.cy, zmin = f.depth_min, zmax = f.depth_max, band = f.band;
  const double W = f.width, H = f.height;
  const int columns = f.width;
  const float* __restrict image = f.depth;
  const double* __restrict x = lanes.x;
  const double* __restrict y = lanes.y;
  const double* __restrict z = lanes.z;
  double* __restrict unknown = lanes.unknown;
  double* __restrict whole_free = lanes.whole_free;
  alignas(64) double depth[B], norm2[B], surface[B];
  alignas(64) int pixel[B], seen[B], in_band[B];

  // Pass 1, in three loops that each vectorize (a masked gather of floats
  // indexed by ints between loops over doubles does not): FrameIndex::project
  // (u = floor(a) is in [0, W) exactly when a is, and then equals its
  // truncation), the render's depth there, and the cuts of occupancy.cpp's
  // per-point loop.
#pragma omp simd
  for (int j = 0; j < count; ++j) {
    const double p0 = r0 * x[j] + r1 * y[j] + r2 * z[j] + t0;
    const double p1 = r3 * x[j] + r4 * y[j] + r5 * z[j] + t1;
    const double p2 = r6 * x[j] + r7 * y[j] + r8 * z[j] + t2;
    const double a = fx * p0 / p2 + cx + 0.5;
    const double b = fy * p1 / p2 + cy + 0.5;
    const bool in = p2 > zmin && p2 <= zmax && a >= 0 && b >= 0 && a < W && b < H;
    seen[j] = in;
    pixel[j] = static_cast<int>(in ? b : 0.0) * columns + static_cast<int>(in ? a : 0.0);
    depth[j] = p2;
    norm2[j] = p0 * p0 + p1 * p1 + p2 * p2;
  }
#pragma omp simd
  for (int j = 0; j < count; ++j) surface[j] = image[pixel[j]];
  int any_in_band = 0;
#pragma omp simd reduction(| : any_in_band)
  for (int j = 0; j < count; ++j) {
    const double d = surface[j];
    const bool surface_seen = seen[j] && d == d;  // NaN: no surface rendered, no evidence
    const double gap = depth[j] - d;
    const bool free_whole = surface_seen && gap < -band;
    whole_free[j] = free_whole ? whole_free[j] + 1.0 : whole_free[j];
    unknown[j] = free_whole ? 0.0 : unknown[j];
    in_band[j] = surface_seen && !(gap < -band) && !(gap > band);
    any_in_band |= in_band[j];
  }
  if (!any_in_band) return;  // the usual case: nothing for pass 2

  // The points within the band, packed (contiguous loops vectorize where
  // gathers by a list would not).
  int k = 0;
  alignas(64) double band_depth[B], band_norm2[B], band_surface[B];
#if defined(__AVX512F__) && defined(__AVX512VL__)
  // Eight lanes at a time, compressed in registers and stored whole (a
  // compressing store to memory is microcoded on some CPUs): the lanes past
  // the packed ones are overwritten or never read, and k + 8 <= j + 8 <= B.
  // Each group's mask and first packed lane are kept for the expansion at
  // the end.
  __mmask8 group_band[B / 8];
  int group_first[B / 8];
  for (int j = 0; j < count; j += 8) {
    const __m256i flags = _mm256_load_si256(reinterpret_cast<const __m256i*>(in_band + j));
    const __mmask8 valid = count - j >= 8 ? 0xff : static_cast<__mmask8>((1u << (count - j)) - 1u);
    const __mmask8 m = static_cast<__mmask8>(_mm256_test_epi32_mask(flags, flags) & valid);
    group_band[j / 8] = m;
    group_first[j / 8] = k;
    _mm512_storeu_pd(band_depth + k, _mm512_maskz_compress_pd(m, _mm512_load_pd(depth + j)));
    _mm512_storeu_pd(band_norm2 + k, _mm512_maskz_compress_pd(m, _mm512_load_pd(norm2 + j)));
    _mm512_storeu_pd(band_surface + k, _mm512_maskz_compress_pd(m, _mm512_load_pd(surface + j)));
    k += __builtin_popcount(m);
  }
#else
  alignas(64) int list[B];
  for (int j = 0; j < count; ++j) {
    list[k] = j;
    band_depth[k] = depth[j];
    band_norm2[k] = norm2[j];
    band_surface[k] = surface[j];
    k += in_band[j];
  }
#endif

  // Pass 2: Evidence::add for the points within the band.
  const double h = f.thickness, sigma = f.sigma;
  const double* __restrict c = f.phi;
  alignas(64) double e_of[B], b_of[B], o_of[B];
  alignas(64) int kind[B];  // 0: no evidence, 1: whole free, 2: e, b, o
#if defined(__AVX512F__) && defined(__AVX512VL__)
  // Eight packed lanes at a time with the table's four coefficients of a
  // lane read by one 32-byte load and transposed in registers (four gathers
  // of one double a lane each, which the compiler splits into scalar loads,
  // were most of this pass). The same operations in the same order as
  // phi() and the loop below; lanes past k hold stale values whose results
  // are never read (their table index is clamped like any other).
  const __m512d kLo = _mm512_set1_pd(PhiTable::kLo), kHi = _mm512_set1_pd(PhiTable::kHi);
  const __m512d per_unit = _mm512_set1_pd(PhiTable::kPerUnit), cut = _mm512_set1_pd(kExactSigmas);
  const __m512d minus_cut = _mm512_set1_pd(-kExactSigmas), one = _mm512_set1_pd(1.0), zero = _mm512_setzero_pd();
  const __m512i low = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13), high = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
  const auto table = [&](__m512d x) {
    const __m512d inside = _mm512_mask_blend_pd(
        _mm512_cmp_pd_mask(x, kLo, _CMP_LT_OQ), _mm512_mask_blend_pd(_mm512_cmp_pd_mask(x, kHi, _CMP_GT_OQ), x, kHi),
        kLo);
    const __m512d s = _mm512_mul_pd(_mm512_sub_pd(inside, kLo), per_unit);
    __m256i i = _mm512_cvttpd_epi32(s);
    i = _mm256_min_epi32(_mm256_max_epi32(i, _mm256_setzero_si256()), _mm256_set1_epi32(PhiTable::kIntervals - 1));
    const __m512d t = _mm512_sub_pd(s, _mm512_cvtepi32_pd(i));
    alignas(32) int q[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(q), _mm256_slli_epi32(i, 2));
    const auto pair = [&](int a, int b) {
      return _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_loadu_pd(c + q[a])), _mm256_loadu_pd(c + q[b]), 1);
    };
    const __m512d r04 = pair(0, 4), r15 = pair(1, 5), r26 = pair(2, 6), r37 = pair(3, 7);
    const __m512d t0 = _mm512_unpacklo_pd(r04, r15), t1 = _mm512_unpackhi_pd(r04, r15);
    const __m512d t2 = _mm512_unpacklo_pd(r26, r37), t3 = _mm512_unpackhi_pd(r26, r37);
    const __m512d c0 = _mm512_permutex2var_pd(t0, low, t2), c1 = _mm512_permutex2var_pd(t1, low, t3);
    const __m512d c2 = _mm512_permutex2var_pd(t0, high, t2), c3 = _mm512_permutex2var_pd(t1, high, t3);
    const __m512d v = _mm512_add_pd(c0, _mm512_mul_pd(t, _mm512_add_pd(c1, _mm512_mul_pd(t, _mm512_add_pd(c2, _mm512_mul_pd(t, c3))))));
    return _mm512_mask_blend_pd(_mm512_cmp_pd_mask(x, minus_cut, _CMP_LT_OQ),
                                _mm512_mask_blend_pd(_mm512_cmp_pd_mask(x, cut, _CMP_GT_OQ), v, one), zero);
  };
  const __m512d hv = _mm512_set1_pd(h), sigmav = _mm512_set1_pd(sigma);
  for (int m = 0; m < k; m += 8) {
    const __m512d p2 = _mm512_load_pd(band_depth + m);
    const __m512d ray = _mm512_div_pd(_mm512_sqrt_pd(_mm512_load_pd(band_norm2 + m)), p2);
    const __m512d gap = _mm512_sub_pd(_mm512_mul_pd(p2, ray), _mm512_mul_pd(_mm512_load_pd(band_surface + m), ray));
    const __m512d front = _mm512_div_pd(_mm512_add_pd(gap, hv), sigmav);
    const __m512d back = _mm512_div_pd(_mm512_sub_pd(gap, hv), sigmav);
    const __m512d e = _mm512_sub_pd(one, table(front));
    const __m512d b = table(back);
    const __m512d o = _mm512_sub_pd(_mm512_sub_pd(one, e), b);
    const __mmask8 whole = _mm512_cmp_pd_mask(front, minus_cut, _CMP_LT_OQ);
    const __mmask8 none = _mm512_cmp_pd_mask(back, cut, _CMP_GT_OQ);
    const __m256i two = _mm256_set1_epi32(2);
    _mm256_store_si256(reinterpret_cast<__m256i*>(kind + m),
                       _mm256_mask_blend_epi32(whole, _mm256_mask_blend_epi32(none, two, _mm256_setzero_si256()),
                                               _mm256_set1_epi32(1)));
    _mm512_store_pd(e_of + m, e);
    _mm512_store_pd(b_of + m, b);
    _mm512_store_pd(o_of + m, _mm512_mask_blend_pd(_mm512_cmp_pd_mask(zero, o, _CMP_LT_OQ), zero, o));
  }
#else
#pragma omp simd
  for (int m = 0; m < k; ++m) {
    const double ray = std::sqrt(band_norm2[m]) / band_depth[m];
    const double r = band_depth[m] * ray, s = band_surface[m] * ray;
    const double front = (r - s + h) / sigma;
    const double back = (r - s - h) / sigma;
    const double e = 1.0 - phi(c, front);
    const double b = phi(c, back);
    const double o = 1.0 - e - b;
    kind[m] = front < -kExactSigmas ? 1 : (back > kExactSigmas ? 0 : 2);
    e_of[m] = e;
    b_of[m] = b;
    o_of[m] = 0.0 < o ? o : 0.0;  // std::max(0.0, o)
  }
#endif
#if defined(__AVX512F__) && defined(__AVX512VL__)
  // The packed results expanded back to their lanes, eight at a time, and
  // added under masks: per lane the operations of the loop below, without
  // its branch per packed point on the point's kind (that loop was 7% of a
  // query's CPU; this one 1-3% less in all, README section 7). Lanes past
  // the packed ones are read but masked off, and first + 8 <= j + 8 <= B.
  const __m256i whole_kind = _mm256_set1_epi32(1), evidence_kind = _mm256_set1_epi32(2);
  double* __restrict free = lanes.free;
  double* __restrict occupied = lanes.occupied;
  for (int j = 0; j < count; j += 8) {
    const __mmask8 m = group_band[j / 8];
    if (!m) continue;
    const int first = group_first[j / 8];
    const __m256i kinds =
        _mm256_maskz_expand_epi32(m, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kind + first)));
    const __mmask8 whole = _mm256_mask_cmpeq_epi32_mask(m, kinds, whole_kind);
    const __mmask8 evidence = _mm256_mask_cmpeq_epi32_mask(m, kinds, evidence_kind);
    const __m512d wf = _mm512_load_pd(whole_free + j);
    _mm512_store_pd(whole_free + j, _mm512_mask_add_pd(wf, whole, wf, one));
    const __m512d u = _mm512_mask_mov_pd(_mm512_load_pd(unknown + j), whole, zero);
    _mm512_store_pd(unknown + j,
                    _mm512_mask_mul_pd(u, evidence, u, _mm512_maskz_expand_pd(m, _mm512_loadu_pd(b_of + first))));
    const __m512d fr = _mm512_load_pd(free + j);
    _mm512_store_pd(free + j,
                    _mm512_mask_add_pd(fr, evidence, fr, _mm512_maskz_expand_pd(m, _mm512_loadu_pd(e_of + first))));
    const __m512d oc = _mm512_load_pd(occupied + j);
    _mm512_store_pd(occupied + j,
                    _mm512_mask_add_pd(oc, evidence, oc, _mm512_maskz_expand_pd(m, _mm512_loadu_pd(o_of + first))));
  }
#else
  for (int m = 0; m < k; ++m) {
    const int j = list[m];
    if (kind[m] == 1) {
      whole_free[j] += 1.0;
      unknown[j] = 0.0;
    } else if (kind[m] == 2) {
      unknown[j] *= b_of[m];
      lanes.free[j] += e_of[m];
      lanes.occupied[j] += o_of[m];
    }
  }
#endif
}

}  // namespace sogmm::detail::SOGMM_ISA
