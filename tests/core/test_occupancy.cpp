// Occupancy from a map's own frames (sogmm/occupancy.hpp, issue 31) against
// independent truth: a plane at z = 2 m seen by a camera at the origin, so
// that a point at z = 1 is free, at z = 2 occupied, at z = 3 (behind the
// surface) and outside the frustum unknown; the per-point probability
// against the formula of the header with the rendered depth; the same scene
// seen from a moved pose; maps that observed nothing; bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "sogmm/map.hpp"
#include "sogmm/occupancy.hpp"
#include "sogmm/render.hpp"
#include "plane_scene.hpp"
#include "test_util.hpp"

namespace {

using sogmm::OccupancyState;

using sogmm_test::kPlaneZ;
using sogmm_test::plane_map;
const sogmm::Camera& kCam = sogmm_test::kPlaneCamera;

sogmm::Pose identity() { return sogmm_test::kIdentityPose; }

struct Answer {
  std::vector<double> p;
  std::vector<std::uint8_t> s;
};

Answer ask(const sogmm::Map& map, const std::vector<float>& xyz, const sogmm::OccupancyOptions& o = {},
           int threads = 0) {
  Answer a;
  a.p.assign(xyz.size() / 3, -1.0);
  a.s.assign(xyz.size() / 3, 255);
  sogmm::occupancy(map, xyz.data(), a.p.size(), a.p.data(), a.s.data(), o, threads);
  return a;
}

double phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

TEST(Occupancy, PlaneSeenFromTheOriginIsFreeOccupiedAndUnknown) {
  const sogmm::Map map = plane_map(identity());
  // On the optical axis: before, on and behind the plane; beside the
  // frustum; behind the camera; beyond the depth range (3 m) with no surface.
  const std::vector<float> xyz = {0, 0, 1, 0, 0, 2, 0, 0, 3, 0.3f, 0.2f, 1.5f, 5, 0, 2, 0, 0, -1, -0.5f, 0.3f, 1.0f};
  const Answer a = ask(map, xyz);
  EXPECT_EQ(a.s[0], static_cast<int>(OccupancyState::Free));
  EXPECT_LT(a.p[0], 1e-6);
  EXPECT_EQ(a.s[1], static_cast<int>(OccupancyState::Occupied));
  EXPECT_GT(a.p[1], 0.9);
  EXPECT_EQ(a.s[2], static_cast<int>(OccupancyState::Unknown));
  EXPECT_EQ(a.p[2], 0.5);  // hidden by more than 98 sigma: exactly no evidence
  EXPECT_EQ(a.s[3], static_cast<int>(OccupancyState::Free));
  EXPECT_EQ(a.s[4], static_cast<int>(OccupancyState::Unknown));
  EXPECT_EQ(a.p[4], 0.5);
  EXPECT_EQ(a.s[5], static_cast<int>(OccupancyState::Unknown));
  EXPECT_EQ(a.p[5], 0.5);
  EXPECT_EQ(a.s[6], static_cast<int>(OccupancyState::Free));
  for (double p : a.p) EXPECT_TRUE(p >= 0.0 && p <= 1.0);
}

TEST(Occupancy, ProbabilityIsTheFormulaOfTheRenderedDepth) {
  const sogmm::Map map = plane_map(identity());
  const sogmm::CameraInfo& info = map.model().camera;
  sogmm::RenderOptions ro;
  ro.depth_min = info.depth_min;
  ro.depth_max = info.depth_max;
  const sogmm::RenderedImages img = sogmm::render(map.model().gmm, kCam, identity(), ro);
  // Pixel (40, 30) of the full-size camera (decimation 1); points along its ray.
  const int u = 40, v = 30;
  const double d = img.depth[static_cast<std::size_t>(v) * kCam.width + u];
  EXPECT_NEAR(d, kPlaneZ, 0.005);  // the fitted plane renders where it is
  const double rx = (u - kCam.cx) / kCam.fx, ry = (v - kCam.cy) / kCam.fy, ray = std::sqrt(rx * rx + ry * ry + 1);
  sogmm::OccupancyOptions o;
  for (double z : {1.9, 1.97, 1.99, 2.0, 2.01, 2.03}) {
    const std::vector<float> xyz = {static_cast<float>(rx * z), static_cast<float>(ry * z), static_cast<float>(z)};
    const Answer a = ask(map, xyz, o);
    const double zf = xyz[2];  // the point as float
    const double s = (zf - d) * ray, h = o.thickness, sg = o.surface_sigma;
    const double e = 1 - phi((s + h) / sg), b = phi((s - h) / sg), occ = 1 - e - b;
    const double expected = (1 - b) * occ / (occ + e) + 0.5 * b;
    EXPECT_NEAR(a.p[0], expected, 1e-6) << "z = " << z;
  }
}

TEST(Occupancy, MovedPoseMovesTheAnswer) {
  // The camera 1 m along x and turned 90 degrees about y (looking along +x):
  // the plane is now x = 3 in the world.
  const sogmm::Pose pose = {0, 0, 1, 1, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 0, 1};
  const sogmm::Map map = plane_map(pose);
  const std::vector<float> xyz = {2, 0, 0, 3, 0, 0, 4, 0, 0, 0, 0, 2};
  const Answer a = ask(map, xyz);
  EXPECT_EQ(a.s[0], static_cast<int>(OccupancyState::Free));
  EXPECT_EQ(a.s[1], static_cast<int>(OccupancyState::Occupied));
  EXPECT_EQ(a.s[2], static_cast<int>(OccupancyState::Unknown));
  EXPECT_EQ(a.s[3], static_cast<int>(OccupancyState::Unknown));  // behind that camera
}

TEST(Occupancy, SameAnswerForAnyThreadCount) {
  const sogmm::Map map = plane_map(identity());
  std::vector<float> xyz;
  for (int i = 0; i < 3000; ++i) {
    xyz.push_back(static_cast<float>((i % 31) * 0.05 - 0.75));
    xyz.push_back(static_cast<float>((i % 17) * 0.05 - 0.4));
    xyz.push_back(static_cast<float>(0.5 + (i % 53) * 0.05));
  }
  const Answer one = ask(map, xyz, {}, 1), two = ask(map, xyz, {}, 2);
  EXPECT_EQ(one.p, two.p);
  EXPECT_EQ(one.s, two.s);
}

// The renders a map keeps between calls (Map::frame_depth) are the renders
// of its current components: the same image as render() itself, and a second
// frame that adds components changes the answer exactly as a map loaded
// afresh (which keeps nothing) gives it.
TEST(Occupancy, KeptRendersFollowTheComponents) {
  sogmm::Map map = plane_map(identity());
  const sogmm::CameraInfo& info = map.model().camera;
  sogmm::RenderOptions ro;
  ro.depth_min = info.depth_min;
  ro.depth_max = info.depth_max;
  const std::vector<float> direct =
      sogmm::render(map.model().gmm, sogmm::decimated(info.camera, info.decimation), identity(), ro).depth;
  const auto kept = map.frame_depth(0);
  ASSERT_EQ(kept->size(), direct.size());
  for (std::size_t i = 0; i < direct.size(); ++i)
    ASSERT_TRUE((std::isnan(direct[i]) && std::isnan((*kept)[i])) || direct[i] == (*kept)[i]) << i;
  EXPECT_EQ(map.frame_depth(0).get(), kept.get());  // kept, not rendered again

  // A box in front of the plane, seen by a second frame: the point at
  // z = 1.5 m was free and becomes occupied.
  const std::vector<float> xyz = {0, 0, 1.5f, 0, 0, 1.0f, 0.3f, 0.2f, 1.5f};
  const Answer before = ask(map, xyz);
  EXPECT_EQ(before.s[0], static_cast<int>(OccupancyState::Free));
  const sogmm::Camera& cam = kCam;
  std::vector<std::uint16_t> depth(static_cast<std::size_t>(cam.width * cam.height), 2000);
  for (int v = 18; v < 30; ++v)
    for (int u = 26; u < 38; ++u) depth[static_cast<std::size_t>(v * cam.width + u)] = 1500;
  std::vector<float> gray(depth.size(), 0.5f);
  map.insert_rgbd({depth.data(), gray.data(), cam}, identity());
  map.flush();
  EXPECT_NE(map.frame_depth(0).get(), kept.get());
  const Answer after = ask(map, xyz);
  EXPECT_EQ(after.s[0], static_cast<int>(OccupancyState::Occupied));
  const Answer fresh = ask(sogmm::Map::from_model(map.to_model(), map.options()), xyz);
  EXPECT_EQ(after.p, fresh.p);
  EXPECT_EQ(after.s, fresh.s);
}

TEST(Occupancy, MapsThatObservedNothingAnswerUnknown) {
  const std::vector<float> xyz = {0, 0, 1, 0, 0, 2};
  const sogmm::Map empty;
  Answer a = ask(empty, xyz);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(a.p[i], 0.5);
    EXPECT_EQ(a.s[i], static_cast<int>(OccupancyState::Unknown));
  }
  // Points-only inserts record no camera: no view to reason with.
  sogmm::MapOptions o;
  o.novelty = false;
  sogmm::Map points_only(o);
  std::vector<float> cloud;
  for (int i = 0; i < 400; ++i) {
    cloud.insert(cloud.end(), {static_cast<float>((i % 20) * 0.05 - 0.5), static_cast<float>((i / 20) * 0.05 - 0.5),
                               2.0f, 0.5f});
  }
  points_only.insert_points({cloud.data(), cloud.size() / 4}, identity());
  points_only.flush();
  ASSERT_GT(points_only.size(), 0u);
  a = ask(points_only, xyz);
  EXPECT_EQ(a.p[0], 0.5);
  EXPECT_EQ(a.s[1], static_cast<int>(OccupancyState::Unknown));
}

TEST(Occupancy, BadInputIsRefusedAndNothingIsWritten) {
  const sogmm::Map map = plane_map(identity());
  std::vector<float> xyz = {0, 0, 1, 0, std::numeric_limits<float>::quiet_NaN(), 2};
  std::vector<double> p(2, -1.0);
  sogmm_test::expect_error([&] { sogmm::occupancy(map, xyz.data(), 2, p.data(), nullptr); },
                            sogmm::ErrorCode::InvalidData, {"row 1"}, "a NaN point");
  EXPECT_EQ(p[0], -1.0);
  xyz[4] = 0;
  sogmm::OccupancyOptions bad;
  bad.surface_sigma = 0;
  sogmm_test::expect_error([&] { sogmm::occupancy(map, xyz.data(), 2, p.data(), nullptr, bad); },
                            sogmm::ErrorCode::InvalidArgument, {"sigma"}, "sigma 0");
  bad = {};
  bad.thickness = -1;
  sogmm_test::expect_error([&] { sogmm::occupancy(map, xyz.data(), 2, p.data(), nullptr, bad); },
                            sogmm::ErrorCode::InvalidArgument, {"thickness"}, "thickness -1");
}

}  // namespace
