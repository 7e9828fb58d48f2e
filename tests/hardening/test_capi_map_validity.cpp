// Issue 36 through the C API: a map insert either commits points a flush can
// fit or fails at that call with a status and a message naming the cause,
// leaving the map unchanged; sogmm_map_discard_pending drops what is pending;
// sogmm_map_load refuses a model of unknown support and signed counts in
// "map_frames". Each case locked the map (every later flush failing, and the
// save refusing) or was accepted wrongly on 9ad39ee.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "capi_calls.hpp"
#include "sogmm/sogmm.h"
#include "test_support.hpp"

namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }
std::string last_error() { return sogmm_last_error(); }

std::vector<double> translated(double tx) {
  return {1, 0, 0, tx, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
}

// n points (x, y, z, gray) on a textured wall 1.5 m ahead, from a fixed LCG.
std::vector<float> wall(std::size_t n, std::uint64_t seed) {
  std::uint64_t s = seed;
  auto next = [&] {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(s >> 40) / static_cast<double>(1ULL << 24);
  };
  std::vector<float> p;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = 0.6 * next() - 0.3, y = 0.6 * next() - 0.3;
    p.insert(p.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(1.5 + 0.004 * next()),
                       static_cast<float>(0.5 + 0.3 * std::sin(8.0 * x))});
  }
  return p;
}

// The map totals these tests compare before and after a refused call.
struct MapTotals {
  std::int64_t n_components = -1, n_pending = -1, n_frames = -1, n_flushes = -1;
};

struct MapHandle {
  sogmm_map* map = nullptr;
  explicit MapHandle(int64_t batch = 100000) {
    sogmm_options* o = nullptr;
    EXPECT_EQ(sogmm_options_create(&o), SOGMM_OK);
    EXPECT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, batch), SOGMM_OK);
    EXPECT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_THREADS, 2), SOGMM_OK);
    EXPECT_EQ(sogmm_map_create(&map, o), SOGMM_OK);
    sogmm_options_free(o);
  }
  ~MapHandle() { sogmm_map_free(map); }
  MapTotals stats() const {
    MapTotals s;
    EXPECT_EQ(sogmm_map_get_i64(map, SOGMM_MAP_N_COMPONENTS, &s.n_components), SOGMM_OK);
    EXPECT_EQ(sogmm_map_get_i64(map, SOGMM_MAP_N_PENDING, &s.n_pending), SOGMM_OK);
    EXPECT_EQ(sogmm_map_get_i64(map, SOGMM_MAP_N_FRAMES, &s.n_frames), SOGMM_OK);
    EXPECT_EQ(sogmm_map_get_i64(map, SOGMM_MAP_N_FLUSHES, &s.n_flushes), SOGMM_OK);
    return s;
  }
  sogmm_status insert(const std::vector<float>& p, const std::vector<double>& pose) {
    return sogmm_map_insert_points_f32(map, p.data(), p.size() / 4, pose.data());
  }
};

void expect_same(const MapTotals& a, const MapTotals& b) {
  EXPECT_EQ(a.n_components, b.n_components);
  EXPECT_EQ(a.n_pending, b.n_pending);
  EXPECT_EQ(a.n_frames, b.n_frames);
  EXPECT_EQ(a.n_flushes, b.n_flushes);
}

