// Map deltas (sogmm/map_delta.hpp, issue 33): a receiver that applies a
// sender's deltas in order holds a bitwise equal map after every one; gaps,
// duplicates, other maps' and damaged deltas are refused and change nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "map_test_util.hpp"
#include "sogmm/map_delta.hpp"

namespace {
using namespace sogmm_test;
using sogmm::MapDelta;

// n points on a textured wall (z = 1.5 m) and floor (y = 0.4 m), 2 mm depth
// noise, the texture's phase set by `shift` (so later frames differ).
std::vector<float> scene_points(std::size_t n, std::uint64_t seed, double shift) {
  TestRng rng(seed);
  std::vector<float> p;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = shift + 0.8 * rng.uniform() - 0.4;
    const bool floor = i % 3 == 2;
    const double y = floor ? 0.4 + 0.002 * rng.normal() : 0.6 * rng.uniform() - 0.2;
    const double z = floor ? 1.0 + 0.5 * rng.uniform() : 1.5 + 0.002 * rng.normal();
    const double gray = 0.5 + 0.3 * std::sin(9.0 * x) + 0.02 * rng.normal();
    p.insert(p.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(gray)});
  }
  return p;
}

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

// Bitwise equality of two maps' components and provenance, field by field
// (not through the digest the implementation checks itself).
void expect_same_map(const Map& sender, const Map& receiver) {
  EXPECT_EQ(receiver.revision(), sender.revision());
  EXPECT_EQ(receiver.id(), sender.id());
  ASSERT_EQ(receiver.size(), sender.size());
  if (sender.size() > 0) {
    const sogmm::Gmm& a = sender.model().gmm;
    const sogmm::Gmm& b = receiver.model().gmm;
    EXPECT_TRUE(same_floats(a.weights, b.weights));
    EXPECT_TRUE(same_floats(a.means, b.means));
    EXPECT_TRUE(same_floats(a.covariances, b.covariances));
    EXPECT_EQ(a.support_size, b.support_size);
    EXPECT_EQ(sender.model().key_values, receiver.model().key_values);
  }
  ASSERT_EQ(receiver.frames().size(), sender.frames().size());
  for (std::size_t k = 0; k < sender.frames().size(); ++k) {
    const sogmm::FrameStats &f = sender.frames()[k], &g = receiver.frames()[k];
    EXPECT_EQ(f.index, g.index);
    EXPECT_EQ(f.n_points, g.n_points);
    EXPECT_EQ(f.n_novel, g.n_novel);
    EXPECT_EQ(f.n_components, g.n_components);
    EXPECT_EQ(std::memcmp(f.pose.data(), g.pose.data(), sizeof f.pose), 0);
  }
}

// Every delta crosses the model form the file stores.
void send(const Map& sender, Map& receiver) {
  receiver.apply_delta(sogmm::delta_from_model(sogmm::delta_to_model(sender.delta_since(receiver.revision()))));
}

// How many steps of each kind the deltas carried (merge, remove, set, drop).
struct KindCounts {
  int n[4] = {0, 0, 0, 0};
  void add(const MapDelta& d) {
    for (const sogmm::DeltaOp& op : d.ops) ++n[static_cast<int>(op.kind)];
  }
};

MapOptions points_options(bool novelty, bool fusion, double precision = 0.0) {
  MapOptions o;
  o.component_precision = precision;
  o.novelty = novelty;
  o.fusion = fusion;
  o.batch_size = 1500;  // some inserts only add pending points, some flush
  o.fit.em.threads = 2;
  return o;
}

TEST(MapDeltaTest, ReceiverIsBitwiseEqualAfterEveryDelta) {
  struct Case {
    bool novelty, fusion;
    double precision;  // MapOptions::component_precision: rounded components travel as rounded
  };
  for (const Case c : {Case{true, false, 0}, Case{false, true, 0}, Case{true, true, 0}, Case{false, true, 0.25}}) {
    SCOPED_TRACE(std::string("novelty ") + (c.novelty ? "on" : "off") + ", fusion " + (c.fusion ? "on" : "off") +
                 ", precision " + std::to_string(c.precision));
    Map sender(points_options(c.novelty, c.fusion, c.precision));
    Map receiver;  // default options: a receiver's own options do not matter
    KindCounts kinds;
    // Each of three scenes seen twice, 3 mm apart: with novelty off fusion
    // folds the second view into the first (MapTest.FusionKeepsMoments...).
    for (int frame = 0; frame < 6; ++frame) {
      const std::vector<float> p = scene_points(1200, 40 + frame / 2, 0.3 * (frame / 2));
      sender.insert_points({p.data(), p.size() / 4}, translated(0.003 * (frame % 2)));
      kinds.add(sender.delta_since(receiver.revision()));
      send(sender, receiver);
      expect_same_map(sender, receiver);
    }
    const bool pending = sender.pending() > 0;
    sender.flush();
    kinds.add(sender.delta_since(receiver.revision()));
    send(sender, receiver);
    expect_same_map(sender, receiver);
    EXPECT_EQ(sender.revision(), pending ? 7u : 6u);  // six inserts, and the flush when it fitted
    EXPECT_GT(kinds.n[0], 1) << "merges";
    if (c.fusion && !c.novelty) {  // whole overlapping frames: fusion is certain
      EXPECT_GT(kinds.n[2], 0) << "fusion changed a component in place";
      EXPECT_GT(kinds.n[3], 0) << "fusion dropped new components";
    }
  }
}

