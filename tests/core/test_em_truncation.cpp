// The truncated E-step's component choice (core/src/em_truncation.hpp),
// tested directly against brute force in double: every component a block
// skips is more than `nats` below every point's best, and the group
// candidates (used from the second iteration on) give exactly the list that
// bounding all M components gives; em_finish with the truncation's nats
// leaves out only terms more than nats below their point's best.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "em_kernel.hpp"
#include "em_truncation.hpp"

namespace {
using sogmm::detail::kBlock;
using sogmm::detail::kParamStride;
using sogmm::detail::kStatStride;

constexpr double kNats = 6.0;
constexpr std::size_t kM = 80;
constexpr std::size_t kBlocks = 20;  // 2.5 groups of 8: a partial last group too

struct Scene {
  std::vector<float> x, y, z, g;       // kBlocks x kBlock points, block by block
  std::vector<float> box, group_box;   // min[4], max[4] each
  std::vector<float> params;           // packed as em.cpp packs them
  std::vector<double> exact;
};

// Components scattered over the unit cube (gray in [0, 1]) with random
// anisotropic covariances, and blocks of points each drawn near one centre,
// so every block sees a few components up close and most far away.
Scene make_scene(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  Scene s;
  s.params.assign(kM * kParamStride, 0.f);
  s.exact.assign(kM * kParamStride, 0.0);
  for (std::size_t k = 0; k < kM; ++k) {
    Eigen::Matrix4d a;
    for (int i = 0; i < 16; ++i) a(i / 4, i % 4) = normal(rng);
    Eigen::Matrix4d cov = 0.002 * a * a.transpose() + 1e-5 * Eigen::Matrix4d::Identity();
    const Eigen::Matrix4d l = cov.llt().matrixL();
    const Eigen::Matrix4d u = l.triangularView<Eigen::Lower>().solve(Eigen::Matrix4d::Identity()).transpose();
    double* q = &s.exact[k * kParamStride];
    for (int i = 0; i < 4; ++i) q[i] = unit(rng);
    int t = 4;
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) q[t++] = u(i, j);
    q[14] = std::log(0.5 + unit(rng)) + u.diagonal().array().log().sum() - 20.0;
    for (int i = 0; i < kParamStride; ++i) s.params[k * kParamStride + i] = static_cast<float>(q[i]);
    for (int i = 0; i < kParamStride; ++i) q[i] = s.params[k * kParamStride + i];  // the float32 model, exactly
  }
  std::vector<float>* coords[4] = {&s.x, &s.y, &s.z, &s.g};
  for (std::size_t b = 0; b < kBlocks; ++b) {
    const double centre[4] = {unit(rng), unit(rng), unit(rng), unit(rng)};
    for (int p = 0; p < kBlock; ++p)
      for (int j = 0; j < 4; ++j) coords[j]->push_back(static_cast<float>(centre[j] + 0.03 * normal(rng)));
  }
  s.box.resize(8 * kBlocks);
  for (std::size_t b = 0; b < kBlocks; ++b)
    for (int j = 0; j < 4; ++j) {
      const auto range = std::minmax_element(coords[j]->begin() + b * kBlock, coords[j]->begin() + (b + 1) * kBlock);
      s.box[8 * b + j] = *range.first;
      s.box[8 * b + 4 + j] = *range.second;
    }
  const std::size_t groups = (kBlocks + sogmm::detail::kGroupBlocks - 1) / sogmm::detail::kGroupBlocks;
  s.group_box.resize(8 * groups);
  for (std::size_t gi = 0; gi < groups; ++gi)
    for (int j = 0; j < 4; ++j) {
      float lo = std::numeric_limits<float>::infinity(), hi = -lo;
      for (std::size_t b = gi * sogmm::detail::kGroupBlocks;
           b < std::min(kBlocks, (gi + 1) * sogmm::detail::kGroupBlocks); ++b) {
        lo = std::min(lo, s.box[8 * b + j]);
        hi = std::max(hi, s.box[8 * b + 4 + j]);
      }
      s.group_box[8 * gi + j] = lo;
      s.group_box[8 * gi + 4 + j] = hi;
    }
  return s;
}

