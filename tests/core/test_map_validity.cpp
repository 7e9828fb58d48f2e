// Issue 36: a map insert either commits points a flush can fit, or fails at
// that call naming the cause and leaves the map unchanged; pending points can
// be dropped; a map file the map could not extend is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sogmm/fit.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/map.hpp"
#include "map_test_util.hpp"

namespace {
using namespace sogmm_test;

// n points on a textured wall 1.5 m in front of the camera.
std::vector<float> wall(std::size_t n, std::uint64_t seed) {
  TestRng rng(seed);
  std::vector<float> p;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = 0.6 * rng.uniform() - 0.3, y = 0.6 * rng.uniform() - 0.3;
    p.insert(p.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(1.5 + 0.002 * rng.normal()),
                       static_cast<float>(0.5 + 0.3 * std::sin(8.0 * x))});
  }
  return p;
}

sogmm::PointsView view(const std::vector<float>& p) { return {p.data(), p.size() / 4}; }

MapOptions explicit_flushes() {
  MapOptions o;
  o.batch_size = 100000;  // flushes are explicit
  o.fit.em.threads = 2;
  return o;
}

// The map as a caller sees it: what a failed call must leave as it was.
struct Snapshot {
  std::size_t components, pending, frames;
  explicit Snapshot(const Map& m) : components(m.size()), pending(m.pending()), frames(m.frames().size()) {}
  bool operator==(const Snapshot& o) const {
    return components == o.components && pending == o.pending && frames == o.frames;
  }
};

// A frame far from the pending one (1e10 and 1e20 m): on 9ad39ee both went
// pending and every later flush failed with "use a larger bandwidth".
TEST(MapValidity, AFrameFarFromThePendingOnesFailsAtItsInsert) {
  for (const double far : {1e10, 1e20}) {
    SCOPED_TRACE(far);
    Map map(explicit_flushes());
    const std::vector<float> a = wall(300, 1), b = wall(300, 2);
    map.insert_points(view(a), translated(far));  // alone, a batch a flush can fit
    const Snapshot before(map);
    expect_error([&] { map.insert_points(view(b), kIdentity); }, ErrorCode::Limit,
                 {"batch", "pending", "flush"}, "a frame far from the pending one");
    EXPECT_TRUE(Snapshot(map) == before);
    EXPECT_GT(map.flush(), 0u);  // the map is not locked
    map.insert_points(view(b), kIdentity);
    EXPECT_GT(map.flush(), 0u);
    EXPECT_NO_THROW(map.to_model());
  }
}

// A translation beyond float32 (1e39): on 9ad39ee the insert returned OK and
// the flush failed.
TEST(MapValidity, APoseBeyondFloat32IsRefusedAtTheInsert) {
  Map map(explicit_flushes());
  const std::vector<float> a = wall(300, 3);
  expect_error([&] { map.insert_points(view(a), translated(1e39)); }, ErrorCode::InvalidArgument,
               {"float32", "pose"}, "translation 1e39");
  EXPECT_EQ(map.pending(), 0u);
  EXPECT_EQ(map.frames().size(), 0u);
  // The largest float32 is still a map coordinate.
  EXPECT_NO_THROW(map.insert_points(view(a), translated(3.0e38)));
}

