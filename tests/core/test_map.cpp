// The incremental map (sogmm/map.hpp): append-everything equivalence,
// novelty, fusion, bad input, export and provenance round trip.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

#include "sogmm/inference.hpp"
#include "sogmm/map.hpp"
#include "sogmm/shortest_decimal.hpp"
#include "sogmm/warm_start.hpp"
#include "map_test_util.hpp"

namespace {
using namespace sogmm_test;

// Rotation about y by `angle` and translation t (a camera turning and moving).
Pose pose_y(double angle, double tx, double ty, double tz) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c, 0, s, tx, 0, 1, 0, ty, -s, 0, c, tz, 0, 0, 0, 1};
}

// A camera-frame frame of n points on two textured planar patches (a wall at
// z ~ 1.5 m and a floor strip), 2 mm depth noise, offset by `shift` along x.
std::vector<float> make_frame(std::size_t n, std::uint64_t seed, double shift = 0.0) {
  TestRng rng(seed);
  std::vector<float> p;
  for (std::size_t i = 0; i < n; ++i) {
    double x, y, z;
    if (i % 3 == 2) {  // floor: y = 0.4, z in [1, 1.5]
      x = shift + 0.6 * rng.uniform() - 0.3;
      z = 1.0 + 0.5 * rng.uniform();
      y = 0.4 + 0.002 * rng.normal();
    } else {  // wall
      x = shift + 0.6 * rng.uniform() - 0.3;
      y = 0.6 * rng.uniform() - 0.2;
      z = 1.5 + 0.002 * rng.normal();
    }
    const double gray = 0.5 + 0.3 * std::sin(8.0 * (x - shift)) + 0.02 * rng.normal();
    p.insert(p.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(gray)});
  }
  return p;
}

sogmm::PointsView view(const std::vector<float>& p) { return {p.data(), p.size() / 4}; }

MapOptions options(bool novelty, bool fusion) {
  MapOptions o;
  o.novelty = novelty;
  o.fusion = fusion;
  o.batch_size = 100000;  // flushes are explicit in these tests
  o.fit.em.threads = 2;
  return o;
}

// The points moved to the world frame (rows of 4 floats).
std::vector<float> to_world(const std::vector<float>& p, const Pose& pose) {
  std::vector<float> w(p);
  for (std::size_t i = 0; i < p.size(); i += 4)
    for (int r = 0; r < 3; ++r)
      w[i + r] = static_cast<float>(pose[4 * r] * p[i] + pose[4 * r + 1] * p[i + 1] + pose[4 * r + 2] * p[i + 2] +
                                    pose[4 * r + 3]);
  return w;
}

// Mixture mean and covariance (4-D) of a model, in double.
void total_moments(const sogmm::Gmm& g, Eigen::Vector4d* mean, Eigen::Matrix4d* cov) {
  *mean = Eigen::Vector4d::Zero();
  for (std::size_t k = 0; k < g.size(); ++k) *mean += g.weights[k] * mean_of(g, k);
  *cov = Eigen::Matrix4d::Zero();
  for (std::size_t k = 0; k < g.size(); ++k) {
    const Eigen::Vector4d d = mean_of(g, k) - *mean;
    *cov += g.weights[k] * (cov_of(g, k) + d * d.transpose());
  }
}

TEST(MapTest, NoveltyAndFusionOffReproduceAppendEverything) {
  const std::vector<std::vector<float>> frames = {make_frame(2000, 1), make_frame(2400, 2, 0.5),
                                                  make_frame(1800, 3, -0.4)};
  const std::vector<Pose> poses = {kIdentity, pose_y(0.3, 0.2, 0.0, -0.1), pose_y(-0.5, -0.3, 0.05, 0.2)};
  MapOptions o = options(false, false);
  o.batch_size = 12288;  // novelty off: every insert fits its own frame whatever the batch size
  Map map(o);
  sogmm::Model expected;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const sogmm::FrameStats s = map.insert_points(view(frames[f]), poses[f]);
    EXPECT_TRUE(s.flushed);
    EXPECT_EQ(s.n_novel, s.n_points);
    // What `sogmm fit --sequence` does per frame: fit, move, merge.
    sogmm::FitResult r = sogmm::fit(view(frames[f]), o.fit);
    sogmm::Model world;
    world.gmm = sogmm::transform(r.gmm, poses[f]);
    world.fit.known = true;
    world.fit.bandwidth = o.fit.bandwidth;
    world.fit.tol = o.fit.em.tol;
    world.fit.reg_covar = r.em.reg_covar.spatial;
    world.fit.max_iter = o.fit.em.max_iter;
    world.fit.n_iter = r.em.iterations;
    world.fit.converged = r.em.converged;
    world.fit.log_likelihood = r.em.log_likelihood;
    world.key_values = {{sogmm::kCoordinateFrameKey, "world"}};
    expected = f == 0 ? world : sogmm::merge(expected, world);
    EXPECT_EQ(s.n_components, expected.gmm.size());
  }
  const sogmm::Model& got = map.model();
  EXPECT_EQ(got.gmm.weights, expected.gmm.weights);
  EXPECT_EQ(got.gmm.means, expected.gmm.means);
  EXPECT_EQ(got.gmm.covariances, expected.gmm.covariances);
  EXPECT_EQ(got.gmm.support_size, expected.gmm.support_size);
  EXPECT_EQ(got.fit.n_iter, expected.fit.n_iter);
  EXPECT_EQ(got.fit.log_likelihood, expected.fit.log_likelihood);
  EXPECT_EQ(got.key_values, expected.key_values);
  EXPECT_EQ(map.stats().n_flushes, 3u);
  EXPECT_EQ(map.pending(), 0u);
}

// The inverse of a rigid pose: (R^T, -R^T t), computed here independently of
// the map's own.
Pose inverse_of(const Pose& p) {
  Pose q{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) q[4 * r + c] = p[4 * c + r];
    q[4 * r + 3] = -(p[r] * p[3] + p[4 + r] * p[7] + p[8 + r] * p[11]);
  }
  q[15] = 1;
  return q;
}

