// EM driver: blocked, fused E+M passes with a fixed reduction order.
#include "sogmm/em.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "covariance_storage.hpp"
#include "em_acceleration.hpp"
#include "em_kernel.hpp"
#include "em_regions.hpp"
#include "em_truncation.hpp"
#include "em_working.hpp"
#include "lower_inverse.hpp"
#include "sogmm/options.hpp"
#include "parallel.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "z_order.hpp"

namespace sogmm {
namespace {

using detail::kBlock;
using detail::kParamStride;
using detail::kStatStride;

constexpr double kLog2Pi = 1.8378770664093454836;
// scikit-learn adds 10 * machine epsilon to every component's responsibility
// sum so that an empty component does not divide by zero.
constexpr double kEmptyGuard = 10.0 * std::numeric_limits<double>::epsilon();
// Chunks of points processed in one parallel wave. Fixed (not the thread
// count), so the order in which partial sums are added never changes.
constexpr std::size_t kWave = 16;
constexpr std::size_t kMaxBlocksPerChunk = 32;
// The chunks' partial statistics a parallel region may hold at once
// (em_regions.hpp): as many waves as fit run in one region (the reduction
// order, chunk by chunk, is the same), so that a sparse (truncated) pass, whose
// waves are short, does not pay a region's start, tail imbalance and serial
// reduction per wave.
std::atomic<std::size_t> g_region_bytes{detail::kDefaultEmRegionBytes};

// The regulariser per diagonal (x, y, z, gray).
using RegDiagonal = std::array<double, 4>;
RegDiagonal diagonal(const RegCovarFloors& f) { return {f.spatial, f.spatial, f.spatial, f.gray}; }

void check_options(const EmOptions& o) {
  require_option(OptionKey::TOL, o.tol, "EM tol");
  require_option(OptionKey::MAX_ITER, std::int64_t{o.max_iter}, "EM max_iter");
  require_option(OptionKey::THREADS, std::int64_t{o.threads}, "EM threads");
  require_option(OptionKey::TRUNCATION_NATS, o.truncation_nats, "EM truncation_nats");
  require_option(OptionKey::EM_ACCELERATION, static_cast<std::int64_t>(o.acceleration), "EM acceleration");
  require_option(OptionKey::TOL_STANDARD_ERRORS, o.tol_standard_errors, "EM tol_standard_errors");
}

// The frame the fit works in: the midpoint of the data's bounding box per
// coordinate, so that every coordinate the float32 kernels see is at most half
// the data's extent whatever its offset (a cloud 10 km from the origin is
// fitted exactly as the same cloud at the origin), and the data's scale, from
// which every floor that the user does not set is derived.
struct Frame {
  double origin[4];
  double extent;  // largest side of the 4-D bounding box (> 0)

  explicit Frame(const PointsView& pts) {
    float lo[4], hi[4];
    for (int j = 0; j < 4; ++j) lo[j] = hi[j] = pts[0][j];
    for (std::size_t i = 1; i < pts.size; ++i)
      for (int j = 0; j < 4; ++j) {
        lo[j] = std::min(lo[j], pts[i][j]);
        hi[j] = std::max(hi[j], pts[i][j]);
      }
    extent = 0.0;
    for (int j = 0; j < 4; ++j) {
      // The origin need not be exact: it only has to be near the data's centre.
      origin[j] = 0.5 * (static_cast<double>(lo[j]) + static_cast<double>(hi[j]));
      extent = std::max(extent, static_cast<double>(hi[j]) - static_cast<double>(lo[j]));
    }
    if (!(extent > 0.0)) extent = 1.0;  // all points equal: any unit will do
  }
};

// Points relative to the frame's origin as four coordinate arrays (structure
// of arrays), padded to whole blocks. Points are sorted along a Z-order curve
// of cells 2^-20 of the extent so that each block is spatially compact: whole
// rows of negligible components can then be skipped exactly, and the truncated
// E-step's bounds are tight. Sums run in that (deterministic) order, which a
// translation or a scaling of the data does not change.
struct SoaPoints {
  std::vector<float> x, y, z, g;
  std::size_t n = 0;
  std::size_t n_blocks = 0;
  std::vector<float> box;        // per block: min[4], max[4]
  std::vector<float> group_box;  // per group of detail::kGroupBlocks blocks: the union of their boxes

