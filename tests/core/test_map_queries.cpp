// World-frame queries on a map (sogmm/map_queries.hpp) and the strong error
// guarantee of inserts: the answers are the model queries on map.model(),
// bitwise, with and without a progress sink; a cancelled insert or flush
// leaves the map as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "sogmm/inference.hpp"
#include "sogmm/map.hpp"
#include "sogmm/map_queries.hpp"
#include "map_test_util.hpp"

namespace {
using namespace sogmm_test;

// Three tight clusters in (x, y, z, gray).
std::vector<float> clusters(std::size_t n, std::uint64_t seed) {
  const float centres[3][4] = {{0, 0, 1, 0.2f}, {0.5f, 0, 1.5f, 0.5f}, {0, 0.5f, 2, 0.8f}};
  TestRng rng(seed);
  std::vector<float> p(4 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < 4; ++d) p[4 * i + d] = centres[i % 3][d] + static_cast<float>(0.02 * rng.normal());
  return p;
}

MapOptions options(bool novelty) {
  MapOptions o;
  o.novelty = novelty;
  o.batch_size = 100000;
  o.fit.em.threads = 2;
  return o;
}

Map two_frame_map() {
  const std::vector<float> p = clusters(3000, 1);
  Map map(options(true));
  map.insert_points({p.data(), 3000}, kIdentity);
  map.insert_points({p.data(), 3000}, translated(2.0));
  map.flush();
  return map;
}

// Query points: the cloud, every fifth point moved 3.5 m off (far regime).
std::vector<float> queries(std::size_t n, int dims) {
  const std::vector<float> p = clusters(n, 9);
  std::vector<float> q;
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < dims; ++d) q.push_back(p[4 * i + d] + (i % 5 == 0 && d == 0 ? 3.5f : 0.0f));
  return q;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

TEST(MapQueries, EqualTheModelQueriesBitwiseWithAndWithoutASink) {
  const Map map = two_frame_map();
  const sogmm::Gmm& gmm = map.model().gmm;
  const std::size_t n = 10000;  // three chunks with a sink
  std::uint64_t reports = 0, last_step = 0;
  const sogmm::ProgressSink sink = [&](const sogmm::Progress& p) {
    ++reports;
    last_step = p.step;
    return false;
  };
  for (int dims : {3, 4}) {
    const std::vector<float> q = queries(n, dims);
    std::vector<double> want(n), plain(n), chunked(n);
    sogmm::score_samples(gmm, q.data(), n, dims, want.data());
    sogmm::score_samples(map, q.data(), n, dims, plain.data());
    reports = 0;
    sogmm::score_samples(map, q.data(), n, dims, chunked.data(), {}, sink);
    EXPECT_TRUE(same_bits(want, plain));
    EXPECT_TRUE(same_bits(want, chunked));
    EXPECT_GE(reports, 2u);  // the start and the end at least
    EXPECT_EQ(last_step, n);
    EXPECT_LT(want[0], want[1] - 50.0);  // the far points are far
  }
  const std::vector<float> q = queries(n, 3);
  std::vector<float> mean(n), var(n), mean_m(n), var_m(n), mean_s(n);
  sogmm::regress_gray(gmm, q.data(), n, mean.data(), var.data());
  sogmm::regress_gray(map, q.data(), n, mean_m.data(), var_m.data());
  sogmm::regress_gray(map, q.data(), n, mean_s.data(), nullptr, {}, sink);
  EXPECT_TRUE(same_bits(mean, mean_m) && same_bits(var, var_m) && same_bits(mean, mean_s));

  std::vector<float> s(4 * n), s_m(4 * n);
  sogmm::sample(gmm, n, 5, 4, s.data(), 1.5);
  sogmm::sample(map, n, 5, 4, s_m.data(), 1.5, sink);
  EXPECT_TRUE(same_bits(s, s_m));
}

TEST(MapQueries, RefuseAnEmptyMapAndBadPoints) {
  const Map empty(options(true));
  std::vector<float> q = queries(4, 3);
  std::vector<double> out(4);
  std::vector<float> g(4);
  expect_error([&] { sogmm::score_samples(empty, q.data(), 4, 3, out.data()); }, ErrorCode::InvalidData,
               {"no component"}, "empty map score");
  expect_error([&] { sogmm::regress_gray(empty, q.data(), 0, g.data(), nullptr); }, ErrorCode::InvalidData,
               {"no component"}, "empty map regress, n = 0");
  expect_error([&] { sogmm::sample(empty, 4, 1, 4, g.data()); }, ErrorCode::InvalidData, {"no component"},
               "empty map sample");
  const Map map = two_frame_map();
  expect_error([&] { sogmm::score_samples(map, q.data(), 4, 5, out.data()); }, ErrorCode::InvalidArgument,
               {"dims"}, "dims 5");
  q[7] = NAN;  // row 2 of 3-float rows; with a sink the row is the caller's row too
  for (bool with_sink : {false, true}) {
    const sogmm::ProgressSink sink = with_sink ? sogmm::ProgressSink([](const sogmm::Progress&) { return false; })
                                               : sogmm::ProgressSink();
    expect_error([&] { sogmm::score_samples(map, q.data(), 4, 3, out.data(), {}, sink); }, ErrorCode::InvalidData,
                 {"row 2"}, "NaN score");
    expect_error([&] { sogmm::regress_gray(map, q.data(), 4, g.data(), nullptr, {}, sink); }, ErrorCode::InvalidData,
                 {"row 2"}, "NaN regress");
  }
}

TEST(MapQueries, ACancelledQueryThrowsCancelled) {
  const Map map = two_frame_map();
  const std::vector<float> q = queries(100, 4);
  std::vector<double> out(100);
  expect_error([&] { sogmm::score_samples(map, q.data(), 100, 4, out.data(), {}, [](const sogmm::Progress&) { return true; }); },
               ErrorCode::Cancelled, {"scoring"}, "cancel score");
}

// Components, means and stats of a map, to compare before and after.
struct Snapshot {
  std::size_t size, pending, frames, flushes;
  std::vector<float> means;
  bool operator==(const Snapshot& o) const {
    return size == o.size && pending == o.pending && frames == o.frames && flushes == o.flushes &&
           means == o.means;
  }
};
Snapshot snapshot(const Map& m) {
  const sogmm::MapStats s = m.stats();
  return {s.n_components, s.n_pending, s.n_frames, s.n_flushes, m.size() ? m.model().gmm.means : std::vector<float>{}};
}

TEST(MapQueries, ACancelledInsertOrFlushLeavesTheMapAsItWas) {
  const std::vector<float> p = clusters(3000, 3);
  const sogmm::ProgressSink cancel = [](const sogmm::Progress&) { return true; };
  for (bool novelty : {false, true}) {
    SCOPED_TRACE(novelty ? "novelty on" : "novelty off");
    MapOptions o = options(novelty);
    o.batch_size = 1000;  // with novelty, a new frame's 3000 novel points flush at once
    Map map(o);
    map.insert_points({p.data(), 3000}, kIdentity);
    const Snapshot before = snapshot(map);
    ASSERT_GT(before.size, 0u);
    expect_error([&] { map.insert_points({p.data(), 3000}, translated(3.0), cancel); }, ErrorCode::Cancelled,
                 {"cancelled"}, "cancelled insert");
    EXPECT_TRUE(snapshot(map) == before);
    EXPECT_EQ(map.frames().size(), 1u);
    // The same insert then succeeds and is the second frame.
    map.insert_points({p.data(), 3000}, translated(3.0));
    EXPECT_EQ(map.frames().size(), 2u);
    EXPECT_EQ(map.frames()[1].index, 1u);
    EXPECT_GT(map.size(), before.size);
  }
  // A cancelled flush keeps the pending points.
  Map map(options(true));
  map.insert_points({p.data(), 3000}, kIdentity);
  const Snapshot before = snapshot(map);
  expect_error([&] { map.flush(cancel); }, ErrorCode::Cancelled, {"cancelled"}, "cancelled flush");
  EXPECT_TRUE(snapshot(map) == before);
  EXPECT_EQ(map.pending(), 3000u);
  EXPECT_GT(map.flush(), 0u);
}

}  // namespace