TEST(CapiMapValidity, FarPosesFailAtTheInsertNotAtALaterFlush) {
  const std::vector<float> a = wall(300, 1), b = wall(300, 2);
  for (const double far : {1e10, 1e20}) {
    SCOPED_TRACE(far);
    MapHandle m;
    ASSERT_EQ(m.insert(a, translated(far)), SOGMM_OK);
    const MapTotals before = m.stats();
    EXPECT_EQ(m.insert(b, translated(0)), SOGMM_E_LIMIT);
    EXPECT_TRUE(has(last_error(), "pending") && has(last_error(), "flush")) << last_error();
    expect_same(m.stats(), before);
    EXPECT_EQ(sogmm_map_flush(m.map), SOGMM_OK) << last_error();
    EXPECT_EQ(m.insert(b, translated(0)), SOGMM_OK) << last_error();
    EXPECT_EQ(sogmm_map_flush(m.map), SOGMM_OK) << last_error();
  }
  MapHandle m;
  EXPECT_EQ(m.insert(a, translated(1e39)), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(has(last_error(), "float32")) << last_error();
  EXPECT_EQ(m.stats().n_frames, 0);
  EXPECT_EQ(m.stats().n_pending, 0);
}

// One point 2e6 m away. A batch of one frame is fitted at the bandwidth
// itself (0.02), where sogmm_fit_points_f32 accepts it too; after a frame of
// 300 other points the batch (two frames, h = (300^2 + 301^2) / 601^2 of its
// point pairs from one frame) is fitted at 0.02 x (0.7 + 0.3 h^2) = 0.0155,
// where 2e6 m is 1.29e8 bandwidths (the mode count takes 1e8): refused, as
// sogmm_fit_points_f32 refuses those points at 0.0155.
TEST(CapiMapValidity, AFarPointIsJudgedAsAFitAtTheBatchBandwidth) {
  std::vector<float> pts = wall(300, 3);
  pts.insert(pts.end(), {2.0e6f, 0.0f, 0.0f, 0.5f});
  std::vector<float> other = wall(300, 4);  // 1 m aside: no point near a pending one
  for (std::size_t i = 0; i < other.size(); i += 4) other[i] += 1.0f;
  std::vector<float> pooled(other);
  pooled.insert(pooled.end(), pts.begin(), pts.end());
  const double h = (300.0 * 300.0 + 301.0 * 301.0) / (601.0 * 601.0);
  sogmm_options* o = nullptr;
  ASSERT_EQ(sogmm_options_create(&o), SOGMM_OK);
  ASSERT_EQ(sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 0.02 * (0.7 + 0.3 * h * h)), SOGMM_OK);
  sogmm_model* fitted = nullptr;
  EXPECT_EQ(sogmm_fit_points_f32(&fitted, pooled.data(), pooled.size() / 4, nullptr, o), SOGMM_E_LIMIT);
  ASSERT_EQ(sogmm_options_set_f64(o, SOGMM_OPT_BANDWIDTH, 0.02), SOGMM_OK);
  EXPECT_EQ(sogmm_fit_points_f32(&fitted, pts.data(), pts.size() / 4, nullptr, o), SOGMM_OK) << last_error();
  sogmm_model_free(fitted);
  sogmm_options_free(o);
  MapHandle alone;
  EXPECT_EQ(alone.insert(pts, translated(0)), SOGMM_OK) << last_error();
  MapHandle m;
  ASSERT_EQ(m.insert(other, translated(0)), SOGMM_OK) << last_error();
  EXPECT_EQ(m.insert(pts, translated(0)), SOGMM_E_LIMIT);
  EXPECT_TRUE(has(last_error(), "batch bandwidth 0.0155")) << last_error();
  EXPECT_EQ(m.stats().n_frames, 1);
  EXPECT_EQ(m.stats().n_pending, 300);
}

// fx = fy = 1e-30 on the first RGB-D frame: refused, and the camera is not fixed.
TEST(CapiMapValidity, AnAbsurdFirstCameraIsRefusedAndFixesNothing) {
  const uint32_t w = 64, h = 48;
  std::vector<uint16_t> depth(w * h);
  std::vector<uint8_t> gray(w * h);
  for (std::size_t i = 0; i < depth.size(); ++i) {
    depth[i] = static_cast<uint16_t>(1400 + (i % w) * 3);
    gray[i] = static_cast<uint8_t>(80 + 100 * ((i / w) % 2));
  }
  MapHandle m;
  const std::vector<double> pose = translated(0);
  EXPECT_EQ(sogmm_test::map_insert_rgbd(m.map, depth.data(), gray.data(), SOGMM_COLOR_GRAY8, w, h, 1e-30, 1e-30, 32, 24,
                                  pose.data()),
            SOGMM_E_LIMIT);
  EXPECT_TRUE(has(last_error(), "intrinsics")) << last_error();
  EXPECT_EQ(m.stats().n_frames, 0);
  EXPECT_EQ(sogmm_test::map_insert_rgbd(m.map, depth.data(), gray.data(), SOGMM_COLOR_GRAY8, w, h, 60, 60, 32, 24,
                                  pose.data()),
            SOGMM_OK)
      << last_error();
}

TEST(CapiMapValidity, AFixedKAboveTheBatchSizeIsRefusedAtCreate) {
  sogmm_options* o = nullptr;
  ASSERT_EQ(sogmm_options_create(&o), SOGMM_OK);
  ASSERT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, 100), SOGMM_OK);
  ASSERT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 50), SOGMM_OK);
  sogmm_map* map = nullptr;
  EXPECT_EQ(sogmm_map_create(&map, o), SOGMM_E_INVALID_ARG);
  EXPECT_EQ(map, nullptr);
  EXPECT_TRUE(has(last_error(), "K = 100")) << last_error();
  sogmm_options_free(o);
}