// MapOptions::warm_start with novelty off: the first frame is a cold fit, each
// later one fit_warm from the previous fit moved from its camera into this
// frame's (world <- previous camera, then this camera <- world).
// Three overlapping frames of a slowly turning camera, and warm-start
// append-everything options.
struct WarmSequence {
  std::vector<std::vector<float>> frames = {make_frame(2000, 1), make_frame(2000, 2, 0.1), make_frame(2000, 3, 0.2)};
  std::vector<Pose> poses = {kIdentity, pose_y(0.05, 0.02, 0.0, 0.0), pose_y(0.1, 0.04, 0.0, 0.01)};
  MapOptions o = [] {
    MapOptions w = options(false, false);
    w.warm_start = true;
    return w;
  }();
};

TEST(MapTest, WarmStartFitsEachFrameFromThePreviousOne) {
  const auto& [frames, poses, o] = WarmSequence();
  Map map(o);
  sogmm::Gmm previous;
  std::vector<float> expected_means;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    map.insert_points(view(frames[f]), poses[f]);
    const sogmm::FitResult r =
        f == 0 ? sogmm::fit(view(frames[f]), o.fit)
               : sogmm::fit_warm(view(frames[f]),
                                 sogmm::transform(sogmm::transform(previous, poses[f - 1]), inverse_of(poses[f])),
                                 o.fit);
    previous = r.gmm;
    const sogmm::Gmm world = sogmm::transform(r.gmm, poses[f]);
    expected_means.insert(expected_means.end(), world.means.begin(), world.means.end());
  }
  // The map's means are the frames' world-frame means, appended in order
  // (the same arithmetic, so bitwise).
  EXPECT_EQ(map.model().gmm.means, expected_means);

  MapOptions runs = o;
  runs.fit.n_init = 2;
  EXPECT_THROW({ Map bad(runs); }, sogmm::Error);
}

// A saved warm-start map records warm_start, and once loaded its first fit
// warm-starts from the last saved fit (recovered from the per-frame
// component counts): nearly the fit the unsaved map makes, not a cold one.
TEST(MapTest, WarmStartSurvivesSaveAndLoad) {
  const auto& [frames, poses, o] = WarmSequence();
  Map map(o);
  map.insert_points(view(frames[0]), poses[0]);
  map.insert_points(view(frames[1]), poses[1]);
  const sogmm::Model saved = map.to_model();
  std::string recorded;
  for (const auto& kv : saved.key_values)
    if (kv.first == sogmm::kMapOptionsKey) recorded = kv.second;
  EXPECT_NE(recorded.find("warm_start=1"), std::string::npos) << recorded;
  // Numbers in their shortest round-trip form (fusion_threshold 0.3, not 0.29999999999999999).
  EXPECT_NE(recorded.find(" fusion_threshold=" + sogmm::shortest_decimal(o.fusion_threshold) + " "), std::string::npos)
      << recorded;
  EXPECT_EQ(recorded.find("99999"), std::string::npos) << recorded;
  Map loaded = Map::from_model(saved, o);
  const std::size_t m = map.size();
  map.insert_points(view(frames[2]), poses[2]);
  loaded.insert_points(view(frames[2]), poses[2]);
  // The third frame's block, warm from the map before the save and after the load.
  const sogmm::Gmm& a = map.model().gmm;
  const sogmm::Gmm& b = loaded.model().gmm;
  ASSERT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (std::size_t i = 4 * m; i < a.means.size(); ++i) worst = std::max(worst, std::fabs(double(a.means[i]) - b.means[i]));
  EXPECT_LT(worst, 1e-3);
  // Without the restore the load would fit the frame cold: a different fit.
  MapOptions cold_options = o;
  cold_options.warm_start = false;
  Map cold = Map::from_model(saved, cold_options);
  cold.insert_points(view(frames[2]), poses[2]);
  const sogmm::Gmm& c = cold.model().gmm;
  double cold_worst = 0.0;
  if (c.size() == a.size())
    for (std::size_t i = 4 * m; i < a.means.size(); ++i)
      cold_worst = std::max(cold_worst, std::fabs(double(a.means[i]) - c.means[i]));
  EXPECT_TRUE(c.size() != a.size() || cold_worst > 10 * worst) << cold_worst << " vs " << worst;
}

TEST(MapTest, ReinsertingAFrameAddsAlmostNothingANewRegionAdds) {
  const std::vector<float> frame = make_frame(3000, 5);
  const Pose pose = pose_y(0.2, 0.1, 0.0, 0.3);
  Map map(options(true, false));
  const sogmm::FrameStats first = map.insert_points(view(frame), pose);
  EXPECT_EQ(first.n_novel, first.n_points);  // empty map: everything is new
  EXPECT_EQ(map.pending(), 3000u);
  map.flush();
  const std::size_t m1 = map.size();
  ASSERT_GT(m1, 2u);

  // The same frame at the same pose: the map already explains it.
  const sogmm::FrameStats again = map.insert_points(view(frame), pose);
  EXPECT_LT(again.n_novel, again.n_points / 50) << again.n_novel << " of " << again.n_points << " novel";
  map.flush();
  EXPECT_LE(map.size(), m1 + m1 / 10);

  // A fresh draw of the same surfaces: mostly explained (what is novel lies in
  // the thin tails of the noise and at the patch borders: 8 % here).
  const sogmm::FrameStats redraw = map.insert_points(view(make_frame(3000, 6)), pose);
  EXPECT_LT(redraw.n_novel, redraw.n_points / 8);

  // A region 3 m away: all of it is novel and it adds components.
  const std::size_t m2 = map.size();
  const sogmm::FrameStats elsewhere = map.insert_points(view(frame), pose_y(0.2, 3.1, 0.0, 0.3));
  EXPECT_EQ(elsewhere.n_novel, elsewhere.n_points);
  map.flush();
  EXPECT_GE(map.size(), m2 + m1 / 2);
  EXPECT_EQ(map.frames().size(), 4u);
}