// log w_k N(x_p) - shift in double, straight from the definition.
double log_density(const Scene& s, std::size_t b, int p, std::size_t k) {
  const std::size_t i = b * kBlock + p;
  const double* q = &s.exact[k * kParamStride];
  const double d[4] = {s.x[i] - q[0], s.y[i] - q[1], s.z[i] - q[2], s.g[i] - q[3]};
  const double y0 = q[4] * d[0];
  const double y1 = q[5] * d[0] + q[8] * d[1];
  const double y2 = q[6] * d[0] + q[9] * d[1] + q[11] * d[2];
  const double y3 = q[7] * d[0] + q[10] * d[1] + q[12] * d[2] + q[13] * d[3];
  return q[14] - 0.5 * (y0 * y0 + y1 * y1 + y2 * y2 + y3 * y3);
}

sogmm::detail::Block block_of(const Scene& s, std::size_t b) {
  const std::size_t f = b * kBlock;
  return {{&s.x[f], &s.y[f], &s.z[f], &s.g[f]}, kBlock};
}

// One E-step over all blocks with one scan (as one thread's chunk); returns
// the evaluated lists and checks each against brute force.
std::vector<std::vector<std::uint32_t>> e_step(const Scene& s, sogmm::detail::TruncationMemory& memory,
                                               std::size_t* skipped) {
  const sogmm::detail::EmKernels& kernels = sogmm::detail::em_kernels();
  sogmm::detail::BoundParams bounds;
  bounds.load(s.params);
  sogmm::detail::TruncatedScan scan(bounds, kNats, kBlocks);
  std::vector<float> rows((kBlock + 1) * kM);
  std::vector<double> stats(kM * kStatStride);
  std::vector<std::vector<std::uint32_t>> lists;
  for (std::size_t b = 0; b < kBlocks; ++b) {
    alignas(64) float max_lp[kBlock];
    std::fill(max_lp, max_lp + kBlock, -std::numeric_limits<float>::infinity());
    float* row_max = rows.data() + kM * kBlock;
    const sogmm::detail::Block block = block_of(s, b);
    scan.evaluate(kernels, block, b, s.box.data(), s.group_box.data(), s.params, s.exact, memory, rows.data(), row_max,
                  max_lp);
    const std::vector<std::uint32_t>& list = scan.list();
    std::vector<char> in(kM, 0);
    for (std::uint32_t k : list) in[k] = 1;
    for (int p = 0; p < kBlock; ++p) {
      double best = -std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < kM; ++k) best = std::max(best, log_density(s, b, p, k));
      for (std::size_t k = 0; k < kM; ++k)
        if (!in[k]) {
          // Skipped: provably below the best by more than kNats (1e-3 covers
          // the float32 kernel's rounding of the maximum it compared with).
          EXPECT_LT(log_density(s, b, p, k), best - kNats + 1e-3) << "block " << b << ", point " << p << ", k " << k;
          ++*skipped;
        }
    }
    double squares = 0.0;
    kernels.finish(block, s.params.data(), s.exact.data(), list.data(), list.size(), rows.data(), max_lp, row_max,
                   stats.data(), static_cast<float>(kNats), &squares);
    scan.remember(b, row_max, memory);
    lists.push_back(list);
  }
  memory.next_iteration();
  return lists;
}

TEST(EmTruncation, SkippedComponentsAreBelowEveryPointsBestByTheCut) {
  const Scene s = make_scene(3);
  sogmm::detail::TruncationMemory memory(kBlocks);
  std::size_t skipped = 0;
  e_step(s, memory, &skipped);  // first iteration: bounds over all M
  const std::size_t first_skipped = skipped;
  EXPECT_GT(first_skipped, kBlocks * kBlock * kM / 2) << "most pairs should be skipped, or the test is vacuous";
  // Second iteration of the same model: every block's cut is at least its
  // previous one (its warm list holds each point's best component), so each
  // block bounds only its group's candidates.
  sogmm::detail::TruncationMemory full = memory;
  std::fill(full.previous_cut.begin(), full.previous_cut.end(), -std::numeric_limits<double>::infinity());
  const std::vector<std::vector<std::uint32_t>> grouped = e_step(s, memory, &skipped);
  // The same warm lists without previous cuts: every block bounds all M.
  std::size_t unused = 0;
  const std::vector<std::vector<std::uint32_t>> everything = e_step(s, full, &unused);
  for (std::size_t b = 0; b < kBlocks; ++b) EXPECT_EQ(grouped[b], everything[b]) << "block " << b;
}

}  // namespace