// One finite point 2e6 m away. A fit of the same points at 0.02 succeeds; at
// 0.0155 it fails (1.29e8 bandwidths, over the mode count's 1e8). The insert
// applies the fit's own rule at the batch bandwidth: it fails exactly when a
// fit at that bandwidth fails. Alone, the frame is a batch of one view,
// fitted at the bandwidth itself (0.02: accepted); after another frame of
// 300 points the batch (h = (300^2 + 301^2) / 601^2) is fitted at
// 0.02 x (0.7 + 0.3 h^2) = 0.0155 (refused).
TEST(MapValidity, AFarPointIsJudgedAsTheFitAtTheBatchBandwidthJudgesIt) {
  std::vector<float> pts = wall(300, 4);
  pts.insert(pts.end(), {2.0e6f, 0.0f, 0.0f, 0.5f});
  std::vector<float> other = wall(300, 5);  // 1 m aside: no point near a pending one
  for (std::size_t i = 0; i < other.size(); i += 4) other[i] += 1.0f;
  std::vector<float> pooled(other);
  pooled.insert(pooled.end(), pts.begin(), pts.end());
  MapOptions o = explicit_flushes();
  const double h = (300.0 * 300.0 + 301.0 * 301.0) / (601.0 * 601.0);
  sogmm::FitOptions batch = o.fit;
  batch.bandwidth = o.fit.bandwidth * (0.7 + 0.3 * h * h);
  expect_error([&] { sogmm::fit(view(pooled), batch); }, ErrorCode::Limit, {"larger bandwidth"}, "fit at 0.0155");
  EXPECT_NO_THROW(sogmm::fit(view(pts), o.fit));  // at 0.02
  Map alone(o);
  EXPECT_NO_THROW(alone.insert_points(view(pts), kIdentity));
  EXPECT_EQ(alone.pending(), 301u);
  Map novel(o);
  novel.insert_points(view(other), kIdentity);
  expect_error([&] { novel.insert_points(view(pts), kIdentity); }, ErrorCode::Limit,
               {"batch bandwidth 0.0155", "range"}, "map at 0.0155");
  EXPECT_EQ(novel.pending(), 300u);
  EXPECT_EQ(novel.frames().size(), 1u);
  o.novelty = false;  // every frame fitted at the bandwidth itself, as sogmm::fit
  Map append(o);
  append.insert_points(view(pts), kIdentity);
  EXPECT_GT(append.size(), 0u);
}

// A first RGB-D frame with fx = fy = 1e-30 (points ~1e32 m away): on 9ad39ee
// it went pending and fixed the camera, so every correct frame was refused.
TEST(MapValidity, AnAbsurdFirstCameraFailsAtItsInsertAndFixesNothing) {
  Map map(explicit_flushes());
  std::vector<std::uint16_t> depth(64 * 48);
  std::vector<float> gray(64 * 48);
  for (std::size_t i = 0; i < depth.size(); ++i) {
    depth[i] = static_cast<std::uint16_t>(1400 + (i % 64) * 3);
    gray[i] = static_cast<float>(0.3 + 0.4 * ((i / 64) % 2));
  }
  const sogmm::Camera bad{64, 48, 1e-30, 1e-30, 32.0, 24.0};
  expect_error([&] { map.insert_rgbd({depth.data(), gray.data(), bad}, kIdentity); }, ErrorCode::Limit,
               {"intrinsics"}, "fx = fy = 1e-30");
  EXPECT_EQ(map.frames().size(), 0u);
  const sogmm::Camera good{64, 48, 60.0, 60.0, 32.0, 24.0};
  map.insert_rgbd({depth.data(), gray.data(), good}, kIdentity);
  EXPECT_GT(map.flush(), 0u);
  EXPECT_TRUE(map.model().camera.known);
  EXPECT_EQ(map.model().camera.camera.fx, 60.0);
}

// A fixed K: a batch needs K points. On 9ad39ee a map with batch_size < K
// kept fewer than K points pending and could never flush them.
TEST(MapValidity, AFixedKNeedsKPointsInEveryBatch) {
  MapOptions o = explicit_flushes();
  o.batch_size = 50;
  o.fit.n_components = 100;
  expect_error([&] { Map m(o); }, ErrorCode::InvalidArgument, {"batch_size", "K = 100"}, "batch below K");
  o.novelty = false;  // each frame is its batch
  Map map(o);
  const std::vector<float> small = wall(60, 5), big = wall(300, 6);
  expect_error([&] { map.insert_points(view(small), kIdentity); }, ErrorCode::InvalidArgument,
               {"fixed K = 100", "60 points"}, "frame of fewer than K points");
  EXPECT_EQ(map.frames().size(), 0u);
  map.insert_points(view(big), kIdentity);
  EXPECT_EQ(map.size(), 100u);
}