// Points waiting for a fit count as mapped: the same frame again before a
// flush adds nothing, a fresh draw of the pending surfaces little, a new
// region everything.
TEST(MapTest, PendingPointsAreNotNovelAgain) {
  const std::vector<float> frame = make_frame(3000, 5);
  const Pose pose = pose_y(0.2, 0.1, 0.0, 0.3);
  Map map(options(true, false));  // batch 100000: nothing is fitted until flush()
  EXPECT_EQ(map.insert_points(view(frame), pose).n_novel, 3000u);
  const sogmm::FrameStats again = map.insert_points(view(frame), pose);
  EXPECT_EQ(again.n_novel, 0u);
  EXPECT_EQ(map.pending(), 3000u);
  EXPECT_EQ(map.size(), 0u);
  // Another draw of the same surfaces (2 mm noise, points 1.3-1.7 cm apart
  // at random): all within a voxel of a pending point but those in the rare
  // gaps of the first draw and at the patch borders (2.5 % here).
  const sogmm::FrameStats redraw = map.insert_points(view(make_frame(3000, 6)), pose);
  EXPECT_LT(redraw.n_novel, redraw.n_points / 25) << redraw.n_novel << " novel";
  // A region 3 m away: all new, and pending as well from now on.
  const Pose far = pose_y(0.2, 3.1, 0.0, 0.3);
  EXPECT_EQ(map.insert_points(view(frame), far).n_novel, 3000u);
  EXPECT_EQ(map.insert_points(view(frame), far).n_novel, 0u);
  EXPECT_EQ(map.pending(), 6000u + redraw.n_novel);
  // After the flush the map itself explains them.
  map.flush();
  EXPECT_EQ(map.pending(), 0u);
  const sogmm::FrameStats after = map.insert_points(view(frame), pose);
  EXPECT_LT(after.n_novel, after.n_points / 50) << after.n_novel << " novel";
}

// The novelty score of a point renormalises the weights over the components
// whose box holds it, so it is the same whatever else the map holds or the
// query asks: for a point near one component alone it is that component's 3-D
// log-density, whatever its weight.
TEST(MapTest, NoveltyScoreIsLocalToEachPoint) {
  sogmm::Model m;
  m.gmm.resize(2);
  m.gmm.weights = {0.9f, 0.1f};
  m.gmm.means = {0.0f, 0.0f, 1.0f, 0.5f, 2.0f, 0.0f, 1.0f, 0.5f};
  std::fill(m.gmm.covariances.begin(), m.gmm.covariances.end(), 0.0f);
  const float var0[4] = {4e-4f, 1e-4f, 9e-6f, 0.01f}, var1[4] = {1e-4f, 4e-4f, 4e-6f, 0.01f};
  for (int i = 0; i < 4; ++i) {
    m.gmm.covariances[5 * i] = var0[i];
    m.gmm.covariances[16 + 5 * i] = var1[i];
  }
  m.gmm.covariances[1] = m.gmm.covariances[4] = 5e-5f;  // a tilt in x-y for the first
  m.gmm.support_size = 1000;
  m.key_values = {{sogmm::kCoordinateFrameKey, "world"}};
  const Map map = Map::from_model(m, options(true, false));
  // Independent truth: log N(x | mu, Sigma_xx) by Eigen.
  auto log_n = [&](std::size_t k, const Eigen::Vector3d& x) {
    const Eigen::Matrix3d c = cov_of(m.gmm, k).topLeftCorner<3, 3>();
    const Eigen::Vector3d d = x - mean_of(m.gmm, k).head<3>();
    return -1.5 * std::log(2 * M_PI) - 0.5 * std::log(c.determinant()) - 0.5 * d.dot(c.ldlt().solve(d));
  };
  const double xyz[9] = {0.01, -0.005, 1.001, 2.0, 0.01, 0.998, 1.0, 0.0, 1.0};
  std::vector<double> both(3), one(1);
  map.local_log_likelihood(xyz, 3, both.data());
  EXPECT_NEAR(both[0], log_n(0, {xyz[0], xyz[1], xyz[2]}), 1e-4);
  EXPECT_NEAR(both[1], log_n(1, {xyz[3], xyz[4], xyz[5]}), 1e-4);
  EXPECT_EQ(both[2], -INFINITY);  // between them, in no box
  // The same point alone: the same score (the rest of the query is no part of it).
  map.local_log_likelihood(xyz + 3, 1, one.data());
  EXPECT_EQ(one[0], both[1]);
}

