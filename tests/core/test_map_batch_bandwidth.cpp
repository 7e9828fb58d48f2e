// The bandwidth a map batch is fitted with (detail::batch_bandwidth,
// core/src/map_batch_bandwidth.cpp): bandwidth x (s + (1 - s) h^2), with
// h = sum n_f^2 / N^2 the share of the batch's point pairs from one frame.
// Hand-computed cases; no fit runs, so the test is exact on every SIMD kernel
// (SSE2, AVX2, AVX-512): only double arithmetic on point counts.
#include <gtest/gtest.h>

#include <vector>

#include "map_state.hpp"
#include "sogmm/map.hpp"

namespace {

using sogmm::MapOptions;
using sogmm::detail::batch_bandwidth;
using sogmm::detail::PendingFrame;
using sogmm::detail::same_view_share;

PendingFrame frame_of(std::size_t points) {
  PendingFrame p;
  p.xyzg.assign(4 * points, 0.0f);
  return p;
}

MapOptions novelty_options() {
  MapOptions o;
  o.novelty = true;
  o.novelty_bandwidth_scale = 0.7;
  o.fit.bandwidth = 0.02;
  return o;
}

}  // namespace

TEST(MapBatchBandwidth, SameViewShareIsTheShareOfPairsFromOneFrame) {
  EXPECT_DOUBLE_EQ(same_view_share({frame_of(3000)}), 1.0);
  EXPECT_DOUBLE_EQ(same_view_share({frame_of(3000), frame_of(3000)}), 0.5);
  // 900 + 100 points: (810000 + 10000) / 1e6.
  EXPECT_DOUBLE_EQ(same_view_share({frame_of(900), frame_of(100)}), 0.82);
  // `extra` counts as one more frame of the batch.
  const PendingFrame extra = frame_of(100);
  EXPECT_DOUBLE_EQ(same_view_share({frame_of(900)}, &extra), 0.82);
  std::vector<PendingFrame> ten(10, frame_of(300));
  EXPECT_DOUBLE_EQ(same_view_share(ten), 0.1);
}

// Livingroom frames 0-2's batch (10674 + 955 + 933 novel points:
// h = 115716790 / 157803844 = 0.7333) is fitted at 0.8613 x the bandwidth; a
// batch of one frame at the bandwidth itself; ten equal slivers at 0.703;
// novelty off always at the bandwidth. Removing the rule (bandwidth x s for
// every batch) fails the first three.
TEST(MapBatchBandwidth, OneViewGetsTheBandwidthAndPooledSliversTheScale) {
  const MapOptions o = novelty_options();
  EXPECT_DOUBLE_EQ(batch_bandwidth(o, {frame_of(5000)}), 0.02);
  const std::vector<PendingFrame> room = {frame_of(10674), frame_of(955), frame_of(933)};
  const double h = (10674.0 * 10674 + 955.0 * 955 + 933.0 * 933) / (12562.0 * 12562);
  EXPECT_NEAR(h, 0.7333, 1e-4);
  EXPECT_DOUBLE_EQ(batch_bandwidth(o, room), 0.02 * (0.7 + 0.3 * h * h));
  EXPECT_NEAR(batch_bandwidth(o, room) / 0.02, 0.8613, 1e-4);
  const std::vector<PendingFrame> ten(10, frame_of(300));
  EXPECT_DOUBLE_EQ(batch_bandwidth(o, ten), 0.02 * 0.703);
  MapOptions off = o;
  off.novelty = false;
  EXPECT_DOUBLE_EQ(batch_bandwidth(off, ten), 0.02);
}