  // The keys, the transposition and the boxes run on `threads` threads, each
  // element written by one loop index (the same values for any team); only
  // the radix sort is serial. Serial, this set-up was ~8% of the truncated
  // d = 1 fit's EM CPU on one thread, with the other thread idle (issue 35).
  SoaPoints(const PointsView& pts, const Frame& frame, int threads) : n(pts.size) {
    std::vector<std::uint32_t> order(n);
    sort_by_z_order(pts, frame, order, threads);
    n_blocks = (n + kBlock - 1) / kBlock;
    const std::size_t padded = n_blocks * kBlock;
    x.assign(padded, 0.f);
    y.assign(padded, 0.f);
    z.assign(padded, 0.f);
    g.assign(padded, 0.f);
    float* out[4] = {x.data(), y.data(), z.data(), g.data()};
    box.resize(8 * n_blocks);
    // Per block: its points' coordinates, then its box.
    detail::parallel_for(n_blocks, threads, kBlocksPerClaim, [&](std::size_t b, int) {
      for (std::size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i)
        for (int j = 0; j < 4; ++j)
          out[j][i] = static_cast<float>(static_cast<double>(pts[order[i]][j]) - frame.origin[j]);
      float* bb = &box[8 * b];
      for (int j = 0; j < 4; ++j) {
        bb[j] = std::numeric_limits<float>::infinity();
        bb[4 + j] = -std::numeric_limits<float>::infinity();
      }
      for (std::size_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i) {
        const float v[4] = {x[i], y[i], z[i], g[i]};
        for (int j = 0; j < 4; ++j) {
          bb[j] = std::min(bb[j], v[j]);
          bb[4 + j] = std::max(bb[4 + j], v[j]);
        }
      }
    });
    const std::size_t n_groups = (n_blocks + detail::kGroupBlocks - 1) / detail::kGroupBlocks;
    group_box.resize(8 * n_groups);
    for (std::size_t gi = 0; gi < n_groups; ++gi) {
      float* gb = &group_box[8 * gi];
      std::copy(&box[8 * gi * detail::kGroupBlocks], &box[8 * gi * detail::kGroupBlocks] + 8, gb);
      for (std::size_t b = gi * detail::kGroupBlocks + 1; b < std::min(n_blocks, (gi + 1) * detail::kGroupBlocks); ++b)
        for (int j = 0; j < 4; ++j) {
          gb[j] = std::min(gb[j], box[8 * b + j]);
          gb[4 + j] = std::max(gb[4 + j], box[8 * b + 4 + j]);
        }
    }
  }

 private:
  // Blocks (of kBlock points) per claim of the set-up loops.
  static constexpr std::size_t kBlocksPerClaim = 16;