// With novelty on, a batch is fitted with the bandwidth times
// s + (1 - s) h^2, s = novelty_bandwidth_scale and h the share of the batch's
// point pairs that come from one frame (sum n_f^2 / N^2); with novelty off,
// each frame with the bandwidth. With identity poses a batch of frames is
// their points one after the other, so the map must hold exactly fit() of
// that cloud at that bandwidth. Hand-computed h: one frame 1; two frames of
// 3000 points 1/2.
TEST(MapTest, NovelPointsAreFittedWithTheScaledBandwidth) {
  const std::vector<float> a = make_frame(3000, 8), b = make_frame(3000, 9, 2.0);
  std::vector<float> both(a);
  both.insert(both.end(), b.begin(), b.end());
  for (double scale : {0.7, 1.0, 0.5}) {
    SCOPED_TRACE("scale " + std::to_string(scale));
    MapOptions o = options(true, false);
    o.novelty_bandwidth_scale = scale;
    sogmm::FitOptions f = o.fit;
    f.bandwidth = o.fit.bandwidth * (scale + (1 - scale) * 0.25);  // h = 1/2
    Map pooled(o);
    pooled.insert_points(view(a), kIdentity);
    pooled.insert_points(view(b), kIdentity);
    pooled.flush();
    const sogmm::FitResult want = sogmm::fit(view(both), f);
    ASSERT_EQ(pooled.size(), want.gmm.size());
    EXPECT_EQ(pooled.model().gmm.means, want.gmm.means);
    EXPECT_EQ(pooled.model().gmm.covariances, want.gmm.covariances);
    // One all-novel frame (h = 1), e.g. a map's first insert: the bandwidth
    // itself, as that frame's own fit.
    Map single(o);
    single.insert_points(view(a), kIdentity);
    single.flush();
    EXPECT_EQ(single.model().gmm.means, sogmm::fit(view(a), o.fit).gmm.means);
    // Novelty off (append everything): the bandwidth itself.
    o.novelty = false;
    Map append(o);
    append.insert_points(view(a), kIdentity);
    EXPECT_EQ(append.model().gmm.means, sogmm::fit(view(a), o.fit).gmm.means);
  }
  // The bandwidths give different mode counts here, so the test tells them
  // apart: the scale itself (0.7) and s + (1 - s) h^2 at h = 1/2 (0.775).
  // Other h (0.82, 0.1) are hand-checked in test_map_batch_bandwidth.cpp.
  sogmm::FitOptions f = options(true, false).fit;
  std::vector<std::size_t> k;
  for (double x : {0.7, 0.775}) {
    sogmm::FitOptions g = f;
    g.bandwidth = f.bandwidth * x;
    k.push_back(sogmm::fit(view(both), g).gmm.size());
  }
  EXPECT_NE(k[0], k[1]);
  const std::size_t k1 = sogmm::fit(view(both), f).gmm.size();
  f.bandwidth *= 0.5;
  EXPECT_LT(k1, sogmm::fit(view(both), f).gmm.size());
  // Out of (0, 1]: refused, naming the option.
  MapOptions o = options(true, false);
  for (double bad : {0.0, -0.5, 1.5, std::nan("")}) {
    o.novelty_bandwidth_scale = bad;
    EXPECT_THROW(
        try { Map m(o); } catch (const sogmm::Error& e) {
          EXPECT_NE(std::string(e.what()).find("novelty_bandwidth_scale"), std::string::npos) << e.what();
          throw;
        },
        sogmm::Error);
  }
}

TEST(MapTest, BatchSizeTriggersTheFlush) {
  MapOptions o = options(true, false);
  o.batch_size = 5000;
  Map map(o);
  const sogmm::FrameStats a = map.insert_points(view(make_frame(3000, 8)), kIdentity);
  EXPECT_FALSE(a.flushed);
  EXPECT_EQ(map.size(), 0u);
  // A second, disjoint region: 6000 pending points >= 5000, one fit of both.
  const sogmm::FrameStats b = map.insert_points(view(make_frame(3000, 9)), pose_y(0.0, 2.0, 0.0, 0.0));
  EXPECT_TRUE(b.flushed);
  EXPECT_EQ(map.pending(), 0u);
  EXPECT_GT(map.size(), 0u);
  EXPECT_EQ(map.model().gmm.support_size, 6000u);
  EXPECT_EQ(b.n_components, map.size());
  // The batch was fitted in the latest frame's camera frame and moved to the
  // world: the map explains both regions.
  std::vector<double> ll(2);
  const double xyz[6] = {0.0, 0.1, 1.5, 2.0, 0.1, 1.5};
  map.local_log_likelihood(xyz, 2, ll.data());
  EXPECT_GT(ll[0], 3.0);
  EXPECT_GT(ll[1], 3.0);
}

TEST(MapTest, FusionKeepsMomentsAndCostsLittleLikelihood) {
  // The same surfaces seen twice, 3 mm apart: with fusion the second frame's
  // components fold into the first's.
  const Pose p1 = kIdentity, p2 = pose_y(0.0, 0.003, 0.0, 0.0);
  for (sogmm::FusionMethod method : {sogmm::FusionMethod::Hellinger, sogmm::FusionMethod::KL}) {
    SCOPED_TRACE(method == sogmm::FusionMethod::Hellinger ? "Hellinger" : "KL");
    MapOptions fo = options(false, true);
    fo.fusion_method = method;
    fo.fusion_threshold = method == sogmm::FusionMethod::Hellinger ? 0.3 : 0.2;
    Map fused(fo);
    Map append(options(false, false));
    for (const Pose& p : {p1, p2}) {
      append.insert_points(view(make_frame(3000, 12)), p);
      fused.insert_points(view(make_frame(3000, 12)), p);
    }
    const sogmm::Gmm& a = append.model().gmm;
    const sogmm::Gmm& f = fused.model().gmm;
    EXPECT_LT(f.size(), a.size() * 3 / 4) << "fused " << fused.stats().n_fused << " of " << a.size();
    EXPECT_EQ(fused.stats().n_fused, a.size() - f.size());
    EXPECT_TRUE(model_is_valid(f));
    // Moment matching keeps the mixture's total mean and covariance.
    Eigen::Vector4d ma, mf;
    Eigen::Matrix4d ca, cf;
    total_moments(a, &ma, &ca);
    total_moments(f, &mf, &cf);
    EXPECT_LT((ma - mf).norm(), 1e-5);
    EXPECT_LT((ca - cf).norm(), 1e-5 * ca.norm());
    // The likelihood of the points (joint, 4-D) drops by little.
    const std::vector<float> pts = to_world(make_frame(3000, 13), p1);
    const double la = score(a, pts), lf = score(f, pts);
    EXPECT_GT(lf, la - 0.25) << "append " << la << ", fused " << lf;
    RecordProperty("loglik_append", std::to_string(la));
    RecordProperty("loglik_fused", std::to_string(lf));
    std::printf("fusion %s: %zu -> %zu components, mean log-likelihood %.4f -> %.4f\n",
                method == sogmm::FusionMethod::Hellinger ? "Hellinger" : "KL", a.size(), f.size(), la, lf);
  }
}