TEST(CapiMapValidity, DiscardPendingDropsThePendingPoints) {
  MapHandle m;
  const std::vector<float> a = wall(300, 4);
  ASSERT_EQ(m.insert(a, translated(0)), SOGMM_OK);
  const std::string dir = sogmm::test::make_scratch_dir("sogmm-discard");
  const std::string path = dir + "/map.sogmm";
  EXPECT_EQ(sogmm_map_save(m.map, path.c_str(), nullptr), SOGMM_E_INVALID_ARG);  // pending: flush first
  uint64_t dropped = 7;
  EXPECT_EQ(sogmm_map_discard_pending(m.map, &dropped), SOGMM_OK);
  EXPECT_EQ(dropped, 300u);
  EXPECT_EQ(m.stats().n_pending, 0);
  EXPECT_EQ(m.stats().n_frames, 1);
  EXPECT_EQ(sogmm_map_discard_pending(m.map, nullptr), SOGMM_OK);  // the count is optional
  EXPECT_EQ(sogmm_map_discard_pending(nullptr, &dropped), SOGMM_E_NULL_ARG);
  ASSERT_EQ(m.insert(a, translated(0)), SOGMM_OK);
  ASSERT_EQ(sogmm_map_flush(m.map), SOGMM_OK);
  EXPECT_EQ(sogmm_map_save(m.map, path.c_str(), nullptr), SOGMM_OK) << last_error();
  sogmm::test::remove_scratch_dir(dir);
}

// A world-frame file of unknown support (0) and "map_frames" with signed counts.
TEST(CapiMapValidity, LoadRefusesUnknownSupportAndSignedCounts) {
  const float weight = 1.0f, mean[4] = {0, 0, 1, 0.5f};
  float cov[16] = {};
  for (int i = 0; i < 4; ++i) cov[5 * i] = 0.01f;
  const std::string dir = sogmm::test::make_scratch_dir("sogmm-load");
  const std::string path = dir + "/m.sogmm";
  sogmm_map* map = nullptr;
  for (const uint64_t support : {uint64_t{0}, uint64_t{10}}) {
    sogmm_model* model = nullptr;
    ASSERT_EQ(sogmm_model_from_arrays_f32(&model, 1, &weight, mean, cov, support), SOGMM_OK);
    ASSERT_EQ(sogmm_model_set_value(model, "coordinate_frame", "world"), SOGMM_OK);
    ASSERT_EQ(sogmm_model_save(model, path.c_str(), nullptr), SOGMM_OK) << last_error();
    EXPECT_EQ(sogmm_map_load(&map, path.c_str(), nullptr), support == 0 ? SOGMM_E_INVALID_ARG : SOGMM_OK);
    if (support == 0) {
      EXPECT_TRUE(has(last_error(), "support size is 0")) << last_error();
    }
    sogmm_map_free(map);
    map = nullptr;
    for (const char* frames : {"0 -1 10 1 0 0 0 0 1 0 0 0 0 1 0 1\n", "0 10 10 1 0 0 0 0 1 0 0 0 0 1 0 -1\n"}) {
      if (support == 0) break;
      SCOPED_TRACE(frames);
      ASSERT_EQ(sogmm_model_set_value(model, "map_frames", frames), SOGMM_OK);
      ASSERT_EQ(sogmm_model_save(model, path.c_str(), nullptr), SOGMM_OK) << last_error();
      EXPECT_EQ(sogmm_map_load(&map, path.c_str(), nullptr), SOGMM_E_FORMAT);
      EXPECT_TRUE(has(last_error(), "map_frames")) << last_error();
      EXPECT_EQ(map, nullptr);
    }
    sogmm_model_free(model);
  }
  sogmm::test::remove_scratch_dir(dir);
}