  static void sort_by_z_order(const PointsView& pts, const Frame& frame, std::vector<std::uint32_t>& order,
                              int threads) {
    const double cell = std::ldexp(frame.extent, -20);
    // (key, index) pairs in index order, radix-sorted: the order of a stable
    // sort by key (sort_by_key), in a third of std::stable_sort's time.
    std::vector<std::pair<std::uint64_t, std::size_t>> keyed(pts.size);
    const std::size_t span = kBlocksPerClaim * kBlock;
    detail::parallel_for((pts.size + span - 1) / span, threads, 1, [&](std::size_t part, int) {
      for (std::size_t i = part * span; i < std::min(pts.size, (part + 1) * span); ++i) {
        std::uint64_t c[3];
        for (int j = 0; j < 3; ++j) {
          const double from_low = static_cast<double>(pts[i][j]) - frame.origin[j] + 0.5 * frame.extent;
          c[j] = checked::to_int<std::uint64_t>(std::clamp(std::floor(from_low / cell), 0.0, 2097151.0), "EM block cell");
        }
        keyed[i] = {detail::z_order_key(c[0], c[1], c[2]), i};
      }
    });
    detail::sort_by_key(keyed);
    for (std::size_t i = 0; i < pts.size; ++i) order[i] = static_cast<std::uint32_t>(keyed[i].second);
  }
};

using detail::Working;

// Whether float32 arithmetic would lose component k's thin directions. The
// kernels compute y_j = sum_i U_ij d_i with d about the size of the
// component's standard deviations, so each y_j carries an absolute float32
// error of about eps_f sum_i |U_ij| sqrt(Sigma_ii) (~1 for y ~ 1 means every
// digit is lost), and the second moments sum r d d^T carry errors of eps_f
// Sigma_ii where the thin variance may be 1e8 times smaller. Above
// kDoubleAmplification (relative error of y ~ 1.5e-5, of the thinnest
// variance ~ 4e-3) the kernels evaluate the component in double. A room-sized
// scene's components (10 cm x 1 mm: ~50) stay in float32 and bit for bit as
// before; a 1 km plane with 1 cm noise (~3e4) does not.
constexpr double kDoubleAmplification = 256.0;

bool needs_double(const Eigen::Matrix4d& cov, const Eigen::Matrix4d& u) {
  double worst = 0.0;
  for (int j = 0; j < 4; ++j) {
    double a = 0.0;
    for (int i = 0; i <= j; ++i) a += std::fabs(u(i, j)) * std::sqrt(cov(i, i));
    worst = std::max(worst, a);
  }
  return worst > kDoubleAmplification;
}

// Writes component k's packed kernel parameters, in float32 to `out` and in
// double to `exact` (the same layout; used by the kernels for components
// flagged by needs_double). The precision Cholesky factor U = L^-T
// (covariance = L L^T) is computed in double by a triangular solve. Returns
// false when the covariance is not positive definite.
bool pack_component(const Working& w, std::size_t k, float* out, double* exact) {
  const Eigen::Matrix4d cov = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(&w.covariance[16 * k]);
  Eigen::LLT<Eigen::Matrix4d> llt(cov);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::Matrix4d l = llt.matrixL();
  if (!(l.diagonal().minCoeff() > 0.0)) return false;
  const Eigen::Matrix4d u = detail::lower_inverse(l).transpose();
  for (int i = 0; i < 4; ++i) exact[i] = w.mean[4 * k + i];
  int t = 4;
  for (int i = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j) exact[t++] = u(i, j);
  exact[14] = w.log_weight[k] + u.diagonal().array().log().sum() - 2.0 * kLog2Pi;
  exact[15] = needs_double(cov, u) ? 1.0 : 0.0;
  for (int i = 0; i < kParamStride; ++i) out[i] = static_cast<float>(exact[i]);
  return std::isfinite(out[14]);
}

// Makes component k's covariance numerically positive definite in double,
// with escalating diagonal loading when it is not (reg_covar = 0 on a
// degenerate component): first each diagonal's reg_covar or 1e-12 of the
// component's largest variance (of the data's extent squared when it has
// none), then x10 up to 12 times, so the loading follows the component's own
// scale.
void make_positive_definite(Working& w, std::size_t k, const RegDiagonal& reg, double data_scale2, float* packed,
                            double* exact) {
  double* c = &w.covariance[16 * k];
  double own = 0.0;
  for (int i = 0; i < 4; ++i) own = std::max(own, c[5 * i]);
  RegDiagonal extra;
  for (int i = 0; i < 4; ++i) extra[i] = std::max(reg[i], 1e-12 * (own > 0.0 ? own : data_scale2));
  int attempts = 0;
  while (!pack_component(w, k, packed, exact)) {
    require(++attempts <= 12, ErrorCode::Numeric,
            "EM: covariance of component " + std::to_string(k) + " is not positive definite; increase reg_covar");
    for (int i = 0; i < 4; ++i) {
      c[5 * i] += extra[i];
      extra[i] *= 10.0;
    }
  }
}

// Packs every component and returns the shift taken out of their constants:
// the largest constant (log w + log det U - 2 log 2 pi) is subtracted from
// each, in double, before rounding to float32, and the E-step adds it back to
// the log-likelihood. Only differences of constants reach the
// responsibilities, and the constants the kernels round then do not depend on
// where the data's scale puts them: a 4-D scaling by a power of two changes
// every constant by -4 ln s, which the shift absorbs, so the fit and its
// log-likelihood are the same to double rounding (~1e-15; unshifted, each
// float32 constant near 10 rounds differently, ~5e-7).
// The components pack independently, on `threads` threads: packing ran
// serially between the E-steps, ~20% of a truncated d = 5 fit's EM CPU time.
// A component that does not pack as it is gets its diagonal loading
// afterwards, serially in component order (make_positive_definite repeats the
// failed attempt and goes on as before), so the result and the error naming
// the first component that cannot be loaded do not depend on the thread count.
double pack_all(Working& w, const RegDiagonal& reg, double data_scale2, std::vector<float>& params,
                std::vector<double>& exact, int threads) {
  const std::size_t m = w.size();
  params.assign(m * kParamStride, 0.f);
  exact.assign(m * kParamStride, 0.0);
  std::vector<char> packed(m);
  detail::parallel_for(m, threads, detail::kComponentsPerClaim, [&](std::size_t k, int) {
    packed[k] = pack_component(w, k, &params[k * kParamStride], &exact[k * kParamStride]) ? 1 : 0;
  });
  for (std::size_t k = 0; k < m; ++k)
    if (!packed[k]) make_positive_definite(w, k, reg, data_scale2, &params[k * kParamStride], &exact[k * kParamStride]);
  double shift = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < m; ++k) shift = std::max(shift, exact[k * kParamStride + 14]);
  for (std::size_t k = 0; k < m; ++k) {
    double& c = exact[k * kParamStride + 14];
    c -= shift;
    params[k * kParamStride + 14] = static_cast<float>(c);
  }
  return shift;
}

// M-step for one component from its statistics, which are centred at the
// mean the kernels used, `centre` (the packed float32 one, or the double one
// for a flagged component); returns sum r + guard.
double m_step_component(const double* st, const RegDiagonal& reg, const double* centre, double* mean, double* cov) {
  const double nk = st[0] + kEmptyGuard;
  if (st[0] <= 0.0) {
    // No point is responsible: keep the mean, reset the shape to the regulariser.
    for (int i = 0; i < 16; ++i) cov[i] = (i % 5 == 0) ? reg[i / 5] : 0.0;
    return nk;
  }
  double delta[4];
  for (int i = 0; i < 4; ++i) delta[i] = st[1 + i] / nk;
  // sum r (d - delta)(d - delta)^T / nk with d centred at the packed mean.
  const double shrink = st[0] / nk;
  int t = 5;
  for (int i = 0; i < 4; ++i) {
    for (int j = i; j < 4; ++j) {
      double c = st[t++] / nk - 2.0 * delta[i] * delta[j] + shrink * delta[i] * delta[j];
      if (i == j) c += reg[i];
      cov[4 * i + j] = cov[4 * j + i] = c;
    }
  }
  for (int i = 0; i < 4; ++i) mean[i] = centre[i] + delta[i];
  return nk;
}

// The model handed out: means moved back from the frame, covariances checked
// in double and rounded to float32 so that they stay positive definite.
Gmm to_model(Working& w, const Frame& frame, const RegDiagonal& reg, std::size_t n) {
  const std::size_t m = w.size();
  Gmm gmm;
  gmm.resize(m);
  std::vector<float> packed(kParamStride);
  std::vector<double> exact(kParamStride);
  double max_lw = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < m; ++k) max_lw = std::max(max_lw, w.log_weight[k]);
  double sum = 0.0;
  for (std::size_t k = 0; k < m; ++k) sum += std::exp(w.log_weight[k] - max_lw);
  for (std::size_t k = 0; k < m; ++k) {
    make_positive_definite(w, k, reg, frame.extent * frame.extent, packed.data(), exact.data());
    detail::store_covariance(&w.covariance[16 * k], &gmm.covariances[16 * k]);
    for (int i = 0; i < 4; ++i) gmm.means[4 * k + i] = static_cast<float>(frame.origin[i] + w.mean[4 * k + i]);
    gmm.weights[k] = static_cast<float>(std::exp(w.log_weight[k] - max_lw) / sum);
  }
  gmm.support_size = n;
  return gmm;
}

