// The automatic reg_covar (issue 14): floors from the data's spatial and gray
// scales, checked against hand-computed clouds, exact decade scaling, the
// shared room frames (where it must be the paper's 1e-6 and leave the fit
// bit for bit as an explicit 1e-6), and the bypass by an explicit value.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "sogmm/em.hpp"
#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/kmeanspp.hpp"
#include "sogmm/reg_covar.hpp"
#include "test_util.hpp"

namespace {

sogmm::PointsView view(const std::vector<float>& p) { return {p.data(), p.size() / 4}; }

// 37 points: the origin and, for each radius r, the six points at +-r on the
// x, y and z axes (x `scale`), with gray stepping through 7 levels that span
// [gray_lo, gray_hi] exactly. The coordinate-wise lower median is the origin,
// so the median distance is the lower median of the radii: sorted, the
// distances are 0, six each of 0.2 and 0.5, twelve of 0.9, six each of 1.2 and
// 2.0; element 18 is 0.9 (x scale). In 4-D the points are at least 0.2 x scale
// or (gray_hi - gray_lo) / 6 apart.
std::vector<float> star(double scale, double gray_lo, double gray_hi) {
  const double radii[] = {0.2, 0.5, 0.9, 0.9, 1.2, 2.0};
  std::vector<float> p;
  int i = 0;
  for (double r : radii)
    for (int axis = 0; axis < 3; ++axis)
      for (double sign : {-1.0, 1.0}) {
        float xyz[3] = {0.f, 0.f, 0.f};
        xyz[axis] = static_cast<float>(sign * r * scale);
        const double g = gray_lo + (gray_hi - gray_lo) * (i++ % 7) / 6.0;  // spans [lo, hi] exactly
        p.insert(p.end(), {xyz[0], xyz[1], xyz[2], static_cast<float>(g)});
      }
  p.insert(p.end(), {0.f, 0.f, 0.f, static_cast<float>(gray_lo)});  // an odd count: one centre point
  return p;
}

// The same set of points with every coordinate scaled by `s` exactly.
std::vector<float> scaled_xyz(std::vector<float> p, float s) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (i % 4 != 3) p[i] *= s;
  return p;
}

}  // namespace

// Hand-computed: 37 points, the coordinate-wise median is the origin; sorted
// distances are 0, then 6 each of 0.2, 0.5, 0.9, 0.9, 1.2, 2.0; the lower
// median (index 18) is 0.9 -> 10^0 -> 1e-6 m^2. Gray spans [0, 1] -> 1e-6.
TEST(RegCovarAuto, RoomScaleCloudGetsExactlyThePapersValue) {
  const sogmm::RegCovarFloors f = sogmm::auto_reg_covar(view(star(1.0, 0.0, 1.0)));
  EXPECT_TRUE(f.automatic);
  EXPECT_EQ(f.spatial, 1e-6);
  EXPECT_EQ(f.gray, 1e-6);
}

// Scaling x, y, z by 10 moves the median distance one decade: the spatial
// floor is exactly 100 times larger each time (closed form 1e-6 x 100^k, the
// same doubles as the literals), and gray keeps its own floor.
TEST(RegCovarAuto, FloorsScaleExactlyBy100PerDecade) {
  const std::vector<float> base = star(1.0, 0.0, 1.0);
  const struct {
    float s;
    double spatial;
  } cases[] = {{10.f, 1e-4}, {100.f, 1e-2}, {1000.f, 1.0}, {1e4f, 1e2}, {0.1f, 1e-8}, {0.01f, 1e-10}};
  for (const auto& c : cases) {
    SCOPED_TRACE("s = " + std::to_string(c.s));
    const sogmm::RegCovarFloors f = sogmm::auto_reg_covar(view(scaled_xyz(base, c.s)));
    EXPECT_EQ(f.spatial, c.spatial);
    EXPECT_EQ(f.gray, 1e-6);
  }
}

