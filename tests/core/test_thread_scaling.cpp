// Issue 17's thread-scaling work: the culled queries' parallel set-up (Z-order
// keys and a parallel sort) gives the same point order, so the same bits, for
// any team; the loop accounting counts loops and their CPU time.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "sogmm/fit.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/loop_accounting.hpp"
#include "test_util.hpp"

namespace {

// 300 small components in a 2 m box and 20,000 points drawn from them: enough
// points for the sort to split into pieces (>= 4096 each) and merge them.
sogmm::Gmm scattered_model(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t m = 300;
  sogmm::Gmm g;
  g.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    Eigen::Matrix4d b;
    for (int i = 0; i < 16; ++i) b(i / 4, i % 4) = (u(rng) - 0.5) * 0.05;
    sogmm_test::set_component(g, k, 1.0 / m, Eigen::Vector4d(2 * u(rng), 2 * u(rng), 1 + 2 * u(rng), u(rng)),
                  b * b.transpose() + 1e-5 * Eigen::Matrix4d::Identity());
  }
  g.support_size = 1000;
  return g;
}

// n points (x, y, z, gray) drawn from g with the given seed.
std::vector<float> drawn_points(const sogmm::Gmm& g, std::size_t n, std::uint64_t seed) {
  std::vector<float> pts(4 * n);
  sogmm::sample(g, n, seed, 4, pts.data());
  return pts;
}

// The loop accounting after an exact score of the rows of pts (x, y, z, gray)
// under g on `threads` threads: two loops, the model's packing and the points.
sogmm::LoopAccounting accounting_after_score(const sogmm::Gmm& g, const std::vector<float>& pts, int threads) {
  std::vector<double> s(pts.size() / 4);
  sogmm::QueryOptions o;
  o.threads = threads;
  sogmm::score_samples(g, pts.data(), s.size(), 4, s.data(), o);
  return sogmm::loop_accounting();
}

TEST(ThreadScaling, CulledQueriesBitwiseIdenticalForAnyTeamOnLargeInputs) {
  const sogmm::Gmm g = scattered_model(17);
  const std::size_t n = 20000;
  const std::vector<float> pts = drawn_points(g, n, 18);
  std::vector<float> xyz(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) xyz[3 * i + j] = pts[4 * i + j];
  // At 2 nats the culling skips many terms, so a different point order (other
  // blocks) would change the answers.
  std::vector<double> s1(n);
  std::vector<float> m1(n), v1(n);
  for (int threads : {1, 2, 3, 5}) {
    sogmm::QueryOptions o;
    o.threads = threads;
    o.truncation_nats = 2.0;
    std::vector<double> s(n);
    std::vector<float> mean(n), var(n);
    sogmm::score_samples(g, pts.data(), n, 4, s.data(), o);
    sogmm::regress_gray(g, xyz.data(), n, mean.data(), var.data(), o);
    if (threads == 1) {
      s1 = s, m1 = mean, v1 = var;
      continue;
    }
    EXPECT_EQ(0, std::memcmp(s.data(), s1.data(), n * sizeof(double))) << threads << " threads";
    EXPECT_EQ(0, std::memcmp(mean.data(), m1.data(), n * sizeof(float))) << threads << " threads";
    EXPECT_EQ(0, std::memcmp(var.data(), v1.data(), n * sizeof(float))) << threads << " threads";
  }
}

TEST(ThreadScaling, LoopAccountingCountsOnlyWhenOn) {
  const sogmm::Gmm g = scattered_model(19);
  const std::size_t n = 5000;
  const std::vector<float> pts = drawn_points(g, n, 20);
  std::vector<double> s(n);
  sogmm::QueryOptions o;
  o.threads = 1;
  // Off: nothing is counted.
  sogmm::set_loop_accounting(false);
  const sogmm::LoopAccounting a0 = sogmm::loop_accounting();
  const sogmm::LoopAccounting a1 = accounting_after_score(g, pts, 1);
  EXPECT_EQ(a1.loops, a0.loops);
  EXPECT_EQ(a1.cpu_seconds_in_loops, a0.cpu_seconds_in_loops);
  // On: an exact score is two loops (the model's packing and the points),
  // and their CPU time is part of the calling thread's.
  sogmm::set_loop_accounting(true);
  const double t0 = sogmm::thread_cpu_seconds();
  sogmm::score_samples(g, pts.data(), n, 4, s.data(), o);
  const double t1 = sogmm::thread_cpu_seconds();
  const sogmm::LoopAccounting a2 = sogmm::loop_accounting();
  sogmm::set_loop_accounting(false);
  EXPECT_EQ(a2.loops - a1.loops, 2u);
  const double in_loops = a2.cpu_seconds_in_loops - a1.cpu_seconds_in_loops;
  EXPECT_GT(in_loops, 0.0);
  EXPECT_LE(in_loops, t1 - t0 + 1e-9);
}

}  // namespace

namespace {

// The team split of the loop accounting: per loop, wall = busy + start +
// imbalance + join by construction (each part truncated to whole nanoseconds,
// so up to 3 ns per loop apart), and each part is non-negative (members start
// after the loop opens, a member's items fit between the opening and its last
// finish, and the caller returns after the last member). Checked on team
// loops of both kinds: parallel_for (the queries) and staged regions (the
// k-means++ steps of a fit).
void expect_split_adds_up(const sogmm::LoopAccounting& a, const sogmm::LoopAccounting& b) {
  const double loops = static_cast<double>(b.team_loops - a.team_loops);
  ASSERT_GT(loops, 0.0);
  const double wall = b.team_wall_seconds - a.team_wall_seconds, busy = b.team_busy_seconds - a.team_busy_seconds,
               start = b.team_start_seconds - a.team_start_seconds,
               imbalance = b.team_imbalance_seconds - a.team_imbalance_seconds,
               join = b.team_join_seconds - a.team_join_seconds;
  EXPECT_GT(busy, 0.0);
  EXPECT_GE(start, 0.0);
  EXPECT_GE(imbalance, 0.0);
  EXPECT_GE(join, 0.0);
  EXPECT_NEAR(wall, busy + start + imbalance + join, 3e-9 * loops + 1e-12 * wall);
}

TEST(ThreadScaling, TeamSplitAddsUpToTheWallTime) {
  const sogmm::Gmm g = scattered_model(23);
  const std::size_t n = 20000;
  const std::vector<float> pts = drawn_points(g, n, 24);
  sogmm::set_loop_accounting(true);
  // One thread: no team loop.
  const sogmm::LoopAccounting a0 = sogmm::loop_accounting();
  const sogmm::LoopAccounting a1 = accounting_after_score(g, pts, 1);
  EXPECT_EQ(a1.team_loops, a0.team_loops);
  EXPECT_EQ(a1.team_wall_seconds, a0.team_wall_seconds);
  // Two threads: each of the score's two loops is a team loop.
  const sogmm::LoopAccounting a2 = accounting_after_score(g, pts, 2);
  EXPECT_EQ(a2.team_loops - a1.team_loops, 2u);
  expect_split_adds_up(a1, a2);
  // A fit on two threads: its k-means++ steps run as stages of one region.
  sogmm::FitOptions fo;
  fo.bandwidth = 0.3;
  fo.em.threads = 2;
  fo.em.max_iter = 3;
  sogmm::fit(sogmm::PointsView{pts.data(), n}, fo);
  const sogmm::LoopAccounting a3 = sogmm::loop_accounting();
  sogmm::set_loop_accounting(false);
  EXPECT_GT(a3.team_loops - a2.team_loops, 2u);
  expect_split_adds_up(a2, a3);
}

}  // namespace