TEST(MapTest, BadInputIsRejectedAndLeavesTheMapUnchanged) {
  Map map(options(true, false));
  const std::vector<float> frame = make_frame(500, 21);
  map.insert_points(view(frame), kIdentity);
  const std::size_t pending = map.pending();
  Pose nan_pose = kIdentity;
  nan_pose[3] = std::nan("");
  expect_error([&] { map.insert_points(view(frame), nan_pose); }, ErrorCode::InvalidArgument, {"not finite"},
               "NaN pose");
  Pose scaled = kIdentity;
  scaled[0] = scaled[5] = scaled[10] = 2.0;
  expect_error([&] { map.insert_points(view(frame), scaled); }, ErrorCode::InvalidArgument, {"orthonormal"},
               "scaled pose");
  Pose mirror = kIdentity;
  mirror[0] = -1.0;
  expect_error([&] { map.insert_points(view(frame), mirror); }, ErrorCode::InvalidArgument, {"reflection"},
               "mirror pose");
  Pose last_row = kIdentity;
  last_row[14] = 0.5;
  expect_error([&] { map.insert_points(view(frame), last_row); }, ErrorCode::InvalidArgument, {"last row"},
               "projective pose");
  expect_error([&] { map.insert_points(sogmm::PointsView{frame.data(), 0}, kIdentity); }, ErrorCode::InvalidData,
               {"no point"}, "empty frame");
  std::vector<float> bad = frame;
  bad[41] = INFINITY;
  expect_error([&] { map.insert_points(view(bad), kIdentity); }, ErrorCode::InvalidData, {"finite"},
               "non-finite point");
  EXPECT_EQ(map.pending(), pending);
  EXPECT_EQ(map.frames().size(), 1u);

  // RGB-D: the first frame fixes the camera.
  sogmm::Camera cam{64, 48, 60.0, 60.0, 32.0, 24.0};
  std::vector<std::uint16_t> depth(64 * 48, 1500);
  std::vector<float> gray(64 * 48, 0.5f);
  map.insert_rgbd({depth.data(), gray.data(), cam}, kIdentity);
  sogmm::Camera other = cam;
  other.width = 32;
  expect_error([&] { map.insert_rgbd({depth.data(), gray.data(), other}, kIdentity); }, ErrorCode::InvalidArgument,
               {"differs"}, "frame of another size");
  std::vector<std::uint16_t> empty_depth(64 * 48, 0);
  expect_error([&] { map.insert_rgbd({empty_depth.data(), gray.data(), cam}, kIdentity); }, ErrorCode::InvalidData,
               {"no valid depth"}, "frame without a valid pixel");
  EXPECT_EQ(map.frames().size(), 2u);

  MapOptions o;
  o.batch_size = 0;
  expect_error([&] { Map m(o); }, ErrorCode::InvalidArgument, {"batch_size"}, "batch size 0");
  o = MapOptions();
  o.novelty_threshold = NAN;
  expect_error([&] { Map m(o); }, ErrorCode::InvalidArgument, {"novelty_threshold"}, "NaN threshold");
  o = MapOptions();
  o.fusion_threshold = 0;
  expect_error([&] { Map m(o); }, ErrorCode::InvalidArgument, {"fusion_threshold"}, "fusion threshold 0");
  Map empty(options(true, false));
  expect_error([&] { empty.model(); }, ErrorCode::InvalidData, {"no component"}, "empty map export");
}

TEST(MapTest, ExtractBoxHoldsTheComponentsWhoseBoxesMeetIt) {
  Map map(options(true, false));
  map.insert_points(view(make_frame(3000, 31)), kIdentity);
  map.insert_points(view(make_frame(3000, 32)), pose_y(0.0, 2.0, 0.0, 0.0));
  map.flush();
  sogmm::Box3 box;
  box.lo = {-0.5, -0.5, 0.5};
  box.hi = {0.5, 0.5, 2.0};
  const sogmm::Model part = map.extract(box);
  const sogmm::Gmm& all = map.model().gmm;
  std::size_t expected = 0;
  for (std::size_t k = 0; k < all.size(); ++k)
    expected += sogmm::component_box(all, k, 3.0).intersects(box) ? 1 : 0;
  EXPECT_EQ(part.gmm.size(), expected);
  EXPECT_LT(part.gmm.size(), all.size());
  EXPECT_TRUE(model_is_valid(part.gmm));
  EXPECT_EQ(sogmm::coordinate_frame(part), "world");
  EXPECT_NEAR(static_cast<double>(part.gmm.support_size), 3000.0, 300.0);
  sogmm::Box3 bad = box;
  bad.lo[1] = 1.0;
  expect_error([&] { map.extract(bad); }, ErrorCode::InvalidArgument, {"min <= max"}, "inverted box");
  sogmm::Box3 nowhere;
  nowhere.lo = {50, 50, 50};
  nowhere.hi = {51, 51, 51};
  expect_error([&] { map.extract(nowhere); }, ErrorCode::InvalidData, {"no component"}, "empty box");
}

TEST(MapTest, ProvenanceRoundTrip) {
  Map map(options(true, false));
  map.insert_points(view(make_frame(2000, 41)), kIdentity);
  map.insert_points(view(make_frame(2000, 42)), pose_y(0.4, 1.0, 0.0, 0.0));
  expect_error([&] { map.to_model(); }, ErrorCode::InvalidArgument, {"flush"}, "pending points");
  map.flush();
  const sogmm::Model saved = map.to_model();
  const Map loaded = Map::from_model(saved, options(true, false));
  EXPECT_EQ(loaded.model().gmm.means, map.model().gmm.means);
  EXPECT_EQ(loaded.model().gmm.weights, map.model().gmm.weights);
  ASSERT_EQ(loaded.frames().size(), 2u);
  for (std::size_t f = 0; f < 2; ++f) {
    EXPECT_EQ(loaded.frames()[f].pose, map.frames()[f].pose);
    EXPECT_EQ(loaded.frames()[f].n_points, map.frames()[f].n_points);
    EXPECT_EQ(loaded.frames()[f].n_novel, map.frames()[f].n_novel);
  }
  const double xyz[3] = {0.0, 0.1, 1.5};
  double a = 0, b = 0;
  map.local_log_likelihood(xyz, 1, &a);
  loaded.local_log_likelihood(xyz, 1, &b);
  EXPECT_EQ(a, b);
  // The saved model holds each provenance key once, also after a reload.
  const sogmm::Model again = loaded.to_model();
  std::size_t frames_keys = 0;
  for (const auto& kv : again.key_values) frames_keys += kv.first == sogmm::kMapFramesKey ? 1 : 0;
  EXPECT_EQ(frames_keys, 1u);

  sogmm::Model camera_frame = saved;
  camera_frame.key_values.clear();
  expect_error([&] { Map::from_model(camera_frame); }, ErrorCode::InvalidArgument, {"camera frame"},
               "camera-frame model");
  sogmm::Model broken = saved;
  for (auto& kv : broken.key_values)
    if (kv.first == sogmm::kMapFramesKey) kv.second = "0 10 5 1 0 0 0 0 1 0 0 0 0 1\n";
  expect_error([&] { Map::from_model(broken); }, ErrorCode::Format, {"map_frames"}, "truncated provenance");
}

}  // namespace