Gmm run_em(const PointsView& points, Working w, const Frame& frame, const RegCovarFloors& floors,
           const EmOptions& options, EmReport* report, const EmIterationCallback& on_iteration) {
  const RegDiagonal reg = diagonal(floors);
  const std::size_t n = points.size, m = w.size();
  const bool truncated = options.truncation_nats > 0;
  const double data_scale2 = frame.extent * frame.extent;
  const int threads = detail::team_size(options.threads);
  const SoaPoints soa(points, frame, threads);
  const std::size_t n_blocks = soa.n_blocks;
  // Chunks as equal as possible and a whole number of full waves, so no wave
  // ends with a lone chunk that leaves threads idle.
  const std::size_t n_waves = (n_blocks + kWave * kMaxBlocksPerChunk - 1) / (kWave * kMaxBlocksPerChunk);
  const std::size_t blocks_per_chunk = std::max<std::size_t>(1, (n_blocks + kWave * n_waves - 1) / (kWave * n_waves));
  const std::size_t n_chunks = (n_blocks + blocks_per_chunk - 1) / blocks_per_chunk;
  const std::size_t region_chunks =
      std::min(n_chunks, std::max(kWave, kWave * (detail::em_region_bytes() / (kWave * m * kStatStride * sizeof(double)))));
  const detail::EmKernels& kernels = detail::em_kernels();
  // The statistics' cut (see EmFinishFn): the truncation's, or none.
  const float finish_nats =
      truncated ? static_cast<float>(options.truncation_nats) : std::numeric_limits<float>::infinity();

  std::vector<float> params;
  std::vector<double> exact;
  detail::BoundParams bounds;
  std::vector<std::uint32_t> all(m);
  for (std::size_t k = 0; k < m; ++k) all[k] = static_cast<std::uint32_t>(k);
  // Per chunk of a region: its partial sums, reduced in chunk order afterwards
  // (so the result does not depend on which thread ran which chunk).
  std::vector<double> slot_stats(region_chunks * m * kStatStride);
  // Per chunk of a region: the components its blocks evaluated (each once), so
  // that only their statistics are zeroed and reduced; every other slot entry
  // would add an exact +0 (a truncated chunk touches a few of the M).
  std::vector<std::vector<std::uint32_t>> slot_touched(region_chunks);
  std::vector<char> slot_marked(region_chunks * m, 0);
  std::vector<double> slot_ll(region_chunks);
  std::vector<double> slot_squares(region_chunks);  // of the points' log-likelihoods
  std::vector<double> slot_pairs(region_chunks);
  // Per thread: one block's log-density rows and row maxima, (kBlock + 1) x M
  // floats, so the scratch is threads x block, not waves x block.
  const std::size_t scratch_floats = checked::mul<std::size_t>(kBlock + 1, m, "EM scratch");
  std::vector<float> thread_scratch(checked::mul<std::size_t>(static_cast<std::size_t>(threads), scratch_floats, "EM scratch"));
  // Truncated E-step: per block, what it keeps across iterations.
  detail::TruncationMemory memory(truncated ? n_blocks : 0);
  std::vector<double> stats(m * kStatStride);
  std::vector<double> nk(m);

  EmReport rep;
  rep.max_iter = options.max_iter;
  double pairs_evaluated = 0.0;
  // The first model's kernel parameters; each pass packs the next.
  double shift = pack_all(w, reg, data_scale2, params, exact, threads);  // of the log-densities in params
  double next_shift = 0.0;
  std::vector<float> next_params;
  std::vector<double> next_exact;
  int passes = 0;
  double standard_error = 0.0;  // of the last pass's mean log-likelihood
  // EM stops when a pass changes the mean log-likelihood by less than this
  // (EmOptions::tol_standard_errors): the noise of the mean itself, when
  // larger than tol, is a change no further pass can make meaningful.
  const detail::EmTolerance tolerance = [&] {
    return options.tol > 0 ? std::max(options.tol, options.tol_standard_errors * standard_error) : 0.0;
  };
  // One E+M pass (detail::EmPass): the E-step of the packed model, the M-step
  // into `cur`, which is packed for the next pass.
  const detail::EmPass pass = [&](Working& cur) {
    ++passes;
    if (truncated) bounds.load(params);
    double mean_ll = 0.0, iteration_pairs = 0.0;
    bool promoted = false;
    do {
      std::fill(stats.begin(), stats.end(), 0.0);
      double total_ll = 0.0, total_squares = 0.0;
      iteration_pairs = 0.0;
      for (std::size_t wave_start = 0; wave_start < n_chunks; wave_start += region_chunks) {
        const std::size_t wave_chunks = std::min(region_chunks, n_chunks - wave_start);
        detail::parallel_for(wave_chunks, threads, 1, [&](std::size_t s, int thread) {
          double* st = &slot_stats[s * m * kStatStride];
          std::vector<std::uint32_t>& touched = slot_touched[s];
          char* marked = &slot_marked[s * m];
          touched.clear();
          float* scratch = &thread_scratch[static_cast<std::size_t>(thread) * scratch_floats];  // m rows, then m maxima
          float* row_max = scratch + m * kBlock;
          detail::TruncatedScan scan(bounds, options.truncation_nats, n_blocks);
          alignas(64) float max_lp[kBlock];
          double ll = 0.0, squares = 0.0, pairs = 0.0;
          // The per-point logs for the spread cost 16 times the logs of the
          // sum alone: only when the stopping rule reads them.
          double* squares_or_null = options.tol_standard_errors > 0 ? &squares : nullptr;
          const std::size_t b0 = (wave_start + s) * blocks_per_chunk;
          const std::size_t b1 = std::min(n_blocks, b0 + blocks_per_chunk);
          for (std::size_t b = b0; b < b1; ++b) {
            const std::size_t first = b * kBlock;
            const detail::Block block{{&soa.x[first], &soa.y[first], &soa.z[first], &soa.g[first]},
                                      static_cast<int>(std::min<std::size_t>(kBlock, n - first))};
            std::fill(max_lp, max_lp + kBlock, -std::numeric_limits<float>::infinity());
            const std::vector<std::uint32_t>* evaluated = &all;
            if (truncated) {
              scan.evaluate(kernels, block, b, soa.box.data(), soa.group_box.data(), params, exact, memory, scratch,
                            row_max, max_lp);
              evaluated = &scan.list();
            } else {
              kernels.log_density(block, params.data(), exact.data(), all.data(), m, scratch, row_max, max_lp);
            }
            const std::size_t ne = evaluated->size();
            for (std::uint32_t k : *evaluated)
              if (!marked[k]) {
                marked[k] = 1;
                touched.push_back(k);
                std::fill(st + std::size_t{k} * kStatStride, st + (std::size_t{k} + 1) * kStatStride, 0.0);
              }
            ll += kernels.finish(block, params.data(), exact.data(), evaluated->data(), ne, scratch, max_lp, row_max, st,
                                 finish_nats, squares_or_null);
            pairs += static_cast<double>(block.count) * ne;
            // Next iteration starts from the components some point of this
            // block still gives at least exp(-nats) of its best weight.
            if (truncated) scan.remember(b, row_max, memory);
          }
          slot_ll[s] = ll;
          slot_squares[s] = squares;
          slot_pairs[s] = pairs;
        });
        // Fixed-order reduction: chunk 0, 1, 2, ... whatever thread ran them.
        for (std::size_t s = 0; s < wave_chunks; ++s) {
          const double* st = &slot_stats[s * m * kStatStride];
          for (std::uint32_t k : slot_touched[s]) {
            for (std::size_t i = std::size_t{k} * kStatStride; i < (std::size_t{k} + 1) * kStatStride; ++i) stats[i] += st[i];
            slot_marked[s * m + k] = 0;
          }
          total_ll += slot_ll[s];
          total_squares += slot_squares[s];
          iteration_pairs += slot_pairs[s];
        }
      }
      mean_ll = total_ll / static_cast<double>(n) + shift;
      // The per-point log-likelihoods' variance (the shift moves them all
      // alike), and the standard error of their mean.
      if (options.tol_standard_errors > 0) {
        const double unshifted = total_ll / static_cast<double>(n);
        const double variance = std::max(0.0, total_squares / static_cast<double>(n) - unshifted * unshifted);
        standard_error = std::sqrt(variance / static_cast<double>(n));
      }
      require(std::isfinite(mean_ll), ErrorCode::Numeric, "EM: log-likelihood is not finite at iteration " +
                                                              std::to_string(passes));

      // M-step: each component from its own statistics (on every thread;
      // it was serial between the E-steps), then the weights' sum in
      // component order.
      detail::parallel_for(m, threads, detail::kComponentsPerClaim, [&](std::size_t k, int) {
        const float* packed = &params[k * kParamStride];
        double centre[4];
        for (int i = 0; i < 4; ++i) centre[i] = packed[15] != 0.0f ? exact[k * kParamStride + i] : packed[i];
        nk[k] = m_step_component(&stats[k * kStatStride], reg, centre, &cur.mean[4 * k], &cur.covariance[16 * k]);
        if (!options.quantisation.empty()) {
          double mean[4];
          for (int i = 0; i < 4; ++i) mean[i] = frame.origin[i] + cur.mean[4 * k + i];
          options.quantisation.floor_covariance_at(mean, &cur.covariance[16 * k]);
        }
      });
      double weight_sum = 0.0;
      for (std::size_t k = 0; k < m; ++k) weight_sum += nk[k];
      for (std::size_t k = 0; k < m; ++k) cur.log_weight[k] = std::log(nk[k] / weight_sum);

      // The next model's parameters. A component evaluated in float32 whose
      // new covariance is too elongated for float32 (needs_double) got
      // statistics that cannot hold its thin direction: the float32 second
      // moments of a 1 km plane carry errors above its thickness, and they
      // differ between kernels. This E+M step is repeated with such
      // components evaluated in double (e.g. the first step of a large
      // scene, from point-sized seeds; never on the shared room-sized
      // frames, whose components stay below a third of the threshold).
      next_shift = pack_all(cur, reg, data_scale2, next_params, next_exact, threads);
      promoted = false;
      for (std::size_t k = 0; k < m; ++k)
        if (params[k * kParamStride + 15] == 0.0f && next_params[k * kParamStride + 15] != 0.0f) {
          params[k * kParamStride + 15] = 1.0f;
          promoted = true;
        }
    } while (promoted);
    pairs_evaluated += iteration_pairs;
    if (truncated) memory.next_iteration();
    params.swap(next_params);
    exact.swap(next_exact);
    shift = next_shift;
    return mean_ll;
  };

  if (options.acceleration == EmAcceleration::Squarem) {
    // Makes a model current (detail::EmLoad): a component packs as it is
    // (so pack_all then changes nothing in it) and, extrapolated, keeps its
    // reg_covar floors, or is replaced by the fallback's (t2's) component.
    // Which components are models as they are: checked on every thread (each
    // on its own), then resolved in component order.
    std::vector<char> usable(m);
    const detail::EmLoad load = [&](Working& cur, const Working* fallback) {
      detail::parallel_for(m, threads, detail::kComponentsPerClaim, [&](std::size_t k, int) {
        float one[kParamStride];
        double one_exact[kParamStride];
        bool ok = pack_component(cur, k, one, one_exact);
        if (ok && fallback) {
          Eigen::Matrix4d above = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(&cur.covariance[16 * k]);
          for (int i = 0; i < 4; ++i) above(i, i) -= reg[i];
          ok = Eigen::LLT<Eigen::Matrix4d>(above).info() == Eigen::Success;
        }
        usable[k] = ok ? 1 : 0;
      });
      std::size_t replaced = 0;
      for (std::size_t k = 0; k < m; ++k) {
        if (usable[k]) continue;
        if (!fallback) return false;
        std::copy_n(&fallback->mean[4 * k], 4, &cur.mean[4 * k]);
        std::copy_n(&fallback->covariance[16 * k], 16, &cur.covariance[16 * k]);
        cur.log_weight[k] = fallback->log_weight[k];
        ++replaced;
      }
      if (replaced == m) return false;  // nothing extrapolated: the fallback is current already
      if (replaced > 0) detail::renormalise_log_weights(cur.log_weight);
      shift = pack_all(cur, reg, data_scale2, params, exact, threads);
      return true;
    };
    // A kept pass is reported right after it ran: its standard error is the
    // current one (a rejected extrapolation's is never reported).
    const EmIterationCallback on_kept = [&](int iter, double ll) {
      rep.standard_error = standard_error;
      if (on_iteration) on_iteration(iter, ll);
    };
    detail::run_squarem(w, options, pass, load, tolerance, rep, on_kept);
  } else {
    double previous = -std::numeric_limits<double>::infinity();
    for (int iter = 1; iter <= options.max_iter; ++iter) {
      const double mean_ll = pass(w);
      rep.iterations = iter;
      rep.log_likelihood = mean_ll;
      rep.standard_error = standard_error;
      if (on_iteration) on_iteration(iter, mean_ll);
      if (std::fabs(mean_ll - previous) < tolerance()) {
        rep.converged = true;
        break;
      }
      previous = mean_ll;
    }
  }
  rep.kernel = kernels.isa;
  rep.reg_covar = floors;
  rep.pair_fraction = pairs_evaluated / (static_cast<double>(n) * m * rep.iterations);
  if (report) *report = rep;
  return to_model(w, frame, reg, n);
}

}  // namespace