// The map's origin (anchor) through the C API: the first frame's translation
// rounded to 1 km, or declared before the first insert; a map saved 1000 km
// out stores it as its pose (spec/format.md 2.3.1) and loads it back, and its
// export is in world coordinates.
TEST(CapiMapValidity, AFarMapKeepsItsOriginThroughSaveAndLoad) {
  const std::vector<float> a = wall(300, 5);
  double origin[3] = {7, 7, 7};
  {
    MapHandle m;
    EXPECT_EQ(sogmm_map_get_origin(m.map, origin), SOGMM_OK);
    EXPECT_EQ(origin[0], 0.0);  // nothing inserted, nothing declared
    const double declared[3] = {1.0e6 + 0.5, 2, 3};
    EXPECT_EQ(sogmm_map_set_origin(m.map, declared), SOGMM_OK);
    ASSERT_EQ(m.insert(a, translated(1.0e6 + 12.25)), SOGMM_OK);
    EXPECT_EQ(sogmm_map_get_origin(m.map, origin), SOGMM_OK);
    EXPECT_EQ(origin[0], 1.0e6 + 0.5);
    EXPECT_EQ(origin[2], 3.0);
    EXPECT_EQ(sogmm_map_set_origin(m.map, declared), SOGMM_E_INVALID_ARG);
    EXPECT_TRUE(has(last_error(), "before the first insert")) << last_error();
  }
  MapHandle m;
  const double bad[3] = {0, NAN, 0};
  EXPECT_EQ(sogmm_map_set_origin(m.map, bad), SOGMM_E_INVALID_ARG);
  EXPECT_TRUE(has(last_error(), "origin axis 1")) << last_error();
  EXPECT_EQ(sogmm_map_set_origin(m.map, nullptr), SOGMM_E_NULL_ARG);
  EXPECT_EQ(sogmm_map_get_origin(m.map, nullptr), SOGMM_E_NULL_ARG);
  EXPECT_EQ(sogmm_map_get_origin(nullptr, origin), SOGMM_E_NULL_ARG);
  ASSERT_EQ(m.insert(a, translated(1.0e6 + 12.25)), SOGMM_OK);
  ASSERT_EQ(sogmm_map_flush(m.map), SOGMM_OK);
  EXPECT_EQ(sogmm_map_get_origin(m.map, origin), SOGMM_OK);
  EXPECT_EQ(origin[0], 1.0e6);
  EXPECT_EQ(origin[1], 0.0);

  const std::string dir = sogmm::test::make_scratch_dir("sogmm-origin");
  const std::string path = dir + "/far.sogmm";
  ASSERT_EQ(sogmm_map_save(m.map, path.c_str(), nullptr), SOGMM_OK) << last_error();
  sogmm_model* file = nullptr;
  ASSERT_EQ(sogmm_model_load(&file, path.c_str(), nullptr), SOGMM_OK);
  double pose[16] = {};
  ASSERT_EQ(sogmm_model_get_pose(file, pose), SOGMM_OK);  // the origin, as a translation
  EXPECT_EQ(pose[3], 1.0e6);
  EXPECT_EQ(pose[0], 1.0);
  sogmm_map* loaded = nullptr;
  ASSERT_EQ(sogmm_map_load(&loaded, path.c_str(), nullptr), SOGMM_OK) << last_error();
  double loaded_origin[3] = {};
  EXPECT_EQ(sogmm_map_get_origin(loaded, loaded_origin), SOGMM_OK);
  EXPECT_EQ(loaded_origin[0], 1.0e6);
  // The export is world-frame: the file's means moved by the origin.
  sogmm_model* world = nullptr;
  ASSERT_EQ(sogmm_map_export(&world, loaded, nullptr), SOGMM_OK);
  size_t n = 0;
  ASSERT_EQ(sogmm_model_n_components(file, &n), SOGMM_OK);
  std::vector<float> file_mean(4 * n), world_mean(4 * n);
  ASSERT_EQ(sogmm_model_get_means_f32(file, file_mean.data(), file_mean.size()), SOGMM_OK);
  ASSERT_EQ(sogmm_model_get_means_f32(world, world_mean.data(), world_mean.size()), SOGMM_OK);
  for (size_t k = 0; k < n; ++k) {
    EXPECT_EQ(world_mean[4 * k], static_cast<float>(static_cast<double>(file_mean[4 * k]) + 1.0e6));
    EXPECT_EQ(world_mean[4 * k + 2], file_mean[4 * k + 2]);
    EXPECT_LT(std::fabs(file_mean[4 * k] - 12.25f), 1.0f);  // the file's means are near the origin
  }
  sogmm_model_free(world);
  sogmm_model_free(file);
  sogmm_map_free(loaded);
  sogmm::test::remove_scratch_dir(dir);
}

}  // namespace