namespace {

// A world-frame model (support 3000) of three axis-aligned flat components
// on the plane z = 1.5 m, at x = x[k] (y = 0, gray 0.5) with weights w[k]:
// the first two with variances a (x, y, z, gray), the third with b.
sogmm::Model flat_components(const float (&x)[3], const float (&w)[3], const float (&a)[4], const float (&b)[4]) {
  sogmm::Model m;
  m.gmm.resize(3);
  m.gmm.weights = {w[0], w[1], w[2]};
  m.gmm.means = {x[0], 0.0f, 1.5f, 0.5f, x[1], 0.0f, 1.5f, 0.5f, x[2], 0.0f, 1.5f, 0.5f};
  std::fill(m.gmm.covariances.begin(), m.gmm.covariances.end(), 0.0f);
  for (int i = 0; i < 4; ++i) {
    m.gmm.covariances[5 * i] = m.gmm.covariances[16 + 5 * i] = a[i];
    m.gmm.covariances[32 + 5 * i] = b[i];
  }
  m.gmm.support_size = 3000;
  m.key_values = {{sogmm::kCoordinateFrameKey, "world"}};
  return m;
}

// A wall at z = 1.5 m drawn coarsely: two wide flat components at x = -0.5
// and 0.5 (sigma 0.3 m in x and y: about a fifth of each lies beyond the
// edges of RefitScene's view, |x| > 0.8 m, |y| > 0.6 m) and a small one far
// to the side (x = 5).
sogmm::Model coarse_wall() {
  return flat_components({-0.5f, 0.5f, 5.0f}, {0.4f, 0.4f, 0.2f}, {0.09f, 0.09f, 4e-6f, 0.04f},
                         {0.01f, 0.01f, 4e-6f, 0.04f});
}

// An RGB-D view of that wall (64 x 48, f = 60: |x| <= 0.8 m, |y| <= 0.6 m at
// 1.5 m) with gray stripes of 8 levels: a frame that has many more modes
// than the coarse map has components on it. An 8 x 8 pixel box at 1 m in a
// corner is new to the map (its points are novel).
struct RefitScene {
  sogmm::Camera cam{64, 48, 60.0, 60.0, 32.0, 24.0};
  std::vector<std::uint16_t> depth = std::vector<std::uint16_t>(64 * 48, 1500);
  std::vector<float> gray = std::vector<float>(64 * 48);
  explicit RefitScene(bool box = true) {
    for (int v = 0; v < 48; ++v)
      for (int u = 0; u < 64; ++u) {
        gray[64 * v + u] = static_cast<float>(((u / 4) % 8) / 8.0);
        if (box && u < 8 && v < 8) depth[64 * v + u] = 1000;
      }
  }
  sogmm::RgbdView frame() const { return {depth.data(), gray.data(), cam}; }
};

MapOptions refit_options(double ratio, int threads = 2) {
  MapOptions o = options(true, false);
  o.revisit_refit_ratio = ratio;
  o.fit.em.threads = threads;
  return o;
}

// Whether component k of `a` appears (bitwise mean and covariance) in `b`.
bool has_component(const sogmm::Gmm& b, const sogmm::Gmm& a, std::size_t k) {
  for (std::size_t j = 0; j < b.size(); ++j)
    if (std::equal(a.mean(k), a.mean(k) + 4, b.mean(j)) && std::equal(a.covariance(k), a.covariance(k) + 16, b.covariance(j)))
      return true;
  return false;
}

}  // namespace

TEST(MapTest, RevisitRefitReplacesWhatTheFrameSeesAndKeepsTheRest) {
  const sogmm::Model wall = coarse_wall();
  const RefitScene scene;
  Map map = Map::from_model(wall, refit_options(1.5));
  const double log_before_outside = [&] {
    const double x[3] = {1.0, 0.0, 1.5};  // on the wall, beyond the view's edge
    double ll = 0;
    map.local_log_likelihood(x, 1, &ll);
    return ll;
  }();
  const sogmm::FrameStats f = map.insert_rgbd(scene.frame(), kIdentity);
  // Both wall components are on the frame's surface; the far one is not.
  EXPECT_EQ(f.n_replaced, 2u);
  EXPECT_TRUE(f.flushed);  // a refit is a fit
  EXPECT_EQ(map.stats().n_refits, 1u);
  EXPECT_EQ(map.stats().n_flushes, 1u);
  const sogmm::Gmm& g = map.model().gmm;
  EXPECT_FALSE(has_component(g, wall.gmm, 0));
  EXPECT_FALSE(has_component(g, wall.gmm, 1));
  ASSERT_TRUE(has_component(g, wall.gmm, 2));
  EXPECT_GT(g.size(), 3u);  // the striped frame has many more modes
  // The far component keeps its mass in points (0.2 x 3000), and the refit
  // holds the frame's explained points plus the sampled mass beyond the view
  // (about a fifth of the replaced 2400).
  std::size_t far = 0;
  for (std::size_t j = 0; j < g.size(); ++j)
    if (std::equal(wall.gmm.mean(2), wall.gmm.mean(2) + 4, g.mean(j))) far = j;
  EXPECT_NEAR(g.weights[far] * static_cast<double>(g.support_size), 600.0, 1.0);
  const std::size_t explained = f.n_points - f.n_novel;
  EXPECT_GT(explained, f.n_points / 2);
  EXPECT_GE(g.support_size, 600u + explained + 200u);
  EXPECT_LE(g.support_size, 600u + f.n_points + 2400u);
  // The unseen half of the wall is still mapped (no hole where the replaced
  // components reached beyond the view).
  const double x[3] = {1.0, 0.0, 1.5};
  double ll = 0;
  map.local_log_likelihood(x, 1, &ll);
  EXPECT_GT(ll, map.options().novelty_threshold) << "before the refit: " << log_before_outside;
  // Where the frame sees the wall, the refit follows its stripes: gray is
  // regressed closer to the frame's than the coarse map's constant 0.5.
  std::vector<float> xyz;
  std::vector<float> truth;
  for (int u = 2; u < 62; u += 4) {
    const double z = 1.5, xw = (u - 32.0) * z / 60.0;
    xyz.insert(xyz.end(), {static_cast<float>(xw), 0.0f, static_cast<float>(z)});
    truth.push_back(scene.gray[64 * 24 + u]);
  }
  std::vector<float> mean(truth.size());
  sogmm::regress_gray(g, xyz.data(), truth.size(), mean.data(), nullptr);
  double se_map = 0, se_const = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    se_map += (mean[i] - truth[i]) * (mean[i] - truth[i]);
    se_const += (0.5 - truth[i]) * (0.5 - truth[i]);
  }
  EXPECT_LT(se_map, 0.25 * se_const);
}

