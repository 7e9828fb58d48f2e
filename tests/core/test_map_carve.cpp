// The map's free-space carve (MapOptions::free_space_carve, issue 29): a
// component whose tail hangs past an outline, where a frame sees a farther
// surface, is reshaped to the moments of its samples the frame does not see
// past; a component the frame does not see past, and every component with
// the carve off, stay bitwise.
//
// Kernels: the carve is scalar double arithmetic on the component and the
// frame's depth (no E-step kernel), and the bounds below are closed-form
// Gaussian tail masses with margins of 2x, so they hold alike under
// SOGMM_ISA=sse2, avx2 and AVX-512 (which only the novelty scores, not the
// carve, would run).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "map_test_util.hpp"

namespace sogmm_test {
namespace {

// A 64 x 48 camera (f = 60) that sees a board at 1 m for pixel columns
// u < 40 (x / z < 0.125) and a wall at 2 m beyond it.
struct OutlineScene {
  sogmm::Camera cam{64, 48, 60.0, 60.0, 32.0, 24.0};
  std::vector<std::uint16_t> depth = std::vector<std::uint16_t>(64 * 48);
  std::vector<float> gray = std::vector<float>(64 * 48, 0.5f);
  OutlineScene() {
    for (int v = 0; v < 48; ++v)
      for (int u = 0; u < 64; ++u) depth[64 * v + u] = u < 40 ? 1000 : 2000;
  }
  sogmm::RgbdView frame() const { return {depth.data(), gray.data(), cam}; }
};

// The board as the map holds it, fitted from a view where its right edge was
// an outline: one flat component at x = -0.2 m with sigma 0.25 m in x, so
// 8.6% of its mass lies right of x = 0.142 m, where every pixel of the
// scene's frame and its neighbours see the wall (columns >= 41 at z = 1 m).
sogmm::Model board() {
  sogmm::Model m;
  m.gmm.resize(1);
  m.gmm.weights = {1.0f};
  m.gmm.means = {-0.2f, 0.0f, 1.0f, 0.5f};
  m.gmm.covariances.assign(16, 0.0f);
  const float var[4] = {0.0625f, 0.0225f, 4e-6f, 0.01f};
  for (int i = 0; i < 4; ++i) m.gmm.covariances[5 * i] = var[i];
  m.gmm.support_size = 3000;
  m.key_values = {{sogmm::kCoordinateFrameKey, "world"}};
  return m;
}

// The mass of component k right of x = x0 (closed form).
double mass_right_of(const sogmm::Gmm& g, std::size_t k, double x0) {
  const double s = std::sqrt(static_cast<double>(g.covariance(k)[0]));
  return 0.5 * std::erfc((x0 - g.mean(k)[0]) / (s * std::sqrt(2.0)));
}

MapOptions carve_options(double share) {
  MapOptions o;
  o.batch_size = 100000;        // the wall's novel points wait: no flush
  o.revisit_refit_ratio = 0;    // the carve alone
  o.free_space_carve = share;
  o.fit.em.threads = 2;
  return o;
}

constexpr double kSeenPast = (40.5 - 32.0) / 60.0;  // x at 1 m where column 41's pixels begin

TEST(MapCarve, ATailPastAnOutlineIsCarvedByAViewThatSeesPastIt) {
  const OutlineScene scene;
  const sogmm::Model start = board();
  ASSERT_GT(mass_right_of(start.gmm, 0, kSeenPast), 0.08);
  Map map = Map::from_model(start, carve_options(0.01));
  for (int i = 0; i < 4; ++i) map.insert_rgbd(scene.frame(), kIdentity);
  const sogmm::Gmm& g = map.model().gmm;
  ASSERT_EQ(g.size(), 1u);
  // The tail the frame sees past is (nearly) gone: at most the 1% share that
  // triggers a carve, plus the 256 samples' spread (2x).
  EXPECT_LT(mass_right_of(g, 0, kSeenPast), 0.02);
  // The board stays where it is: the mean moves left, not away; y, depth and
  // the mass are the frame's business no more than before.
  EXPECT_LT(g.mean(0)[0], -0.2f);
  EXPECT_GT(g.mean(0)[0], -0.35f);
  EXPECT_NEAR(g.mean(0)[2], 1.0f, 1e-3f);
  EXPECT_NEAR(std::sqrt(g.covariance(0)[5]), 0.15, 0.15 * 0.05);
  EXPECT_GT(std::sqrt(g.covariance(0)[0]), 0.15);
  EXPECT_EQ(g.weights[0], 1.0f);
  EXPECT_EQ(g.support_size, 3000u);
}

TEST(MapCarve, OffOrNothingSeenPastLeavesTheComponentBitwise) {
  const OutlineScene scene;
  const sogmm::Model start = board();
  Map off = Map::from_model(start, carve_options(0.0));
  off.insert_rgbd(scene.frame(), kIdentity);
  EXPECT_EQ(off.model().gmm.means, start.gmm.means);
  EXPECT_EQ(off.model().gmm.covariances, start.gmm.covariances);
  // A board whose 3 sigma stays left of the outline (sigma 0.1 m at
  // x = -0.3 m): no sample is seen past, nothing changes.
  sogmm::Model inside = start;
  inside.gmm.means[0] = -0.3f;
  inside.gmm.covariances[0] = 0.01f;
  Map on = Map::from_model(inside, carve_options(0.01));
  on.insert_rgbd(scene.frame(), kIdentity);
  EXPECT_EQ(on.model().gmm.means, inside.gmm.means);
  EXPECT_EQ(on.model().gmm.covariances, inside.gmm.covariances);
}

TEST(MapCarve, OutOfRangeShareIsRefused) {
  for (double bad : {-0.1, 0.51, 1.0, std::nan("")}) {
    MapOptions o = carve_options(bad);
    EXPECT_THROW(Map m(o), sogmm::Error) << bad;
  }
}

}  // namespace
}  // namespace sogmm_test
