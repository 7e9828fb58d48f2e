// Map-to-map merge (Map::merge_map, core/src/map_merge.cpp; issue 33): into
// an empty map it gives the other map, with a copy of itself it adds
// nothing, the sharper of two views of one surface wins in either merge
// order (hand-made maps with closed-form weights), deltas follow it bitwise,
// and bad input changes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "map_test_util.hpp"
#include "sogmm/map_delta.hpp"
#include "sogmm/model.hpp"

namespace {
using namespace sogmm_test;
using sogmm::Gmm;
using sogmm::Model;

// A component with a diagonal covariance (sx, sy, sz, gray variance 0.01).
struct Comp {
  float w, x, y, z, sx, sy, sz;
};

// A world-frame map of the given components and support size.
Map hand_map(const std::vector<Comp>& comps, std::uint64_t support) {
  Model m;
  m.gmm.resize(comps.size());
  for (std::size_t k = 0; k < comps.size(); ++k) {
    const Comp& c = comps[k];
    m.gmm.weights[k] = c.w;
    const float mean[4] = {c.x, c.y, c.z, 0.5f};
    std::copy_n(mean, 4, m.gmm.means.data() + 4 * k);
    float* cov = m.gmm.covariances.data() + 16 * k;
    std::fill_n(cov, 16, 0.0f);
    cov[0] = c.sx * c.sx;
    cov[5] = c.sy * c.sy;
    cov[10] = c.sz * c.sz;
    cov[15] = 0.01f;
  }
  m.gmm.support_size = support;
  m.key_values.emplace_back(sogmm::kCoordinateFrameKey, "world");
  return Map::from_model(m);
}

// One coarse component over a 40 x 40 cm patch of the wall z = 1.5 (a
// distant robot's view) and the same patch in four fine components (a close
// one's): the fine view's local density beats the coarse one's at 5 of the
// coarse component's 7 test points (its mean and +-1 sigma in x and y; off
// the surface, +-1 sigma in z, the thin fine components lose).
const Comp kCoarse = {1.0f, 0.0f, 0.0f, 1.5f, 0.1f, 0.1f, 0.005f};
std::vector<Comp> fine_patch() {
  std::vector<Comp> c;
  for (float x : {-0.05f, 0.05f})
    for (float y : {-0.05f, 0.05f}) c.push_back({0.25f, x, y, 1.5f, 0.05f, 0.05f, 0.002f});
  return c;
}
// A component far from the patch (2 m away in x), in no other map.
const Comp kElsewhere = {0.0f, 2.0f, 0.0f, 1.5f, 0.03f, 0.03f, 0.003f};

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

void expect_same_gmm(const Gmm& a, const Gmm& b) {
  EXPECT_TRUE(same_floats(a.weights, b.weights));
  EXPECT_TRUE(same_floats(a.means, b.means));
  EXPECT_TRUE(same_floats(a.covariances, b.covariances));
  EXPECT_EQ(a.support_size, b.support_size);
}

// A fitted map: two frames of a textured wall and floor, each a flush;
// fitted once, each test takes a copy (its saved form, as a robot's).
Map fitted_map() {
  static const Model saved = [] {
    MapOptions o;
    o.batch_size = 1;
    Map m(o);
    TestRng rng(7);
    for (int f = 0; f < 2; ++f) {
      std::vector<float> p;
      for (int i = 0; i < 1500; ++i) {
        const double x = 0.1 * f + 0.8 * rng.uniform() - 0.4;
        const bool floor = i % 3 == 2;
        const double y = floor ? 0.4 + 0.002 * rng.normal() : 0.6 * rng.uniform() - 0.2;
        const double z = floor ? 1.0 + 0.5 * rng.uniform() : 1.5 + 0.002 * rng.normal();
        const double gray = 0.5 + 0.3 * std::sin(9.0 * x) + 0.02 * rng.normal();
        p.insert(p.end(),
                 {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(gray)});
      }
      m.insert_points({p.data(), p.size() / 4}, kIdentity);
    }
    return m.to_model();
  }();
  return Map::from_model(saved);
}

TEST(MapMerge, IntoAnEmptyMapGivesTheOtherMap) {
  const Map other = fitted_map();
  ASSERT_GT(other.size(), 0u);
  Map empty;
  const sogmm::MapMergeStats st = empty.merge_map(other, kIdentity);
  EXPECT_EQ(st.n_added, other.size());
  EXPECT_EQ(st.n_kept + st.n_removed + st.n_skipped, 0u);
  expect_same_gmm(empty.model().gmm, other.model().gmm);
  ASSERT_EQ(empty.frames().size(), other.frames().size());
  for (std::size_t k = 0; k < other.frames().size(); ++k) {
    EXPECT_EQ(empty.frames()[k].index, k);
    EXPECT_EQ(empty.frames()[k].pose, other.frames()[k].pose);
  }
  EXPECT_EQ(empty.revision(), 1u);
}

TEST(MapMerge, WithACopyOfItselfAddsNoComponent) {
  Map map = fitted_map();
  const Map copy = Map::from_model(map.to_model());
  const Gmm before = map.model().gmm;
  const sogmm::MapMergeStats st = map.merge_map(copy, kIdentity);
  EXPECT_EQ(st.n_skipped, before.size());  // every component ties with its twin
  EXPECT_EQ(st.n_added, 0u);
  EXPECT_EQ(st.n_removed, 0u);
  expect_same_gmm(map.model().gmm, before);
  EXPECT_EQ(map.frames().size(), 2 * copy.frames().size());  // both provenances kept
}

// The sharper view of the patch wins whichever map receives the other, and
// the weights are the closed form of the kept mass: the far component keeps
// its 0.25 x 400 = 100 points, the fine patch its 800, so after the merge
// the far one weighs 100 / 900 and each fine one 0.25 x 800 / 900.
TEST(MapMerge, SharperViewWinsInEitherOrder) {
  std::vector<Comp> coarse_side = {kCoarse, kElsewhere};
  coarse_side[0].w = 0.75f;
  coarse_side[1].w = 0.25f;
  const Map fine = hand_map(fine_patch(), 800);

  Map a = hand_map(coarse_side, 400);
  const sogmm::MapMergeStats sa = a.merge_map(fine, kIdentity);
  EXPECT_EQ(sa.n_removed, 1u);
  EXPECT_EQ(sa.n_kept, 1u);
  EXPECT_EQ(sa.n_added, 4u);
  EXPECT_EQ(sa.n_skipped, 0u);
  const Gmm& g = a.model().gmm;
  ASSERT_EQ(g.size(), 5u);
  EXPECT_EQ(g.support_size, 900u);
  EXPECT_NEAR(g.weights[0], 100.0 / 900.0, 1e-6);
  EXPECT_EQ(g.means[0], 2.0f);
  for (std::size_t k = 1; k < 5; ++k) EXPECT_NEAR(g.weights[k], 200.0 / 900.0, 1e-6);

  Map b = hand_map(fine_patch(), 800);
  const sogmm::MapMergeStats sb = b.merge_map(hand_map(coarse_side, 400), kIdentity);
  EXPECT_EQ(sb.n_skipped, 1u);  // the coarse component
  EXPECT_EQ(sb.n_added, 1u);    // the far one
  EXPECT_EQ(sb.n_removed, 0u);
  ASSERT_EQ(b.size(), 5u);
  EXPECT_EQ(b.model().gmm.support_size, 900u);
  // The same component set: fine patch and the far component, same weights.
  const Gmm& h = b.model().gmm;
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(h.weights[k], 200.0 / 900.0, 1e-6);
    EXPECT_TRUE(std::memcmp(h.mean(k), g.mean(k + 1), 4 * sizeof(float)) == 0);
  }
  EXPECT_NEAR(h.weights[4], 100.0 / 900.0, 1e-6);
  EXPECT_EQ(h.means[16], 2.0f);
}