TEST(MapValidity, DiscardPendingDropsThePendingPointsOnly) {
  Map map(explicit_flushes());
  const std::vector<float> a = wall(300, 7), b = wall(200, 8);
  map.insert_points(view(a), kIdentity);
  map.flush();
  const std::size_t components = map.size();
  map.insert_points(view(b), translated(5.0));  // all new: nothing mapped there
  ASSERT_EQ(map.pending(), 200u);
  EXPECT_THROW(map.to_model(), sogmm::Error);  // pending points: no save
  EXPECT_EQ(map.discard_pending(), 200u);
  EXPECT_EQ(map.pending(), 0u);
  EXPECT_EQ(map.size(), components);
  EXPECT_EQ(map.frames().size(), 2u);
  EXPECT_EQ(map.flush(), 0u);
  EXPECT_NO_THROW(map.to_model());
  EXPECT_EQ(map.discard_pending(), 0u);
  // The voxels of the dropped points are forgotten: the same frame is new again.
  EXPECT_EQ(map.insert_points(view(b), translated(5.0)).n_novel, 200u);
}

// Support size 0 (unknown): every flush merges by support size, and merge()
// refuses a known count against an unknown one; on 9ad39ee such a map loaded
// and then every flush failed.
TEST(MapValidity, AModelOfUnknownSupportIsRefusedAsAMap) {
  Map map(explicit_flushes());
  const std::vector<float> a = wall(300, 9);
  map.insert_points(view(a), kIdentity);
  map.flush();
  sogmm::Model m = map.to_model();
  ASSERT_NO_THROW(Map::from_model(m));
  m.gmm.support_size = 0;
  expect_error([&] { Map::from_model(m); }, ErrorCode::InvalidArgument, {"support size is 0"}, "support 0");
}

// map_frames counts with a sign were read by operator>> and wrapped to 2^64 - 1.
TEST(MapValidity, ASignedCountInTheProvenanceIsMalformed) {
  Map map(explicit_flushes());
  const std::vector<float> a = wall(300, 10);
  map.insert_points(view(a), kIdentity);
  map.flush();
  const sogmm::Model good = map.to_model();
  const std::string text = *sogmm::find_value(good, sogmm::kMapFramesKey);
  ASSERT_EQ(text.rfind("0 300 300 ", 0), 0u) << text;
  const std::string tail = text.substr(std::string("0 300 300 ").size());
  const std::size_t last = text.find_last_of(' ');
  const std::string pose_part = text.substr(std::string("0 300 300 ").size(), last - std::string("0 300 300 ").size());
  for (const std::string& line : {"0 -1 300 " + tail, "0 300 -1 " + tail, "-0 300 300 " + tail,
                                  "0 +300 300 " + tail, "0 300 300 " + pose_part + " -5\n"}) {
    SCOPED_TRACE(line);
    sogmm::Model bad = good;
    sogmm::set_value(bad, sogmm::kMapFramesKey, line);
    expect_error([&] { Map::from_model(bad); }, ErrorCode::Format, {"map_frames"}, "signed count");
  }
  EXPECT_NO_THROW(Map::from_model(good));
}

// The "already pending" test far from the origin: its voxel keys held only
// +-10 km, so on 9ad39ee a frame inserted again 1000 km out went pending
// twice (and the map grew with every repeat), unlike at the origin.
TEST(MapValidity, APendingFrameInsertedAgainAddsNothingAt0And1000Km) {
  const std::vector<float> a = wall(400, 11);
  for (const double offset : {0.0, 1.0e6, -1.0e6}) {
    SCOPED_TRACE(offset);
    Map map(explicit_flushes());
    EXPECT_EQ(map.insert_points(view(a), translated(offset)).n_novel, 400u);
    EXPECT_EQ(map.insert_points(view(a), translated(offset)).n_novel, 0u);
    EXPECT_EQ(map.pending(), 400u);
  }
}

}  // namespace