Gmm fit_em(const PointsView& points, const std::vector<std::size_t>& seed_indices, const EmOptions& options,
           EmReport* report, const EmIterationCallback& on_iteration) {
  check_options(options);
  require_finite_points(points, "EM input");
  const std::size_t m = seed_indices.size();
  require(m >= 1 && m <= points.size, ErrorCode::InvalidArgument,
          "number of components must be in [1, N = " + std::to_string(points.size) + "], got " + std::to_string(m));
  const RegCovarFloors floors = resolve_reg_covar(points, options.reg_covar);
  const RegDiagonal reg = diagonal(floors);
  const Frame frame(points);
  Working w;
  w.mean.resize(4 * m);
  w.covariance.assign(16 * m, 0.0);
  // One-hot responsibilities on the seeds give each component weight 1 / N
  // before normalisation (scikit-learn's _initialize); only the first
  // iteration's log-likelihood sees the difference.
  w.log_weight.assign(m, -std::log(static_cast<double>(points.size)));
  for (std::size_t k = 0; k < m; ++k) {
    require(seed_indices[k] < points.size, ErrorCode::InvalidArgument,
            "seed index " + std::to_string(seed_indices[k]) + " is out of range");
    for (int i = 0; i < 4; ++i) w.mean[4 * k + i] = static_cast<double>(points[seed_indices[k]][i]) - frame.origin[i];
    for (int i = 0; i < 4; ++i) w.covariance[16 * k + 5 * i] = reg[i];
  }
  return run_em(points, std::move(w), frame, floors, options, report, on_iteration);
}

Gmm fit_em_from(const PointsView& points, const Gmm& initial, const EmOptions& options, EmReport* report,
                const EmIterationCallback& on_iteration) {
  check_options(options);
  require_finite_points(points, "EM input");
  validate(initial);
  const RegCovarFloors floors = resolve_reg_covar(points, options.reg_covar);
  const Frame frame(points);
  const std::size_t m = initial.size();
  Working w;
  w.mean.resize(4 * m);
  w.covariance.assign(initial.covariances.begin(), initial.covariances.end());
  w.log_weight.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    for (int i = 0; i < 4; ++i) w.mean[4 * k + i] = static_cast<double>(initial.mean(k)[i]) - frame.origin[i];
    w.log_weight[k] = initial.weights[k] > 0 ? std::log(static_cast<double>(initial.weights[k])) : -1e30;
  }
  return run_em(points, std::move(w), frame, floors, options, report, on_iteration);
}

std::size_t detail::em_region_bytes() { return g_region_bytes.load(std::memory_order_relaxed); }

std::size_t detail::set_em_region_bytes(std::size_t bytes) {
  return g_region_bytes.exchange(bytes, std::memory_order_relaxed);
}

}  // namespace sogmm