// Moving the other map's content and its pose together changes nothing: the
// fine patch held 0.5 m along x (a robot's own frame) merged with the pose
// that moves it back equals the patch merged with the identity.
TEST(MapMerge, OtherFrameAndPoseCancel) {
  std::vector<Comp> shifted = fine_patch();
  for (Comp& c : shifted) c.x += 0.5f;
  Map a = hand_map({kCoarse}, 400), b = hand_map({kCoarse}, 400);
  a.merge_map(hand_map(fine_patch(), 800), kIdentity);
  b.merge_map(hand_map(shifted, 800), translated(-0.5));
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a.model().gmm.weights[k], b.model().gmm.weights[k]);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(a.model().gmm.mean(k)[i], b.model().gmm.mean(k)[i], 1e-6);
  }
}

// Disjoint maps (the other 10 m away): nothing is outmatched, every
// component stays with its mass in points: weights w S / (S_a + S_b).
TEST(MapMerge, DisjointMapsKeepEveryComponentWithItsMass) {
  Map a = fitted_map();
  const Map b = fitted_map();
  const Gmm ga = a.model().gmm, gb = b.model().gmm;
  const sogmm::MapMergeStats st = a.merge_map(b, translated(10.0));
  EXPECT_EQ(st.n_removed + st.n_skipped, 0u);
  ASSERT_EQ(a.size(), ga.size() + gb.size());
  const double sa = ga.support_size, sb = gb.support_size;
  EXPECT_EQ(a.model().gmm.support_size, ga.support_size + gb.support_size);
  for (std::size_t k = 0; k < ga.size(); ++k) EXPECT_NEAR(a.model().gmm.weights[k], ga.weights[k] * sa / (sa + sb), 1e-7);
  for (std::size_t k = 0; k < gb.size(); ++k) {
    EXPECT_NEAR(a.model().gmm.weights[ga.size() + k], gb.weights[k] * sb / (sa + sb), 1e-7);
    EXPECT_NEAR(a.model().gmm.mean(ga.size() + k)[0], gb.mean(k)[0] + 10.0, 1e-5);
  }
  EXPECT_EQ(a.frames().back().pose[3], 10.0);  // the other's frames moved to this world
}