// The refit takes the frame's explained points that the replaced components
// dominate, not those under a kept one: a kept component whose mean lies
// beyond the view's edge (x = 0.9) but which dominates the frame's points
// near it keeps them as its mass. Wall components of sigma 0.1 m (x) and
// 0.2 m (y) at x = -/+0.3 hold almost no mass outside the view (3 sigma in
// y), so the refit is those points (plus a few samples): the map's support
// is the kept mass plus the dominated points, counted independently here.
TEST(MapTest, RevisitRefitTakesOnlyThePointsTheReplacedComponentsDominate) {
  const sogmm::Model m = flat_components({-0.3f, 0.3f, 0.9f}, {0.3f, 0.3f, 0.4f}, {0.01f, 0.04f, 4e-6f, 0.04f},
                                         {0.01f, 0.09f, 4e-6f, 0.04f});
  const RefitScene scene(false);
  Map map = Map::from_model(m, refit_options(1.25));
  // Independent truth: the frame's points (identity pose: world = camera),
  // their novelty scores, and the component with the largest
  // weight x N(x | mu, Sigma_xx) by Eigen.
  const sogmm::PointCloud cloud = sogmm::backproject(scene.frame(), sogmm::DepthOptions{});
  std::vector<double> xyz;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    for (int r = 0; r < 3; ++r) xyz.push_back(cloud.xyzg[4 * i + r]);
  std::vector<double> ll(cloud.size());
  map.local_log_likelihood(xyz.data(), cloud.size(), ll.data());
  std::size_t dominated_by_wall = 0, dominated_by_edge = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!(ll[i] >= map.options().novelty_threshold)) continue;
    const Eigen::Vector3d x(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    double best = -INFINITY;
    std::size_t arg = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      const Eigen::Matrix3d c = cov_of(m.gmm, k).topLeftCorner<3, 3>();
      const Eigen::Vector3d d = x - mean_of(m.gmm, k).head<3>();
      const double lp = std::log(m.gmm.weights[k]) - 0.5 * d.dot(c.ldlt().solve(d)) -
                        0.5 * std::log(c.determinant());
      if (lp > best) {
        best = lp;
        arg = k;
      }
    }
    (arg == 2 ? dominated_by_edge : dominated_by_wall) += 1;
  }
  ASSERT_GT(dominated_by_edge, 100u);  // the edge component reaches well into the view
  const sogmm::FrameStats f = map.insert_rgbd(scene.frame(), kIdentity);
  ASSERT_EQ(f.n_replaced, 2u);
  const sogmm::Gmm& g = map.model().gmm;
  ASSERT_TRUE(has_component(g, m.gmm, 2));
  const std::uint64_t kept = static_cast<std::uint64_t>(std::round(3000.0 * static_cast<double>(0.4f)));
  EXPECT_GE(g.support_size, kept + dominated_by_wall);
  EXPECT_LE(g.support_size, kept + dominated_by_wall + 30);  // a few samples beyond the view's y edges
}