// The decade rules at their edges: the spatial size rounds to the nearest
// decade on a log scale (0.9 m x 3.5 = 3.15 < 10^0.5 stays at 10^0; x 3.6 =
// 3.24 moves to 10^1); the gray range takes the smallest power of ten not
// below it (exactly 1 -> 10^0, and 1 + 1e-7 too, float rounding; 1 + 1e-5 and
// 1.25 -> 10^1; 0.0625 -> 10^-1; 0.125 -> 10^0).
TEST(RegCovarAuto, DecadeRulesAtTheirEdges) {
  EXPECT_EQ(sogmm::auto_reg_covar(view(scaled_xyz(star(1.0, 0.0, 1.0), 3.5f))).spatial, 1e-6);
  EXPECT_EQ(sogmm::auto_reg_covar(view(scaled_xyz(star(1.0, 0.0, 1.0), 3.6f))).spatial, 1e-4);
  EXPECT_EQ(sogmm::auto_reg_covar(view(star(1.0, 0.0, 1.25))).gray, 1e-4);
  EXPECT_EQ(sogmm::auto_reg_covar(view(star(1.0, 0.0, 1.0000001))).gray, 1e-6);  // float rounding above 1
  EXPECT_EQ(sogmm::auto_reg_covar(view(star(1.0, 0.0, 1.00001))).gray, 1e-4);
  EXPECT_EQ(sogmm::auto_reg_covar(view(star(1.0, 0.5, 0.5625))).gray, 1e-8);  // range 0.0625
  EXPECT_EQ(sogmm::auto_reg_covar(view(star(1.0, 0.5, 0.625))).gray, 1e-6);   // range 0.125
  EXPECT_EQ(sogmm::auto_reg_covar(view(star(1.0, 0.5, 0.5))).gray, 1e-6);     // constant gray: 10^0
}

namespace {
// `gray.size()` points on a 1 cm grid 100 points wide at z = 1, with the given gray.
std::vector<float> grid_with_gray(const std::vector<float>& gray) {
  std::vector<float> p;
  for (std::size_t i = 0; i < gray.size(); ++i)
    p.insert(p.end(), {0.01f * static_cast<float>(i % 100), 0.01f * static_cast<float>(i / 100), 1.f, gray[i]});
  return p;
}
}  // namespace

// Issue 36: one out-of-range pixel (gray 1000 in a GRAY_F32 frame of gray in
// [0, 1], 12,288 points) set the gray floor of every component to 1 (range
// 1000 -> 10^3); the gray scale is now the spread between the 1% and 99%
// quantiles, so the floor stays 1e-6, the frame's own. Gray in [0, 255] with
// one pixel of 1e5 keeps its own floor, 1, likewise.
TEST(RegCovarAuto, OneOutOfRangePixelDoesNotSetTheGrayFloor) {
  std::vector<float> gray(12288);
  for (std::size_t i = 0; i < gray.size(); ++i) gray[i] = static_cast<float>((i * 37) % 256) / 255.f;
  EXPECT_EQ(sogmm::auto_reg_covar(view(grid_with_gray(gray))).gray, 1e-6);
  gray[5000] = 1000.f;
  EXPECT_EQ(sogmm::auto_reg_covar(view(grid_with_gray(gray))).gray, 1e-6);
  gray[7] = -1000.f;  // one at each end
  EXPECT_EQ(sogmm::auto_reg_covar(view(grid_with_gray(gray))).gray, 1e-6);
  for (float& g : gray) g *= 255.f;
  gray[5000] = 1e5f;
  gray[7] = 0.f;
  EXPECT_EQ(sogmm::auto_reg_covar(view(grid_with_gray(gray))).gray, 1.0);
}

// The rule at its edge, hand-computed: 1001 points, so the 1% quantile is
// order statistic floor(0.01 x 1000) = 10 (0-based) from each end. Ten
// points at each of 0 and 1000 around 981 in [0.5, 0.5625] leave the spread
// 0.0625 -> 10^-1 -> 1e-8; an eleventh point at 1000 is order statistic 990,
// the spread becomes 999.5 -> 10^3 -> 1. When more than 98% of the points
// share one gray (spread 0), the full range decides, as for a constant gray.
TEST(RegCovarAuto, GrayQuantileSpreadAtItsEdges) {
  std::vector<float> gray(1001);
  for (std::size_t i = 0; i < 981; ++i) gray[i] = 0.5f + 0.0625f * static_cast<float>(i) / 980.f;
  for (std::size_t i = 981; i < 991; ++i) gray[i] = 0.f;
  for (std::size_t i = 991; i < 1001; ++i) gray[i] = 1000.f;
  EXPECT_EQ(sogmm::auto_reg_covar(view(grid_with_gray(gray))).gray, 1e-8);
  gray[980] = 1000.f;
  EXPECT_EQ(sogmm::auto_reg_covar(view(grid_with_gray(gray))).gray, 1.0);
  std::vector<float> flat(1001, 0.5f);
  flat[3] = 0.f;
  flat[4] = 1000.f;
  EXPECT_EQ(sogmm::auto_reg_covar(view(grid_with_gray(flat))).gray, 1.0);
}

