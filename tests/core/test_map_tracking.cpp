// Tracking's odometry fallback (sogmm/map_tracking.hpp, issue 32): the
// rule that decides a frame's pose (hand-made registration results), the
// RMS displacement between two poses (closed forms), and frames of an
// analytic room corner (floor y = 0.6, back wall z = 2.2, side wall
// x = -0.9, uniform gray, ray-cast per pixel of a 200 x 150 camera: points
// about 1.3 cm apart at 2 m, so that 4 cm odometry cells hold enough) tracked
// against maps that hold only part of what the last frame saw.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "map_test_util.hpp"
#include "sogmm/map_tracking.hpp"
#include "sogmm/model.hpp"
#include "tracking_odometry.hpp"

namespace {

using namespace sogmm_test;
using sogmm::PoseSource;
using sogmm::RegistrationResult;
using sogmm::RegistrationStatus;

RegistrationResult result(RegistrationStatus status, double inliers) {
  RegistrationResult r;
  r.status = status;
  r.inlier_ratio = inliers;
  return r;
}

TEST(MapTracking, DecidePoseFollowsTheRule) {
  const sogmm::RegistrationOptions reg;  // min_inlier_ratio 0.5
  const sogmm::TrackingOptions opt;      // max_disagreement 0.02
  const RegistrationResult odo = result(RegistrationStatus::Converged, 0.9);
  const RegistrationResult odo_bad = result(RegistrationStatus::NotConverged, 0.9);
  const RegistrationResult conv = result(RegistrationStatus::Converged, 0.9);
  const RegistrationResult degen = result(RegistrationStatus::Degenerate, 0.9);
  const RegistrationResult low = result(RegistrationStatus::LowFitness, 0.3);
  const RegistrationResult stuck = result(RegistrationStatus::NotConverged, 0.9);
  const RegistrationResult stuck_few = result(RegistrationStatus::NotConverged, 0.3);
  // The map's own verdict first; odometry never vetoes it.
  EXPECT_EQ(sogmm::decide_pose(conv, nullptr, 0.0, reg, opt), PoseSource::Map);
  EXPECT_EQ(sogmm::decide_pose(conv, &odo, 1.0, reg, opt), PoseSource::Map);
  // Without a converged odometry nothing else is inserted.
  for (const RegistrationResult* m : {&degen, &low, &stuck})
    for (const RegistrationResult* o : {static_cast<const RegistrationResult*>(nullptr), &odo_bad})
      EXPECT_EQ(sogmm::decide_pose(*m, o, 0.0, reg, opt), PoseSource::None);
  // They agree (the bound itself agrees).
  EXPECT_EQ(sogmm::decide_pose(degen, &odo, 0.02, reg, opt), PoseSource::Map);
  EXPECT_EQ(sogmm::decide_pose(low, &odo, 0.01, reg, opt), PoseSource::Odometry);
  EXPECT_EQ(sogmm::decide_pose(stuck, &odo, 0.01, reg, opt), PoseSource::Odometry);
  // They do not: only a map with too few inliers to judge yields.
  EXPECT_EQ(sogmm::decide_pose(degen, &odo, 0.0201, reg, opt), PoseSource::None);
  EXPECT_EQ(sogmm::decide_pose(stuck, &odo, 0.05, reg, opt), PoseSource::None);
  EXPECT_EQ(sogmm::decide_pose(low, &odo, 0.05, reg, opt), PoseSource::Odometry);
  EXPECT_EQ(sogmm::decide_pose(stuck_few, &odo, 0.05, reg, opt), PoseSource::Odometry);
}

TEST(MapTracking, RmsDisplacementHasItsClosedForms) {
  // Points on the circle of radius 2 about the z axis (and one on the axis).
  std::vector<float> p;
  for (int k = 0; k < 8; ++k) p.insert(p.end(), {float(2 * std::cos(k * 0.785)), float(2 * std::sin(k * 0.785)), 1.0f, 0.5f});
  const sogmm::PointsView v{p.data(), 8, false};
  // A translation moves every point by its length.
  EXPECT_NEAR(sogmm::detail::rms_displacement(v, kIdentity, translated(0.03)), 0.03, 1e-12);
  // A turn by a about z moves a point at radius r by 2 r sin(a / 2).
  const double a = 0.1, c = std::cos(a), s = std::sin(a);
  const Pose turn = {c, -s, 0, 0, s, c, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  EXPECT_NEAR(sogmm::detail::rms_displacement(v, turn, kIdentity), 2 * 2 * std::sin(a / 2), 1e-6);
  EXPECT_EQ(sogmm::detail::rms_displacement(v, turn, turn), 0.0);
}

enum Surfaces { kFloor = 1, kBack = 2, kSide = 4, kAll = 7 };
const sogmm::Camera kCamera{200, 150, 150, 150, 99.5, 74.5};

// The corner's points (camera frame; uniform gray, so that only geometry
// fixes a pose and a lone wall slides) seen from camera-to-world `pose`,
// keeping the surfaces in `keep`; every `step`-th pixel per axis.
std::vector<float> corner(const Pose& pose, int keep, int step = 1) {
  std::vector<float> out;
  for (int v = 0; v < kCamera.height; v += step)
    for (int u = 0; u < kCamera.width; u += step) {
      const double dc[3] = {(u - kCamera.cx) / kCamera.fx, (v - kCamera.cy) / kCamera.fy, 1.0};
      double d[3], o[3];
      for (int k = 0; k < 3; ++k) {
        d[k] = pose[4 * k] * dc[0] + pose[4 * k + 1] * dc[1] + pose[4 * k + 2] * dc[2];
        o[k] = pose[4 * k + 3];
      }
      const int axis[3] = {1, 2, 0};
      const double offset[3] = {0.6, 2.2, -0.9};
      double best = 1e30;
      int hit = -1;
      for (int k = 0; k < 3; ++k) {
        const double t = d[axis[k]] != 0 ? (offset[k] - o[axis[k]]) / d[axis[k]] : -1;
        if (t > 0 && t < best) best = t, hit = k;
      }
      if (hit < 0 || !(keep & (1 << hit))) continue;
      out.insert(out.end(), {float(best * dc[0]), float(best * dc[1]), float(best), 0.5f});
    }
  return out;
}

sogmm::PointsView view_of(const std::vector<float>& p) { return {p.data(), p.size() / 4, true}; }

// 2 degrees about y, 3 cm along x and 1 cm along z: the second frame's truth.
Pose moved() {
  const double a = 2.0 * 3.14159265358979 / 180, c = std::cos(a), s = std::sin(a);
  return {c, 0, s, 0.03, 0, 1, 0, 0, -s, 0, c, 0.01, 0, 0, 0, 1};
}

double translation_error(const Pose& a, const Pose& b) {
  return std::sqrt(std::pow(a[3] - b[3], 2) + std::pow(a[7] - b[7], 2) + std::pow(a[11] - b[11], 2));
}

// Odometry runs only with gray (the default; said here, as the tests are of it).
sogmm::RegistrationOptions gray() {
  sogmm::RegistrationOptions o;
  o.use_gray = true;
  return o;
}

sogmm::RegistrationOptions geometry_only() {
  sogmm::RegistrationOptions o;
  o.use_gray = false;
  return o;
}

MapOptions corner_options(double component_precision = 0) {
  MapOptions o;
  o.fit.bandwidth = 0.05;
  o.depth.decimate = 1;
  o.component_precision = component_precision;
  return o;
}

// The map holds only part of frame 0 (as after discard_pending or a frame
// whose surfaces were not all kept); the tracking state holds all of it.
struct PartialMap {
  Map map;
  sogmm::TrackingState state;
  explicit PartialMap(int kept, double component_precision = 0) : map(corner_options(component_precision)) {
    // The map's part at every 3rd pixel: its fit stays cheap.
    const std::vector<float> part = corner(kIdentity, kept, 3), whole = corner(kIdentity, kAll);
    map.insert_backprojected(view_of(part), kCamera, kIdentity);
    map.flush();
    state.cells = sogmm::detail::odometry_target(view_of(whole));
    state.pose = kIdentity;
    state.n_frames = map.frames().size();
  }
};

TEST(MapTracking, AFrameTheMapCannotJudgeIsPosedByOdometry) {
  // The map holds the floor and the side wall (about 40% of the next view):
  // the next frame has too few inliers there; against frame 0 it converges.
  PartialMap m(kFloor | kSide);
  const std::vector<float> next = corner(moved(), kAll);
  const sogmm::TrackedFrame t =
      sogmm::track_backprojected(m.map, m.state, view_of(next), kCamera, kIdentity, gray(), {}, 1);
  EXPECT_TRUE(t.odometry_ran);
  EXPECT_LT(t.registration.inlier_ratio, 0.5);
  EXPECT_EQ(t.odometry.status, RegistrationStatus::Converged);
  ASSERT_TRUE(t.inserted);
  EXPECT_EQ(t.source, PoseSource::Odometry);
  // Noise-free planes through cells of 4 cm: within 5 mm of the truth.
  EXPECT_LT(translation_error(t.pose, moved()), 0.005);
  EXPECT_EQ(m.map.frames().size(), 2u);
  EXPECT_EQ(m.map.frames().back().pose, t.pose);
  // The state now holds the inserted frame.
  EXPECT_EQ(m.state.pose, t.pose);
  EXPECT_EQ(m.state.n_frames, 2u);
  // Without odometry the same frame is skipped.
  PartialMap off(kFloor | kSide);
  sogmm::TrackingOptions no;
  no.odometry = false;
  const sogmm::TrackedFrame u = sogmm::track_backprojected(off.map, off.state, view_of(next), kCamera, kIdentity, gray(), no, 1);
  EXPECT_FALSE(u.inserted || u.odometry_ran);
  EXPECT_EQ(off.map.frames().size(), 1u);
  // Nor does odometry run without gray (the same map: the skip changed nothing).
  const sogmm::TrackedFrame w =
      sogmm::track_backprojected(off.map, off.state, view_of(next), kCamera, kIdentity, geometry_only(), {}, 1);
  EXPECT_FALSE(w.inserted || w.odometry_ran);
  EXPECT_EQ(off.map.frames().size(), 1u);
}

TEST(MapTracking, TheStateHoldsThePoseAsTheMapRecordedIt) {
  // With component_precision > 0 the map records poses on a 2^-16 grid
  // (component_precision.hpp): the state must hold that pose, not the
  // estimate, or the odometry's "state holds the map's last frame" test
  // fails from the next frame on and odometry never runs again.
  PartialMap m(kFloor | kSide, 0.1);
  const std::vector<float> next = corner(moved(), kAll);
  const sogmm::TrackedFrame t =
      sogmm::track_backprojected(m.map, m.state, view_of(next), kCamera, kIdentity, gray(), {}, 1);
  ASSERT_TRUE(t.inserted);
  EXPECT_EQ(m.state.pose, m.map.frames().back().pose);
  // The estimate itself is off the grid (so the case is exercised), by at
  // most half a grid step per entry.
  EXPECT_NE(t.pose, m.map.frames().back().pose);
  for (int i = 0; i < 12; ++i) EXPECT_LE(std::fabs(t.pose[i] - m.map.frames().back().pose[i]), std::ldexp(1.0, -17));
}

TEST(MapTracking, AFrameThatAgreesWithNeitherIsSkipped) {
  // The map holds the back wall only (about 60% of the next view: enough
  // inliers to judge, but uniform gray lets it slide in its plane:
  // Degenerate; started at the true pose it slid 5.6 cm along the wall,
  // measured with a truthful record). The odometry's last frame is recorded at the identity but was
  // seen from 5 cm to the left: its converged pose is off too. The two
  // disagree, so the frame is skipped and nothing changes.
  PartialMap m(kBack);
  m.state.cells = sogmm::detail::odometry_target(view_of(corner(translated(-0.05), kAll)));
  const std::vector<float> next = corner(moved(), kAll);
  const sogmm::TrackedFrame t = sogmm::track_backprojected(m.map, m.state, view_of(next), kCamera, moved(), gray(), {}, 1);
  EXPECT_EQ(t.registration.status, RegistrationStatus::Degenerate);
  EXPECT_GE(t.registration.inlier_ratio, 0.5);
  ASSERT_TRUE(t.odometry_ran);
  EXPECT_EQ(t.odometry.status, RegistrationStatus::Converged);
  EXPECT_GT(t.disagreement, 0.03);
  EXPECT_FALSE(t.inserted);
  EXPECT_EQ(t.source, PoseSource::None);
  EXPECT_EQ(m.map.frames().size(), 1u);
  EXPECT_EQ(m.state.pose, kIdentity);  // the state keeps the last inserted frame
}

}  // namespace