// An RGB-D wall at 1.5 m, 64 x 48 pixels, striped gray (`stripes`) or flat.
struct WallFrame {
  sogmm::Camera cam{64, 48, 60.0, 60.0, 32.0, 24.0};
  std::vector<std::uint16_t> depth = std::vector<std::uint16_t>(64 * 48, 1500);
  std::vector<float> gray = std::vector<float>(64 * 48, 0.5f);
  explicit WallFrame(bool stripes) {
    for (int v = 0; v < 48 && stripes; ++v)
      for (int u = 0; u < 64; ++u) gray[64 * v + u] = static_cast<float>(((u / 4) % 8) / 8.0);
  }
  sogmm::RgbdView view() const { return {depth.data(), gray.data(), cam}; }
};

TEST(MapDeltaTest, RevisitRefitTravelsAndALoadedMapIsABase) {
  MapOptions o;
  o.revisit_refit_ratio = 1.25;
  o.batch_size = 1;
  o.fit.em.threads = 2;
  Map sender(o);
  sender.insert_rgbd(WallFrame(false).view(), kIdentity);  // a flat wall: few components
  // A base map file: the receiver starts from it, not from revision 0.
  Map receiver = Map::from_model(sender.to_model());
  EXPECT_EQ(receiver.revision(), sender.revision());
  EXPECT_EQ(receiver.id(), sender.id());
  const std::size_t before = sender.size();
  const sogmm::FrameStats f = sender.insert_rgbd(WallFrame(true).view(), kIdentity);
  ASSERT_GT(f.n_replaced, 0u) << "the striped view refits the flat wall";
  KindCounts kinds;
  kinds.add(sender.delta_since(receiver.revision()));
  EXPECT_EQ(kinds.n[1], 1) << "a remove step";
  send(sender, receiver);
  expect_same_map(sender, receiver);
  EXPECT_GT(receiver.size(), before);
  // A receiver relays: a third map rebuilt from the receiver's deltas.
  Map relay = Map::from_model(sender.to_model());
  EXPECT_EQ(relay.revision(), receiver.revision());
}