// Gray scaled by 1000 with the geometry unchanged gets its own floor (range
// 1000 -> 10^3 -> 1e-6 x 100^3 = 1); the spatial floor does not move. With one
// component per point (every point at least 0.2 m = 200 spatial or 167 gray
// standard deviations from any other, so the responsibilities are exactly
// one-hot) each covariance is exactly the floors: diag(1e-6, 1e-6, 1e-6, 1).
TEST(RegCovarAuto, GrayScaledBy1000GetsItsOwnFloor) {
  std::vector<float> p = star(1.0, 0.0, 1.0);
  for (std::size_t i = 3; i < p.size(); i += 4) p[i] *= 1000.f;
  const sogmm::RegCovarFloors f = sogmm::auto_reg_covar(view(p));
  EXPECT_EQ(f.spatial, 1e-6);
  EXPECT_EQ(f.gray, 1.0);
  std::vector<std::size_t> every(p.size() / 4);
  for (std::size_t i = 0; i < every.size(); ++i) every[i] = i;
  sogmm::EmOptions o;
  o.max_iter = 3;
  sogmm::EmReport r;
  const sogmm::Gmm g = sogmm::fit_em(view(p), every, o, &r);
  EXPECT_EQ(r.reg_covar.gray, 1.0);
  EXPECT_EQ(r.reg_covar.spatial, 1e-6);
  ASSERT_TRUE(sogmm_test::model_is_valid(g));
  for (std::size_t k = 0; k < g.size(); ++k)
    for (int i = 0; i < 16; ++i)
      ASSERT_EQ(g.covariances[16 * k + i], i == 15 ? 1.0f : (i % 5 == 0 ? 1e-6f : 0.0f))
          << "component " << k << ", entry " << i;
}

// An explicit value bypasses the rule: on all four diagonals, as given, even
// where auto would pick another; and an explicit 1e-6 on a room-sized cloud
// gives the very model the automatic default gives.
TEST(RegCovarAuto, ExplicitValueBypassesAuto) {
  const std::vector<float> km = scaled_xyz(star(1.0, 0.0, 1.0), 1000.f);
  sogmm::EmOptions o;
  o.reg_covar = 1e-4;
  sogmm::EmReport r;
  sogmm::fit_em(view(km), sogmm::kmeanspp_seeds(view(km), 3, 0), o, &r);
  EXPECT_FALSE(r.reg_covar.automatic);
  EXPECT_EQ(r.reg_covar.spatial, 1e-4);
  EXPECT_EQ(r.reg_covar.gray, 1e-4);
  o.reg_covar = 0.0;  // zero is a value, not "auto"
  sogmm::fit_em(view(km), sogmm::kmeanspp_seeds(view(km), 3, 0), o, &r);
  EXPECT_EQ(r.reg_covar.spatial, 0.0);
  EXPECT_EQ(r.reg_covar.gray, 0.0);

  const std::vector<float> room = star(1.0, 0.0, 1.0);
  sogmm::FitOptions fo;
  fo.n_components = 5;
  const sogmm::FitResult automatic = sogmm::fit(view(room), fo);
  fo.em.reg_covar = 1e-6;
  const sogmm::FitResult explicit_value = sogmm::fit(view(room), fo);
  EXPECT_TRUE(automatic.em.reg_covar.automatic);
  EXPECT_FALSE(explicit_value.em.reg_covar.automatic);
  EXPECT_TRUE(sogmm_test::bit_identical(automatic.gmm, explicit_value.gmm));
  EXPECT_EQ(automatic.em.log_likelihood, explicit_value.em.log_likelihood);
}

TEST(RegCovarAuto, NegativeOrNonFiniteValuesAreRefused) {
  const std::vector<float> room = star(1.0, 0.0, 1.0);
  for (double bad : {-1e-6, -1.0, std::nan(""), HUGE_VAL, -HUGE_VAL}) {
    sogmm::EmOptions o;
    o.reg_covar = bad;
    try {
      sogmm::fit_em(view(room), {0, 1}, o);
      ADD_FAILURE() << "reg_covar " << bad << " was accepted";
    } catch (const sogmm::Error& e) {
      EXPECT_EQ(e.code(), sogmm::ErrorCode::InvalidArgument);
      EXPECT_NE(std::string(e.what()).find("reg_covar"), std::string::npos) << e.what();
    }
  }
}