// A receiver of this map's deltas follows the merge bitwise (a Remove and a
// Merge step), at one revision more.
TEST(MapMerge, DeltasFollowTheMerge) {
  std::vector<Comp> coarse_side = {kCoarse, kElsewhere};
  coarse_side[0].w = 0.75f;
  coarse_side[1].w = 0.25f;
  Map a = hand_map(coarse_side, 400);
  // A receiver holding a's base map (a loaded map's file, with its identity).
  Map receiver = Map::from_model(a.to_model());
  const std::uint64_t before = a.revision();
  a.merge_map(hand_map(fine_patch(), 800), kIdentity);
  EXPECT_EQ(a.revision(), before + 1);
  const sogmm::MapDelta d = a.delta_since(before);
  ASSERT_EQ(d.ops.size(), 2u);
  EXPECT_EQ(d.ops[0].kind, sogmm::DeltaOp::Kind::Remove);
  EXPECT_EQ(d.ops[1].kind, sogmm::DeltaOp::Kind::Merge);
  receiver.apply_delta(sogmm::delta_from_model(sogmm::delta_to_model(d)));
  EXPECT_EQ(receiver.revision(), a.revision());
  expect_same_gmm(receiver.model().gmm, a.model().gmm);
}

// Bad input: a clear error, and the map as before (components, frames,
// revision).
TEST(MapMerge, BadInputChangesNothing) {
  Map map = fitted_map();
  const Map other = fitted_map();
  const Gmm before = map.model().gmm;
  const std::uint64_t revision = map.revision();
  const std::size_t frames = map.frames().size();
  auto unchanged = [&] {
    expect_same_gmm(map.model().gmm, before);
    EXPECT_EQ(map.revision(), revision);
    EXPECT_EQ(map.frames().size(), frames);
  };
  expect_error([&] { map.merge_map(map, kIdentity); }, ErrorCode::InvalidArgument, {"merged into itself"}, "merged into itself");
  unchanged();
  Pose nan_pose = kIdentity;
  nan_pose[3] = std::numeric_limits<double>::quiet_NaN();
  expect_error([&] { map.merge_map(other, nan_pose); }, ErrorCode::InvalidArgument, {"not finite"}, "not finite");
  unchanged();
  Pose scaled = kIdentity;
  scaled[0] = 2.0;
  expect_error([&] { map.merge_map(other, scaled); }, ErrorCode::InvalidArgument, {"not a rigid transform"}, "not a rigid transform");
  unchanged();
  expect_error([&] { map.merge_map(Map(), kIdentity); }, ErrorCode::InvalidData, {"no component"}, "no component");
  unchanged();
  // Points pending in the other map (a busy robot: flush first).
  MapOptions o;
  o.batch_size = 100000;
  Map busy(o);
  const std::vector<float> p = {0.0f, 0.0f, 1.0f, 0.5f, 0.01f, 0.0f, 1.0f, 0.5f};
  busy.insert_points({p.data(), 2}, kIdentity);
  ASSERT_GT(busy.pending(), 0u);
  expect_error([&] { map.merge_map(busy, kIdentity); }, ErrorCode::InvalidArgument, {"pending"}, "pending");
  unchanged();
  expect_error([&] { busy.merge_map(map, kIdentity); }, ErrorCode::InvalidArgument, {"pending"}, "pending");
  EXPECT_EQ(busy.size(), 0u);
  // A pose that moves components beyond float32.
  expect_error([&] { map.merge_map(other, translated(1e39)); }, ErrorCode::InvalidArgument, {"float32"}, "float32");
  unchanged();
}

}  // namespace