// The ratio is a hysteresis (spec/api.md, MAP_REVISIT_REFIT_RATIO): after a
// refit, the same frame again has about as many modes as the refit left
// components on its surface, short of the default 1.25 times as many, so
// repeating it runs no refit and the map keeps its size (issue 36: at ratio
// 1, with no margin, a loop's map crept from 2221 to 2451 components over
// 16 laps of the same frames). At ratio 1 the count may only grow by what a
// refit adds; this checks the default holds still.
TEST(MapTest, RevisitRefitAtTheDefaultRatioDoesNotCreepOnRepeats) {
  const RefitScene scene(false);
  Map map = Map::from_model(coarse_wall(), refit_options(MapOptions{}.revisit_refit_ratio));
  map.insert_rgbd(scene.frame(), kIdentity);
  ASSERT_EQ(map.stats().n_refits, 1u);
  const sogmm::Gmm after = map.model().gmm;
  for (int lap = 0; lap < 6; ++lap) {
    const sogmm::FrameStats f = map.insert_rgbd(scene.frame(), kIdentity);
    EXPECT_EQ(f.n_replaced, 0u) << "lap " << lap;
    EXPECT_EQ(map.model().gmm.size(), after.size()) << "lap " << lap;
  }
  EXPECT_EQ(map.stats().n_refits, 1u);
  // The refit's components are exactly symmetric, as the file stores them.
  const sogmm::Gmm& g = map.model().gmm;
  for (std::size_t k = 0; k < g.size(); ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        ASSERT_EQ(g.covariance(k)[4 * i + j], g.covariance(k)[4 * j + i]) << "component " << k << " entry " << i << j;
}

TEST(MapTest, RevisitRefitIsOffAtRatioZeroAndBelowTheRatio) {
  const sogmm::Model wall = coarse_wall();
  const RefitScene scene;
  for (double ratio : {0.0, 1000.0}) {
    SCOPED_TRACE(ratio);
    Map map = Map::from_model(wall, refit_options(ratio));
    const sogmm::FrameStats f = map.insert_rgbd(scene.frame(), kIdentity);
    EXPECT_EQ(f.n_replaced, 0u);
    EXPECT_EQ(map.stats().n_refits, 0u);
    EXPECT_EQ(map.model().gmm.weights, wall.gmm.weights);
    EXPECT_EQ(map.model().gmm.means, wall.gmm.means);
  }
  // Points-only inserts carry no camera: no refit, even once an RGB-D frame
  // (turned away from the wall: it sees none of it) has fixed the camera.
  Map map = Map::from_model(wall, refit_options(1.0));
  map.insert_rgbd(scene.frame(), pose_y(3.14159265358979, 0, 0, 0));
  ASSERT_EQ(map.stats().n_refits, 0u);
  const sogmm::PointCloud cloud = sogmm::backproject(scene.frame(), sogmm::DepthOptions{});
  map.insert_points(cloud.view(), kIdentity);
  EXPECT_EQ(map.stats().n_refits, 0u);
  // The cases without a refit: a fixed K (no mode count to compare), a warm
  // start. Each insert succeeds. (A map of unknown support size is refused
  // at load: MapValidity.AModelOfUnknownSupportIsRefusedAsAMap.)
  {
    MapOptions fixed_k = refit_options(1.0);
    fixed_k.fit.n_components = 40;
    MapOptions warm = refit_options(1.0);
    warm.warm_start = true;
    for (const MapOptions& o : {fixed_k, warm}) {
      Map m = Map::from_model(wall, o);
      m.insert_rgbd(scene.frame(), kIdentity);
      EXPECT_EQ(m.stats().n_refits, 0u);
      EXPECT_EQ(m.model().gmm.means, wall.gmm.means);
    }
  }
  // Validation.
  for (double bad : {0.5, -1.0, double(NAN), double(INFINITY)}) {
    MapOptions o;
    o.revisit_refit_ratio = bad;
    expect_error([&] { Map m(o); }, ErrorCode::InvalidArgument, {"revisit_refit_ratio"}, "bad ratio");
  }
}

TEST(MapTest, RevisitRefitIsTheSameForAnyThreadCountAndUndoneWhenCancelled) {
  const sogmm::Model wall = coarse_wall();
  const RefitScene scene;
  Map one = Map::from_model(wall, refit_options(1.5, 1));
  Map two = Map::from_model(wall, refit_options(1.5, 2));
  one.insert_rgbd(scene.frame(), kIdentity);
  two.insert_rgbd(scene.frame(), kIdentity);
  ASSERT_EQ(one.stats().n_refits, 1u);
  EXPECT_EQ(one.model().gmm.weights, two.model().gmm.weights);
  EXPECT_EQ(one.model().gmm.means, two.model().gmm.means);
  EXPECT_EQ(one.model().gmm.covariances, two.model().gmm.covariances);
  EXPECT_EQ(one.model().gmm.support_size, two.model().gmm.support_size);

  // Everything an insert may change, to compare before and after.
  auto state = [](const Map& m) {
    return std::make_tuple(m.model().gmm.weights, m.model().gmm.means, m.model().gmm.covariances,
                           m.model().gmm.support_size, m.pending(), m.frames().size(), m.stats().n_refits,
                           m.stats().n_flushes);
  };
  Map map = Map::from_model(wall, refit_options(1.5));
  const auto before = state(map);
  const sogmm::ProgressSink cancel = [](const sogmm::Progress&) { return true; };
  expect_error([&] { map.insert_rgbd(scene.frame(), kIdentity, cancel); }, ErrorCode::Cancelled, {"cancelled"},
               "cancelled refit");
  EXPECT_TRUE(state(map) == before);
  {
    // The failed first RGB-D insert did not fix the camera: another camera is
    // accepted (in a copy of the map, which stays as it was).
    Map copy = Map::from_model(wall, refit_options(1.5));
    expect_error([&] { copy.insert_rgbd(scene.frame(), kIdentity, cancel); }, ErrorCode::Cancelled, {"cancelled"},
                 "cancelled refit");
    sogmm::Camera other = scene.cam;
    other.fx = other.fy = 50.0;
    EXPECT_NO_THROW(copy.insert_rgbd({scene.depth.data(), scene.gray.data(), other}, kIdentity));
  }
  // A later step of the insert failing undoes the refit too: a batch of 1
  // flushes this frame's novel points (the box), and a cancelling callback
  // that lets the refit's fit through (the first fit) stops the flush's.
  MapOptions o = refit_options(1.5);
  o.batch_size = 1;
  Map undo = Map::from_model(wall, o);
  const auto undo_before = state(undo);
  int fits = 0;
  sogmm::Stage last = sogmm::Stage::Em;
  const sogmm::ProgressSink second = [&](const sogmm::Progress& p) {
    if (p.stage == sogmm::Stage::ModeCount && last != sogmm::Stage::ModeCount) ++fits;
    last = p.stage;
    return fits >= 2;
  };
  expect_error([&] { undo.insert_rgbd(scene.frame(), kIdentity, second); }, ErrorCode::Cancelled, {"cancelled"},
               "cancelled flush after a refit");
  EXPECT_EQ(fits, 2);
  EXPECT_TRUE(state(undo) == undo_before);
  // The same insert then succeeds: refit and flush.
  const sogmm::FrameStats f = undo.insert_rgbd(scene.frame(), kIdentity);
  EXPECT_TRUE(f.flushed);
  EXPECT_EQ(undo.stats().n_refits, 1u);
  EXPECT_EQ(undo.stats().n_flushes, 2u);
}