// em_finish with the truncation's nats (em_kernel.hpp) against brute force in
// double over all M components of each block: each component's responsibility
// sum may miss only terms more than `nats` below their point's best, each
// below exp(-nats), and the normalisers only as many such terms; the
// log-likelihood (products of 16 sums, 16 logs a block) is the sum over points
// of log sum_k w_k N. Bounds hold on every kernel: the kernels' float32
// log-densities carry ~1e-5 nats of rounding (1e-4 allowed per term) and their
// float sums ~1e-6 relative; the same data and the same brute force serve
// SSE2, AVX2 and AVX-512. Fails if a row's range loses a segment holding a
// near point (e.g. `hi / kSegment` without + 1: errors of order 1), or if a
// lane of the log-likelihood's sums is lost (~16 x 20 nats).
TEST(EmTruncation, FinishLeavesOutOnlyTermsBeyondTheCut) {
  constexpr float kFinishNats = 12.0f;
  const Scene s = make_scene(5);
  const sogmm::detail::EmKernels& kernels = sogmm::detail::em_kernels();
  std::vector<std::uint32_t> all(kM);
  for (std::size_t k = 0; k < kM; ++k) all[k] = static_cast<std::uint32_t>(k);
  std::size_t left_out = 0;
  for (std::size_t b = 0; b < kBlocks; ++b) {
    const sogmm::detail::Block block = block_of(s, b);
    std::vector<float> rows(kBlock * kM), row_max(kM);
    alignas(64) float max_lp[kBlock];
    std::fill(max_lp, max_lp + kBlock, -std::numeric_limits<float>::infinity());
    kernels.log_density(block, s.params.data(), s.exact.data(), all.data(), kM, rows.data(), row_max.data(), max_lp);
    std::vector<double> stats(kM * kStatStride, 0.0);
    const double ll = kernels.finish(block, s.params.data(), s.exact.data(), all.data(), kM, rows.data(), max_lp,
                                     row_max.data(), stats.data(), kFinishNats, nullptr);
    // Brute force: responsibilities of all M components, and per component
    // what it may lose (its far terms, and its near terms' share of the
    // normaliser's far terms).
    double expected_ll = 0.0;
    std::vector<double> mass(kM, 0.0), slack(kM, 0.0);
    for (int p = 0; p < kBlock; ++p) {
      std::vector<double> lp(kM);
      double best = -std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < kM; ++k) best = std::max(best, lp[k] = log_density(s, b, p, k));
      double total = 0.0, far = 0.0;
      for (std::size_t k = 0; k < kM; ++k) {
        total += std::exp(lp[k] - best);
        if (lp[k] < best - kFinishNats - 1e-4) far += std::exp(lp[k] - best);
      }
      expected_ll += best + std::log(total);
      for (std::size_t k = 0; k < kM; ++k) {
        const double r = std::exp(lp[k] - best) / total;
        mass[k] += r;
        if (lp[k] < best - kFinishNats + 1e-4) {
          slack[k] += r;
          ++left_out;
        } else {
          slack[k] += r * far / (total - far);
        }
      }
    }
    EXPECT_NEAR(ll, expected_ll, kBlock * 1e-4) << "block " << b;
    for (std::size_t k = 0; k < kM; ++k)
      EXPECT_NEAR(stats[k * kStatStride], mass[k], slack[k] + 1e-4 * mass[k] + 1e-6) << "block " << b << ", k " << k;
  }
  EXPECT_GT(left_out, kBlocks * kBlock) << "the cut should leave terms out, or the test is vacuous";
}