TEST(MapDeltaTest, GapsDuplicatesOtherMapsAndDamageAreRefusedAndChangeNothing) {
  MapOptions o = points_options(true, false);
  o.batch_size = 200;  // every insert fits its novel points
  Map sender(o);
  std::vector<MapDelta> deltas;
  for (int frame = 0; frame < 3; ++frame) {
    const std::uint64_t r = sender.revision();
    const std::vector<float> p = scene_points(1600, 70 + frame, 0.2 * frame);
    sender.insert_points({p.data(), p.size() / 4}, kIdentity);
    deltas.push_back(sender.delta_since(r));
  }
  Map receiver;
  receiver.apply_delta(deltas[0]);
  const std::uint64_t revision = receiver.revision();
  const sogmm::Gmm held = receiver.model().gmm;
  auto unchanged = [&] {
    EXPECT_EQ(receiver.revision(), revision);
    EXPECT_TRUE(same_floats(receiver.model().gmm.weights, held.weights));
    EXPECT_TRUE(same_floats(receiver.model().gmm.means, held.means));
    EXPECT_EQ(receiver.frames().size(), 1u);
  };
  auto refused = [&](const MapDelta& d, ErrorCode code, const char* says) {
    try {
      receiver.apply_delta(d);
      ADD_FAILURE() << "accepted: " << says;
    } catch (const sogmm::Error& e) {
      EXPECT_EQ(e.code(), code) << e.what();
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
    unchanged();
  };
  refused(deltas[2], ErrorCode::InvalidArgument, "a delta is missing");
  refused(deltas[0], ErrorCode::InvalidArgument, "already applied");
  Map other(points_options(true, false));
  const std::vector<float> p = scene_points(1600, 70, 0.0);
  other.insert_points({p.data(), p.size() / 4}, kIdentity);
  other.insert_points({p.data(), p.size() / 4}, kIdentity);
  refused(other.delta_since(1), ErrorCode::InvalidArgument, "is for map");
  // Damaged: one bit of a carried weight, a component position beyond the
  // map, a frame line cut short.
  ASSERT_GT(deltas[1].model.gmm.size(), 0u);
  MapDelta bit = deltas[1];
  std::uint32_t w;
  std::memcpy(&w, &bit.model.gmm.weights[0], 4);
  w ^= 1u;
  std::memcpy(&bit.model.gmm.weights[0], &w, 4);
  refused(bit, ErrorCode::Format, "digest mismatch");
  MapDelta far = deltas[1];
  far.ops.insert(far.ops.begin(), sogmm::DeltaOp{sogmm::DeltaOp::Kind::Drop, 0, 0, {1u << 20}});
  refused(far, ErrorCode::Format, "names component");
  MapDelta cut = deltas[1];
  cut.frames += "7 12\n";  // a frame line without its pose
  refused(cut, ErrorCode::Format, "delta_frames");
  // The model form: a truncated step list and a missing key.
  sogmm::Model form = sogmm::delta_to_model(deltas[1]);
  for (auto& kv : form.key_values)
    if (kv.first == sogmm::kDeltaOpsKey) kv.second = kv.second.substr(0, kv.second.find('\n')) + "\nmerge 3";
  EXPECT_THROW(sogmm::delta_from_model(form), sogmm::Error);
  sogmm::Model plain = sender.model();
  try {
    sogmm::delta_from_model(plain);
    ADD_FAILURE() << "a plain model read as a delta";
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Format);
    EXPECT_NE(std::string(e.what()).find("not a map delta"), std::string::npos) << e.what();
  }
  // After all that, the right next delta still applies.
  receiver.apply_delta(deltas[1]);
  receiver.apply_delta(deltas[2]);
  expect_same_map(sender, receiver);
}

TEST(MapDeltaTest, AFailedInsertKeepsTheRevisionAndRangesAreChecked) {
  Map map(points_options(true, false));
  std::vector<float> p = scene_points(500, 5, 0.0);
  map.insert_points({p.data(), p.size() / 4}, kIdentity);
  EXPECT_EQ(map.revision(), 1u);
  p[0] = std::nanf("");
  EXPECT_THROW(map.insert_points({p.data(), p.size() / 4}, kIdentity), sogmm::Error);
  EXPECT_EQ(map.revision(), 1u);
  const MapDelta none = map.delta_since(1);
  EXPECT_TRUE(none.ops.empty());
  EXPECT_EQ(none.base_revision, none.revision);
  EXPECT_THROW(map.delta_since(2), sogmm::Error);
  EXPECT_EQ(map.discard_pending(), 500u);
  EXPECT_EQ(map.revision(), 1u);  // pending points are not in a delta
}

// MapOptions::delta_history bounds what the sender keeps: deltas from its
// last N revisions are cut as before (a receiver that follows stays bitwise
// equal), an older start is refused naming the oldest kept, and a receiver
// that fell behind catches up from the whole map.
TEST(MapDeltaTest, ABoundedHistoryKeepsTheLastRevisionsOnly) {
  MapOptions o = points_options(true, false);
  o.delta_history = 2;
  Map sender(o), follower(o);
  for (int k = 0; k < 6; ++k) {
    const std::vector<float> p = scene_points(900, 40 + k, 0.3 * k);
    sender.insert_points({p.data(), p.size() / 4}, kIdentity);
    send(sender, follower);
    expect_same_map(sender, follower);
  }
  const std::uint64_t head = sender.revision();
  ASSERT_GE(head, 6u);
  EXPECT_NO_THROW(sender.delta_since(head - 2));
  EXPECT_NO_THROW(sender.delta_since(head));
  try {
    sender.delta_since(head - 3);
    ADD_FAILURE() << "a delta from beyond the history was cut";
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), sogmm::ErrorCode::InvalidArgument);
    EXPECT_NE(std::string(e.what()).find("changes from revision " + std::to_string(head - 2)), std::string::npos)
        << e.what();
  }
  // The unbounded default still cuts from revision 0.
  Map unbounded(points_options(true, false));
  for (int k = 0; k < 3; ++k) {
    const std::vector<float> p = scene_points(900, 40 + k, 0.3 * k);
    unbounded.insert_points({p.data(), p.size() / 4}, kIdentity);
  }
  Map late(points_options(true, false));
  late.apply_delta(unbounded.delta_since(0));
  expect_same_map(unbounded, late);
}

}  // namespace
